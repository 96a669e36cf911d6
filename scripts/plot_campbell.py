#!/usr/bin/env python3
"""Campbell diagram of a rotorfit run: reads OUTDIR/campbell.csv (required) and, if present,
OUTDIR/critical_speeds.csv and OUTDIR/summary.txt; writes OUTDIR/campbell.png.

One line per tracked mode (speed order): forward whirl red, backward blue, mixed/non-lateral grey
dashed (a track takes the majority of its forward/backward points); unstable points 'x'. A track is
not bridged over a speed gap > 1.5 x the median speed step nor over a change to/from fit_state
'open' (after the loss of fit a body is loose: such rows are no assembly modes and are drawn faded).
Excitation lines f = order * rpm / 60 (1X always, plus every order in critical_speeds.csv); critical
speeds as circles (labels within 3 % of the x range merged); loss of fit of each interface that
opened within the sweep as a dotted vertical line; points whose static state did not converge as
squares; a run that failed or was interrupted says so in the title. y axis: 0 .. 1.1 x max frequency, capped by --fmax.

Usage: plot_campbell.py OUTDIR [--fmax HZ]
"""
import argparse
import csv
import math
import os
import statistics
import sys
from collections import Counter, defaultdict

def read_csv(path):
    """Rows of a CSV file as dicts (empty list if the file has no data rows)."""
    with open(path, newline="") as f:
        return [{k.strip(): (v or "").strip() for k, v in r.items() if k} for r in csv.DictReader(f)]


def num(s, default=None):
    try:
        v = float(s.rstrip("xX"))
        return v if math.isfinite(v) else default
    except (AttributeError, ValueError):
        return default


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


