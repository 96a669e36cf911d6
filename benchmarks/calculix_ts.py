#!/usr/bin/env python3
"""TS against CalculiX on one mesh, in one run (doc/calculix.md).

  python3 benchmarks/calculix_ts.py [--rotorfit build/rotorfit] [--work DIR]
        [--h-fit 3e-3 --h-max 6e-3] [--speeds 0,10000,20000 | 0:30000:1000]
        [--runs 3] [--threads N] [--main-job] [--ccx ccx] [--reuse]

1. gmsh meshes prm/test_shaft.geo once (quadratic tetrahedra) into ts.msh; both
   codes read that file, so the meshes are the same node for node.
2. CalculiX (Debian's calculix-ccx) solves, per speed, the usual three steps:
   a linear *STATIC step under *DLOAD CENTRIF (fit bonded: the coincident
   interface nodes merged), a *FREQUENCY perturbation step (stress stiffness of
   the static step) and *COMPLEX FREQUENCY, CORIOLIS. Bearings: the lateral
   displacement of a reference node is tied by *EQUATION to the area-weighted
   average of the end face (weights (1/A) int N_i dA, curved P2 triangles), a
   grounded spring of stiffness k on it: the same bearing as rotorfit's.
   Static supports: u_z on one axis node and u_y at one node on the +x side;
   the frequency steps drop them (*BOUNDARY, OP=NEW), as rotorfit's
   eigenproblem has none. No damping (CalculiX's complex step has none).
3. rotorfit solves the same speeds on ts.msh with the bearing dampers off; the
   CalculiX frequencies (rotating frame) are converted to the stationary frame
   (doc/calculix.md) and matched mode by mode.
4. With --main-job, rotorfit's default TS job (31 speeds, contact updated,
   damping, unbalance response) is timed on the same mesh size.

Times and peak memory come from /usr/bin/time -v; medians over --runs runs.
CalculiX runs with OMP_NUM_THREADS = --threads (default: every core).
Writes DIR/calculix_ts.md (tables) and DIR/calculix_ts.csv (every mode).
"""
import argparse
import csv
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
# the .msh and .dat readers are the test suite's (tests/calculix_reference.py)
sys.path.insert(0, os.path.join(ROOT, "tests"))
from calculix_reference import TET10, read_ccx_complex, read_ccx_real, read_msh22  # noqa: E402

# TS (prm/test_shaft.prm): materials and bearings
MATERIALS = {"shaft": (205e9, 0.30, 7850.0), "sleeve": (68.9e9, 0.33, 2700.0)}
BEARING_K = 1e7
N_REAL = 30     # real modes of the *FREQUENCY step (the complex step's basis)
N_COMPLEX = 20  # complex modes asked for
F_LOWER = 10.0  # Hz: the *FREQUENCY shift, rotorfit's Eigenproblem/Shift


def die(msg):
    sys.exit("calculix_ts.py: " + msg)


# ---------------------------------------------------------------- the mesh
def mesh(work, h_fit, h_max):
    geo = os.path.join(work, "ts_mesh.geo")
    with open(geo, "w") as f:
        f.write("h_fit = %r;\nh_max = %r;\nInclude \"%s\";\n" %
                (h_fit, h_max, os.path.join(ROOT, "prm", "test_shaft.geo")))
    msh = os.path.join(work, "ts.msh")
    subprocess.run(["gmsh", "-3", "-order", "2", "-format", "msh22", geo,
                    "-o", msh], check=True, stdout=subprocess.DEVNULL)
    return msh


# CalculiX reads at most 20 characters a number and 132 a line (%.13g);
# material, spring and load values are written with an exponent (%.13e):
# "10000000" as a spring constant gave "*SPRING card without data".


