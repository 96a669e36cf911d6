#!/usr/bin/env python3
"""The hub's edge under mesh refinement: a singularity, next to nominal values
that converge.

Where the fit ends at the hub's face the hub's bore corner presses on the
shaft like a rigid punch's edge: the elastic contact pressure and the stress
there are singular. This study runs the test shaft TS on the hexahedra of the
section mesher (tests/ts_hex_symmetry.prm, statics at rest only: no modes,
speed 0) at a sequence of fit element sizes (Geometry/Sections/Fit element
size; Element size stays at the file's 10 mm, the mesher grades from the fit)
and collects per mesh: DOFs, the mean pressure, the edge peak ratio
p_max / p_mean, the hub's (body sleeve) nominal bore von Mises stress at the
fit's mid-plane (DIN 7190's design value), the hub's largest von Mises stress
and where it sits (at the edge: bore radius 10 mm, z = 0.11 or 0.15 m), and
the shaft's nominal and largest values. It fits the growth exponent of the
peaks, p_max / p_mean ~ h^-alpha, by least squares on log-log axes.

    /usr/bin/python3 benchmarks/edge_peak.py [--sizes 4,2,1,0.5] [--work DIR]
                                             [--no-run]
(repository root, build/rotorfit built, or ROTORFIT=/path/to/rotorfit;
python3 with matplotlib). One run at a time, each under /usr/bin/time -v; a
finer mesh is skipped once a run took more than 180 s or 6 GB (resident).
--no-run collects the outputs already in the work folder.

Writes the runs into DIR/<h_mm>/ (default /tmp/edgepeak), the table
benchmarks/edge_peak.csv, the plot doc/images/edge_peak.png, and prints the
table (Markdown) and the fitted exponents.
"""
import argparse
import csv
import math
import os
import re
import subprocess
import sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
exe = os.environ.get("ROTORFIT", os.path.join(root, "build", "rotorfit"))
prm = os.path.join(root, "tests", "ts_hex_symmetry.prm")
ELEMENT_SIZE = 10e-3          # m, the file's Element size (away from the fit)
BORE, EDGES = 0.010, (0.11, 0.15)  # the hub's bore radius and faces [m]
LIMIT_S, LIMIT_KIB = 180., 6e9 / 1024.  # stop refining past 3 min or 6 GB

ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
ap.add_argument("--sizes", default="4,2,1,0.5", help="fit element sizes [mm]")
ap.add_argument("--work", default="/tmp/edgepeak", help="scratch folder of the runs")
ap.add_argument("--no-run", action="store_true", help="collect existing outputs only")
args = ap.parse_args()
sizes = [float(s) for s in args.sizes.split(",")]


def tag(h_mm):
    return f"{h_mm:g}"


def run(h_mm):
    """One static run at rest at fit element size h_mm [mm]; returns (wall s, peak KiB)."""
    out = os.path.join(args.work, tag(h_mm))
    cmd = ["/usr/bin/time", "-v", exe, "--output", out,
           "--set", f"Geometry/Sections/Fit element size={h_mm * 1e-3:g}",
           "--set", f"Geometry/Sections/Element size={max(ELEMENT_SIZE, h_mm * 1e-3):g}",
           "--set", "Eigenproblem/Compute modes=false",
           "--set", "Speeds/Mode=list", "--set", "Speeds/List=0",
           "--set", "Unbalances=",
           "--set", "Output/Write ParaView files=false", "--set", "Output/Pictures=false",
           prm]
    print("running:", " ".join(cmd[2:]), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "time.txt"), "w") as f:
        f.write(r.stderr)
    if r.returncode != 0:
        sys.exit(f"rotorfit failed at h = {h_mm} mm (exit {r.returncode}):\n{r.stdout}\n{r.stderr}")
    return read_time(out)


def read_time(out):
    text = open(os.path.join(out, "time.txt")).read()
    m = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", text)
    wall = (int(m.group(1) or 0) * 3600 + int(m.group(2)) * 60 + float(m.group(3))) if m else math.nan
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    return wall, (int(m.group(1)) if m else math.nan)


def collect(h_mm):
    out = os.path.join(args.work, tag(h_mm))
    log = open(os.path.join(out, "log.txt")).read()
    m = re.search(r"Mesh: (\d+) \S+, (\d+) DOFs", log)
    cells, dofs = int(m.group(1)), int(m.group(2))
    m = re.search(r"Interface fit: (\d+) node pairs", log)
    pairs = int(m.group(1))
    fit = [r for r in csv.DictReader(open(os.path.join(out, "fit.csv")))
           if float(r["speed_rpm"]) == 0 and r["interface"] == "fit"][0]
    body = {r["body"]: r for r in csv.DictReader(open(os.path.join(out, "body_stress.csv")))
            if float(r["speed_rpm"]) == 0}
    wall, kib = read_time(out)
    row = {"fit_element_size_mm": h_mm, "cells": cells, "dofs": dofs, "pairs": pairs,
           "wall_s": round(wall, 1), "peak_rss_MiB": round(kib / 1024.),
           "mean_pressure_MPa": float(fit["mean_pressure_Pa"]) / 1e6,
           "edge_peak_ratio": float(fit["edge_peak_ratio"]),
           "hub_nominal_vm_MPa": float(fit["hub_bore_von_mises_Pa"]) / 1e6,
           "shaft_nominal_vm_MPa": float(fit["shaft_bore_von_mises_Pa"]) / 1e6}
    for name, key in (("sleeve", "hub"), ("shaft", "shaft")):
        b = body[name]
        x, y, z = (float(b[k]) for k in ("x_m", "y_m", "z_m"))
        r = math.hypot(x, y)
        dz = min(abs(z - e) for e in EDGES)
        row[f"{key}_max_vm_MPa"] = float(b["max_von_mises_Pa"]) / 1e6
        row[f"{key}_max_r_mm"] = r * 1e3
        row[f"{key}_max_z_mm"] = z * 1e3
        # at the edge: within one fit element of the bore corner (r = 10 mm, z = 110 or 150 mm)
        row[f"{key}_max_at_edge"] = int(abs(r - BORE) <= 1.01 * h_mm * 1e-3 and dz <= 1.01 * h_mm * 1e-3)
    row["hub_max_over_nominal"] = row["hub_max_vm_MPa"] / row["hub_nominal_vm_MPa"]
    row["shaft_max_over_nominal"] = row["shaft_max_vm_MPa"] / row["shaft_nominal_vm_MPa"]
    return row


