#!/usr/bin/env python3
"""Campbell diagram of a rotorfit run: reads OUTDIR/campbell.csv (required) and, if present,
OUTDIR/critical_speeds.csv, OUTDIR/stability_onsets.csv and OUTDIR/summary.txt; writes
OUTDIR/campbell.png.

One line per tracked mode (speed order): forward whirl red, backward blue, mixed/non-lateral grey
dashed (a track takes the majority of its forward/backward points); unstable points 'x'. A track is
not bridged over a speed gap > 1.5 x the median speed step nor over a change to/from fit_state
'open' (after the loss of fit a body is loose: such rows are no assembly modes and are drawn faded).
Excitation lines f = order * rpm / 60 (1X always, plus every order of a lateral row of
critical_speeds.csv), each order its own grey shade and dash with a legend entry "1X", "2X", ...;
critical speeds (kind non-lateral never drawn) as circles, labelled "21,514 FW r/min" (crossings of
one order within 3 % of both axis ranges share a label, more than three as "N crossings A-B r/min";
the order is added when several are drawn);
stability onsets (stability_onsets.csv: tracked_id, whirl, onset_rpm, frequency_hz, direction
"unstable above" / "stable above"; onset_rpm nan = not reached; frequency_hz nan = taken from the
track at onset_rpm) as black diamonds, filled for "unstable above", open for "stable above",
labelled "onset 12,345 r/min" (an onset above the frequency range sits on the top edge as a
triangle and its label gives the frequency); loss of fit of each interface that opened within the
sweep as a dotted vertical line labelled "loss of fit (NAME)"; points whose static state did not converge as
squares; a run that failed or was interrupted says so in the title. The legend (right of the axes)
lists forward/backward whirl, and mixed / non-lateral, faded lines, unstable and unconverged points,
critical speed, stability onset and loss of fit when they are drawn, and every kX line.
Labels never overlap each other nor leave the axes: they are placed by label_layout.py (sorted by
speed, stacked upwards/downwards in display coordinates with leader lines when moved away from their
point; --check-labels verifies the drawn boxes and exits 1 on an overlap or a label outside).

Frequency range: 0 .. --fmax HZ when given. Otherwise 0 .. 1.15 x the highest excitation line at the
top speed (max order x top r/min / 60), but at least 1.1 x the lowest drawn mode frequency (so one
mode line shows); a run with no speed above 0 (e.g. free-free) keeps 0 .. 1.1 x the highest mode.

Usage: plot_campbell.py OUTDIR [--fmax HZ] [--check-labels]
"""
import argparse
import math
import os
import statistics
import sys
from collections import Counter, defaultdict

import plot_common
from plot_common import labels_ok, num, read_csv




def loss_of_fit(path):
    """{interface name: loss-of-fit speed [r/min]} for interfaces that opened within the sweep."""
    kv = {}
    if os.path.isfile(path):
        with open(path) as f:
            kv = {p[0]: p[1] for p in (line.split() for line in f) if len(p) >= 2}
    out = {}
    for key, val in kv.items():
        if key.startswith("interface.") and key.endswith(".loss_of_fit_within_sweep") and num(val) == 1:
            name = key[len("interface."):-len(".loss_of_fit_within_sweep")]
            rpm = num(kv.get(f"interface.{name}.loss_of_fit_rpm"))
            if rpm is not None:
                out[name] = rpm
    return out


def run_status(path):
    """run.* lines of summary.txt (written when a run stops early)."""
    out = {}
    if os.path.isfile(path):
        with open(path) as f:
            for line in f:
                p = line.split(None, 1)
                if len(p) == 2 and p[0].startswith("run."):
                    out[p[0]] = p[1].strip()
    return out


def order_style(index):
    """Line style of the index-th excitation order (0 = 1X): darker and solid first."""
    shades = ["black", "0.35", "0.5", "0.6", "0.68"]
    dashes = ["-", "--", "-.", ":", (0, (5, 2, 1, 2, 1, 2))]
    return dict(color=shades[min(index, len(shades) - 1)], ls=dashes[index % len(dashes)],
                lw=1.0 if index == 0 else 0.9)