def main(outdir, fmax_cap=None):
    path = os.path.join(outdir, "campbell.csv")
    if not os.path.isfile(path):
        sys.exit(f"plot_campbell.py: {path} not found")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        sys.exit(f"plot_campbell.py: matplotlib not importable ({e})")

    tracks = defaultdict(list)            # tracked_id -> [(rpm, Hz, whirl, stable, open)]
    per_speed = Counter()                 # rpm -> number of modes
    for r in read_csv(path):
        rpm, hz = num(r.get("speed_rpm")), num(r.get("frequency_hz"))
        if rpm is not None and hz is not None:
            tracks[r.get("tracked_id", "")].append((rpm, hz, r.get("whirl", ""), r.get("stable", "1") != "0",
                                                    r.get("fit_state", "") == "open",
                                                    r.get("static_converged", "1") != "0"))
            per_speed[rpm] += 1
    steps = [b - a for a, b in zip(sorted(per_speed), sorted(per_speed)[1:])]
    max_gap = 1.5 * statistics.median(steps) if steps else math.inf
    cpath = os.path.join(outdir, "critical_speeds.csv")
    crit = [(num(r.get("order"), 1.0), num(r.get("speed_rpm")), num(r.get("frequency_hz")),
             {"forward": "FW", "backward": "BW"}.get(r.get("whirl"), ""))
            for r in (read_csv(cpath) if os.path.isfile(cpath) else [])
            # non-lateral lines (axial, torsional) are not critical speeds
            if r.get("kind", "lateral") != "non-lateral"]
    crit = sorted(c for c in crit if c[1] is not None and c[2] is not None)
    orders = sorted({1.0} | {c[0] for c in crit if c[0] > 0})
    lof = loss_of_fit(os.path.join(outdir, "summary.txt"))

    fig, ax = plt.subplots(figsize=(10.5, 6))
    style = {"forward": dict(color="tab:red", ls="-"), "backward": dict(color="tab:blue", ls="-"),
             "other": dict(color="grey", ls="--")}
    used, fmax, speeds = set(), 0.0, [c[1] for c in crit] + list(lof.values()) + list(per_speed)
    for pts in tracks.values():
        pts.sort()
        votes = Counter(p[2] for p in pts if p[2] in ("forward", "backward"))
        kind = votes.most_common(1)[0][0] if votes else "other"
        segs = [[pts[0]]]                 # split at a large speed gap or a change to/from 'open'
        for a, b in zip(pts, pts[1:]):
            if b[0] - a[0] > max_gap or b[4] != a[4]:
                segs.append([])
            segs[-1].append(b)
        for seg in segs:
            is_open = seg[0][4]
            used.add("open" if is_open else kind)
            fade = dict(alpha=0.35, lw=0.8) if is_open else dict(lw=1.3)
            ax.plot([p[0] for p in seg], [p[1] for p in seg], marker="." if len(pts) < 60 or len(seg) == 1 else None,
                    ms=3, **fade, **style[kind])
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
        fmax = max([fmax] + [p[1] for p in pts])
    fmax = max([fmax] + [c[2] for c in crit])
    ytop = min(1.1 * fmax if fmax > 0 else (fmax_cap or 1.0), fmax_cap or math.inf)

    xmin, xmax = min(speeds + [0.0]), max(speeds + [0.0])
    xrange = xmax - xmin
    if xmax > 0:
        for order in orders:
            ax.plot([0, xmax], [0, order * xmax / 60], color="black", lw=0.8 if order == 1 else 0.6)
            xe = min(xmax, 60 * 0.97 * ytop / order)
            ax.text(xe, order * xe / 60, f" {order:g}X", fontsize=8, va="bottom" if xe < xmax else "center",
                    ha="right" if xe < xmax else "left", clip_on=False)   # at the top, or right of the axes
    groups = []                           # critical speeds closer than 3 % of the x range share a label
    for c in crit:
        if groups and c[1] - groups[-1][0][1] < 0.03 * xrange:
            groups[-1].append(c)
        else:
            groups.append([c])
    for group in groups:
        for c in group:
            ax.plot(c[1], c[2], "o", mfc="none", mec="black", ms=8)
        rpm, hz = group[0][1], max(c[2] for c in group)
        if hz > ytop:
            continue
        label = " / ".join(f"{c[1]:,.0f}" + (f" {c[3]}" if c[3] else "") for c in group) + " r/min"
        right = xrange > 0 and rpm > xmin + 0.5 * xrange
        below = hz > 0.9 * ytop
        ax.annotate(label, (rpm, hz), textcoords="offset points", xytext=(-6 if right else 6, -8 if below else 6),
                    ha="right" if right else "left", va="top" if below else "bottom", fontsize=8,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8))
    for name, rpm in lof.items():
        ax.axvline(rpm, color="black", ls=":", lw=1)
        ax.text(rpm, 0.98, f"loss of fit ({name}) ", transform=ax.get_xaxis_transform(), rotation=90,
                fontsize=8, va="top", ha="right")
    counts = sorted(set(per_speed.values())) or [0]
    modes = f"{counts[0]}" if len(counts) == 1 else f"{counts[0]}-{counts[-1]}"
    ends = [o * xmax / 60 / ytop for o in orders if o * xmax / 60 / ytop < 0.12]   # low lines at the right edge
    ax.text(0.99, 0.015 + max([0] + ends),
            f"{len(per_speed)} speeds, {modes} modes per speed" if per_speed else "no modes in campbell.csv",
            transform=ax.transAxes, ha="right", va="bottom", fontsize=8,
            bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8))

    handles = [plt.Line2D([], [], label=lab, **style[k]) for k, lab in
               (("forward", "forward whirl"), ("backward", "backward whirl"), ("other", "mixed / non-lateral"))
               if k in used or k != "other"]
    if "open" in used:
        handles.append(plt.Line2D([], [], color="black", lw=0.8, alpha=0.35, marker=".", ms=3,
                                  label="after loss of fit\n(not assembly modes)"))
    handles.append(plt.Line2D([], [], color="black", lw=0.8, label="1X (f = rpm/60)"))
    if "unstable" in used:
        handles.append(plt.Line2D([], [], color="black", ls="none", marker="x", label="unstable"))
    if "unconverged" in used:
        handles.append(plt.Line2D([], [], ls="none", marker="s", mfc="none", mec="black",
                                  label="static state not\nconverged (contact.csv)"))
    if crit:
        handles.append(plt.Line2D([], [], ls="none", marker="o", mfc="none", mec="black", label="critical speed"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=9)
    ax.set_xlabel("speed [r/min]")
    ax.set_ylabel("frequency [Hz]")
    status = run_status(os.path.join(outdir, "summary.txt"))
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
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "campbell.png"), dpi=150)
    plt.close(fig)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Campbell diagram of a rotorfit output folder.")
    parser.add_argument("outdir")
    parser.add_argument("--fmax", type=float, metavar="HZ", help="upper limit of the frequency axis")
    args = parser.parse_args()
    if args.fmax is not None and not 0 < args.fmax < math.inf:
        parser.error("--fmax must be a positive number")
    main(args.outdir, args.fmax)
