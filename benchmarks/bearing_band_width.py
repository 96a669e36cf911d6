#!/usr/bin/env python3
"""Band-width sensitivity of journal bearings given by axial position and width
(doc/bearings.md): runs prm/overhung_rotor.prm with both bearing bands WIDTH mm
wide (default 5, 10, 20, 40) at the speeds 0 and 10,000 r/min, and prints the
first two whirl pairs (backward / forward) of each run and their deviation from
the 20 mm run as a markdown table.

  python3 benchmarks/bearing_band_width.py [EXE] [WIDTH_MM ...]

EXE defaults to build/rotorfit; results go to output/band_width_W/.
"""
import csv
import os
import subprocess
import sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
exe = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "build", "rotorfit")
widths = [float(w) for w in sys.argv[2:]] or [5.0, 10.0, 20.0, 40.0]
speeds = (0.0, 10000.0)
prm = os.path.join(root, "prm", "overhung_rotor.prm")


def run(width_mm):
    out = os.path.join(root, "output", f"band_width_{width_mm:g}")
    sets = [f"Bearing {b}/Width={width_mm / 1000:g}" for b in ("left", "right")]
    sets += ["Speeds/Mode=list", "Speeds/List=" + ", ".join(f"{s:g}" for s in speeds),
             "Output/Pictures=false", "Eigenproblem/Write mode shapes=false",
             "Eigenproblem/Number of modes=4"]
    cmd = [exe, "--output", out] + sum((["--set", s] for s in sets), []) + [prm]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    table = list(csv.DictReader(open(os.path.join(out, "campbell.csv"))))
    result = {}
    for s in speeds:
        rows = [r for r in table if float(r["speed_rpm"]) == s]
        bw = sorted(float(r["frequency_hz"]) for r in rows if r["whirl"] == "backward")
        fw = sorted(float(r["frequency_hz"]) for r in rows if r["whirl"] == "forward")
        result[s] = list(zip(bw, fw))[:2]
    return result


results = {w: run(w) for w in widths}
ref = results.get(20.0, results[widths[-1]])
print("| band width | " + " | ".join(f"pair {p + 1} at {s:,.0f} r/min: BW / FW [Hz]"
                                      for s in speeds for p in range(2)) + " |")
print("|---" * (1 + 2 * len(speeds)) + "|")
for w in widths:
    cells = []
    for s in speeds:
        for p in range(2):
            b, f = results[w][s][p]
            rb, rf = ref[s][p]
            cells.append(f"{b:.2f} / {f:.2f} ({100 * (b / rb - 1):+.2f} / {100 * (f / rf - 1):+.2f} %)")
    print(f"| {w:g} mm | " + " | ".join(cells) + " |")