def frequency_top(orders, top_rpm, mode_hz, fmax=None):
    """Upper end of the frequency axis (see the module docstring)."""
    if fmax is not None:
        return fmax
    positive = [f for f in mode_hz if f > 0]
    line_top = max(orders) * top_rpm / 60 if top_rpm > 0 else 0.0
    if line_top > 0:
        return max(1.15 * line_top, 1.1 * min(positive) if positive else 0.0)
    return 1.1 * max(positive) if positive else 1.0


def interpolate_track(pts, rpm):
    """Frequency of a track [(rpm, Hz, ...)] at rpm (linear; None outside the track)."""
    for a, b in zip(pts, pts[1:]):
        if a[0] <= rpm <= b[0] and b[0] > a[0]:
            return a[1] + (b[1] - a[1]) * (rpm - a[0]) / (b[0] - a[0])
    return pts[0][1] if len(pts) == 1 and pts[0][0] == rpm else None




def main(outdir, fmax_cap=None, check_labels=False):
    """Draw OUTDIR/campbell.png; returns 0, or 1 when check_labels finds a bad label."""
    path = os.path.join(outdir, "campbell.csv")
    if not os.path.isfile(path):
        sys.exit(f"plot_campbell.py: {path} not found")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        layout_module = plot_common.layout_module()
    except ImportError as e:
        sys.exit(f"plot_campbell.py: matplotlib not importable ({e})")

    tracks = defaultdict(list)            # tracked_id -> [(rpm, Hz, whirl, stable, open, converged)]
    per_speed = Counter()                 # rpm -> number of modes
    for r in read_csv(path):
        rpm, hz = num(r.get("speed_rpm")), num(r.get("frequency_hz"))
        if rpm is not None and hz is not None:
            tracks[r.get("tracked_id", "")].append((rpm, hz, r.get("whirl", ""), r.get("stable", "1") != "0",
                                                    r.get("fit_state", "") == "open",
                                                    r.get("static_converged", "1") != "0"))
            per_speed[rpm] += 1
    for pts in tracks.values():
        pts.sort()
    steps = [b - a for a, b in zip(sorted(per_speed), sorted(per_speed)[1:])]
    max_gap = 1.5 * statistics.median(steps) if steps else math.inf
    crit = [(num(r.get("order"), 1.0), num(r.get("speed_rpm")), num(r.get("frequency_hz")),
             {"forward": "FW", "backward": "BW"}.get(r.get("whirl"), ""))
            for r in read_csv(os.path.join(outdir, "critical_speeds.csv"))
            # non-lateral lines (axial, torsional) are not critical speeds
            if r.get("kind", "lateral") != "non-lateral"]
    crit = sorted(c for c in crit if c[1] is not None and c[2] is not None)
    orders = sorted({1.0} | {c[0] for c in crit if c[0] > 0})
    onsets = []                           # (rpm, Hz, unstable above)
    for r in read_csv(os.path.join(outdir, "stability_onsets.csv")):
        rpm, hz = num(r.get("onset_rpm")), num(r.get("frequency_hz"))
        if rpm is None:
            continue                      # nan: not reached
        if hz is None and r.get("tracked_id") in tracks:
            hz = interpolate_track(tracks[r["tracked_id"]], rpm)
        if hz is not None:
            onsets.append((rpm, hz, r.get("direction", "unstable above").strip().lower() != "stable above"))
    onsets.sort()
    summary = os.path.join(outdir, "summary.txt")
    lof = loss_of_fit(summary)

    fig, ax = plt.subplots(figsize=(10.5, 6), dpi=150)
    style = {"forward": dict(color="tab:red", ls="-"), "backward": dict(color="tab:blue", ls="-"),
             "other": dict(color="grey", ls="--")}
    speeds = [c[1] for c in crit] + list(lof.values()) + list(per_speed) + [o[0] for o in onsets]
    xmin, xmax = min(speeds + [0.0]), max(speeds + [0.0])
    xrange = xmax - xmin
    ytop = frequency_top(orders, xmax, [p[1] for pts in tracks.values() for p in pts], fmax_cap)

    used, curves = set(), []
    for pts in tracks.values():
        votes = Counter(p[2] for p in pts if p[2] in ("forward", "backward"))
        kind = votes.most_common(1)[0][0] if votes else "other"
        segs = [[pts[0]]]                 # split at a large speed gap or a change to/from 'open'
        for a, b in zip(pts, pts[1:]):
            if b[0] - a[0] > max_gap or b[4] != a[4]:
                segs.append([])
            segs[-1].append(b)
        for seg in segs:
            is_open = seg[0][4]
            if min(p[1] for p in seg) <= ytop:   # legend entries only for what shows
                used.add("open" if is_open else kind)
            fade = dict(alpha=0.35, lw=0.8) if is_open else dict(lw=1.3)
            ax.plot([p[0] for p in seg], [p[1] for p in seg], marker="." if len(pts) < 60 or len(seg) == 1 else None,
                    ms=3, **fade, **style[kind])
            curves.append([p[:2] for p in seg])   # for the labels to avoid
            bad = [p for p in seg if not p[3]]
            if bad:
                ax.plot([p[0] for p in bad], [p[1] for p in bad], "x", color=style[kind]["color"], ms=7,
                        alpha=fade.get("alpha", 1.0))
                used.add("unstable")
            doubtful = [p for p in seg if not p[5]]
            if doubtful:
                ax.plot([p[0] for p in doubtful], [p[1] for p in doubtful], "s", mfc="none", mec="black",
                        ms=7)
                used.add("unconverged")

    order_handles = []
    for i, order in enumerate(orders):
        st = order_style(i)
        if xmax > 0:
            ax.plot([0, xmax], [0, order * xmax / 60], **st)
        order_handles.append(plt.Line2D([], [], label=f"{order:g}X", **st))
    groups = []                           # crossings of one order close in speed and frequency share a label
    for c in crit:
        g = groups[-1] if groups else None
        if g and c[0] == g[0][0] and c[1] - g[0][1] < 0.03 * xrange and abs(c[2] - g[0][2]) < 0.03 * ytop:
            g.append(c)
        else:
            groups.append([c])
    for c in crit:
        ax.plot(c[1], c[2], "o", mfc="none", mec="black", ms=8, zorder=4)
    for rpm, hz, unstable in onsets:
        if hz <= ytop:
            ax.plot(rpm, hz, "D", mfc="black" if unstable else "white", mec="black", ms=7, zorder=5)
        else:                             # above the range: on the top edge, pointing up
            ax.plot(rpm, ytop, "^", mfc="black" if unstable else "white", mec="black", ms=8, zorder=5,
                    clip_on=False)
    for name, rpm in lof.items():
        ax.axvline(rpm, color="black", ls=":", lw=1)

    ax.set_xlabel("speed [r/min]")
    ax.set_ylabel("frequency [Hz]")
    status = run_status(summary)
    if status.get("run.status") in ("failed", "interrupted"):
        ax.set_title(f"Campbell diagram: run {status['run.status'].upper()} "
                     f"{status.get('run.stopped_at', '')} (see log.txt); speeds up to there only",
                     color="tab:red", fontsize=10)
    else:
        ax.set_title("Campbell diagram")
    ax.set_ylim(0, ytop)
    if xmax > 0:
        ax.set_xlim(xmin, xmax)
    ax.grid(alpha=0.3)

    handles = [plt.Line2D([], [], label=lab, **style[k]) for k, lab in
               (("forward", "forward whirl"), ("backward", "backward whirl"), ("other", "mixed / non-lateral"))
               if k in used or k != "other"]
    if "open" in used:
        handles.append(plt.Line2D([], [], color="black", lw=0.8, alpha=0.35, marker=".", ms=3,
                                  label="after loss of fit\n(not assembly modes)"))
    handles += order_handles
    if "unstable" in used:
        handles.append(plt.Line2D([], [], color="black", ls="none", marker="x", label="unstable"))
    if "unconverged" in used:
        handles.append(plt.Line2D([], [], ls="none", marker="s", mfc="none", mec="black",
                                  label="static state not\nconverged (contact.csv)"))
    if crit:
        handles.append(plt.Line2D([], [], ls="none", marker="o", mfc="none", mec="black", label="critical speed"))
    if any(o[2] for o in onsets):
        handles.append(plt.Line2D([], [], ls="none", marker="D", mfc="black", mec="black",
                                  label="stability onset\n(unstable above)"))
    if any(not o[2] for o in onsets):
        handles.append(plt.Line2D([], [], ls="none", marker="D", mfc="white", mec="black",
                                  label="stability onset\n(stable above)"))
    if lof:
        handles.append(plt.Line2D([], [], color="black", ls=":", lw=1, label="loss of fit"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=9 if len(handles) < 13 else 8)
    fig.tight_layout()

    # labels: placed last, on the final layout, so that none overlaps another or leaves the axes
    layout = layout_module.LabelLayout(ax, avoid=curves)
    counts = sorted(set(per_speed.values())) or [0]
    modes = f"{counts[0]}" if len(counts) == 1 else f"{counts[0]}-{counts[-1]}"
    ends = [o * xmax / 60 / ytop for o in orders if o * xmax / 60 / ytop < 0.12]   # low lines at the right edge
    info = ax.text(0.99, 0.015 + max([0] + ends),
                   f"{len(per_speed)} speeds, {modes} modes per speed" if per_speed else "no modes in campbell.csv",
                   transform=ax.transAxes, ha="right", va="bottom", fontsize=8,
                   bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8))
    layout.add_text(info)
    for c in crit:                        # every circle and diamond, labelled or not, stays visible
        layout.add_marker((c[1], c[2]))
    for rpm, hz, _ in onsets:
        layout.add_marker((rpm, min(hz, ytop)))
    texts = [info]
    if xmax > 0:                          # "kX" where each excitation line leaves the axes
        items = []
        for order in orders:
            xe = min(xmax, 60 * ytop / order)
            items.append(dict(x=xe, y=order * xe / 60, text=f"{order:g}X", prefer=("left", "up")))
        texts += layout.place(items, fontsize=8, box=False)
    items = []
    for group in groups:
        _, rpm, hz, _ = max(group, key=lambda c: c[2])      # at the highest circle of the group
        if hz > ytop:
            continue
        if len(group) <= 3:
            label = " / ".join(f"{c[1]:,.0f}" + (f" {c[3]}" if c[3] else "") for c in group) + " r/min"
        else:                             # a crowd: its speed range
            label = f"{len(group)} crossings {group[0][1]:,.0f}-{group[-1][1]:,.0f} r/min"
        if len(orders) > 1:
            label += f" ({group[0][0]:g}X)"
        right = not (xrange > 0 and rpm > xmin + 0.5 * xrange)
        items.append(dict(x=rpm, y=hz, text=label, prefer=("right" if right else "left", "up")))
    for rpm, hz, unstable in onsets:
        label = f"onset {rpm:,.0f} r/min" + (f" at {hz:,.0f} Hz" if hz > ytop else "")
        right = not (xrange > 0 and rpm > xmin + 0.5 * xrange)
        items.append(dict(x=rpm, y=min(hz, ytop), text=label, prefer=("right" if right else "left", "down")))
    for name, rpm in lof.items():
        items.append(dict(x=rpm, y=0.98 * ytop, text=f"loss of fit ({name})", prefer=("left", "down")))
    texts += layout.place(items, fontsize=8)
    fig.savefig(os.path.join(outdir, "campbell.png"), dpi=150)
    ok = labels_ok(fig, [t for t in texts if t is not None]) if check_labels else True
    plt.close(fig)
    if not ok:
        print("plot_campbell.py: labels overlap or leave the axes (see above)", file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Campbell diagram of a rotorfit output folder "
                                     "(writes OUTDIR/campbell.png).")
    parser.add_argument("outdir")
    parser.add_argument("--fmax", type=float, metavar="HZ", help="upper limit of the frequency axis "
                        "(default: 1.15 x max order x top r/min / 60, at least 1.1 x the lowest mode)")
    parser.add_argument("--check-labels", action="store_true",
                        help="exit 1 if two labels overlap or one leaves the axes")
    args = parser.parse_args()
    if args.fmax is not None and not 0 < args.fmax < math.inf:
        parser.error("--fmax must be a positive number")
    sys.exit(main(args.outdir, args.fmax, args.check_labels))
