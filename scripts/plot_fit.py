#!/usr/bin/env python3
"""The fit designer's numbers over speed: reads OUTDIR/fit.csv (header speed_rpm, interface,
radial_interference_m, mean_pressure_Pa, edge_peak_ratio, torque_capacity_Nm, axial_capacity_N,
slip_safety, slip_rpm, hub_bore_von_mises_Pa, shaft_bore_von_mises_Pa, hub_bore_hoop_Pa,
shaft_bore_hoop_Pa, hub_yield_safety, shaft_yield_safety; one row per speed and interface, rows
without a numeric speed skipped; an empty field, nan or a missing column is "not defined": the
capacities, slip safety and slip speed without a friction coefficient, a yield safety without a
yield strength; slip_safety may be inf when no load is given; edge_peak_ratio and the hoop stresses
are not drawn) and, if present, OUTDIR/summary.txt (lines "key value": interface.NAME.torque_load_Nm,
interface.NAME.axial_load_N, interface.NAME.slip_rpm, interface.NAME.loss_of_fit_rpm, run.status,
run.stopped_at; the first word of a value is read as a number, a value that is not one (nan, n/a)
counts as absent, other keys and malformed lines are ignored); writes OUTDIR/fit.png.

Two panels sharing the speed axis [r/min], one colour per interface (the legend, in a column on the
right, gives its radial interference at the first and last speed):
  top: with a friction coefficient, the torque capacity [N m] (solid, left axis) and the axial
  capacity [N] (wide dotted, right axis: both are proportional to the pressure, so the two curves
  may lie on each other); the loads of summary.txt as horizontal lines (torque dashed on the left
  axis, axial dash-dot on the right one) labelled with their value. When no interface has a friction
  coefficient (all capacity fields empty) the panel shows the mean contact pressure [MPa] instead,
  and its axis label says so; an interface without friction among others with it is listed in the
  panel's note box.
  bottom: the safeties: slip safety (solid; finite values only), hub yield safety (dashed) and shaft
  yield safety (dash-dot), each where defined, and a black line at 1; where a yield safety first
  falls below 1 (linear between speeds) an open circle and a label. The axis ends at 10 at most;
  higher safeties leave the panel (note box). When no interface has any safety defined, the panel
  shows the nominal bore von Mises stresses [MPa] of hub (solid) and shaft (dashed) instead.
  Both: a vertical dashed line at each slip speed (slip_rpm of the interface's last row when finite,
  else summary.txt's interface.NAME.slip_rpm) labelled "slip NAME 12,345 r/min", and a dotted one
  at summary.txt's loss_of_fit_rpm labelled "loss of fit NAME 12,345 r/min", each only within the
  sweep; a slip speed outside the sweep, or none although friction is defined (no load given, or no
  slip), is listed in the top note box.
Labels never overlap each other nor leave the axes (label_layout.py; --check-labels verifies the
drawn boxes and exits 1 otherwise). Title: the case name (the folder's name) and the run status of
summary.txt (red when failed or interrupted). A missing fit.csv or one without rows with a speed:
message on stderr, exit 1; so is a missing matplotlib.

Usage: plot_fit.py OUTDIR [--check-labels]
"""
import argparse
import math
import os
import sys

import plot_common
from plot_common import labels_ok, num, read_csv, summary_values

COLORS = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:cyan"]
SAFETY_CAP = 10.0                         # top of the safety axis at most: the interest is near 1
SAFETIES = (("slip", "slip_safety", "-"), ("hub yield", "hub_yield_safety", "--"),
            ("shaft yield", "shaft_yield_safety", "-."))
COLUMNS = dict(interference="radial_interference_m", pressure="mean_pressure_Pa",
               torque="torque_capacity_Nm", axial="axial_capacity_N", slip_rpm="slip_rpm",
               hub_vm="hub_bore_von_mises_Pa", shaft_vm="shaft_bore_von_mises_Pa")


def value(s):
    """Float of a field, inf kept (slip safety without a load); None for empty, malformed, nan."""
    try:
        v = float(s)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(v) else v


def summary_number(summary, key):
    """First number of summary.txt's value for key, or None (missing, text, nan or inf)."""
    text = summary.get(key, "")
    return num(text.split()[0]) if text.split() else None


def fmt(v):
    """A value for an axis or label: thousands separated, at most 4 significant digits."""
    return f"{v:,.0f}" if abs(v) >= 1000 else f"{v:.4g}"


def first_below_one(rows, key):
    """Speed where the curve key first falls below 1 (linear between speeds), or None."""
    pts = [(r["rpm"], r[key]) for r in rows if r[key] is not None and math.isfinite(r[key])]
    if pts and pts[0][1] < 1:
        return pts[0][0]
    for (s0, v0), (s1, v1) in zip(pts, pts[1:]):
        if v0 >= 1 > v1:
            return s0 + (v0 - 1) / (v0 - v1) * (s1 - s0)
    return None


