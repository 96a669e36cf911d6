#!/usr/bin/env python3
"""Unbalance response of a rotorfit run: reads OUTDIR/response.csv (required: speed_rpm, probe,
fit_state, amplitude_x_m, phase_x_deg, amplitude_y_m, phase_y_deg, major_m, minor_m, whirl, residual,
optionally converged; one row per speed and probe) and, if present, OUTDIR/response_peaks.csv
(probe, speed_rpm, major_m, amplification_factor, half_power_low_rpm, half_power_high_rpm,
separation_margin_percent, required_margin_percent, margin_ok: 1/0 or yes/no/n/a) and
OUTDIR/summary.txt (response.operating_range_rpm MIN MAX, run.status); writes
OUTDIR/response_bode.png and OUTDIR/response_polar.png.

response_bode.png, two panels sharing the speed axis:
  top: major semi-axis of the orbit per probe in micrometres, log axis down to at most 4 decades
  below the highest (from amplitude and phase of x and y when major_m is missing or nan; zero and
  nan points leave a gap; rows with converged 0 as open squares); the peaks of
  response_peaks.csv as black-edged dots with their half-power band (horizontal bar at
  peak / sqrt 2 from half_power_low to half_power_high) and a label "AF 12.3, SM 18 % (req. 12 %)":
  red, and "SM 8 % < req. 12 %", when the margin is below the required one or margin_ok is 0 / no;
  nan parts left out; the probe name in front when there are several probes; peaks of several
  probes at one speed with the same text share one label;
  bottom: phase of x in degrees, lag convention x(t) = A cos(Omega t - phase), unwrapped so it is
  continuous through the resonances.
  Both: the operating range (summary.txt) hatched green; the fit state of each speed (the loosest of
  the probes' rows: open > partly open = partial > closed) as background bands (closed and n/a none,
  partly open light orange, open light red), each band reaching halfway to the neighbouring speeds,
  so a loosening fit is seen where the response changes.
response_polar.png: polar (Nyquist) plot of x per probe, real part A cos(phase) against imaginary
  part -A sin(phase) in micrometres, equal axes, the first speed an open circle; speed labels at the
  peak of every probe and, along the largest curve, at the sweep speeds nearest to 1/7 .. 6/7 of its
  length and at the last speed (equal labels at the same place shown once).
Labels never overlap each other nor leave the axes (label_layout.py: sorted by speed, stacked in
display coordinates with leader lines); --check-labels verifies the drawn boxes of both pictures and
exits 1 on an overlap or a label outside. Each probe has its own colour and dash, so identical probes
stay visible. A missing response.csv or one without rows: message on stderr, exit 1.

Usage: plot_response.py OUTDIR [--check-labels]
"""
import argparse
import math
import os
import sys

import plot_common
from plot_common import labels_ok, num, read_csv, summary_values

FIT_BANDS = {"partly open": ("#ffd9a8", "fit partly open"), "open": ("#ffb8b8", "fit open")}
FIT_RANK = {"open": 3, "partly open": 2, "closed": 1}





def fit_state(s):
    """Normalised fit state: closed, partly open, open or n/a."""
    s = (s or "").strip().lower().replace("_", " ")
    return {"partial": "partly open", "partially open": "partly open"}.get(s, s if s in FIT_RANK else "n/a")


def major_axis(ax_, px, ay, py):
    """Major semi-axis of the orbit x = ax cos(wt - px), y = ay cos(wt - py) (phases in degrees)."""
    if ax_ is None or ay is None:
        return ax_ if ay is None else ay
    if px is None or py is None:
        return max(ax_, ay)
    c = math.cos(math.radians(px - py))
    s, d = ax_ * ax_ + ay * ay, math.sqrt((ax_ * ax_ - ay * ay) ** 2 + 4 * (ax_ * ay * c) ** 2)
    return math.sqrt(max(0.0, (s + d) / 2))


def probe_style(index):
    """Colour and dash of the index-th probe."""
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:cyan", "tab:pink", "tab:olive"]
    dashes = ["-", "--", "-.", ":"]
    return dict(color=colors[index % len(colors)], ls=dashes[index % len(dashes)])


