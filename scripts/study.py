#!/usr/bin/env python3
"""rotorfit's study driver: one case over a list of settings, one table.

    python3 scripts/study.py STUDY.json [--rotorfit PATH] [--output DIR]

STUDY.json names the case (a .prm, relative to the study file), the speeds of
the static sweep (dense around the fit's opening: the half-open speed is
interpolated in them), the speeds of the modal runs, entries set on every run,
and series of runs. Each run of a series is the case with its own entries set
(rotorfit --set 'Subsection/Entry=value'); a series is one method refined
step by step (finer element sizes, more refinement cycles). Per run: DOFs,
wall time and peak memory of both runs, first, half and full opening speed,
mean contact pressure at rest, the constraint error, the whirl pairs at the
modal speeds, the 1X critical speeds. Per series and quantity, from its three
finest runs: the Richardson-extrapolated value and the observed order, with
the effective element size h = DOFs^(-1/3) (on the harmonic model's meridian
DOFs^(-1/2), its largest harmonic's DoFs; doc/accuracy.md); each run's error
against it. "one run": true solves every run once at the static and the modal
speeds together (an adaptive mesh whose indicator needs the modes is then the
same for all quantities).

{
  "case": "../prm/test_shaft.prm",
  "static speeds": "0, 20000, 20500, 21000",
  "modal speeds": "0, 10000, 20000",
  "pairs": 2,
  "set": {"Output/Write ParaView files": "false"},
  "series": [
    {"name": "tet P2", "set": {"Geometry/Mesher": "gmsh"},
     "runs": [{"Geometry/Geometry parameters": "h_fit: 4e-3, h_max: 8e-3"}, ...]}
  ]
}

Writes DIR/study.csv (one row per run), DIR/extrapolated.csv (one row per
series and quantity) and DIR/study.md (both as Markdown tables); each run's
results stay in DIR/<series>/<run>/{static,modal}/.
"""
import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_common  # noqa: E402


def run_rotorfit(exe, prm, out, sets, reuse=False):
    """Run rotorfit; return (log text, wall seconds, peak resident MB, CPU
    seconds of the process and its threads). With
    REUSE a completed earlier run in OUT (its cost in OUT/cost.json) is read
    instead."""
    cost = os.path.join(out, "cost.json")
    if reuse and os.path.exists(cost) and \
            summary(out).get("run.status") == "completed" and \
            json.load(open(cost)).get("sets", sets) == sets:
        c = json.load(open(cost))
        return (open(os.path.join(out, "stdout.txt")).read(), c["wall_s"], c["peak_mb"],
                c.get("cpu_s", math.nan))
    os.makedirs(out, exist_ok=True)
    args = [exe, "--output", out]
    for k, v in sets.items():
        args += ["--set", f"{k}={v}"]
    args.append(prm)
    start = time.time()
    with open(os.path.join(out, "stdout.txt"), "w") as log, \
            open(os.path.join(out, "stderr.txt"), "w") as err:
        p = subprocess.Popen(args, stdout=log, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
    wall = time.time() - start
    text = open(os.path.join(out, "stdout.txt")).read()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"study: rotorfit failed in {out} (exit {os.waitstatus_to_exitcode(status)}):\n"
                 + open(os.path.join(out, "stderr.txt")).read())
    cpu = usage.ru_utime + usage.ru_stime
    json.dump({"wall_s": wall, "cpu_s": cpu, "peak_mb": usage.ru_maxrss / 1024.0, "sets": sets},
              open(cost, "w"))
    return text, wall, usage.ru_maxrss / 1024.0, cpu


def summary(out):
    return plot_common.summary_values(os.path.join(out, "summary.txt"))


def num(x):
    return plot_common.num(x, math.nan)


def half_open(out, interface):
    """Speed where the contact fraction falls through 0.5 (linear between speeds)."""
    rows = [r for r in plot_common.read_csv(os.path.join(out, "contact.csv"))
            if r["interface"] == interface]
    for a, b in zip(rows, rows[1:]):
        fa, fb = num(a["contact_fraction"]), num(b["contact_fraction"])
        if fa >= 0.5 > fb:
            wa, wb = num(a["speed_rpm"]), num(b["speed_rpm"])
            return wa + (fa - 0.5) / (fa - fb) * (wb - wa)
    return math.nan


def whirl_pairs(out, speeds, n_pairs):
    """{'f1b@0': Hz, 'f1f@0': Hz, ...}: the lateral pairs in order of frequency."""
    rows = plot_common.read_csv(os.path.join(out, "campbell.csv"))
    q = {}
    for rpm in speeds:
        at = [r for r in rows if num(r["speed_rpm"]) == rpm]
        bw = sorted(num(r["frequency_hz"]) for r in at if r["whirl"] == "backward")
        fw = sorted(num(r["frequency_hz"]) for r in at if r["whirl"] == "forward")
        for k in range(n_pairs):
            q[f"f{k + 1}b@{rpm:g}"] = bw[k] if k < len(bw) else math.nan
            q[f"f{k + 1}f@{rpm:g}"] = fw[k] if k < len(fw) else math.nan
    return q


