#!/usr/bin/env python3
"""Contact state of the fits over speed: reads OUTDIR/contact.csv (required: speed_rpm, interface,
closed_pairs, total_pairs, contact_fraction, mean_pressure_Pa, max_pressure_Pa, converged,
first_opening_rpm, loss_of_fit_rpm, status, ...; one row per speed and interface) and, if present,
OUTDIR/summary.txt (interface.NAME.first_opening_rpm / loss_of_fit_rpm / loss_of_fit_within_sweep,
run.status, run.stopped_at) and OUTDIR/pair_openings.csv (interface, opening_rpm per tied pair);
writes OUTDIR/contact.png.

One colour per interface: contact fraction (closed pairs / all pairs) as a solid line with dots on
the left axis (0 .. 1.05), mean contact pressure in MPa as a dashed line on the right axis; the
fraction of pairs not yet opened according to pair_openings.csv (1 - pairs with opening_rpm <= speed
over total_pairs: the opening speeds are interpolated between the sweep speeds) as a thin step line.
Rows whose static state did not converge (converged 0 or a status other than ok) as open squares on
both curves. Per interface, vertical lines with labels: first opening (dash-dot; last finite
first_opening_rpm of contact.csv, else summary.txt), half open (dashed; contact fraction 0.5,
linearly interpolated between the first two speeds around it) and loss of fit (dotted;
summary.txt's loss_of_fit_rpm when loss_of_fit_within_sweep is 1, else the last finite
loss_of_fit_rpm of contact.csv if it lies within the sweep). nan means "not reached": no line; an
event not reached, or a loss-of-fit estimate beyond the sweep, is listed in a note box. Labels never
overlap each other nor leave the axes (label_layout.py: stacked from the top in display coordinates,
leader lines when moved; --check-labels verifies the drawn boxes and exits 1 otherwise).
Title: the case name (the folder's name) and the run status of summary.txt (red when failed or
interrupted). A missing contact.csv or one without rows: message on stderr, exit 1.

Usage: plot_contact.py OUTDIR [--check-labels]
"""
import argparse
import math
import os
import re
import sys

import plot_common
from plot_common import labels_ok, num, read_csv, summary_values

EVENTS = (("first opening", "-."), ("half open", "--"), ("loss of fit", ":"))





def half_open(rows):
    """Speed where the contact fraction first falls to 0.5 (linear between speeds), or None."""
    pts = [(r["rpm"], r["fraction"]) for r in rows if r["fraction"] is not None]
    for (s0, f0), (s1, f1) in zip(pts, pts[1:]):
        if f0 >= 0.5 > f1:
            return s0 + (f0 - 0.5) / (f0 - f1) * (s1 - s0)
    if pts and pts[0][1] == 0.5:
        return pts[0][0]
    return None


def events(name, rows, summary, lo, hi):
    """{event: speed or None}, and notes for what is not reached / beyond the sweep."""
    def last(key):
        vals = [r[key] for r in rows if r[key] is not None]
        return vals[-1] if vals else None
    first = last("first_opening")
    if first is None:
        first = num(summary.get(f"interface.{name}.first_opening_rpm"))
    lof, lof_estimate = None, None
    within = summary.get(f"interface.{name}.loss_of_fit_within_sweep")
    if within is not None:
        value = num(summary.get(f"interface.{name}.loss_of_fit_rpm"))
        if num(within) == 1:
            lof = value
        else:
            lof_estimate = value
    else:
        value = last("loss_of_fit")
        if value is not None and lo <= value <= hi:
            lof = value
        else:
            lof_estimate = value
    ev = {"first opening": first, "half open": half_open(rows), "loss of fit": lof}
    notes = []
    for key, rpm in ev.items():
        if rpm is None:
            if key == "loss of fit" and lof_estimate is not None:
                notes.append(f"{name}: loss of fit beyond the sweep (estimate {lof_estimate:,.0f} r/min)")
            else:
                notes.append(f"{name}: {key} not reached")
        elif not lo <= rpm <= hi:
            notes.append(f"{name}: {key} at {rpm:,.0f} r/min, outside the sweep")
            ev[key] = None
    return ev, notes