def read_response(path):
    """{probe: [(rpm, state, ax, phx, ay, phy, major, converged)] sorted by speed}, probes in file order."""
    probes = {}
    for r in read_csv(path):
        rpm = num(r.get("speed_rpm"))
        if rpm is None:
            continue
        a_x, p_x, a_y, p_y = (num(r.get(k)) for k in ("amplitude_x_m", "phase_x_deg", "amplitude_y_m", "phase_y_deg"))
        major = num(r.get("major_m"))
        if major is None:
            major = major_axis(a_x, p_x, a_y, p_y)
        if a_x == 0:
            p_x = None      # no response (speed 0): its phase is undefined
        if a_y == 0:
            p_y = None
        probes.setdefault(r.get("probe", "") or "probe", []).append(
            (rpm, fit_state(r.get("fit_state")), a_x, p_x, a_y, p_y, major,
             r.get("converged", "1").lower() not in ("0", "no", "false")))
    for name, rows in probes.items():
        rows.sort(key=lambda t: t[0])
        # a probe that no longer moves (a loose body took the unbalance
        # away) has round-off amplitudes: their phases mean nothing
        top = max((t[6] for t in rows if t[6] is not None and t[6] == t[6]), default=0.0)
        probes[name] = [t if t[6] is None or not t[6] < 1e-6 * top else
                        (t[0], t[1], t[2], None, t[4], None, t[6], t[7]) for t in rows]
    return probes


def fit_bands(probes):
    """[(from rpm, to rpm, state)] of consecutive speeds with the same (loosest) fit state."""
    per_speed = {}
    for rows in probes.values():
        for r in rows:
            old = per_speed.get(r[0], "n/a")
            per_speed[r[0]] = r[1] if FIT_RANK.get(r[1], 0) > FIT_RANK.get(old, 0) else old
    speeds = sorted(per_speed)
    bands = []
    for i, s in enumerate(speeds):
        lo = s if i == 0 else (speeds[i - 1] + s) / 2
        hi = s if i == len(speeds) - 1 else (s + speeds[i + 1]) / 2
        if bands and bands[-1][2] == per_speed[s]:
            bands[-1][1] = hi
        else:
            bands.append([lo, hi, per_speed[s]])
    return [tuple(b) for b in bands]


def unwrap_deg(values):
    """Phases [deg] made continuous (nan kept; jumps over 180 deg taken as wraps)."""
    out, prev, shift = [], None, 0.0
    for v in values:
        if v is None:
            out.append(math.nan)
            continue
        if prev is not None:
            shift -= 360.0 * round((v + shift - prev) / 360.0)
        prev = v + shift
        out.append(prev)
    return out


def interp(rows, rpm, col):
    """Linear interpolation of column col of sorted rows at rpm (None if not possible)."""
    for a, b in zip(rows, rows[1:]):
        if a[0] <= rpm <= b[0] and a[col] is not None and b[col] is not None:
            return a[col] if b[0] == a[0] else a[col] + (b[col] - a[col]) * (rpm - a[0]) / (b[0] - a[0])
    return None


def peak_label(row):
    """'AF 12.3, SM 18 % (req. 12 %)' (parts that are nan left out); red when the margin is too small."""
    af, sm, req = (num(row.get(k)) for k in ("amplification_factor", "separation_margin_percent",
                                              "required_margin_percent"))
    bad = row.get("margin_ok", "").lower() in ("0", "no", "false") or (sm is not None and req is not None and sm < req)
    parts = []
    if af is not None:
        # resolved = 0: the half-power band is narrower than the speed step
        parts.append(f"AF >= {af:.1f} (unresolved)" if row.get("resolved") == "0" else f"AF {af:.1f}")
    if sm is not None and req is not None:
        parts.append(f"SM {sm:.0f} % < req. {req:.0f} %" if sm < req else
                     f"SM {sm:.0f} % (req. {req:.0f} %" + (", not met)" if bad else ")"))
    elif sm is not None:
        parts.append(f"SM {sm:.0f} %" + (", not met" if bad else ""))
    elif req is not None:
        parts.append(f"req. SM {req:.0f} %")
    if not parts:
        parts.append(f"peak {num(row.get('speed_rpm')):,.0f} r/min")
    return ", ".join(parts), bad




