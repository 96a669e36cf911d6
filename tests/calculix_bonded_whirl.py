#!/usr/bin/env python3
"""CTest calculix_bonded_whirl (label independent): TS's pre-stressed whirl
frequencies against CalculiX on the same mesh file.

Reference: CalculiX (Debian calculix-ccx 2.20) on the coarse TS mesh (gmsh,
P2 tetrahedra, h_fit 5 mm, h_max 8 mm), fit bonded (the conforming fit's
shared nodes), bearings as rotorfit's (area average + spring k = 1e7 N/m),
per speed a linear *STATIC step under CENTRIF, a *FREQUENCY perturbation
step (stress stiffness of the static state) and *COMPLEX FREQUENCY,
CORIOLIS, converted from CalculiX's rotating frame to rotorfit's stationary
one (doc/calculix.md). rotorfit: prm/test_shaft.prm on the same .msh, its
bearing dampers set to 0 (CalculiX has none), contact solved with the 3 um
interference (closed at both speeds; the eigenproblem ties the closed pairs).

Compared: both whirl pairs (first and second bending, backward and forward)
at rest (CalculiX's real modes, its complex step being degenerate there;
sorted frequencies) and at 15,000 r/min (CalculiX's complex mode of the
predicted rotating-frame frequency and turning direction, converted back).

Tolerance: 3e-4 relative on every mode, (rotorfit - CalculiX) / CalculiX;
and each pair's gyroscopic split at speed, f_forward - f_backward, where the
elements' common offset cancels but for the members' different shares:
2.6e-2 (first pair, 0.385 Hz, observed +5.3e-3: the offsets +1.12e-4 and
+1.17e-4 of 358 Hz differ by 1.8e-3 Hz) and 7e-4 (second pair, 63.4 Hz,
observed -1.4e-4).
Observed on this mesh: +1.12e-4 .. +1.20e-4 (first pair), +7.0e-5 .. +8.1e-5
(second pair), the same at rest and at speed: an offset of the elements
(CalculiX's 4-point C3D10 rule against rotorfit's degree-4 one; 2e-5 on
the 3/6 mm mesh of doc/calculix.md), not of the rotordynamics.
Faults (each alone): sleeve density x 1.005 fails (first pair -1.29e-3,
second pair -2.1e-4 .. -4.6e-4); G x 1.01 on the sleeve (a source edit)
fails the second pair's split (+9.6e-3) and its forward member (+3.1e-4). Not caught, and not this test's business:
interference x 1.005 (the modes move by 1e-8) and the eigenproblem's tie
stiffness / 10 (Contact penalty scale 100: every mode within 1.7e-5 of the
default's, seven times below the elements' offset).

  calculix_bonded_whirl.py ROTORFIT OUTDIR [--ccx ccx]
                           [--set ENTRY=VALUE ...]   (extra rotorfit --set)
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import calculix_reference as cr  # noqa: E402

H_FIT, H_MAX = 5e-3, 8e-3
SPEED = 15000.0   # r/min: the fit closed in rotorfit (first opening 19,844 on this mesh)
N_REAL = 30       # real modes of the *FREQUENCY step: the complex step's basis
N_COMPLEX = 20
F_LOWER = 10.0    # Hz: excludes the free axial and torsional rigid modes
TOL = 3e-4        # observed up to 1.20e-4 (first pair at rest)
# the gyroscopic split f_forward - f_backward of each pair at speed, relative
# to CalculiX's: the elements' offset, common to both members, cancels in it.
# Observed +5.3e-3 (first pair: a split of 0.385 Hz; the two members' element
# offsets, +1.12e-4 and +1.17e-4 of 358 Hz, differ by 1.8e-3 Hz) and -1.4e-4
# (second pair, 63.4 Hz): 5 x each
TOL_SPLIT = (2.6e-2, 7e-4)


def main():
    args = cr.arguments()
    t_start = time.time()
    cr.require_tools(args.ccx)
    work = os.path.abspath(args.outdir)
    os.makedirs(work, exist_ok=True)
    msh = cr.mesh(work, H_FIT, H_MAX)
    model = cr.ccx_model(msh, "bonded")
    print("mesh %s: CalculiX %d DOFs (fit bonded)" % (msh, model["ndofs"]), flush=True)

    dats, campbell = cr.bonded_speeds(args, work, msh, model, "whirl", SPEED, 6,
                                      (N_REAL, N_COMPLEX, F_LOWER))

    checks = cr.Checks()
    print("\nrelative difference = (rotorfit - CalculiX) / f, in the stationary frame")
    # at rest: both codes' lowest four, sorted (the members of a doublet
    # and their whirl labels are arbitrary there)
    mine = sorted(f for w, f in cr.lowest_whirl(campbell, 0.0, 4))
    theirs = sorted(cr.read_ccx_real(dats[0]))[:4]
    for k, (a, b) in enumerate(zip(mine, theirs)):
        checks.rel("0 r/min, mode %d [Hz]" % (k + 1), a, b, TOL)
    # at speed: each rotorfit mode against the CalculiX mode of its
    # rotating-frame frequency and turning direction (one to one)
    matched = cr.match_whirl(checks, cr.lowest_whirl(campbell, SPEED, 4),
                             dats[1], SPEED, TOL)
    # each pair's split (the gyroscopic effect itself; a 1 % error of one
    # body's G moves the second pair's by about 1 %)
    for k in range(2):
        pair = {w: (f, g) for w, f, g in matched[2 * k:2 * k + 2]}
        if set(pair) != {"backward", "forward"}:
            cr.die("%g r/min: pair %d is not one backward and one forward mode" % (SPEED, k + 1))
        split = pair["forward"][0] - pair["backward"][0]
        split_ccx = pair["forward"][1] - pair["backward"][1]
        checks.rel("%g r/min, pair %d split forward - backward [Hz]" % (SPEED, k + 1),
                   split, split_ccx, TOL_SPLIT[k])
    print("wall time %.1f s" % (time.time() - t_start))
    checks.finish("calculix_bonded_whirl")


if __name__ == "__main__":
    main()
