"""CalculiX (ccx 2.20) as an independent reference for rotorfit: shared code
of tests/calculix_bonded_whirl.py and tests/calculix_contact_pressure.py.

Both codes read one gmsh mesh file (quadratic tetrahedra, .msh 2.2): the TS
assembly of prm/test_shaft.geo, meshed here once. This module writes the
CalculiX model of that mesh, node for node:
  * C3D10 elements (gmsh's tet10 with its last two mid-edge nodes swapped),
    coordinates with 13 digits (CalculiX reads 20 characters a number: with
    %.15g some were cut and the elements turned inside out);
  * the fit bonded (the conforming fit's shared nodes), or with the sleeve's
    fit nodes duplicated, coincident with the shaft's as rotorfit's pairs
    are: a mortar contact pair (mortar_deck) or the closed pairs node to
    node (tied_fit_deck);
  * bearings as rotorfit's (doc/theory.md 5.1): a reference node whose
    lateral displacement is the area average of the end face (*EQUATION,
    weights (1/A) int N_i dA on the curved 6-node faces) and a grounded
    SPRING1 of stiffness k on it;
  * static supports: with duplicated fit nodes rotorfit's statically
    determinate set per body (doc/theory.md 6), u_theta = 0 at five points
    and u_z = 0 at one; the exact axisymmetric solution satisfies them, so
    their reactions vanish up to mesh asymmetry.
It also runs ccx and rotorfit and reads their results. The ideas follow
benchmarks/calculix_ts.py (doc/calculix.md), which is not imported: the
tests stand on their own.
"""
import argparse
import csv
import math
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
TS_GEO = os.path.join(ROOT, "prm", "test_shaft.geo")
TS_PRM = os.path.join(ROOT, "prm", "test_shaft.prm")

# TS (prm/test_shaft.prm): E [Pa], nu, rho [kg/m^3]; bearings; interference
MATERIALS = {"shaft": (205e9, 0.30, 7850.0), "sleeve": (68.9e9, 0.33, 2700.0)}
BEARING_K = 1e7
INTERFERENCE = 3e-6

# gmsh tet10 -> CalculiX C3D10: the last two mid-edge nodes swap
TET10 = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]
# CalculiX tetrahedron faces (vertex positions 0..3): S1 = 1-2-3, S2 = 1-4-2,
# S3 = 2-4-3, S4 = 3-4-1
TET_FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]


def die(msg):
    print("FAILED: " + msg, flush=True)
    sys.exit(1)


def require_tools(ccx):
    """ccx and gmsh must exist: a missing reference fails the test (exit 1)
    with the package to install, never passes silently."""
    for tool, package in ((ccx, "calculix-ccx"), ("gmsh", "gmsh")):
        if shutil.which(tool) is None:
            die("'%s' not found: install it (apt-get install -y %s); this "
                "test needs it as its reference" % (tool, package))


# ------------------------------------------------------------------- mesh
def mesh(work, h_fit, h_max, geo=TS_GEO, params=None):
    """Mesh GEO once with gmsh (P2 tetrahedra, .msh 2.2): both codes read it.
    PARAMS: further DefineConstant values of GEO {name: value}."""
    os.makedirs(work, exist_ok=True)
    wrapper = os.path.join(work, "mesh.geo")
    values = dict(h_fit=h_fit, h_max=h_max, **(params or {}))
    with open(wrapper, "w") as f:
        f.write("".join("%s = %r;\n" % kv for kv in values.items()) +
                "Include \"%s\";\n" % geo)
    msh = os.path.join(work, "mesh.msh")
    r = subprocess.run(["gmsh", "-3", "-order", "2", "-format", "msh22", wrapper,
                        "-o", msh], capture_output=True, text=True)
    if r.returncode != 0 or not os.path.exists(msh):
        die("gmsh failed on %s:\n%s" % (wrapper, r.stdout[-2000:] + r.stderr[-2000:]))
    return msh


def arguments(extra=None):
    """The command line of every CalculiX test: ROTORFIT OUTDIR [--ccx ccx]
    [--set ENTRY=VALUE ...] (extra rotorfit --set, for fault injection);
    EXTRA(parser) adds a test's own options."""
    ap = argparse.ArgumentParser()
    ap.add_argument("rotorfit")
    ap.add_argument("outdir")
    ap.add_argument("--ccx", default="ccx")
    ap.add_argument("--set", action="append", default=[], dest="sets",
                    help="extra rotorfit --set (fault injection)")
    if extra:
        extra(ap)
    return ap.parse_args()