def title_of(outdir, what, status):
    case = os.path.basename(os.path.abspath(outdir))
    st = status.get("run.status", "").split()[0] if status.get("run.status") else ""
    bad = st in ("failed", "interrupted")
    return f"{what}: {case}" + (f" (run {st.upper()}: speeds up to the stop only)" if bad else ""), bad


def draw_bode(plt, layout_module, outdir, probes, peaks, op_range, status):
    """response_bode.png; returns (figure, texts to check)."""
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(11, 7.5), dpi=150,
                                   gridspec_kw=dict(height_ratios=[3, 2]))
    handles = []
    bands = fit_bands(probes)
    shown_states = set()
    for lo, hi, st in bands:
        if st in FIT_BANDS:
            for ax in (ax1, ax2):
                ax.axvspan(lo, hi, color=FIT_BANDS[st][0], alpha=0.6, lw=0, zorder=0)
            shown_states.add(st)
    if op_range:
        for ax in (ax1, ax2):
            ax.axvspan(op_range[0], op_range[1], facecolor="none", edgecolor="tab:green", alpha=0.25,
                       hatch="//", lw=0, zorder=0.5)
            for x in op_range:
                ax.axvline(x, color="tab:green", lw=0.8, alpha=0.7, zorder=0.6)
    avoid, positive, unconverged = [], [], False
    for i, (name, rows) in enumerate(probes.items()):
        st = probe_style(i)
        um = [r[6] * 1e6 if r[6] is not None and r[6] > 0 else math.nan for r in rows]
        speeds = [r[0] for r in rows]
        dots = dict(marker=".", ms=4) if len(rows) < 30 else {}   # few speeds: show the points
        ax1.plot(speeds, um, lw=1.4, **st, **dots, zorder=3)
        ax2.plot(speeds, unwrap_deg([r[3] for r in rows]), lw=1.3, **st, **dots, zorder=3)
        avoid.append(list(zip(speeds, um)))
        bad = [(s, u) for s, u, r in zip(speeds, um, rows) if not r[7] and u == u]
        if bad:
            ax1.plot([b[0] for b in bad], [b[1] for b in bad], "s", mfc="none", mec="black", ms=7, zorder=4)
            unconverged = True
        positive += [u for u in um if u == u]
        handles.append(plt.Line2D([], [], lw=1.4, label=name, **st))
    names = list(probes)
    marks, items, seen = [], [], {}
    for row in peaks:
        rpm, name = num(row.get("speed_rpm")), row.get("probe", "")
        if rpm is None:
            continue                      # nan: no peak in the sweep
        y = num(row.get("major_m"))
        if y is None and name in probes:
            y = interp(probes[name], rpm, 6)
        if y is None or y <= 0:
            continue
        color = probe_style(names.index(name))["color"] if name in names else "black"
        ax1.plot(rpm, y * 1e6, "o", mfc=color, mec="black", ms=6, zorder=5)
        lo, hi = num(row.get("half_power_low_rpm")), num(row.get("half_power_high_rpm"))
        if lo is not None and hi is not None:
            ax1.plot([lo, hi], [y * 1e6 / math.sqrt(2)] * 2, color=color, lw=1.2, marker="|", ms=8, zorder=5)
            marks.append("band")
        marks.append("peak")
        text, bad = peak_label(row)
        key = (round(rpm), text)
        if key in seen:                   # the same peak values on another probe: one label, at the highest
            seen[key]["names"].append(name)
            seen[key]["y"] = max(seen[key]["y"], y * 1e6)
            continue
        seen[key] = dict(x=rpm, y=y * 1e6, text=text, names=[name], color="tab:red" if bad else "black",
                         prefer=("right", "up"))
        items.append(seen[key])
    for it in items:
        if len(probes) > 1 and set(it["names"]) >= set(probes):
            it["text"] = "all probes: " + it["text"]
        elif len(probes) > 1 or len(it["names"]) > 1 or (it["names"][0] not in probes):
            it["text"] = ", ".join(n for n in it["names"] if n) + ": " + it["text"]
    if unconverged:
        handles.append(plt.Line2D([], [], ls="none", marker="s", mfc="none", mec="black", ms=7,
                                  label="not converged"))
    if "peak" in marks:
        handles.append(plt.Line2D([], [], ls="none", marker="o", mfc="white", mec="black", ms=6,
                                  label="peak (response_peaks.csv)"))
    if "band" in marks:
        handles.append(plt.Line2D([], [], color="black", lw=1.2, marker="|", ms=8,
                                  label="half-power band\n(peak / \u221a2)"))
    from matplotlib.patches import Patch
    if op_range:
        handles.append(Patch(facecolor="none", edgecolor="tab:green", hatch="//", alpha=0.6,
                             label=f"operating range\n{op_range[0]:,.0f}-{op_range[1]:,.0f} r/min"))
    for st in ("partly open", "open"):
        if st in shown_states:
            handles.append(Patch(color=FIT_BANDS[st][0], alpha=0.6, label=FIT_BANDS[st][1]))
    if positive:
        lo, hi = min(positive), max(positive)
        ax1.set_ylim(max(lo / 1.6, hi * 1e-4), hi * 2.2)  # 4 decades at most; room above the peaks
        ax1.set_yscale("log")
    else:
        ax1.text(0.5, 0.5, "no positive amplitude in response.csv", transform=ax1.transAxes, ha="center")
    speeds = [r[0] for rows in probes.values() for r in rows] + (list(op_range) if op_range else [])
    if speeds:
        pad = 0.0 if max(speeds) > min(speeds) else max(1.0, 0.05 * abs(speeds[0]))   # a single speed
        ax1.set_xlim(min(speeds) - pad, max(speeds) + pad)
    ax1.set_ylabel("major semi-axis [\u00b5m]")
    ax2.set_ylabel("phase of x [deg] (lag)")
    ax2.set_xlabel("speed [r/min]")
    from matplotlib.ticker import MultipleLocator
    ph = [v for line in ax2.get_lines() for v in line.get_ydata() if v == v]
    if ph and max(ph) - min(ph) <= 1440:
        ax2.yaxis.set_major_locator(MultipleLocator(90 if max(ph) - min(ph) > 360 else 45))
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3, which="major")
    title, bad = title_of(outdir, "Unbalance response", status)
    ax1.set_title(title, color="tab:red" if bad else "black", fontsize=11)
    ax1.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=9)
    fig.tight_layout()
    layout = layout_module.LabelLayout(ax1, avoid=avoid)
    texts = layout.place(items, fontsize=8)
    return fig, texts