def read_fit(path):
    """{interface: rows sorted by speed}, each row a dict of numbers (None = not defined)."""
    by_interface = {}
    for r in read_csv(path):
        rpm = num(r.get("speed_rpm"))
        if rpm is None:
            continue
        row = dict(rpm=rpm)
        for key, column in COLUMNS.items():
            row[key] = value(r.get(column))
        for _, column, _ in SAFETIES:
            row[column] = value(r.get(column))
        by_interface.setdefault(r.get("interface", "") or "fit", []).append(row)
    for rows in by_interface.values():
        rows.sort(key=lambda r: r["rpm"])
    return by_interface


def defined(rows, key, finite=False):
    return any(r[key] is not None and (math.isfinite(r[key]) or not finite) for r in rows)


def curve(rows, key, scale=1.0):
    """(speeds, values * scale) with nan where not defined or not finite (a gap in the line)."""
    return [r["rpm"] for r in rows], [r[key] * scale if r[key] is not None and math.isfinite(r[key])
                                      else math.nan for r in rows]


def events(name, rows, summary, friction, lo, hi):
    """Vertical lines [(rpm, style, label)] and notes for what lies outside the sweep."""
    lines, notes = [], []
    slip = rows[-1]["slip_rpm"]
    if slip is None or not math.isfinite(slip):
        slip = summary_number(summary, f"interface.{name}.slip_rpm")
    if friction:
        if slip is None:
            no_load = all(r["slip_safety"] is None or math.isinf(r["slip_safety"]) for r in rows)
            notes.append(f"{name}: no load given, no slip speed" if no_load else
                         f"{name}: no slip within the sweep")
        elif lo <= slip <= hi:
            lines.append((slip, "--", f"slip {name} {slip:,.0f} r/min"))
        else:
            notes.append(f"{name}: slip at {slip:,.0f} r/min, outside the sweep")
    lof = summary_number(summary, f"interface.{name}.loss_of_fit_rpm")
    if lof is not None and lo <= lof <= hi:
        lines.append((lof, ":", f"loss of fit {name} {lof:,.0f} r/min"))
    return lines, notes


def interference_text(rows):
    vals = [r["interference"] * 1e6 for r in rows if r["interference"] is not None]
    if not vals:
        return ""
    lo, hi = min(vals), max(vals)
    span = f"{vals[0]:.3g} \u00b5m" if hi - lo <= 1e-3 * max(abs(hi), 1e-12) else \
        f"{vals[0]:.3g} \u2192 {vals[-1]:.3g} \u00b5m"
    return f"\n(radial interference {span})"