def whirl_deck(path, model, rpm, n_real, n_complex, f_lower):
    """Static (supports) under CENTRIF at RPM, then a *FREQUENCY perturbation
    step (N_REAL modes above F_LOWER [Hz], the static step's stress
    stiffness) and *COMPLEX FREQUENCY, CORIOLIS (N_COMPLEX) without them."""
    ref_z = ["%d, 3, 3" % r for r in model["refs"]]
    lines = model["lines"] + ["*BOUNDARY"] + ref_z + model["supports"] + [
        "*STEP", "*STATIC", "*DLOAD", centrif(rpm), "*END STEP",
        "*STEP, PERTURBATION", "*FREQUENCY, STORAGE=YES", "%d, %g" % (n_real, f_lower),
        "*BOUNDARY, OP=NEW"] + ref_z + ["*END STEP",
        "*STEP, PERTURBATION", "*COMPLEX FREQUENCY, CORIOLIS", "%d" % n_complex,
        "*END STEP"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def read_msh22(path):
    """Nodes {tag: xyz}, physical names {tag: name} and elements
    [(type, physical tag, node tags)] of an ASCII .msh 2.2 file."""
    with open(path) as f:
        lines = f.read().split("\n")
    names, nodes, elements = {}, {}, []
    i = 0
    while i < len(lines):
        key = lines[i].strip()
        if key == "$PhysicalNames":
            n = int(lines[i + 1])
            for line in lines[i + 2:i + 2 + n]:
                dim, tag, name = line.split(maxsplit=2)
                names[int(tag)] = name.strip('"')
            i += n + 2
        elif key == "$Nodes":
            n = int(lines[i + 1])
            for line in lines[i + 2:i + 2 + n]:
                p = line.split()
                nodes[int(p[0])] = np.array([float(v) for v in p[1:4]])
            i += n + 2
        elif key == "$Elements":
            n = int(lines[i + 1])
            for line in lines[i + 2:i + 2 + n]:
                p = [int(v) for v in line.split()]
                ntags = p[2]
                elements.append((p[1], p[3], p[3 + ntags:]))
            i += n + 2
        else:
            i += 1
    return nodes, names, elements


def tri6_weights(nodes, tris):
    """{node: (1/A) int N_i dA} and A over curved 6-node triangles (gmsh
    order: vertices, then edges 01, 12, 20), 6-point rule of degree 4."""
    acc, area = {}, 0.0
    for tri, pts in tri6_points(nodes, tris):
        for n, w in pts:
            area += w
            for k, t in enumerate(tri):
                acc[t] = acc.get(t, 0.0) + w * n[k]
    return {t: v / area for t, v in acc.items()}, area


def tri6_points(nodes, tris):
    """Per triangle: (tags, [(shape values, weight * |J|)]) at 6 points."""
    a, b = 0.445948490915965, 0.091576213509771
    wa, wb = 0.223381589678011 / 2, 0.109951743655322 / 2
    rule = [(a, a, wa), (1 - 2 * a, a, wa), (a, 1 - 2 * a, wa),
            (b, b, wb), (1 - 2 * b, b, wb), (b, 1 - 2 * b, wb)]
    for tri in tris:
        x = np.array([nodes[t] for t in tri])
        pts = []
        for xi, eta, w in rule:
            l0 = 1 - xi - eta
            n = np.array([l0 * (2 * l0 - 1), xi * (2 * xi - 1), eta * (2 * eta - 1),
                          4 * l0 * xi, 4 * xi * eta, 4 * eta * l0])
            dxi = [-(4 * l0 - 1), 4 * xi - 1, 0, 4 * (l0 - xi), 4 * eta, -4 * eta]
            deta = [-(4 * l0 - 1), 0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l0 - eta)]
            jac = np.linalg.norm(np.cross(np.dot(dxi, x), np.dot(deta, x)))
            pts.append((n, w * jac))
        yield tri, pts


# ----------------------------------------------------------------- model
def _num(v):
    # CalculiX reads at most 20 characters a number: %.13e fits
    return "%.13e" % v


def _equation(terms):
    """*EQUATION of [(node, dof, coefficient)], the first term dependent."""
    lines = ["*EQUATION", "%d" % len(terms)]
    for k in range(0, len(terms), 4):
        lines.append(",".join("%d,%d,%.12g" % t for t in terms[k:k + 4]))
    return lines


