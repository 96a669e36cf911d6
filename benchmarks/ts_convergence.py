#!/usr/bin/env python3
"""TS: how the opening speeds converge with the element size at the fit,
against the Lame bracket 22,896 (plane stress) .. 23,694 r/min (plane strain)
and the study's ~23,000 r/min.

Usage (repository root, after building into build/; ROTORFIT=path overrides
the executable):
    python3 benchmarks/ts_convergence.py [h_fit_mm ...]      (default 4 3 2.5 2)
Writes benchmarks/output/ts_convergence/<h>/ and prints a Markdown table:
pressure at rest, first pair opening, half opening (contact fraction 0.5,
linear in speed between the computed speeds), full opening (total contact
force of the last closed set reaches zero), DOFs, pairs, factorisations.
"""
import csv
import os
import re
import subprocess
import sys
import time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
speeds = "0, 20000, 21000, 22000, 22500, 23000, 23500, 24000, 24500, 25000, 25500, 26000, 27000"


def run(h_fit_mm):
    h = h_fit_mm * 1e-3
    out = os.path.join(root, "benchmarks", "output", "ts_convergence", f"{h_fit_mm:g}mm")
    os.makedirs(out, exist_ok=True)
    text = open(os.path.join(root, "prm", "test_shaft.prm")).read()
    text = re.sub(r"set Geometry parameters = .*", f"set Geometry parameters = h_fit: {h:g}, h_max: {min(2 * h, 8e-3):g}", text)
    text = re.sub(r"set Geometry file\s*=\s*\S+", "set Geometry file = " + os.path.join(root, "prm", "test_shaft.geo"), text)
    text = re.sub(r"set Directory\s*=\s*\S+", "set Directory = " + out, text)
    text = re.sub(r"set Write ParaView files = true", "set Write ParaView files = false", text)
    text = re.sub(r"  set Mode  = range", "  set Mode  = list\n  set List  = " + speeds, text)
    text += "subsection Eigenproblem\n  set Compute modes = false\nend\n"  # a static study
    prm = os.path.join(out, "case.prm")
    open(prm, "w").write(text)
    t = time.time()
    exe = os.environ.get("ROTORFIT", os.path.join(root, "build", "rotorfit"))
    log = subprocess.run([exe, prm], capture_output=True, text=True, check=True).stdout
    wall = time.time() - t
    s = dict(l.split(None, 1) for l in open(os.path.join(out, "summary.txt")))
    rows = list(csv.DictReader(open(os.path.join(out, "contact.csv"))))
    half = float("nan")
    for a, b in zip(rows, rows[1:]):
        fa, fb = float(a["contact_fraction"]), float(b["contact_fraction"])
        if fa >= 0.5 > fb:
            wa, wb = float(a["speed_rpm"]), float(b["speed_rpm"])
            half = wa + (fa - 0.5) / (fa - fb) * (wb - wa)
            break
    dofs = re.search(r"(\d+) tetrahedra, (\d+) DOFs", log)
    return dict(h=h_fit_mm, tets=int(dofs.group(1)), dofs=int(dofs.group(2)),
                pairs=int(s["interface.fit.pairs"]),
                p0=float(s["interface.fit.mean_pressure_first_speed_Pa"]) / 1e6,
                first=float(s["interface.fit.first_opening_rpm"]), half=half,
                full=float(s["interface.fit.loss_of_fit_rpm"]),
                fact=int(s["static.factorizations"]), wall=wall)


if __name__ == "__main__":
    sizes = [float(a) for a in sys.argv[1:]] or [4, 3, 2.5, 2]
    print("| h_fit [mm] | tets | DOFs | pairs | p at rest [MPa] | first opening [r/min] "
          "| half open [r/min] | fully open [r/min] | factorisations | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for h in sizes:
        r = run(h)
        print(f"| {r['h']:g} | {r['tets']} | {r['dofs']} | {r['pairs']} | {r['p0']:.3f} | {r['first']:.0f} "
              f"| {r['half']:.0f} | {r['full']:.0f} | {r['fact']} | {r['wall']:.0f} |", flush=True)