def main(outdir, check_labels=False):
    """Draw OUTDIR/fit.png; returns 0, or 1 when check_labels finds a bad label."""
    path = os.path.join(outdir, "fit.csv")
    if not os.path.isfile(path):
        sys.exit(f"plot_fit.py: {path} not found")
    by_interface = read_fit(path)
    if not by_interface:
        sys.exit(f"plot_fit.py: {path} has no rows with a speed")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import FuncFormatter
        layout_module = plot_common.layout_module()
    except ImportError as e:
        sys.exit(f"plot_fit.py: matplotlib not importable ({e})")
    summary = summary_values(os.path.join(outdir, "summary.txt"))
    speeds = sorted({r["rpm"] for rows in by_interface.values() for r in rows})
    lo, hi = speeds[0], speeds[-1]
    several = len(by_interface) > 1
    friction = {n: defined(rows, "torque") or defined(rows, "axial") for n, rows in by_interface.items()}
    any_friction = any(friction.values())
    any_safety = any(defined(rows, key, finite=True) for rows in by_interface.values() for _, key, _ in SAFETIES)

    # a column of its own for the legends, so that they never cover the right axis' label
    fig, axes = plt.subplots(2, 2, figsize=(11.5, 7.5), dpi=150, gridspec_kw=dict(width_ratios=[3.3, 1]))
    (ax1, leg1), (ax2, leg2) = axes
    ax2.sharex(ax1)
    ax1.tick_params(labelbottom=False)
    for ax in (leg1, leg2):
        ax.axis("off")
    ax1r = ax1.twinx() if any_friction else None
    top_items, bottom_items, notes, bottom_notes, handles = [], [], [], [], []
    top_avoid, bottom_avoid, right_avoid, vertical, used = [], [], [], [], set()
    cut = False
    for i, (name, rows) in enumerate(by_interface.items()):
        c = COLORS[i % len(COLORS)]
        who = f" ({name})" if several else ""
        dots = dict(marker="o", ms=3) if len(rows) < 30 else {}
        # top panel
        if any_friction and friction[name]:
            x, y = curve(rows, "torque")
            ax1.plot(x, y, "-", color=c, lw=1.5, zorder=4, **dots)
            top_avoid.append(list(zip(x, y)))
            x, y = curve(rows, "axial")
            # wider than the torque line: both capacities are proportional to the pressure
            # (torque = axial x radius) and may lie on each other; the dots then show beside it
            ax1r.plot(x, y, ":", color=c, lw=3.0, alpha=0.7, zorder=3)
            right_avoid.append(list(zip(x, y)))
            torque_load = summary_number(summary, f"interface.{name}.torque_load_Nm")
            axial_load = summary_number(summary, f"interface.{name}.axial_load_N")
            if torque_load is not None:
                ax1.axhline(torque_load, color=c, ls="--", lw=1.0, zorder=2)
                top_avoid.append([(lo, torque_load), (hi, torque_load)])
                top_items.append(dict(x=hi, y=torque_load, color=c, prefer=("left", "up"),
                                      text=f"torque load{who} {fmt(torque_load)} N m"))
                used.add("torque load")
            if axial_load is not None:
                ax1r.axhline(axial_load, color=c, ls="-.", lw=1.0, zorder=2)
                right_avoid.append([(lo, axial_load), (hi, axial_load)])
                top_items.append(dict(x=lo, y=axial_load, color=c, transform=ax1r.transData,
                                      prefer=("right", "up"), text=f"axial load{who} {fmt(axial_load)} N"))
                used.add("axial load")
        elif any_friction:
            notes.append(f"{name}: no friction coefficient, no capacity")
        else:
            x, y = curve(rows, "pressure", 1e-6)
            ax1.plot(x, y, "-", color=c, lw=1.5, zorder=4, **dots)
            top_avoid.append(list(zip(x, y)))
        # bottom panel
        if any_safety:
            shown = False
            for label, key, ls in SAFETIES:
                if not defined(rows, key, finite=True):
                    continue
                x, y = curve(rows, key)
                cut |= any(v > SAFETY_CAP for v in y if v == v)
                ax2.plot(x, y, ls, color=c, lw=1.4, zorder=4, **dots)
                bottom_avoid.append(list(zip(x, y)))
                used.add(label)
                shown = True
                if key != "slip_safety":
                    below = first_below_one(rows, key)
                    if below is not None:
                        ax2.plot(below, 1.0, "o", mfc="white", mec=c, ms=6, zorder=5)
                        bottom_items.append(dict(x=below, y=1.0, color=c, prefer=("right", "down"),
                                                 text=f"{label}{who} < 1 from {below:,.0f} r/min"))
            if not shown:
                bottom_notes.append(f"{name}: no safety defined (no friction coefficient, no yield strength)")
        else:
            for key, ls, label in (("hub_vm", "-", "hub bore"), ("shaft_vm", "--", "shaft bore")):
                x, y = curve(rows, key, 1e-6)
                ax2.plot(x, y, ls, color=c, lw=1.4, zorder=4, **dots)
                bottom_avoid.append(list(zip(x, y)))
                used.add(label)
        # speeds: slip and loss of fit, on both panels, labelled on the top one
        lines, why = events(name, rows, summary, friction[name], lo, hi)
        notes += why
        for rpm, ls, text in lines:
            for ax in (ax1, ax2):
                ax.axvline(rpm, color=c, ls=ls, lw=1.0, zorder=2)
            vertical.append(rpm)
            top_items.append(dict(x=rpm, y=0.985, transform=ax1.get_xaxis_transform(), color=c, text=text,
                                  prefer=("left", "down")))
            used.add("slip speed" if text.startswith("slip") else "loss of fit")
        handles.append(plt.Line2D([], [], color=c, lw=4, label=f"interface {name}{interference_text(rows)}"))
    if cut:
        bottom_notes.append(f"safeties above {SAFETY_CAP:g} leave the panel")

    # legend: what the line styles mean
    style = dict(color="black", lw=1.4)
    if any_friction:
        handles += [plt.Line2D([], [], ls="-", label="torque capacity (left)", **style),
                    plt.Line2D([], [], ls=":", color="black", lw=3.0, alpha=0.7, label="axial capacity (right)")]
        for label, ls in (("torque load", "--"), ("axial load", "-.")):
            if label in used:
                handles.append(plt.Line2D([], [], ls=ls, label=f"{label} ({'left' if ls == '--' else 'right'})",
                                          color="black", lw=1.0))
    else:
        handles.append(plt.Line2D([], [], ls="-", label="mean contact pressure", **style))
    for label, ls in (("slip speed", "--"), ("loss of fit", ":")):
        if label in used:
            handles.append(plt.Line2D([], [], ls=ls, color="black", lw=1.0, label=label))
    handles2 = []
    if any_safety:
        for label, _, ls in SAFETIES:
            if label in used:
                handles2.append(plt.Line2D([], [], ls=ls, label=f"{label} safety", **style))
        handles2.append(plt.Line2D([], [], color="black", lw=0.9, label="safety 1"))
    else:
        for label, ls in (("hub bore", "-"), ("shaft bore", "--")):
            handles2.append(plt.Line2D([], [], ls=ls, label=f"{label} von Mises", **style))

    # axes
    pad = 0.0 if hi > lo else max(1.0, 0.05 * abs(lo))    # a single speed: a narrow window around it
    ax1.set_xlim(lo - pad, hi + pad)
    ax2.set_xlabel("speed [r/min]")
    numbers = FuncFormatter(lambda v, _: fmt(v) if v else "0")
    if any_friction:
        ax1.set_ylabel("torque capacity [N m]")
        ax1r.set_ylabel("axial capacity [N]")
        for ax in (ax1, ax1r):
            ax.set_ylim(bottom=0)
            ax.yaxis.set_major_formatter(numbers)
        ax1.set_zorder(ax1r.get_zorder() + 1)   # torque curves and labels above the axial axes
        ax1.patch.set_visible(False)
    else:
        ax1.set_ylabel("mean contact pressure [MPa]\n(no friction coefficient: no capacity)")
        ax1.set_ylim(bottom=0)
    if any_safety:
        ax2.axhline(1.0, color="black", lw=0.9, zorder=3)
        ax2.set_ylabel("safety [-]")
        top = max([v for line in ax2.get_lines() for v in line.get_ydata() if v == v] + [1.0])
        ax2.set_ylim(0, SAFETY_CAP if top > SAFETY_CAP else 1.08 * max(top, 1.5))
    else:
        ax2.set_ylabel("bore von Mises [MPa]\n(no safety defined)")
        ax2.set_ylim(bottom=0)
    ax2.xaxis.set_major_formatter(numbers)
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    case = os.path.basename(os.path.abspath(outdir))
    status = (summary.get("run.status", "").split() or [""])[0]
    failed = status in ("failed", "interrupted")
    title = f"Fit: {case}" + (f", run {status}" if status else "")
    if failed:
        title = " ".join(p for p in (f"Fit: {case}, run {status.upper()}", summary.get("run.stopped_at", ""),
                                     "(see log.txt)") if p)
    ax1.set_title(title, color="tab:red" if failed else "black", fontsize=11)
    leg1.legend(handles=handles, loc="upper left", fontsize=9)
    leg2.legend(handles=handles2, loc="upper left", fontsize=9)
    fig.tight_layout()

    texts = []
    layout = layout_module.LabelLayout(ax1, avoid=top_avoid)
    for pts in right_avoid:
        layout.add_avoid(pts, transform=ax1r.transData, line=True)
    for rpm in vertical:
        layout.add_avoid([(rpm, 0), (rpm, 1)], transform=ax1.get_xaxis_transform(), line=True)
    texts += layout.place(top_items, fontsize=8)
    if notes:                             # what is not defined or outside the sweep: a box placed like a label
        texts += layout.place([dict(x=0.01, y=0.02, transform=ax1.transAxes, text="\n".join(notes),
                                    prefer=("right", "up"))], fontsize=8, leader=False)
    layout = layout_module.LabelLayout(ax2, avoid=bottom_avoid)
    for rpm in vertical:
        layout.add_avoid([(rpm, 0), (rpm, 1)], transform=ax2.get_xaxis_transform(), line=True)
    texts += layout.place(bottom_items, fontsize=8)
    if bottom_notes:
        texts += layout.place([dict(x=0.01, y=0.02, transform=ax2.transAxes, text="\n".join(bottom_notes),
                                    prefer=("right", "up"))], fontsize=8, leader=False)
    fig.savefig(os.path.join(outdir, "fit.png"), dpi=150)
    ok = labels_ok(fig, [t for t in texts if t is not None]) if check_labels else True
    plt.close(fig)
    if not ok:
        print("plot_fit.py: labels overlap or leave the axes (see above)", file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Capacities, loads and safeties of the fits over speed "
                                     "in a rotorfit output folder (writes OUTDIR/fit.png).")
    parser.add_argument("outdir")
    parser.add_argument("--check-labels", action="store_true",
                        help="exit 1 if two labels overlap or one leaves the axes")
    args = parser.parse_args()
    sys.exit(main(args.outdir, args.check_labels))