def _supports(nodes, body_nodes):
    """rotorfit's static supports of one body (doc/theory.md 6): u_theta = 0
    near 0, 90, 180 degrees at z_min + L/4 and near 0, 90 degrees at
    z_max - L/4 (the nearest node with r >= r_max/2, cost r_max |dtheta| +
    |dz|), u_z = 0 at the node nearest the mid-plane (nearest the axis among
    equals). Returns *EQUATION and *BOUNDARY lines."""
    tags = np.array(sorted(body_nodes))
    xyz = np.array([nodes[t] for t in tags])
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    th = np.arctan2(xyz[:, 1], xyz[:, 0])
    z = xyz[:, 2]
    rmax, zmin, zmax = r.max(), z.min(), z.max()
    L = zmax - zmin
    far = r >= 0.5 * rmax
    eqs, used = [], set()
    for target_th, target_z in ((0, zmin + L / 4), (90, zmin + L / 4), (180, zmin + L / 4),
                                (0, zmax - L / 4), (90, zmax - L / 4)):
        t = math.radians(target_th)
        dth = np.abs(np.angle(np.exp(1j * (th - t))))
        cost = np.where(far, rmax * dth + np.abs(z - target_z), np.inf)
        for k in used:
            cost[k] = np.inf
        k = int(np.argmin(cost))
        used.add(k)
        s, c = math.sin(th[k]), math.cos(th[k])
        # -sin u_x + cos u_y = 0, the larger coefficient's DOF dependent
        terms = [(tags[k], 2, c), (tags[k], 1, -s)] if abs(c) >= abs(s) else \
                [(tags[k], 1, -s), (tags[k], 2, c)]
        eqs += _equation(terms)
    zmid = 0.5 * (zmin + zmax)
    k = int(np.lexsort((r, np.round(np.abs(z - zmid), 12)))[0])
    return eqs, ["%d, 3, 3" % tags[k]]


