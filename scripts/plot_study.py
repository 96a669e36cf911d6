#!/usr/bin/env python3
"""Accuracy against cost from a study (scripts/study.py): for each quantity,
the relative error of every run against a reference value, against DOFs and
against wall time, one line per series (method).

    python3 scripts/plot_study.py STUDY_DIR [STUDY_DIR ...] [--quantities q1,q2] \
        [--reference SERIES] [--title TEXT] [--output PREFIX]

Several study folders draw their series on the same axes (a folder needs a
study.csv; its extrapolated.csv is optional).

The reference value of a quantity is the Richardson-extrapolated value of the
reference series (default: the series whose finest run has the most DOFs,
among those with an extrapolated value); --value q=v gives it directly (an
analytic value). Writes PREFIX_<quantity>.png (default STUDY_DIR/error) and
prints the table of errors it drew.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_common  # noqa: E402

LABELS = {"p0_mpa": "contact pressure at rest", "first_open": "first opening speed",
          "half_open": "half-open speed", "full_open": "full-opening speed"}


def label(q):
    if q in LABELS:
        return LABELS[q]
    if "@" in q:
        f, rpm = q.split("@")
        kind = {"b": "backward", "f": "forward"}[f[-1]]
        return f"pair {f[1:-1]} {kind} whirl at {float(rpm):,.0f} r/min"
    if q.startswith("crit"):
        kind = {"b": "backward", "f": "forward"}[q[-1]]
        return f"1X critical speed {q[4:-1]} ({kind})"
    return q


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("study_dir", nargs="+")
    ap.add_argument("--quantities", default="")
    ap.add_argument("--reference", default="")
    ap.add_argument("--value", action="append", default=[])
    ap.add_argument("--title", default="")
    ap.add_argument("--output", default="")
    ap.add_argument("--cost", choices=("wall", "cpu"), default="wall",
                    help="x axis of the right panel: wall time, or CPU time of the process and "
                         "its threads (steadier on a shared machine)")
    a = ap.parse_args()
    rows, ext = [], []
    for d in a.study_dir:
        found = plot_common.read_csv(os.path.join(d, "study.csv"))
        if not found:
            sys.exit(f"plot_study: no study.csv in {d}")
        rows += found
        if os.path.exists(os.path.join(d, "extrapolated.csv")):
            ext += plot_common.read_csv(os.path.join(d, "extrapolated.csv"))
    series = []
    for r in rows:
        if r["series"] not in series:
            series.append(r["series"])
    quantities = [q for q in a.quantities.split(",") if q] or \
        sorted({e["quantity"] for e in ext})
    given = dict(v.split("=", 1) for v in a.value)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    prefix = a.output or os.path.join(a.study_dir[0], "error")
    for q in quantities:
        if q in given:
            ref, ref_name = float(given[q]), "given value"
        else:
            candidates = [e for e in ext if e["quantity"] == q and
                          plot_common.num(e["extrapolated"]) is not None and
                          (not a.reference or e["series"] == a.reference)]
            if not candidates:
                print(f"plot_study: {q}: no reference value (no extrapolated value); skipped")
                continue
            best = max(candidates, key=lambda e: max(plot_common.num(r["dofs"], 0) for r in rows
                                                     if r["series"] == e["series"]))
            ref, ref_name = plot_common.num(best["extrapolated"]), \
                f"extrapolated {best['series']}"
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
        print(f"\n{label(q)}: reference {ref:.7g} ({ref_name})")
        cost_key = "wall_s" if a.cost == "wall" else "cpu_s"
        print(f"| series | DOFs | {a.cost} [s] | value | error |\n|---|---|---|---|---|")
        for s in series:
            pts = []
            for r in rows:
                v = plot_common.num(r.get(q))
                if r["series"] == s and v is not None:
                    err = abs(v - ref) / abs(ref)
                    pts.append((plot_common.num(r["dofs"]), plot_common.num(r.get(cost_key)), v, err))
                    print(f"| {s} | {r['dofs']} | {r.get(cost_key)} | {v:.7g} | {err:.2e} |")
            pts.sort()
            ok = [p for p in pts if p[3] > 0]
            if not ok:
                continue
            axes[0].loglog([p[0] for p in ok], [p[3] for p in ok], "o-", label=s)
            timed = [p for p in ok if p[1] is not None]
            axes[1].loglog([p[1] for p in timed], [p[3] for p in timed], "o-", label=s)
        xlabel = "wall time" if a.cost == "wall" else "CPU time"
        for ax, xl in zip(axes, ("DOFs", f"{xlabel} of the study's runs [s]")):
            ax.set_xlabel(xl)
            ax.grid(True, which="both", alpha=0.3)
            for level, style in ((1e-2, ":"), (1e-3, "--")):
                ax.axhline(level, color="grey", ls=style, lw=0.8)
        axes[0].set_ylabel(f"relative error ({ref_name} {ref:.6g})")
        axes[0].legend(fontsize=8)
        fig.suptitle(a.title + (": " if a.title else "") + label(q))
        fig.tight_layout()
        path = f"{prefix}_{q.replace('@', '_at_')}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        print(f"Picture: {path}")


if __name__ == "__main__":
    main()
