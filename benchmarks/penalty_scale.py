#!/usr/bin/env python3
"""The penalty scale from 1e-2 to 1e8 on the plane-strain Lame case
(hexahedra, tests/lame_plane_strain_hex.prm; exact values from tests/lame.py):
for pure penalty and the augmented Lagrangian, the error of the pressure at
rest and of the loss of fit, the constraint error, the Uzawa iterations and
what rotorfit says (the contact status and the log's warnings).

    python3 benchmarks/penalty_scale.py        (repository root, build/ built)
Writes benchmarks/output/penalty_scale/ and prints a Markdown table
(doc/limits.md).
"""
import csv
import os
import subprocess
import sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
exe = os.environ.get("ROTORFIT", os.path.join(root, "build", "rotorfit"))
prm = os.path.join(root, "tests", "lame_plane_strain_hex.prm")
P0, LOSS = 12.7311e6, 23694.1  # tests/lame.py 0.01 0.04 3e-6 205e9 0.3 7850 68.9e9 0.33 2700

print("| method | penalty scale | pressure error | loss-of-fit error | constraint error | "
      "Uzawa iterations | status at rest | exit | warnings |")
print("|---|---|---|---|---|---|---|---|---|")
for method in ("penalty", "augmented Lagrangian"):
    for scale in ("1e-2", "1e-1", "1", "10", "1e2", "1e4", "1e6", "1e8"):
        out = os.path.join(root, "benchmarks", "output", "penalty_scale",
                           method.split()[0] + "_" + scale)
        r = subprocess.run([exe, "--output", out, "--set", f"Contact/Method={method}",
                            "--set", f"Contact/Penalty scale={scale}", prm],
                           capture_output=True, text=True)
        s = {}
        if os.path.exists(os.path.join(out, "summary.txt")):
            s = dict(l.split(None, 1) for l in open(os.path.join(out, "summary.txt")) if l.strip())
        rows = list(csv.DictReader(open(os.path.join(out, "contact.csv")))) \
            if os.path.exists(os.path.join(out, "contact.csv")) else []
        p0 = float(s.get("interface.fit.mean_pressure_first_speed_Pa", "nan"))
        loss = float(s.get("interface.fit.loss_of_fit_rpm", "nan"))
        err = float(s.get("interface.fit.constraint_error_max", "nan"))
        uzawa = rows[0]["uzawa_iterations"] if rows else "-"
        status = rows[0]["status"] if rows else "-"
        warnings = "; ".join(l.strip()[:90] for l in r.stdout.splitlines() if "Warning" in l) or "-"
        print(f"| {method} | {scale} | {(p0 - P0) / P0:+.2e} | {(loss - LOSS) / LOSS:+.2e} | "
              f"{err:.1e} | {uzawa} | {status} | {r.returncode} | {warnings} |", flush=True)