def ccx_model(msh, fit, materials=MATERIALS):
    """The model lines of MSH for CalculiX. FIT: 'bonded' (the fit's shared
    nodes kept) or 'contact' (the sleeve's fit nodes duplicated; surfaces
    SSHAFT, SSLEEVE). MATERIALS: {physical volume: (E, nu, rho)}, the shaft
    first, then the hub (called the sleeve here, as TS's). Returns a dict:
    lines, refs (bearing reference nodes), supports (*BOUNDARY lines of the
    static steps), fit_area, fit nodes."""
    nodes, names, elements = read_msh22(msh)
    by_name = {v: k for k, v in names.items()}
    bodies = list(materials)
    for need in bodies + ["fit", "bearing_left", "bearing_right"]:
        if need not in by_name:
            die("%s has no physical group '%s'" % (msh, need))
    fit_tris = [tags for typ, ph, tags in elements if typ == 9 and ph == by_name["fit"]]
    fit_nodes = {t for tri in fit_tris for t in tri}
    tets = {"shaft": [], "sleeve": []}
    role = {by_name[bodies[0]]: "shaft", by_name[bodies[1]]: "sleeve"}
    for typ, ph, tags in elements:
        if typ == 11:
            tets[role[ph]].append(list(tags))
    shaft_nodes = {t for tet in tets["shaft"] for t in tet}
    sleeve_nodes = {t for tet in tets["sleeve"] for t in tet}
    if not fit_nodes <= shaft_nodes or not fit_nodes <= sleeve_nodes:
        die("%s: the fit is not conforming (its nodes are not shared by "
            "shaft and sleeve)" % msh)
    twin = {}
    if fit == "contact":
        # the sleeve's own copy of each fit node, at the same place
        top = max(nodes)
        for k, t in enumerate(sorted(fit_nodes)):
            twin[t] = top + 1 + k
            nodes[top + 1 + k] = nodes[t].copy()
        tets["sleeve"] = [[twin.get(t, t) for t in tet] for tet in tets["sleeve"]]
        sleeve_nodes = {t for tet in tets["sleeve"] for t in tet}
    used = shaft_nodes | sleeve_nodes
    lines = ["*NODE, NSET=NALL"]
    for t in sorted(used):
        lines.append("%d,%.13g,%.13g,%.13g" % ((t,) + tuple(nodes[t])))
    eid = 0
    first = {}
    for body in ("shaft", "sleeve"):
        lines.append("*ELEMENT, TYPE=C3D10, ELSET=E%s" % body.upper())
        first[body] = eid + 1
        for tet in tets[body]:
            eid += 1
            lines.append("%d, " % eid + ", ".join(str(tet[k]) for k in TET10))
    lines.append("*ELSET, ELSET=EALL\nESHAFT, ESLEEVE")
    for body, (E, nu, rho) in zip(("shaft", "sleeve"), materials.values()):
        lines += ["*MATERIAL, NAME=%s" % body.upper(), "*ELASTIC",
                  "%s, %s" % (_num(E), _num(nu)), "*DENSITY", _num(rho),
                  "*SOLID SECTION, ELSET=E%s, MATERIAL=%s" % (body.upper(), body.upper())]
    _, fit_area = tri6_weights(nodes, fit_tris)
    if fit == "contact":
        # element faces on the fit: the tet with the triangle's 3 vertices
        for body, surf in (("shaft", "SSHAFT"), ("sleeve", "SSLEEVE")):
            want = {frozenset(twin.get(t, t) if body == "sleeve" else t
                              for t in tri[:3]): tri for tri in fit_tris}
            faces = []
            for k, tet in enumerate(tets[body]):
                for s, face in enumerate(TET_FACES):
                    key = frozenset(tet[j] for j in face)
                    if key in want:
                        faces.append("%d, S%d" % (first[body] + k, s + 1))
            if len(faces) != len(fit_tris):
                die("%s: %d of %d fit faces found on the %s" %
                    (msh, len(faces), len(fit_tris), body))
            lines += ["*SURFACE, NAME=%s, TYPE=ELEMENT" % surf] + faces
    # bearings: reference node = face average (lateral), spring to ground
    ref = max(used) + 1
    refs = []
    for side in ("bearing_left", "bearing_right"):
        tris = [tags for typ, ph, tags in elements if typ == 9 and ph == by_name[side]]
        w, _ = tri6_weights(nodes, tris)
        centre = sum(w[t] * nodes[t] for t in w)
        lines.append("*NODE, NSET=NREF\n%d,%.13g,%.13g,%.13g" % ((ref,) + tuple(centre)))
        for dof in (1, 2):
            lines += _equation([(ref, dof, 1.0)] + [(t, dof, -v) for t, v in sorted(w.items())
                                                    if v != 0.0])
            eid += 1
            lines += ["*ELEMENT, TYPE=SPRING1, ELSET=EB%d%d" % (ref, dof), "%d, %d" % (eid, ref),
                      "*SPRING, ELSET=EB%d%d" % (ref, dof), "%d" % dof, _num(BEARING_K)]
        refs.append(ref)
        ref += 1
    if fit == "contact":
        supports = []
        for body_nodes in (shaft_nodes, sleeve_nodes):
            eqs, bnd = _supports(nodes, body_nodes)
            lines += eqs
            supports += bnd
    else:
        # the bonded assembly: u_z on the axis node nearest mid-length and
        # u_y at a node at +x on the same plane (axial and torsional rigid
        # motion; the bearings hold the rest); no reaction for axisymmetric
        # loads
        tags = np.array(sorted(used))
        xyz = np.array([nodes[t] for t in tags])
        r = np.hypot(xyz[:, 0], xyz[:, 1])
        zmid = 0.5 * (xyz[:, 2].min() + xyz[:, 2].max())
        axis = tags[np.argmin(r * 1e3 + np.abs(xyz[:, 2] - zmid))]
        side = tags[np.argmin(np.abs(xyz[:, 1]) + np.abs(xyz[:, 2] - zmid) +
                              np.where(xyz[:, 0] > 0.5 * r.max(), 0, 1))]
        supports = ["%d, 3, 3" % axis, "%d, 2, 2" % side]
    return {"lines": lines, "refs": refs, "supports": supports, "fit_area": fit_area,
            "nodes": nodes, "fit_tris": fit_tris, "twin": twin, "tets": tets,
            "materials": dict(zip(("shaft", "sleeve"), materials.values())),
            "ndofs": 3 * (len(used) + len(refs))}


def omega2(rpm):
    return (rpm * math.pi / 30) ** 2


def centrif(rpm):
    return "EALL, CENTRIF, %s, 0., 0., 0., 0., 0., 1." % _num(omega2(rpm))