def tri6_weights(nodes, tris):
    """(1/A) int_Gamma N_i dA on curved 6-node triangles (gmsh order:
    vertices, then edges 01, 12, 20), 6-point rule of degree 4."""
    a, b = 0.445948490915965, 0.091576213509771
    wa, wb = 0.223381589678011 / 2, 0.109951743655322 / 2
    pts = [(a, a, wa), (1 - 2 * a, a, wa), (a, 1 - 2 * a, wa),
           (b, b, wb), (1 - 2 * b, b, wb), (b, 1 - 2 * b, wb)]
    acc, area = {}, 0.0
    for tri in tris:
        x = np.array([nodes[t] for t in tri])
        for xi, eta, w in pts:
            l0 = 1 - xi - eta
            n = [l0 * (2 * l0 - 1), xi * (2 * xi - 1), eta * (2 * eta - 1),
                 4 * l0 * xi, 4 * xi * eta, 4 * eta * l0]
            dxi = [-(4 * l0 - 1), 4 * xi - 1, 0, 4 * (l0 - xi), 4 * eta,
                   -4 * eta]
            deta = [-(4 * l0 - 1), 0, 4 * eta - 1, -4 * xi, 4 * xi,
                    4 * (l0 - eta)]
            jac = np.linalg.norm(np.cross(np.dot(dxi, x), np.dot(deta, x)))
            area += w * jac
            for k, t in enumerate(tri):
                acc[t] = acc.get(t, 0.0) + w * jac * n[k]
    return {t: v / area for t, v in acc.items()}, area


def ccx_model(msh):
    """The CalculiX model lines (fit bonded) and what the steps need."""
    nodes, names, elements = read_msh22(msh)
    by_name = {v: k for k, v in names.items()}
    for need in ("shaft", "sleeve", "fit", "bearing_left", "bearing_right"):
        if need not in by_name:
            die("%s has no physical group '%s'" % (msh, need))
    # bonded fit: a sleeve node on the fit takes its coincident shaft node
    fit_nodes = {t for typ, ph, tags in elements
                 if typ == 9 and ph == by_name["fit"] for t in tags}
    shaft_nodes = {t for typ, ph, tags in elements
                   if typ == 11 and ph == by_name["shaft"] for t in tags}
    key = lambda t: tuple(np.round(nodes[t] / 1e-9).astype(np.int64))
    shaft_at = {key(t): t for t in fit_nodes if t in shaft_nodes}
    merge = {}
    for t in fit_nodes:
        if t not in shaft_nodes:
            if key(t) not in shaft_at:
                die("fit node %d has no coincident shaft node" % t)
            merge[t] = shaft_at[key(t)]
    # (gmsh's conforming fit shares its nodes between the bodies: then
    # there is nothing to merge and the fit is bonded as it is)
    lines = ["*NODE, NSET=NALL"]
    used = set()
    tets = {"shaft": [], "sleeve": []}
    for typ, ph, tags in elements:
        if typ == 11:
            tags = [merge.get(t, t) for t in tags]
            used.update(tags)
            tets[names[ph]].append([tags[k] for k in TET10])
    for t in sorted(used):
        lines.append("%d,%.13g,%.13g,%.13g" % ((t,) + tuple(nodes[t])))
    eid = 0
    for body in ("shaft", "sleeve"):
        lines.append("*ELEMENT, TYPE=C3D10, ELSET=E%s" % body.upper())
        for tags in tets[body]:
            eid += 1
            lines.append("%d, " % eid + ", ".join(str(t) for t in tags))
    lines.append("*ELSET, ELSET=EALL\nESHAFT, ESLEEVE")
    for body, (E, nu, rho) in MATERIALS.items():
        lines += ["*MATERIAL, NAME=%s" % body.upper(), "*ELASTIC",
                  "%.13e, %.13e" % (E, nu), "*DENSITY", "%.13e" % rho,
                  "*SOLID SECTION, ELSET=E%s, MATERIAL=%s" %
                  (body.upper(), body.upper())]
    # bearings: reference node = face average (lateral), spring to ground
    ref = max(used) + 1
    refs = []
    for side in ("bearing_left", "bearing_right"):
        tris = [tags for typ, ph, tags in elements
                if typ == 9 and ph == by_name[side]]
        w, area = tri6_weights(nodes, tris)
        centre = sum(w[t] * nodes[t] for t in w)
        lines.append("*NODE, NSET=NREF\n%d,%.13g,%.13g,%.13g" %
                     ((ref,) + tuple(centre)))
        for dof in (1, 2):
            terms = [(ref, dof, 1.0)] + [(t, dof, -v) for t, v in
                                         sorted(w.items()) if v != 0.0]
            lines.append("*EQUATION\n%d" % len(terms))
            for k in range(0, len(terms), 4):
                lines.append(",".join("%d,%d,%.12g" % tm
                                       for tm in terms[k:k + 4]))
            eid += 1
            lines += ["*ELEMENT, TYPE=SPRING1, ELSET=EB%d%d" % (ref, dof),
                      "%d, %d" % (eid, ref),
                      "*SPRING, ELSET=EB%d%d" % (ref, dof),
                      "%d" % dof, "%.13e" % BEARING_K]
        refs.append(ref)
        ref += 1
    # static supports (no reaction for an axisymmetric load): u_z on the
    # axis node nearest mid-length, u_y at the node nearest (r_max/2... r_max,
    # angle 0) at the same height: axial and torsional rigid motion
    xyz = np.array([nodes[t] for t in sorted(used)])
    tags = np.array(sorted(used))
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    zmid = 0.5 * (xyz[:, 2].min() + xyz[:, 2].max())
    axis = tags[np.argmin(r * 1e3 + np.abs(xyz[:, 2] - zmid))]
    side = tags[np.argmin(np.abs(xyz[:, 1]) + np.abs(xyz[:, 2] - zmid) +
                          np.where(xyz[:, 0] > 0.5 * r.max(), 0, 1))]
    supports = ["%d, 3, 3" % axis, "%d, 2, 2" % side]
    return lines, refs, supports, 3 * (len(used) + len(refs))


