#!/usr/bin/env python3
"""CTest checks of the harmonic model's ParaView files against closed forms
(doc/axisymmetric.md, "ParaView"). Tolerances are arguments, stated in
tests/CMakeLists.txt.

  check_paraview.py lame EXE PRM OUT STRESS_TOL U_TOL [H]
      plane-strain Lame fit (tests/axi_lame_plane_strain.prm) at rest, on
      element size H if given: the meridian file solution_0000.vtu's radial,
      hoop and axial stresses at every point within STRESS_TOL x p of the
      closed form (shaft: -p, -p, -2 nu p; hub: A -+ B / r^2, 2 nu A), its
      radial displacement within U_TOL x the interference.
  check_paraview.py rigid EXE PRM OUT RIGID_TOL WHIRL_TOL
      rigid rotor on bearings (tests/axi_rigid_rotor.prm) at 0 and 10,000
      r/min: every harmonic-1 mode of the swept file modes_0001.vtu is a rigid
      motion (no stretch between any two points, relative to the mode's
      largest displacement, <= RIGID_TOL), and whirls as campbell.csv says:
      |U_x - i U_y| / |U_x + i U_y| <= WHIRL_TOL for forward, the inverse for
      backward.
"""

import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run_test  # noqa: E402
import vtu  # noqa: E402


def fail(message):
    print("FAILED: " + message)
    sys.exit(1)


def lame(exe, prm, out, stress_tol, u_tol, sets=()):
    run_test.run(exe, run_test.case(prm, out, ["Speeds/Mode=list", "Speeds/List=0",
                                               "Output/Write ParaView files=true"] + list(sets)))
    delta, a, b = 3e-6, 0.010, 0.040
    e_s, nu_s, e_h, nu_h = 205e9, 0.30, 68.9e9, 0.33
    # plane strain: hub bore and solid shaft under the fit pressure p
    c_hub = (1 + nu_h) * ((1 - 2 * nu_h) * a * a + b * b) / (e_h * (b * b - a * a))
    c_shaft = (1 + nu_s) * (1 - 2 * nu_s) / e_s
    p = delta / (a * (c_hub + c_shaft))
    A = p * a * a / (b * b - a * a)
    B = A * b * b
    d = vtu.read(os.path.join(out, "solution_0000.vtu"))
    worst = {"stress": (0, None), "u": (0, None)}
    for i, x in enumerate(d["points"]):
        r = x[0]
        if d["point"]["body"][i][0] == 0:
            exact = (-p, -p, -2 * nu_s * p, -p * c_shaft * r)
        else:
            exact = (A - B / (r * r), A + B / (r * r), 2 * nu_h * A,
                     (1 + nu_h) / e_h * ((1 - 2 * nu_h) * A * r + B / r))
        got = (d["point"]["radial_stress_Pa"][i][0], d["point"]["hoop_stress_Pa"][i][0],
               d["point"]["axial_stress_Pa"][i][0], d["point"]["displacement_m"][i][0])
        e = max(abs(got[k] - exact[k]) for k in range(3)) / p
        if e > worst["stress"][0]:
            worst["stress"] = (e, x)
        e = abs(got[3] - exact[3]) / delta
        if e > worst["u"][0]:
            worst["u"] = (e, x)
    print("p = %.6g MPa (closed form), %d points" % (p / 1e6, len(d["points"])))
    print("largest stress error / p: %.3g at r = %.4g m, z = %.4g m (tolerance %g)"
          % (worst["stress"][0], worst["stress"][1][0], worst["stress"][1][1], stress_tol))
    print("largest u_r error / delta: %.3g at r = %.4g m, z = %.4g m (tolerance %g)"
          % (worst["u"][0], worst["u"][1][0], worst["u"][1][1], u_tol))
    if not worst["stress"][0] <= stress_tol:
        fail("stresses off the Lame closed form")
    if not worst["u"][0] <= u_tol:
        fail("radial displacement off the Lame closed form")


def rigid(exe, prm, out, rigid_tol, whirl_tol):
    run_test.run(exe, run_test.case(prm, out, ["Speeds/Mode=list", "Speeds/List=0, 10000",
                                               "Output/Write ParaView files=true",
                                               "Output/ParaView speeds=ends"]))
    with open(os.path.join(out, "campbell.csv")) as f:
        rows = [r for r in csv.DictReader(f)
                if float(r["speed_rpm"]) == 10000 and r["harmonic"] == "1"]
    d = vtu.read(os.path.join(out, "modes_0001.vtu"))
    pts = d["points"]
    refs = range(0, len(pts), max(1, len(pts) // 40))
    if not rows:
        fail("no harmonic-1 modes at 10000 r/min in campbell.csv")
    for row in rows:
        name = "h1_mode_%02d" % int(row["mode"])
        if name + "_re" not in d["point"]:
            fail(name + " missing in modes_0001.vtu")
        u = [tuple(complex(re, im) for re, im in zip(d["point"][name + "_re"][i],
                                                     d["point"][name + "_im"][i]))
             for i in range(len(pts))]
        scale = max(math.sqrt(sum(abs(c) ** 2 for c in v)) for v in u)
        # a rigid motion keeps every distance: (u_i - u_j) . (x_i - x_j) = 0
        stretch = 0
        for j in refs:
            for i in range(len(pts)):
                dx = [pts[i][k] - pts[j][k] for k in range(3)]
                length = math.sqrt(sum(c * c for c in dx))
                if length > 0:
                    s = abs(sum((u[i][k] - u[j][k]) * dx[k] for k in range(3))) / length
                    stretch = max(stretch, s / scale)
        fwd = sum(abs(v[0] + 1j * v[1]) for v in u)
        bwd = sum(abs(v[0] - 1j * v[1]) for v in u)
        ratio = bwd / fwd if row["whirl"] == "forward" else fwd / bwd
        print("%s (%s, %s Hz): stretch %.3g (tolerance %g), opposite whirl share %.3g "
              "(tolerance %g)" % (name, row["whirl"], row["frequency_hz"], stretch, rigid_tol,
                                  ratio, whirl_tol))
        if not stretch <= rigid_tol:
            fail(name + " is not a rigid motion in the swept file")
        if not ratio <= whirl_tol:
            fail(name + " does not whirl " + row["whirl"] + " in the swept file")


if __name__ == "__main__":
    mode, args = sys.argv[1], sys.argv[2:]
    if mode == "lame":
        h = args[5:6]
        lame(args[0], args[1], args[2], float(args[3]), float(args[4]),
             ["Geometry/Sections/Element size=" + h[0],
              "Geometry/Sections/Fit element size=" + h[0]] if h else [])
    elif mode == "rigid":
        rigid(args[0], args[1], args[2], float(args[3]), float(args[4]))
    else:
        fail("unknown mode " + mode)
    print("PASSED")
