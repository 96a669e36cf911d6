#!/usr/bin/env python3
"""CTest calculix_contact_pressure (label independent): TS's shrink-fit
contact pressure and loss of fit against CalculiX on the same mesh file.

Both codes read one gmsh mesh (prm/test_shaft.geo, P2 tetrahedra, h_fit
5 mm, h_max 8 mm; 518 fit node pairs), TS's materials, 3 um radial
interference, rotorfit's static supports; CENTRIF on the undeformed radius.
CalculiX's nodal contact forces are its RF at the shaft's fit nodes minus the
consistent centrifugal load there (its own 4-point rule); from them the mean
and the largest pressure are formed exactly as rotorfit forms its own (sum
N_i / fit area; nodal p from M_Gamma p = N on the shaft side, doc/theory.md
7.5), so like is compared with like. Two CalculiX references (Debian
calculix-ccx 2.20):

1. The contact pair: the fit's nodes duplicated (shaft and sleeve each own
   theirs, coincident), a frictionless face-to-face mortar pair, hard
   contact (Lagrange multipliers: no penalty error), the interference as
   *CLEARANCE, VALUE=-3e-6; one nonlinear *STATIC step per speed (0, 15,000,
   23,500, 24,500 r/min). Tolerances, with the observed rotorfit - CalculiX:
     mean pressure at 0 / 15,000 r/min      2e-2 / 3e-2   [+6.4e-3 / +1.1e-2]
     centrifugal drop p(0) - p(15,000)      2e-4          [+3.8e-5]
     largest pressure at 0 / 15,000 r/min   0.5 (loose)   [-0.11 / -0.16]
     rotorfit's full opening (loss of fit) between 23,500 r/min, where
     CalculiX's fit is partly closed, and 24,500, where it is fully open
                                                          [24,057 r/min]
   Why the pressure at rest is only good to 2 %: CalculiX's mortar measures
   the gap of each slave face along the face's mean normal; on this mesh a
   fit face spans 0.5 rad of the circumference, and the mid-edge pairs end
   with a radial jump of 2.94 .. 3.00 um instead of 3 um (rotorfit imposes 3
   um at every pair along its radial normal). The difference falls as h^2
   (+2.3e-3 at h_fit 3 mm, where one CalculiX step takes 4 minutes), and it
   does not touch the centrifugal part, which agrees to 4e-5. The largest
   pressure sits on the sleeve's edge, where the elastic solution is
   singular: node-exact (rotorfit) and weak (mortar) constraints put
   different shares of that peak on the edge pairs, so it is compared only
   loosely here, and like for like against reference 2.
   (The face-to-face penalty pair, TYPE=SURFACE TO SURFACE, is no reference
   here: it measures the gap to flat sub-triangles of the master's curved
   faces, which sag by ~80 um on this mesh against a 3 um interference;
   with a penalty slope of 1e16 Pa/m only a third of its points carried
   load, at up to 190 MPa where the fit's mean is 12 MPa.)
2. The closed fit node to node: per pair n . (u_sleeve - u_shaft) = delta
   along the pair's radial normal (*EQUATION), tangential and axial free:
   rotorfit's closed-pair constraint, solved by CalculiX's elements, loads
   and solver (linear *STATIC at 0 and 15,000 r/min, both with every pair
   closed in rotorfit). Tolerances [observed]:
     mean pressure                          4e-4          [+8.5e-5, +1.4e-4]
     largest pressure                       1e-2          [+3.5e-3, +2.7e-3]
   (what is left is the elements: CalculiX's 4-point C3D10 rule against
   rotorfit's degree-4 one, on curved P2 tetrahedra).
Faults (each alone, tests/CMakeLists.txt): sleeve density x 1.005 and
interference x 1.005 fail here; the eigenproblem's tie stiffness does not
enter the statics.

  calculix_contact_pressure.py ROTORFIT OUTDIR [--ccx ccx]
                               [--set ENTRY=VALUE ...]   (extra rotorfit --set)
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import calculix_reference as cr  # noqa: E402

H_FIT, H_MAX = 5e-3, 8e-3
CLOSED = 15000.0           # r/min: every pair closed (first opening 19,844)
LOW, HIGH = 23500.0, 24500.0
# contact pair (1)
TOL_MEAN_REST, TOL_MEAN_SPEED = 2e-2, 3e-2
TOL_DROP = 2e-4
TOL_MAX_PAIR = 0.5
# node-to-node closed fit (2)
TOL_MEAN_TIED, TOL_MAX_TIED = 4e-4, 1e-2
OPEN = 1e-6                # total normal force / force at rest below: open


def main():
    args = cr.arguments(lambda ap: ap.add_argument(
        "--reuse", action="store_true",
        help="read CalculiX's results of an earlier run in OUTDIR"))
    t_start = time.time()
    cr.require_tools(args.ccx)
    work = os.path.abspath(args.outdir)
    os.makedirs(work, exist_ok=True)
    msh = cr.mesh(work, H_FIT, H_MAX)
    model = cr.ccx_model(msh, "contact")
    print("mesh %s: CalculiX %d DOFs (fit nodes duplicated, %d pairs)" %
          (msh, model["ndofs"], len(model["twin"])), flush=True)

    pair_speeds = [0.0, CLOSED, LOW, HIGH]
    jobs = {rpm: "pair_%05d" % rpm for rpm in pair_speeds}
    if not args.reuse:
        for rpm, job in jobs.items():
            cr.mortar_deck(os.path.join(work, job + ".inp"), model, rpm, cr.INTERFERENCE)
        cr.tied_fit_deck(os.path.join(work, "tied.inp"), model, [0.0, CLOSED], cr.INTERFERENCE)
        # the longest first (idle machine: 51, 41, 42, 27, 11 s), two at a time
        order = [jobs[CLOSED], jobs[0.0], jobs[LOW], jobs[HIGH], "tied"]
        print("CalculiX, 5 jobs: %.1f s" % cr.run_ccx_jobs(args.ccx, order, work), flush=True)

    load = cr.centrifugal_nodal_loads(model, list(model["twin"]))

    def pressures(rf, rpm):
        forces = {t: rf[t] - cr.omega2(rpm) * load[t] for t in model["twin"]}
        return cr.fit_pressures(model, forces)

    def rf_steps(job, n):
        rf = cr.read_rf(os.path.join(work, job + ".dat")).get("NFITSH", [])
        if len(rf) != n:
            cr.die("%s.dat: RF of %d steps, %d expected" % (job, len(rf), n))
        return rf

    pair = {rpm: pressures(rf_steps(jobs[rpm], 1)[0], rpm) for rpm in pair_speeds}
    tied_rf = rf_steps("tied", 2)
    tied = {rpm: pressures(tied_rf[k], rpm) for k, rpm in enumerate([0.0, CLOSED])}
    for name, res in (("contact pair", pair), ("node to node", tied)):
        for rpm, (mean, top, N) in sorted(res.items()):
            print("CalculiX %-12s %6.0f r/min: mean %.7g Pa, max %.7g Pa, total normal "
                  "force %.7g N" % (name, rpm, mean, top, N.sum()))

    out = os.path.join(work, "rotorfit")
    sets = ["Geometry/Geometry file=" + msh, "Geometry/Geometry parameters=",
            "Speeds/Mode=list", "Speeds/List=0, %g, %g, %g" % (CLOSED, LOW, HIGH),
            "Eigenproblem/Compute modes=false", "Unbalances=", "Probes=",
            "Output/Pictures=false", "Output/Write ParaView files=false"]
    print("rotorfit: %.1f s" % cr.run_rotorfit(args.rotorfit, out, sets + args.sets), flush=True)
    rows = {float(r["speed_rpm"]): r for r in cr.read_csv(os.path.join(out, "contact.csv"))}
    lof = float(cr.summary(out)["interface.fit.loss_of_fit_rpm"])

    checks = cr.Checks()
    print("\nrelative difference = (rotorfit - CalculiX) / CalculiX")
    mean, top = {}, {}
    for rpm in (0.0, CLOSED):
        r = rows[rpm]
        checks.true("rotorfit %g r/min: every pair closed, converged" % rpm,
                    r["closed_pairs"] == r["total_pairs"] and r["converged"] == "1",
                    "%s of %s pairs" % (r["closed_pairs"], r["total_pairs"]))
        mean[rpm], top[rpm] = float(r["mean_pressure_Pa"]), float(r["max_pressure_Pa"])
    print("-- 1. the contact pair (mortar, frictionless, *CLEARANCE)")
    checks.rel("0 r/min mean pressure [Pa]", mean[0.0], pair[0.0][0], TOL_MEAN_REST)
    checks.rel("%g r/min mean pressure [Pa]" % CLOSED, mean[CLOSED], pair[CLOSED][0],
               TOL_MEAN_SPEED)
    checks.rel("mean pressure drop 0 -> %g r/min [Pa]" % CLOSED, mean[0.0] - mean[CLOSED],
               pair[0.0][0] - pair[CLOSED][0], TOL_DROP)
    checks.rel("0 r/min largest pressure [Pa] (loose)", top[0.0], pair[0.0][1], TOL_MAX_PAIR)
    checks.rel("%g r/min largest pressure [Pa] (loose)" % CLOSED, top[CLOSED], pair[CLOSED][1],
               TOL_MAX_PAIR)
    n0 = pair[0.0][2].sum()
    n_low, n_high = pair[LOW][2].sum(), pair[HIGH][2].sum()
    checks.true("CalculiX %g r/min: fit partly closed" % LOW, n_low > OPEN * n0,
                "total normal force %.4g N (%d of %d pairs carry load)" %
                (n_low, (pair[LOW][2] > OPEN * n0).sum(), len(model["twin"])))
    checks.true("CalculiX %g r/min: fit fully open" % HIGH, abs(n_high) <= OPEN * n0,
                "total normal force %.3g N" % n_high)
    checks.true("rotorfit loss of fit within (%g, %g) r/min" % (LOW, HIGH), LOW < lof < HIGH,
                "%.1f r/min" % lof)
    checks.true("rotorfit: partly closed at %g, open at %g r/min" % (LOW, HIGH),
                int(rows[LOW]["closed_pairs"]) > 0 and int(rows[HIGH]["closed_pairs"]) == 0,
                "%s and %s pairs closed" % (rows[LOW]["closed_pairs"], rows[HIGH]["closed_pairs"]))
    print("-- 2. the closed fit node to node (*EQUATION along each pair's radial normal)")
    for rpm in (0.0, CLOSED):
        checks.rel("%g r/min mean pressure [Pa]" % rpm, mean[rpm], tied[rpm][0], TOL_MEAN_TIED)
        checks.rel("%g r/min largest pressure [Pa]" % rpm, top[rpm], tied[rpm][1], TOL_MAX_TIED)
    print("wall time %.1f s" % (time.time() - t_start))
    checks.finish("calculix_contact_pressure")


if __name__ == "__main__":
    main()