def ccx_deck(path, model, refs, supports, rpm):
    w2 = (rpm * math.pi / 30) ** 2
    ref_z = ["%d, 3, 3" % r for r in refs]
    deck = model + ["*BOUNDARY"] + ref_z + supports + [
        "*STEP", "*STATIC",
        "*DLOAD", "EALL, CENTRIF, %.13e, 0., 0., 0., 0., 0., 1." % w2,
        "*END STEP",
        "*STEP, PERTURBATION", "*FREQUENCY, STORAGE=YES",
        "%d, %g" % (N_REAL, F_LOWER),
        "*BOUNDARY, OP=NEW"] + ref_z + ["*END STEP",
        "*STEP, PERTURBATION", "*COMPLEX FREQUENCY, CORIOLIS", "%d" % N_COMPLEX,
        "*END STEP"]
    with open(path, "w") as f:
        f.write("\n".join(deck) + "\n")


# ---------------------------------------------------------------- timing
def timed(cmd, cwd, log, env=None):
    """Wall time [s] and peak resident memory [GiB, 2^30 bytes: time -v's KiB / 1024^2] of one command."""
    t0 = time.time()
    with open(log, "w") as out:
        p = subprocess.run(["/usr/bin/time", "-v"] + cmd, cwd=cwd, env=env,
                           stdout=out, stderr=subprocess.STDOUT)
    wall = time.time() - t0
    text = open(log, errors="replace").read()
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    if p.returncode != 0:
        die("%s failed (exit %d); see %s" % (" ".join(cmd), p.returncode,
                                             log))
    return wall, int(m.group(1)) / 1024 ** 2 if m else float("nan")


def read_campbell(path):
    rows = list(csv.DictReader(open(path)))
    out = {}
    for r in rows:
        # a speed rotorfit flags unconverged is not compared as if it were
        fit = r["fit_state"] if r["static_converged"] == "1" else \
            "unconverged"
        out.setdefault(float(r["speed_rpm"]), []).append(
            (r["whirl"], float(r["frequency_hz"]), fit))
    return out