def pair_closed_fraction(path, totals, speeds):
    """{interface: [(rpm, fraction of pairs not yet opened)]} from pair_openings.csv (step curve)."""
    openings = {}
    for r in read_csv(path):
        rpm = num(r.get("opening_rpm"))
        if rpm is not None:
            openings.setdefault(r.get("interface", ""), []).append(rpm)
    out = {}
    for name, values in openings.items():
        total = totals.get(name)
        if not total or not speeds:
            continue
        values.sort()
        pts = [(speeds[0], 1.0 - sum(v <= speeds[0] for v in values) / total)]
        for i, v in enumerate(values):
            if speeds[0] < v <= speeds[-1]:
                pts.append((v, pts[-1][1]))
                pts.append((v, 1.0 - (i + 1) / total))
        pts.append((speeds[-1], pts[-1][1]))
        out[name] = pts
    return out




def main(outdir, check_labels=False):
    """Draw OUTDIR/contact.png; returns 0, or 1 when check_labels finds a bad label."""
    path = os.path.join(outdir, "contact.csv")
    if not os.path.isfile(path):
        sys.exit(f"plot_contact.py: {path} not found")
    table = read_csv(path)
    if not table and os.path.isfile(os.path.join(outdir, "parameters.prm")) and re.search(
            r"^set Interfaces\s*=\s*$", open(os.path.join(outdir, "parameters.prm")).read(), re.M):
        print("plot_contact.py: the case has no interfaces; no contact.png")
        return 0
    by_interface = {}
    for r in table:
        rpm = num(r.get("speed_rpm"))
        if rpm is None:
            continue
        status = (r.get("status") or "ok").lower()
        by_interface.setdefault(r.get("interface", "") or "fit", []).append(dict(
            rpm=rpm, fraction=num(r.get("contact_fraction")), pressure=num(r.get("mean_pressure_Pa")),
            total=num(r.get("total_pairs")), first_opening=num(r.get("first_opening_rpm")),
            loss_of_fit=num(r.get("loss_of_fit_rpm")),
            converged=r.get("converged", "1") not in ("0", "0.0") and status == "ok"))
    if not by_interface:
        sys.exit(f"plot_contact.py: {path} has no rows with a speed")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        layout_module = plot_common.layout_module()
    except ImportError as e:
        sys.exit(f"plot_contact.py: matplotlib not importable ({e})")
    for rows in by_interface.values():
        rows.sort(key=lambda r: r["rpm"])
    summary = summary_values(os.path.join(outdir, "summary.txt"))
    speeds = sorted({r["rpm"] for rows in by_interface.values() for r in rows})
    lo, hi = speeds[0], speeds[-1]
    totals = {n: next((r["total"] for r in rows if r["total"]), None) for n, rows in by_interface.items()}
    steps = pair_closed_fraction(os.path.join(outdir, "pair_openings.csv"), totals, speeds)

    fig, ax = plt.subplots(figsize=(10.5, 6), dpi=150)
    ax2 = ax.twinx()
    colors = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:cyan"]
    several = len(by_interface) > 1
    handles, items, notes, avoid, pressure_max, used = [], [], [], [], 0.0, set()
    for i, (name, rows) in enumerate(by_interface.items()):
        c = colors[i % len(colors)]
        rpm = [r["rpm"] for r in rows]
        frac = [r["fraction"] if r["fraction"] is not None else math.nan for r in rows]
        mpa = [r["pressure"] / 1e6 if r["pressure"] is not None else math.nan for r in rows]
        ax.plot(rpm, frac, "-", marker="o", ms=3, color=c, lw=1.5, zorder=4)
        ax2.plot(rpm, mpa, "--", color=c, lw=1.2, zorder=3)
        pressure_max = max([pressure_max] + [v for v in mpa if v == v])
        avoid.append(list(zip(rpm, frac)))
        bad = [r for r in rows if not r["converged"]]
        if bad:
            used.add("unconverged")
            ax.plot([r["rpm"] for r in bad], [r["fraction"] if r["fraction"] is not None else math.nan for r in bad],
                    "s", mfc="none", mec="black", ms=8, zorder=5)
            ax2.plot([r["rpm"] for r in bad], [r["pressure"] / 1e6 if r["pressure"] is not None else math.nan
                                               for r in bad], "s", mfc="none", mec="black", ms=8, zorder=5)
        if name in steps:
            ax.plot([p[0] for p in steps[name]], [p[1] for p in steps[name]], color=c, lw=0.7, alpha=0.6, zorder=3)
            used.add("pairs")
        ev, why = events(name, rows, summary, lo, hi)
        notes += why
        for key, ls in EVENTS:
            if ev[key] is not None:
                ax.axvline(ev[key], color=c, ls=ls, lw=1.0, zorder=2)
                used.add(key)
                items.append(dict(x=ev[key], y=0.985, transform=ax.get_xaxis_transform(), color=c,
                                  text=f"{key} {ev[key]:,.0f} r/min" + (f" ({name})" if several else ""),
                                  prefer=("left", "down")))
        handles.append(plt.Line2D([], [], color=c, lw=4, label=f"interface {name}"))
    handles += [plt.Line2D([], [], color="black", marker="o", ms=3, lw=1.5, label="contact fraction (left)"),
                plt.Line2D([], [], color="black", ls="--", lw=1.2, label="mean pressure (right)")]
    if "pairs" in used:
        handles.append(plt.Line2D([], [], color="black", lw=0.7, alpha=0.6,
                                  label="pairs not yet opened\n(pair_openings.csv)"))
    if "unconverged" in used:
        handles.append(plt.Line2D([], [], ls="none", marker="s", mfc="none", mec="black", ms=8,
                                  label="not converged\n(converged 0 or status not ok)"))
    for key, ls in EVENTS:
        if key in used:
            handles.append(plt.Line2D([], [], color="black", ls=ls, lw=1.0, label=key))

    ax.set_ylim(0, 1.05)
    ax2.set_ylim(0, 1.1 * pressure_max if pressure_max > 0 else 1.0)
    pad = 0.0 if hi > lo else max(1.0, 0.05 * abs(lo))    # a single speed: a narrow window around it
    ax.set_xlim(lo - pad, hi + pad)
    ax.set_xlabel("speed [r/min]")
    ax.set_ylabel("contact fraction (closed pairs / all pairs)")
    ax2.set_ylabel("mean contact pressure [MPa]")
    ax.grid(alpha=0.3)
    ax.set_zorder(ax2.get_zorder() + 1)   # fraction curve and labels above the pressure axes
    ax.patch.set_visible(False)
    case = os.path.basename(os.path.abspath(outdir))
    status = summary.get("run.status", "")
    failed = status in ("failed", "interrupted")
    title = f"Contact: {case}" + (f", run {status}" if status else "")
    if failed:
        title = f"Contact: {case}, run {status.upper()} {summary.get('run.stopped_at', '')} (see log.txt)"
    ax.set_title(title, color="tab:red" if failed else "black", fontsize=11)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.09, 1), fontsize=9)
    fig.tight_layout()

    layout = layout_module.LabelLayout(ax, avoid=avoid)
    for pts in steps.values():
        layout.add_avoid(pts, line=True)
    for line in ax2.get_lines():
        layout.add_avoid(list(zip(line.get_xdata(), line.get_ydata())), transform=ax2.transData, line=True)
    texts = []
    if notes:                             # what was not reached: a box placed like a label
        texts += layout.place([dict(x=0.01, y=0.02, transform=ax.transAxes, text="\n".join(notes),
                                    prefer=("right", "up"))], fontsize=8, leader=False)
    texts += layout.place(items, fontsize=8)
    fig.savefig(os.path.join(outdir, "contact.png"), dpi=150)
    ok = labels_ok(fig, [t for t in texts if t is not None]) if check_labels else True
    plt.close(fig)
    if not ok:
        print("plot_contact.py: labels overlap or leave the axes (see above)", file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Contact fraction and mean pressure of the fits over speed "
                                     "in a rotorfit output folder (writes OUTDIR/contact.png).")
    parser.add_argument("outdir")
    parser.add_argument("--check-labels", action="store_true",
                        help="exit 1 if two labels overlap or one leaves the axes")
    args = parser.parse_args()
    sys.exit(main(args.outdir, args.check_labels))
