#!/usr/bin/env python3
"""Campbell diagram of a rotorfit run: reads OUTDIR/campbell.csv (required) and, if present,
OUTDIR/critical_speeds.csv and OUTDIR/summary.txt; writes OUTDIR/campbell.png.

One line per tracked mode (speed order): forward whirl red, backward blue, mixed/non-lateral grey
dashed (a track takes the majority of its forward/backward points); unstable points 'x';
excitation lines f = order * rpm / 60 (1X always, plus every order in critical_speeds.csv);
critical speeds as annotated circles; loss of fit of each interface that opened within the sweep
as a dotted vertical line.

Usage: plot_campbell.py OUTDIR
"""
import csv
import math
import os
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
        for line in open(path):
            parts = line.split()
            if len(parts) >= 2:
                kv[parts[0]] = parts[1]
    out = {}
    for key, val in kv.items():
        if key.startswith("interface.") and key.endswith(".loss_of_fit_within_sweep") and num(val) == 1:
            name = key[len("interface."):-len(".loss_of_fit_within_sweep")]
            rpm = num(kv.get(f"interface.{name}.loss_of_fit_rpm"))
            if rpm is not None:
                out[name] = rpm
    return out


def main(outdir):
    path = os.path.join(outdir, "campbell.csv")
    if not os.path.isfile(path):
        sys.exit(f"plot_campbell.py: {path} not found")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        sys.exit(f"plot_campbell.py: matplotlib not importable ({e})")

    tracks = defaultdict(list)            # tracked_id -> [(rpm, Hz, whirl, stable)]
    for r in read_csv(path):
        rpm, hz = num(r.get("speed_rpm")), num(r.get("frequency_hz"))
        if rpm is not None and hz is not None:
            tracks[r.get("tracked_id", "")].append((rpm, hz, r.get("whirl", ""), r.get("stable", "1") != "0"))
    cpath = os.path.join(outdir, "critical_speeds.csv")
    crit = [(num(r.get("order"), 1.0), num(r.get("speed_rpm")), num(r.get("frequency_hz")))
            for r in (read_csv(cpath) if os.path.isfile(cpath) else [])]
    crit = [c for c in crit if c[1] is not None and c[2] is not None]
    lof = loss_of_fit(os.path.join(outdir, "summary.txt"))

    fig, ax = plt.subplots(figsize=(10.5, 6))
    style = {"forward": dict(color="tab:red", ls="-"), "backward": dict(color="tab:blue", ls="-"),
             "other": dict(color="grey", ls="--")}
    used, fmax, speeds = set(), 0.0, [c[1] for c in crit] + list(lof.values())
    for tid, pts in tracks.items():
        pts.sort()
        votes = Counter(p[2] for p in pts if p[2] in ("forward", "backward"))
        kind = votes.most_common(1)[0][0] if votes else "other"
        used.add(kind)
        x, y = [p[0] for p in pts], [p[1] for p in pts]
        ax.plot(x, y, lw=1.3, marker="." if len(pts) < 60 else None, ms=3, **style[kind])
        bad = [p for p in pts if not p[3]]
        if bad:
            ax.plot([p[0] for p in bad], [p[1] for p in bad], "x", color=style[kind]["color"], ms=7)
            used.add("unstable")
        fmax, speeds = max(fmax, max(y)), speeds + x
    fmax = max([fmax] + [c[2] for c in crit])
    ytop = 1.1 * fmax if fmax > 0 else 1.0

    xmax = max(speeds) if speeds else 0.0
    if xmax > 0:
        for order in sorted({1.0} | {c[0] for c in crit}):
            ax.plot([0, xmax], [0, order * xmax / 60], color="black", lw=0.8 if order == 1 else 0.6)
            xe = min(xmax, 60 * 0.97 * ytop / order)
            ax.text(xe, order * xe / 60, f" {order:g}X", fontsize=8, va="bottom", ha="right")
    for order, rpm, hz in crit:
        ax.plot(rpm, hz, "o", mfc="none", mec="black", ms=8)
        ax.annotate(f"{rpm:.0f} r/min", (rpm, hz), textcoords="offset points", xytext=(5, -12), fontsize=8)
    for name, rpm in lof.items():
        ax.axvline(rpm, color="black", ls=":", lw=1)
        ax.text(rpm, 0.02 * ytop, f" loss of fit {name}", rotation=90, fontsize=8, va="bottom", ha="right")

    handles = [plt.Line2D([], [], label=lab, **style[k]) for k, lab in
               (("forward", "forward whirl"), ("backward", "backward whirl"), ("other", "mixed / non-lateral"))
               if k in used or k != "other"]
    handles.append(plt.Line2D([], [], color="black", lw=0.8, label="1X (f = rpm/60)"))
    if "unstable" in used:
        handles.append(plt.Line2D([], [], color="black", ls="none", marker="x", label="unstable"))
    if crit:
        handles.append(plt.Line2D([], [], ls="none", marker="o", mfc="none", mec="black", label="critical speed"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=9)
    ax.set_xlabel("speed [r/min]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title("Campbell diagram")
    ax.set_ylim(0, ytop)
    if xmax > 0:
        ax.set_xlim(min(speeds + [0.0]), xmax)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "campbell.png"), dpi=150)
    plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_campbell.py OUTDIR")
    main(sys.argv[1])