def nset(name, tags):
    return ["*NSET, NSET=%s" % name] + [",".join(str(t) for t in tags[k:k + 8])
                                         for k in range(0, len(tags), 8)]


def _fit_and_supports(model):
    shaft_fit = sorted(model["twin"])
    return (model["lines"] + nset("NFITSH", shaft_fit) +
            nset("NFITSL", sorted(model["twin"].values())),
            ["*BOUNDARY"] + ["%d, 3, 3" % r for r in model["refs"]] + model["supports"])


def _static_step(rpm):
    return ["*STEP", "*STATIC", "1., 1.", "*DLOAD", centrif(rpm),
            "*NODE PRINT, NSET=NFITSH", "RF", "*NODE PRINT, NSET=NFITSL", "RF", "*END STEP"]


def mortar_deck(path, model, rpm, interference):
    """The contact pair at one speed: shaft and sleeve each own their fit
    nodes; frictionless face-to-face mortar contact (slave: the sleeve's bore,
    master: the shaft), hard (Lagrange multipliers: no penalty error), the
    interference as *CLEARANCE, VALUE=-delta (an initial overlap resolved in
    the step). One nonlinear *STATIC step under *DLOAD CENTRIF on the
    undeformed radius (rotorfit's default). One deck per speed: CalculiX
    2.20 carries the clearance from step to step inconsistently (0 -> 10,000
    -> 15,000 -> 20,000 r/min in one run: the mean pressure is not affine in
    Omega^2, 1.4 % high at 10,000 r/min), while one step per speed is affine
    (frictionless elastic contact: the state does not depend on the path)."""
    model_lines, bc = _fit_and_supports(model)
    deck = model_lines + [
        # no *SURFACE BEHAVIOR: hard contact; no *FRICTION: frictionless
        "*SURFACE INTERACTION, NAME=FIT",
        "*CONTACT PAIR, INTERACTION=FIT, TYPE=MORTAR", "SSLEEVE, SSHAFT",
        "*CLEARANCE, MASTER=SSHAFT, SLAVE=SSLEEVE, VALUE=%s" % _num(-interference)] + bc
    deck += _static_step(rpm)
    with open(path, "w") as f:
        f.write("\n".join(deck) + "\n")


def tied_fit_deck(path, model, speeds, interference):
    """The closed fit node to node, as rotorfit's closed pairs (doc/theory.md
    7.1): per pair n . (u_sleeve - u_shaft) = delta along the pair's radial
    normal n, tangential and axial free (frictionless), by *EQUATION with a
    dummy node whose u_x is held at delta (CalculiX's equations are
    homogeneous). Linear *STATIC steps, one per speed."""
    model_lines, bc = _fit_and_supports(model)
    dummy = max(model["nodes"]) + 1000
    lines = model_lines + ["*NODE, NSET=NDELTA", "%d, 0., 0., 0." % dummy]
    for t, s in sorted(model["twin"].items()):
        x = model["nodes"][t]
        n = np.array([x[0], x[1]]) / math.hypot(x[0], x[1])
        k = 0 if abs(n[0]) >= abs(n[1]) else 1
        terms = [(s, k + 1, n[k]), (s, 2 - k, n[1 - k]), (t, 1, -n[0]), (t, 2, -n[1]),
                 (dummy, 1, -1.0)]
        lines += _equation([tm for tm in terms if abs(tm[2]) > 1e-12])
    deck = lines + bc + ["%d, 2, 3" % dummy, "%d, 1, 1, %s" % (dummy, _num(interference))]
    for rpm in speeds:
        deck += _static_step(rpm)
    with open(path, "w") as f:
        f.write("\n".join(deck) + "\n")


def read_rf(dat):
    """{set name: [{node: (fx, fy, fz)} per step, in order]} of a .dat."""
    out = {}
    text = open(dat, errors="replace").read()
    parts = re.split(r"\n forces \(fx,fy,fz\) for set (\S+) and time\s+\S+\n", text)
    for k in range(1, len(parts), 2):
        rows = {}
        for line in parts[k + 1].split("\n"):
            p = line.split()
            if len(p) == 4 and p[0].isdigit():
                rows[int(p[0])] = np.array([float(v) for v in p[1:]])
            elif p:
                break
        out.setdefault(parts[k], []).append(rows)
    return out