def rotating(whirl, f, spin_hz):
    """The rotating-frame frequency and turning direction of a
    stationary-frame mode (lateral modes, one nodal diameter): BW f -> B at
    f + spin; FW f -> F at f - spin above the spin, B at spin - f below it;
    modes without whirl (axial, torsion) keep their frequency."""
    if whirl == "backward":
        return f + spin_hz, "B"
    if whirl == "forward":
        return abs(f - spin_hz), "F" if f > spin_hz else "B"
    return f, "?"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rotorfit", default=os.path.join(ROOT, "build",
                                                      "rotorfit"))
    ap.add_argument("--work", default=os.path.join(ROOT, "benchmarks",
                                                   "output", "calculix"))
    ap.add_argument("--h-fit", type=float, default=3e-3)
    ap.add_argument("--h-max", type=float, default=6e-3)
    ap.add_argument("--speeds", default="0,10000,20000",
                    help="r/min: a list a,b,c or a range start:end:step")
    ap.add_argument("--runs", type=int, default=3,
                    help="CalculiX runs per speed (the median is quoted)")
    ap.add_argument("--ccx", default="ccx")
    ap.add_argument("--threads", type=int, default=os.cpu_count(),
                    help="OMP_NUM_THREADS for CalculiX (default: all cores)")
    ap.add_argument("--main-job", action="store_true")
    ap.add_argument("--reuse", action="store_true",
                    help="read the .dat files of an earlier run, time "
                    "nothing of CalculiX")
    args = ap.parse_args()
    try:
        if ":" in args.speeds:
            a, b, c = (float(v) for v in args.speeds.split(":"))
            if c <= 0 or b < a:
                raise ValueError
            speeds = [a + k * c for k in range(int(round((b - a) / c)) + 1)]
        else:
            speeds = [float(v) for v in args.speeds.split(",")]
    except ValueError:
        die("--speeds '%s': give r/min as a,b,c or start:end:step "
            "(step > 0, end >= start)" % args.speeds)
    if min(speeds) < 0 or any(y <= x for x, y in zip(speeds, speeds[1:])):
        die("--speeds '%s': speeds must be >= 0 and increasing" % args.speeds)
    if args.runs < 1 or args.threads < 1:
        die("--runs and --threads must be at least 1")
    for tool, package in (("gmsh", "gmsh"), (args.ccx, "calculix-ccx"), ("/usr/bin/time", "time")):
        if shutil.which(tool) is None:
            die("'%s' not found: apt-get install -y %s" % (tool, package))
    if not os.access(args.rotorfit, os.X_OK):
        die("no rotorfit at %s (build it, or give --rotorfit)" % args.rotorfit)
    os.makedirs(args.work, exist_ok=True)
    work = os.path.abspath(args.work)
    prm = os.path.join(ROOT, "prm", "test_shaft.prm")
    rotorfit = os.path.abspath(args.rotorfit)

    msh = mesh(work, args.h_fit, args.h_max)
    model, refs, supports, ndofs = ccx_model(msh)
    print("mesh %s: CalculiX %d DOFs (fit merged, 2 reference nodes)" %
          (msh, ndofs))

    # CalculiX, one deck per speed, --runs times each
    ccx = {}
    for rpm in speeds:
        job = "ts_%05d" % rpm
        ccx_deck(os.path.join(work, job + ".inp"), model, refs, supports, rpm)
        walls, mems = [float("nan")], [float("nan")]
        for k in range(0 if args.reuse else args.runs):
            if k == 0:
                walls, mems = [], []
            # both cores for CalculiX too (SPOOLES and its assembly are
            # threaded; rotorfit's MUMPS uses the threaded OpenBLAS)
            wall, mem = timed([args.ccx, job], work,
                              os.path.join(work, job + ".log"),
                              dict(os.environ, OMP_NUM_THREADS=str(
                                  args.threads)))
            walls.append(wall)
            mems.append(mem)
        ccx[rpm] = (statistics.median(walls), max(mems),
                    read_ccx_complex(os.path.join(work, job + ".dat")))
        print("CalculiX %6.0f r/min: %.1f s (median of %d), %.2f GiB" %
              (rpm, ccx[rpm][0], 0 if args.reuse else args.runs,
               ccx[rpm][1]))

    # rotorfit on the same mesh and speeds, bearing dampers off
    common = ["--set", "Geometry/Geometry file=" + msh,
              "--set", "Geometry/Geometry parameters="]

    def undamped(out, speed_list, *extra):
        cmd = [rotorfit, prm, "--output", out] + common + [
            "--set", "Speeds/Mode=list", "--set", "Speeds/List=" +
            ", ".join("%g" % v for v in speed_list)] + list(extra)
        for b in ("left", "right"):
            cmd += ["--set", "Bearing %s/cxx=0" % b,
                    "--set", "Bearing %s/cyy=0" % b]
        return cmd

    out = os.path.join(work, "rotorfit_same")
    cmd = undamped(out, speeds)
    wall, mem = timed(cmd, ROOT, os.path.join(work, "rotorfit_same.log"))
    print("rotorfit, the same %d speeds: %.1f s, %.2f GiB" %
          (len(speeds), wall, mem))
    rf = read_campbell(os.path.join(out, "campbell.csv"))

    rows = []
    for rpm in speeds:
        spin = rpm / 60
        cf = ccx[rpm][2]
        if rpm == 0:
            # at rest CalculiX's complex step is degenerate (it lists a
            # bending pair once): its real modes are the reference there
            cf = [(f, "?") for f in read_ccx_real(
                os.path.join(work, "ts_%05d.dat" % rpm))]
        # one to one: the closest (rotorfit, CalculiX) couples first, a
        # CalculiX mode of the other turning direction never
        want = [(k, whirl, f, fit) + rotating(whirl, f, spin)
                for k, (whirl, f, fit) in enumerate(rf[rpm])]
        couples = sorted(
            (abs(c[0] - w[4]) / w[2], w[0], j)
            for w in want for j, c in enumerate(cf)
            if w[5] == "?" or c[1] == "?" or c[1] == w[5])
        taken, used = {}, set()
        for d, k, j in couples:
            if k not in taken and j not in used:
                taken[k] = j
                used.add(j)
        for k, whirl, f, fit, target, turn in want:
            if k not in taken:
                die("%g r/min: no CalculiX mode left for rotorfit's mode %d"
                    % (rpm, k + 1))
            near, near_turn = cf[taken[k]]
            rows.append((rpm, fit, k + 1, whirl, f, target, turn, near,
                         near_turn, (near - target) / f))
    with open(os.path.join(work, "calculix_ts.csv"), "w") as f:
        f.write("speed_rpm,fit_state,mode,whirl,rotorfit_hz,rotorfit_rotating_hz,"
                "rotorfit_turning,calculix_rotating_hz,calculix_turning,"
                "difference_over_f\n")
        for r in rows:
            f.write("%g,%s,%d,%s,%.9g,%.9g,%s,%.9g,%s,%.3e\n" % r)

    # the model check: at rest without pre-stress both codes solve the same
    # undamped problem K phi = omega^2 M phi; sorted frequencies compared
    rest = []
    if 0.0 in ccx:
        out = os.path.join(work, "rotorfit_rest")
        cmd = undamped(out, [0], "--set",
                       "Eigenproblem/Stress stiffening=off")
        timed(cmd, ROOT, os.path.join(work, "rotorfit_rest.log"))
        mine = sorted(f for w, f, fit in read_campbell(
            os.path.join(out, "campbell.csv"))[0.0])
        theirs = sorted(read_ccx_real(os.path.join(work, "ts_00000.dat")))
        rest = [(a, b, (b - a) / a) for a, b in zip(mine, theirs)]
        print("at rest, no pre-stress: largest difference %.1e" %
              max(abs(r[2]) for r in rest))

    main_job = None
    if args.main_job:
        out = os.path.join(work, "rotorfit_main")
        main_job = timed([rotorfit, prm, "--output", out] + common, ROOT,
                         os.path.join(work, "rotorfit_main.log"))
        print("rotorfit main job (31 speeds): %.1f s, %.2f GiB" % main_job)

    with open(os.path.join(work, "calculix_ts.md"), "w") as f:
        walls = [ccx[rpm][0] for rpm in speeds]
        f.write("| run | wall [s] | peak memory [GiB] |\n|---|---|---|\n")
        f.write("| CalculiX, one speed (median over %d speeds, min %.1f, "
                "max %.1f) | %.1f | %.2f |\n" %
                (len(speeds), min(walls), max(walls),
                 statistics.median(walls), max(ccx[r][1] for r in speeds)))
        f.write("| CalculiX, all %d speeds (sum) | %.1f | |\n" %
                (len(speeds), sum(walls)))
        f.write("| rotorfit, the same %d speeds | %.1f | %.2f |\n" %
                (len(speeds), wall, mem))
        if main_job:
            f.write("| rotorfit main job (31 speeds) | %.1f | %.2f |\n" %
                    main_job)
        if rest:
            f.write("\nAt rest, no pre-stress, no damping (the same "
                    "undamped problem):\n\n| mode | rotorfit [Hz] | "
                    "CalculiX [Hz] | difference / f |\n|---|---|---|---|\n")
            for k, r in enumerate(rest):
                f.write("| %d | %.4f | %.4f | %.1e |\n" % ((k + 1,) + r))
        f.write("\n| r/min | fit | mode | whirl | rotorfit [Hz] | rotating "
                "frame [Hz] | turns | CalculiX [Hz] | turns | difference / f "
                "|\n|---|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            if r[1] == "closed":  # else rotorfit's fit has let go
                f.write("| %g | %s | %d | %s | %.3f | %.3f | %s | %.3f | %s"
                        " | %.1e |\n" % r)
        closed = [r for r in rows if r[1] == "closed"]
        if closed:
            f.write("\nLargest |difference| / f where rotorfit's fit is "
                    "closed: %.1e (%d modes at %d speeds); the speeds where "
                    "it has opened are in calculix_ts.csv only.\n" %
                    (max(abs(r[-1]) for r in closed), len(closed),
                     len({r[0] for r in closed})))
    print("wrote %s/calculix_ts.md and calculix_ts.csv" % work)


if __name__ == "__main__":
    main()