def critical_speeds(out, n_pairs):
    """The 1X crossings of the first pairs' lines, backward and forward."""
    q = {}
    rows = plot_common.read_csv(os.path.join(out, "critical_speeds.csv"))
    for whirl, tag in (("backward", "b"), ("forward", "f")):
        found = sorted(num(r["speed_rpm"]) for r in rows
                       if r["whirl"] == whirl and num(r["order"]) == 1)
        for k in range(n_pairs):
            q[f"crit{k + 1}{tag}"] = found[k] if k < len(found) else math.nan
    return q


def richardson(h, f):
    """Extrapolated value and observed order from three (h, f), h decreasing:
    f = f0 + C h^p, p solved by bisection on (f1 - f2)/(f2 - f3)."""
    (h1, h2, h3), (f1, f2, f3) = h, f
    if any(math.isnan(x) for x in f) or f2 == f3 or f1 == f2:
        return (f3 if f1 == f2 == f3 else math.nan), math.nan
    ratio = (f1 - f2) / (f2 - f3)
    g = lambda p: (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - ratio
    lo, hi = 0.05, 12.0
    if ratio <= 0 or g(lo) * g(hi) > 0:
        return math.nan, math.nan  # not monotone: no asymptotic range yet
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    c = (f2 - f3) / (h2 ** p - h3 ** p)
    return f3 - c * h3 ** p, p


def run_one(study, base_dir, exe, out, sets, reuse):
    case = os.path.normpath(os.path.join(base_dir, study["case"]))
    common = dict(study.get("set", {}))
    common.update(sets)
    modal = dict(common)
    modal.update({"Speeds/Mode": "list", "Speeds/List": study["modal speeds"],
                  "Output/Pictures": "false", "Output/Write ParaView files": "false",
                  "Eigenproblem/Write mode shapes": "false"})
    if study.get("one run"):
        # one run at every static and modal speed: an adaptive mesh whose
        # indicator needs the modes is then the same for both
        speeds = sorted({num(x) for x in (study["static speeds"] + "," +
                                          study["modal speeds"]).split(",")})
        modal["Speeds/List"] = ", ".join(f"{x:g}" for x in speeds)
        log_m, wall_m, mem_m, cpu_m = run_rotorfit(exe, case, os.path.join(out, "modal"), modal,
                                                   reuse)
        log_s, wall_s, mem_s, cpu_s = log_m, 0.0, 0.0, 0.0
        static_dir = os.path.join(out, "modal")
    else:
        static = dict(common)
        # the static sweep: no eigenproblem, so no unbalance response either
        static.update({"Unbalances": "", "Probes": "",
                       "Speeds/Mode": "list", "Speeds/List": study["static speeds"],
                       "Eigenproblem/Compute modes": "false", "Output/Pictures": "false",
                       "Output/Write ParaView files": "false"})
        log_s, wall_s, mem_s, cpu_s = run_rotorfit(exe, case, os.path.join(out, "static"), static,
                                                   reuse)
        log_m, wall_m, mem_m, cpu_m = run_rotorfit(exe, case, os.path.join(out, "modal"), modal,
                                                   reuse)
        static_dir = os.path.join(out, "static")

    s = summary(static_dir)
    interfaces = sorted({k.split(".")[1] for k in s if k.startswith("interface.")})
    f = interfaces[0] if interfaces else ""
    # the last mesh of the log: refinement cycles log theirs before it
    found = re.findall(r"Mesh: (\d+) (\w+), (\d+) DOFs \((\w+)", log_s)
    m = found[-1] if found else None
    meridian = re.findall(r"Meridian mesh: (\d+) quadrilaterals", log_s)
    if not m and meridian:
        # the harmonic model: its largest harmonic's DoFs (harmonic 1's)
        last = log_s[log_s.rindex("Meridian mesh:"):]
        dofs = max(int(x) for x in re.findall(r"Harmonic \d+: (\d+) DoFs", last))
        m = (meridian[-1], "meridian", str(dofs), "Q2")
    row = {"dofs": int(m[2]) if m else 0, "cells": int(m[0]) if m else 0,
           "element": (m[1][:3] + " " + m[3]) if m else "",
           "wall_s": round(wall_s + wall_m, 2), "static_wall_s": round(wall_s, 2),
           "modal_wall_s": round(wall_m, 2), "cpu_s": round(cpu_s + cpu_m, 2),
           "peak_mb": round(max(mem_s, mem_m), 1),
           "pairs": int(num(s.get(f"interface.{f}.pairs", "nan")) or 0),
           "p0_mpa": num(s.get(f"interface.{f}.mean_pressure_first_speed_Pa")) / 1e6,
           "first_open": num(s.get(f"interface.{f}.first_opening_rpm")),
           # the exact path's event, else interpolated between the static speeds
           "half_open": num(s[f"interface.{f}.half_open_rpm"])
           if f"interface.{f}.half_open_rpm" in s else half_open(static_dir, f),
           "full_open": num(s.get(f"interface.{f}.loss_of_fit_rpm")),
           "constraint_error": num(s.get(f"interface.{f}.constraint_error_max"))}
    speeds = [num(x) for x in study["modal speeds"].split(",")]
    row.update(whirl_pairs(os.path.join(out, "modal"), speeds, study.get("pairs", 2)))
    row.update(critical_speeds(os.path.join(out, "modal"), study.get("pairs", 2)))
    return row


QUANTITIES_FIXED = ["p0_mpa", "first_open", "half_open", "full_open"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("study")
    ap.add_argument("--rotorfit", default=os.environ.get("ROTORFIT", "rotorfit"))
    ap.add_argument("--output", default=None)
    ap.add_argument("--reuse", action="store_true",
                    help="read the completed runs already in the output folder instead of "
                         "running them again (after an interrupted study, or to add runs)")
    a = ap.parse_args()
    study = json.load(open(a.study))
    base_dir = os.path.dirname(os.path.abspath(a.study))
    out_dir = a.output or os.path.join(os.getcwd(), "study_" + os.path.splitext(os.path.basename(a.study))[0])
    for key in ("case", "static speeds", "modal speeds", "series"):
        if key not in study:
            sys.exit(f"study: '{a.study}' has no \"{key}\"")
    rows = []
    for series in study["series"]:
        for i, run in enumerate(series["runs"]):
            sets = dict(series.get("set", {}))
            sets.update(run)
            name = re.sub(r"[^A-Za-z0-9]+", "_", series["name"]).strip("_")
            out = os.path.join(out_dir, name, str(i))
            print(f"study: {series['name']} run {i}: {sets}", flush=True)
            row = {"series": series["name"], "run": i}
            row.update(run_one(study, base_dir, a.rotorfit, out, sets, a.reuse))
            rows.append(row)
            write_table(out_dir, rows)  # finished runs survive a stopped study
            print(f"  {row['dofs']} DOFs, {row['wall_s']} s, {row['peak_mb']} MB", flush=True)

    quantities = [k for k in rows[0] if k in QUANTITIES_FIXED or "@" in k or k.startswith("crit")]
    extrapolated = []
    for series in study["series"]:
        mine = [r for r in rows if r["series"] == series["name"]]
        mine.sort(key=lambda r: r["dofs"])
        for q in quantities:
            value, order = math.nan, math.nan
            if len(mine) >= 3:
                last = mine[-3:]
                # a meridian (the harmonic model) is a plane mesh: h = DOFs^(-1/2)
                dim = 2 if last[0]["element"].startswith("mer") else 3
                value, order = richardson([r["dofs"] ** (-1 / dim) for r in last],
                                          [r[q] for r in last])
            extrapolated.append({"series": series["name"], "quantity": q,
                                 "extrapolated": value, "observed_order": order,
                                 "finest": mine[-1][q] if mine else math.nan})
            for r in mine:
                r[f"err_{q}"] = (r[q] - value) / value if value and not math.isnan(value) else math.nan

    write_table(out_dir, rows)
    with open(os.path.join(out_dir, "extrapolated.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(extrapolated[0].keys()))
        w.writeheader()
        w.writerows(extrapolated)
    with open(os.path.join(out_dir, "study.md"), "w") as md:
        cols = ["series", "run", "element", "dofs", "wall_s", "peak_mb"] + quantities
        md.write("| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n")
        for r in rows:
            md.write("| " + " | ".join(fmt(r.get(c)) for c in cols) + " |\n")
        md.write("\n| series | quantity | finest | extrapolated | observed order |\n"
                 "|---|---|---|---|---|\n")
        for e in extrapolated:
            md.write(f"| {e['series']} | {e['quantity']} | {fmt(e['finest'])} | "
                     f"{fmt(e['extrapolated'])} | {fmt(e['observed_order'])} |\n")
    print(f"study: {len(rows)} runs; {out_dir}/study.csv, extrapolated.csv, study.md")


def write_table(out_dir, rows):
    os.makedirs(out_dir, exist_ok=True)
    keys = []
    for r in rows:
        for k in r:
            if k not in keys:
                keys.append(k)
    with open(os.path.join(out_dir, "study.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def fmt(x):
    if isinstance(x, float):
        return "nan" if math.isnan(x) else f"{x:.6g}"
    return str(x)


if __name__ == "__main__":
    main()