def tet10_shape(r, s, t):
    """C3D10 shape functions (CalculiX node order) at (r, s, t)."""
    u = 1 - r - s - t
    return np.array([u * (2 * u - 1), r * (2 * r - 1), s * (2 * s - 1), t * (2 * t - 1),
                     4 * u * r, 4 * r * s, 4 * s * u, 4 * u * t, 4 * r * t, 4 * s * t])


def tet10_grad(r, s, t):
    u = 1 - r - s - t
    return np.array([[-(4 * u - 1)] * 3, [4 * r - 1, 0, 0], [0, 4 * s - 1, 0],
                     [0, 0, 4 * t - 1], [4 * (u - r), -4 * r, -4 * r], [4 * s, 4 * r, 0],
                     [-4 * s, 4 * (u - s), -4 * s], [-4 * t, -4 * t, 4 * (u - t)],
                     [4 * t, 0, 4 * r], [0, 4 * t, 4 * s]])


def centrifugal_nodal_loads(model, tags):
    """{node: consistent nodal load per unit Omega^2 [N s^2]} of TAGS as
    CalculiX integrates CENTRIF on C3D10: its 4-point rule, rho (x, y, 0)
    N_i |J| w. RF at a fit node is this load plus the contact force."""
    a, b = 0.1381966011250105, 0.5854101966249685
    rule = [(a, a, a), (b, a, a), (a, b, a), (a, a, b)]
    want = set(tags)
    out = {t: np.zeros(3) for t in want}
    nodes = model["nodes"]
    for body, tets in model["tets"].items():
        rho = model["materials"][body][2]
        for tet in tets:
            if not want.intersection(tet):
                continue
            x = np.array([nodes[tet[k]] for k in TET10])
            for p in rule:
                n = tet10_shape(*p)
                jac = np.linalg.det(tet10_grad(*p).T @ x)
                xp = n @ x
                f = rho * np.array([xp[0], xp[1], 0.0]) * jac / 24
                for k in range(10):
                    t = tet[TET10[k]]
                    if t in want:
                        out[t] += n[k] * f
    return out


def fit_pressures(model, forces):
    """Mean and largest nodal pressure of a fit from its shaft-side nodal
    contact forces {node: force vector}, as rotorfit reports them (doc/
    theory.md 7.5, 9.6): N_i = -n_i . f_i (compression positive, radial
    n_i), mean = sum N_i / fit area, nodal p from M_Gamma p = N with the
    consistent surface mass matrix of the curved 6-node fit faces."""
    nodes = model["nodes"]
    tags = sorted(model["twin"])
    index = {t: k for k, t in enumerate(tags)}
    N = np.zeros(len(tags))
    for t in tags:
        x = nodes[t]
        N[index[t]] = -(forces[t][0] * x[0] + forces[t][1] * x[1]) / math.hypot(x[0], x[1])
    M = np.zeros((len(tags), len(tags)))
    for tri, pts in tri6_points(nodes, model["fit_tris"]):
        ids = [index[t] for t in tri]
        for n, w in pts:
            M[np.ix_(ids, ids)] += w * np.outer(n, n)
    p = np.linalg.solve(M, N)
    return N.sum() / model["fit_area"], p.max(), N


# --------------------------------------------------------------- running
def run_ccx_jobs(ccx, jobs, work, parallel=2):
    """Run the ccx jobs JOBS (WORK/JOB.inp) PARALLEL at a time, each on one
    thread (Debian's ccx factorises with SPOOLES: a second thread gains
    nothing, a second job halves the wall time). Returns the wall time [s];
    any failure fails the test with the job's log."""
    t0 = time.time()
    queue, running = list(jobs), []
    while queue or running:
        while queue and len(running) < parallel:
            job = queue.pop(0)
            log = open(os.path.join(work, job + ".log"), "w")
            running.append((job, log, time.time(), subprocess.Popen(
                [ccx, job], cwd=work, stdout=log, stderr=subprocess.STDOUT,
                env=dict(os.environ, OMP_NUM_THREADS="1"))))
        time.sleep(0.2)
        for item in list(running):
            job, log, t1, p = item
            if p.poll() is None:
                continue
            log.close()
            running.remove(item)
            print("  ccx %s: %.1f s" % (job, time.time() - t1), flush=True)
            text = open(os.path.join(work, job + ".log"), errors="replace").read()
            if p.returncode != 0 or "*ERROR" in text:
                for other in running:
                    other[3].kill()
                die("ccx %s failed (exit %d); the end of %s.log:\n%s" %
                    (job, p.returncode, job, text[-3000:]))
    return time.time() - t0