def slope(xs, ys):
    """Least-squares slope of log y over log x."""
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


rows = []
for h in sizes:
    if not args.no_run:
        wall, kib = run(h)
        print(f"  h = {h:g} mm: {wall:.1f} s, {kib / 1024.:.0f} MiB", flush=True)
    elif not os.path.exists(os.path.join(args.work, tag(h), "log.txt")):
        continue
    rows.append(collect(h))
    if not args.no_run and (wall > LIMIT_S or kib > LIMIT_KIB):
        print(f"  stop: h = {h:g} mm took {wall:.0f} s / {kib / 1024.**2:.1f} GiB; no finer mesh")
        break
if len(rows) < 2:
    sys.exit("fewer than two meshes: nothing to fit")

cols = list(rows[0].keys())
with open(os.path.join(root, "benchmarks", "edge_peak.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=cols, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})

print("| fit element size [mm] | DOFs | p_mean [MPa] | p_max / p_mean | hub nominal vM [MPa] "
      "| hub max vM [MPa] (r, z [mm]) | hub max / nominal | shaft nominal vM [MPa] "
      "| shaft max vM [MPa] | wall [s] | memory [MiB] |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['fit_element_size_mm']:g} | {r['dofs']:,} | {r['mean_pressure_MPa']:.3f} "
          f"| {r['edge_peak_ratio']:.3f} | {r['hub_nominal_vm_MPa']:.3f} "
          f"| {r['hub_max_vm_MPa']:.1f} ({r['hub_max_r_mm']:.2f}, {r['hub_max_z_mm']:.2f}"
          f"{', edge' if r['hub_max_at_edge'] else ''}) | {r['hub_max_over_nominal']:.3f} "
          f"| {r['shaft_nominal_vm_MPa']:.3f} | {r['shaft_max_vm_MPa']:.1f} "
          f"| {r['wall_s']:.0f} | {r['peak_rss_MiB']} |")

h = [r["fit_element_size_mm"] for r in rows]
series = {"p_max / p_mean": [r["edge_peak_ratio"] for r in rows],
          "hub max vM / nominal vM": [r["hub_max_over_nominal"] for r in rows],
          "shaft max vM / nominal vM": [r["shaft_max_over_nominal"] for r in rows]}
alpha = {}
for name, ys in series.items():
    alpha[name] = (-slope(h, ys), -slope(h[-2:], ys[-2:]))
    print(f"growth exponent of {name} ~ h^-alpha: alpha = {alpha[name][0]:.3f} (all meshes), "
          f"{alpha[name][1]:.3f} (two finest, the one to quote: coarse meshes do not resolve "
          f"the corner)")
for name, key in (("p_mean", "mean_pressure_MPa"), ("hub nominal vM", "hub_nominal_vm_MPa"),
                  ("shaft nominal vM", "shaft_nominal_vm_MPa")):
    ys = [r[key] for r in rows]
    print(f"{name}: change over the two finest meshes {(ys[-1] - ys[-2]) / ys[-1]:+.2e} (relative)")

import matplotlib  # noqa: E402 (only needed for the plot)
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

fig, ax = plt.subplots(figsize=(6.4, 4.4))
for (name, ys), mk in zip(series.items(), ("o", "s", "^")):
    ax.loglog(h, ys, mk + "-", label=f"{name} (finest slope alpha = {alpha[name][1]:.2f})")
for name, key, mk in (("p_mean / finest", "mean_pressure_MPa", "x"),
                      ("hub nominal vM / finest", "hub_nominal_vm_MPa", "+")):
    ys = [r[key] / rows[-1][key] for r in rows]
    ax.loglog(h, ys, mk + "--", color="0.4", label=name)
ax.invert_xaxis()
ax.set_xticks(h)
ax.set_xticklabels([f"{x:g}\n{r['dofs'] / 1e3:.0f}k" for x, r in zip(h, rows)])
ax.minorticks_off()
ticks = [0.9, 1, 1.2, 1.5, 2, 2.5, 3]
ax.set_yticks([t for t in ticks if 0.8 * min(min(v) for v in series.values()) <= t
               <= 1.25 * max(max(v) for v in series.values())])
ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
ax.set_xlabel("fit element size [mm] / DOFs")
ax.set_ylabel("ratio [-]")
ax.set_title("TS (hexahedra) at rest: the hub's edge under refinement")
ax.grid(True, which="major", alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
png = os.path.join(root, "doc", "images", "edge_peak.png")
fig.savefig(png, dpi=110)
print("wrote", os.path.join(root, "benchmarks", "edge_peak.csv"), "and", png)