def draw_polar(plt, layout_module, outdir, probes, status):
    """response_polar.png; returns (figure, texts to check)."""
    fig, ax = plt.subplots(figsize=(9.5, 7.5), dpi=150)
    ax.axhline(0, color="0.4", lw=0.7, zorder=1)
    ax.axvline(0, color="0.4", lw=0.7, zorder=1)
    handles, items, avoid, pts_all, curves = [], [], [], [], []
    for i, (name, rows) in enumerate(probes.items()):
        st = probe_style(i)
        pts = [(r[0], r[2] * math.cos(math.radians(r[3])) * 1e6, -r[2] * math.sin(math.radians(r[3])) * 1e6)
               if r[2] is not None and r[3] is not None else (r[0], math.nan, math.nan) for r in rows]
        ax.plot([p[1] for p in pts], [p[2] for p in pts], lw=1.4, zorder=3, **st)
        good = [p for p in pts if p[1] == p[1]]
        avoid.append([(p[1], p[2]) for p in pts])
        pts_all += good
        handles.append(plt.Line2D([], [], lw=1.4, label=name, **st))
        if not good:
            continue
        ax.plot(good[0][1], good[0][2], "o", mfc="white", mec=st["color"], ms=5, zorder=4)
        peak = max(good, key=lambda p: math.hypot(p[1], p[2]))
        curves.append((math.hypot(peak[1], peak[2]), i, good, st["color"]))
        ax.plot(peak[1], peak[2], "o", color=st["color"], ms=4, zorder=4 + 0.01 * (len(probes) - i))
        items.append(dict(x=peak[1], y=peak[2], text=f"{peak[0]:,.0f} r/min", color=st["color"]))
    if curves:                            # speeds spread along the largest curve, and its last one
        _, i, good, color = max(curves)
        arc = [0.0]
        for a, b in zip(good, good[1:]):
            arc.append(arc[-1] + math.hypot(b[1] - a[1], b[2] - a[2]))
        chosen = [good[min(range(len(good)), key=lambda j: abs(arc[j] - arc[-1] * k / 7))] for k in range(1, 7)]
        for p in sorted({p[0]: p for p in chosen + [good[-1]]}.values()):
            ax.plot(p[1], p[2], "o", color=color, ms=3, zorder=4)
            items.append(dict(x=p[1], y=p[2], text=f"{p[0]:,.0f} r/min", color=color))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("Re x = A cos(phase) [\u00b5m]")
    ax.set_ylabel("Im x = \u2212A sin(phase) [\u00b5m]")
    ax.grid(alpha=0.3)
    if pts_all:
        xs, ys = [p[1] for p in pts_all] + [0.0], [p[2] for p in pts_all] + [0.0]
        padx, pady = 0.12 * (max(xs) - min(xs) or 1.0), 0.12 * (max(ys) - min(ys) or 1.0)
        ax.set_xlim(min(xs) - padx, max(xs) + padx)
        ax.set_ylim(min(ys) - pady, max(ys) + pady)
    else:
        ax.text(0.5, 0.5, "no amplitude/phase of x in response.csv", transform=ax.transAxes, ha="center")
    title, bad = title_of(outdir, "Polar plot of x (speed increases from the open circle)", status)
    ax.set_title(title, color="tab:red" if bad else "black", fontsize=11)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=9)
    fig.tight_layout()
    fig.canvas.draw()                     # equal aspect: the final limits exist after a draw
    tol_x = 0.012 * (ax.get_xlim()[1] - ax.get_xlim()[0])
    tol_y = 0.012 * (ax.get_ylim()[1] - ax.get_ylim()[0])
    unique = []                           # equal labels at the same place (identical probes): once
    for it in items:
        if not any(u["text"] == it["text"] and abs(u["x"] - it["x"]) < tol_x and abs(u["y"] - it["y"]) < tol_y
                   for u in unique):
            unique.append(it)
    layout = layout_module.LabelLayout(ax, avoid=avoid)
    texts = layout.place(unique, fontsize=8)
    return fig, texts