def run_rotorfit(exe, out, sets, prm=TS_PRM):
    """Run rotorfit serially on PRM with --set SETS into OUT; returns the
    wall time [s]."""
    if not os.access(exe, os.X_OK):
        die("no rotorfit executable at %s" % exe)
    if os.path.isdir(out):
        shutil.rmtree(out)
    cmd = [exe, "--output", out]
    for s in sets:
        cmd += ["--set", s]
    cmd.append(prm)
    t0 = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.time() - t0
    if r.returncode != 0:
        die("rotorfit exited with %d:\n%s" % (r.returncode, (r.stdout + r.stderr)[-3000:]))
    return wall


def summary(out):
    vals = {}
    for line in open(os.path.join(out, "summary.txt")):
        p = line.split(None, 1)
        if len(p) == 2:
            vals[p[0]] = p[1].strip()
    return vals


def read_csv(path):
    return list(csv.DictReader(open(path)))


# ------------------------------------------------------ CalculiX results
def read_ccx_complex(dat):
    """[(frequency [Hz], 'F' or 'B')] of the last complex-frequency step of
    a .dat file: rotating frame, unsigned, with CalculiX's turning direction."""
    text = open(dat, errors="replace").read()
    blocks = text.split("E I G E N V A L U E   O U T P U T")
    if len(blocks) < 3:
        die("%s: no complex eigenvalue output" % dat)
    table = blocks[-1].split("P A R T I C I P A T I O N")[0]
    freqs = {}
    for line in table.split("\n"):
        p = line.split()
        # mode, real part [rad/s], frequency [Hz], imaginary part [rad/s]
        if len(p) == 4 and p[0].isdigit():
            freqs[int(p[0])] = float(p[2])
    turning = {}
    tail = text.split("T U R N I N G   D I R E C T I O N")
    if len(tail) > 1:
        for line in tail[-1].split("\n"):
            p = line.split()
            if len(p) == 2 and p[0].isdigit() and p[1] in ("F", "B"):
                turning[int(p[0])] = p[1]
    if not freqs:
        die("%s: could not read the complex frequencies" % dat)
    return [(freqs[k], turning.get(k, "?")) for k in sorted(freqs)]


def read_ccx_real(dat):
    """Frequencies [Hz] of the *FREQUENCY step (the first eigenvalue block;
    CalculiX prints only those above the step's lower bound)."""
    text = open(dat, errors="replace").read()
    parts = text.split("E I G E N V A L U E   O U T P U T")
    if len(parts) < 2:
        die("%s: no eigenvalue output" % dat)
    block = parts[1].split("P A R T I C I P A T I O N")[0]
    out = []
    for line in block.split("\n"):
        p = line.split()
        # mode, eigenvalue, real part [rad/s], frequency [Hz], imaginary
        if len(p) == 5 and p[0].isdigit():
            out.append(float(p[3]))
    return out


def rotating(whirl, f, spin_hz):
    """The rotating-frame frequency and turning direction of a
    stationary-frame lateral mode (one nodal diameter, doc/calculix.md):
    BW f -> B at f + spin; FW f -> F at f - spin above the spin, B at
    spin - f below it."""
    if whirl == "backward":
        return f + spin_hz, "B"
    if whirl == "forward":
        return abs(f - spin_hz), "F" if f > spin_hz else "B"
    return f, "?"


def bonded_speeds(args, work, msh, model, name, speed, n_modes, steps, prm=TS_PRM):
    """Both codes at rest and at SPEED [r/min] on MSH, the fit bonded:
    CalculiX's whirl_deck (STEPS = (n_real, n_complex, f_lower)), the two
    speeds side by side, one core each; rotorfit on PRM with N_MODES modes,
    its bearing dampers 0 (CalculiX has none). Returns the two .dat files
    and rotorfit's campbell.csv rows."""
    jobs = []
    for rpm in (0.0, speed):
        job = "%s_%05d" % (name, rpm)
        whirl_deck(os.path.join(work, job + ".inp"), model, rpm, *steps)
        jobs.append(job)
    print("CalculiX, 2 speeds: %.1f s" % run_ccx_jobs(args.ccx, jobs, work), flush=True)
    out = os.path.join(work, "rotorfit")
    sets = ["Geometry/Geometry file=" + msh, "Geometry/Geometry parameters=",
            "Speeds/Mode=list", "Speeds/List=0, %g" % speed,
            "Eigenproblem/Number of modes=%d" % n_modes, "Unbalances=", "Probes=",
            "Output/Pictures=false", "Output/Write ParaView files=false"]
    for b in ("left", "right"):
        sets += ["Bearing %s/cxx=0" % b, "Bearing %s/cyy=0" % b]
    wall = run_rotorfit(args.rotorfit, out, sets + args.sets, prm=prm)
    print("rotorfit, 2 speeds: %.1f s" % wall, flush=True)
    return ([os.path.join(work, j + ".dat") for j in jobs],
            read_csv(os.path.join(out, "campbell.csv")))