def main(outdir, check_labels=False):
    """Draw the two pictures; returns 0, or 1 when check_labels finds a bad label."""
    path = os.path.join(outdir, "response.csv")
    if not os.path.isfile(path):
        sys.exit(f"plot_response.py: {path} not found")
    probes = read_response(path)
    if not probes:
        sys.exit(f"plot_response.py: {path} has no rows with a speed")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        layout_module = plot_common.layout_module()
    except ImportError as e:
        sys.exit(f"plot_response.py: matplotlib not importable ({e})")
    summary = summary_values(os.path.join(outdir, "summary.txt"))
    op = [num(v) for v in summary.get("response.operating_range_rpm", "").split()[:2]]
    op_range = tuple(sorted(op)) if len(op) == 2 and None not in op else None
    peaks = read_csv(os.path.join(outdir, "response_peaks.csv"))
    ok = True
    for name, draw in (("response_bode.png", lambda: draw_bode(plt, layout_module, outdir, probes, peaks,
                                                                 op_range, summary)),
                       ("response_polar.png", lambda: draw_polar(plt, layout_module, outdir, probes, summary))):
        fig, texts = draw()
        fig.savefig(os.path.join(outdir, name), dpi=150)
        if check_labels and not labels_ok(fig, [t for t in texts if t is not None]):
            print(f"plot_response.py: labels of {name} overlap or leave the axes (see above)", file=sys.stderr)
            ok = False
        plt.close(fig)
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Bode and polar plots of the unbalance response in a rotorfit "
                                     "output folder (writes OUTDIR/response_bode.png and response_polar.png).")
    parser.add_argument("outdir")
    parser.add_argument("--check-labels", action="store_true",
                        help="exit 1 if two labels overlap or one leaves the axes")
    args = parser.parse_args()
    sys.exit(main(args.outdir, args.check_labels))