def closed_rows(campbell, rpm):
    """rotorfit's campbell.csv rows at RPM; dies unless the static state
    converged with the fit closed (the bonded reference needs it)."""
    rows = [r for r in campbell if abs(float(r["speed_rpm"]) - rpm) < 0.5]
    if not rows:
        die("campbell.csv has no row at %g r/min" % rpm)
    bad = [r for r in rows if r["static_converged"] != "1" or r["fit_state"] != "closed"]
    if bad:
        die("rotorfit at %g r/min: fit_state %s, static_converged %s (the "
            "bonded reference needs the fit closed)" %
            (rpm, bad[0]["fit_state"], bad[0]["static_converged"]))
    return rows


def lowest_whirl(campbell, rpm, n):
    """rotorfit's N lowest whirl modes at RPM: [(whirl, f [Hz])]."""
    modes = sorted(((r["whirl"], float(r["frequency_hz"])) for r in closed_rows(campbell, rpm)
                    if r["whirl"] in ("backward", "forward")), key=lambda m: m[1])
    if len(modes) < n:
        die("rotorfit at %g r/min: %d whirl modes, %d wanted" % (rpm, len(modes), n))
    return modes[:n]


def match_whirl(checks, modes, dat, rpm, tol):
    """Each rotorfit whirl mode of MODES [(whirl, f [Hz])] at RPM against the
    CalculiX complex mode (DAT) of its rotating-frame frequency and turning
    direction, one to one, converted back to the stationary frame and
    checked to TOL; returns [(whirl, f, f_ccx)]."""
    spin = rpm / 60
    cf = read_ccx_complex(dat)
    used = set()
    matched = []
    for whirl, f in modes:
        target, turn = rotating(whirl, f, spin)
        cands = [(abs(c[0] - target), j) for j, c in enumerate(cf)
                 if c[1] == turn and j not in used]
        if not cands:
            die("%g r/min: no CalculiX mode turning %s for rotorfit's %s %.3f Hz"
                % (rpm, turn, whirl, f))
        j = min(cands)[1]
        used.add(j)
        # back to the stationary frame: f_ccx = its rotating frequency
        # converted the other way
        fr = cf[j][0]
        f_ccx = fr - spin if whirl == "backward" else (fr + spin if turn == "F" else spin - fr)
        checks.rel("%g r/min, %s %.1f Hz (CalculiX %.3f Hz %s rot.)" %
                   (rpm, whirl, f, fr, turn), f, f_ccx, tol)
        matched.append((whirl, f, f_ccx))
    return matched


# ------------------------------------------------------------- checking
class Checks:
    """Each compared value is printed with its reference, the difference
    and the tolerance; the test fails if any is outside."""

    def __init__(self):
        self.failed = []

    def rel(self, what, value, ref, tol, scale=None):
        """|value - ref| / scale <= tol (scale: |ref| by default)."""
        d = (value - ref) / abs(scale if scale is not None else ref)
        ok = abs(d) <= tol
        print("%-58s rotorfit %14.6f  CalculiX %14.6f  diff %+.2e  tol %.1e  %s" %
              (what, value, ref, d, tol, "ok" if ok else "FAILED"), flush=True)
        if not ok:
            self.failed.append(what)
        return d

    def true(self, what, ok, detail=""):
        print("%-58s %s  %s" % (what, detail, "ok" if ok else "FAILED"), flush=True)
        if not ok:
            self.failed.append(what)

    def finish(self, name):
        if self.failed:
            print("%s: %d check(s) FAILED: %s" % (name, len(self.failed), "; ".join(self.failed)))
            sys.exit(1)
        print("%s: all checks passed" % name)
