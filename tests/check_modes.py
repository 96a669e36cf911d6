#!/usr/bin/env python3
"""CTest checks of rotorfit's eigen results (campbell.csv, critical_speeds.csv,
rigid_modes.csv, log.txt) against closed forms or between runs. Every
tolerance is an argument, stated in tests/CMakeLists.txt. A test with closed
forms also has its expected output file tests/NAME.output (--expected FILE):
the values this script computes from the closed forms, with their tolerances,
which the run's values are diffed against with numdiff (--write-expected FILE
writes it).

  check_modes.py timoshenko EXE PRM OUT TOL FINE_H
      free-free cylinder at rest: the first two bending pairs within TOL of
      Timoshenko beam theory (tests/timoshenko.py), and closer on a mesh with
      h = FINE_H.
  check_modes.py rigid_rotor EXE PRM OUT TOL
      stiff short cylinder on two bearings at its end faces: translation,
      forward/backward tilt and translation damping within TOL of doc/theory.md 10d at
      every speed, forward rising and backward falling, 1X critical speeds.
  check_modes.py unbalance EXE PRM OUT TOL AF_TOL
      stiff short cylinder on two damped isotropic bearings (end faces or
      bands) with unbalance masses: the complex amplitude of every probe
      (bearings, unbalance stations, probes) within TOL of the speed's largest
      amplitude (bounds amplitude and phase) of the rigid-rotor forced response of doc/theory.md 13.4 at
      every speed; with one unbalance in the middle (a Jeffcott rotor) the
      peak speed within TOL and the half-power amplification factor within
      AF_TOL of 1/(2 zeta), and the separation margin from the operating range.
  check_modes.py stability_onset EXE PRM OUT TOL
      rigid rotor on bearings whose cross-coupled stiffness kxy = -kyx grows
      linearly with speed (coefficient table): the forward translation line
      becomes unstable where q = c sqrt(2k/m) (doc/theory.md 9.7); the onset
      speed and its frequency within TOL, direction and convergence flagged.
  check_modes.py torsion_crossing EXE PRM OUT TOL
      free-free soft cylinder: the first torsion line at rest within TOL of
      sqrt(G/rho)/(2L), its 1X crossing near 60 f listed as non-lateral and
      not excited by unbalance, every other crossing lateral.
  check_modes.py bearing_table EXE PRM OUT TOL
      rigid rotor on tabulated bearings: translation frequency and damping
      follow the interpolated k(Omega), c(Omega) within TOL.
  check_modes.py free_spin EXE PRM OUT TOL
      spinning free cylinder: forward tilt at Omega Ip/Id (doc/theory.md 10e-1).
  check_modes.py pair_shift EXE PRM_A OUT_A PRM_B OUT_B RPM PAIR MIN MAX
      f_A - f_B of the PAIR-th whirl pair (backward and forward) at RPM lies in
      [MIN, MAX] Hz.
  check_modes.py stiffening EXE PRM_ON PRM_OFF PRM_KSIG OUT RPM
      consistent stress stiffening moves the first two pairs by < 0.05 Hz;
      K_sigma alone raises the tilt pair by 4..10 Hz and puts twist at 1X.
  check_modes.py loss_of_fit EXE PRM OUT BODY
      after the fit opens: the run says so, rows have fit_state = open and the
      loose BODY's modes are listed apart.
  check_modes.py fixed EXE PRM OUT N_MODES
      'fixed' contact: N_MODES assembly modes at every speed, none loose, the
      first pair within 5 % of its value at the first speed.
  check_modes.py mpi EXE PRM OUT1 OUT2 RTOL ATOL
      campbell.csv with 1 and 2 MPI ranks agree (numdiff); the rigid-body
      mode count is the same at every speed and on both.
  check_modes.py failure EXE PRM OUT TEXT
      the run fails with exit code 2 and TEXT in its output; summary.txt
      says failed, where and why; campbell.csv keeps the speeds done before.
  check_modes.py reduced EXE PRM OUT FREQ_TOL ZETA_TOL [SET ...]
      the sweep on the reduced model against the full solve at every speed
      (consistency of two code paths; see check_reduced).
  check_modes.py reduced_fallback EXE PRM OUT FREQ_TOL ZETA_TOL [SET ...]
      the same where an undamped anchor is refused and its speed solved in
      full.
  check_modes.py doublets EXE PRM OUT TOL [SET ...]
      the harmonic model at rest: every mode of n >= 1 paired with its
      partner (equal frequency within TOL, backward then forward), lines
      continued at the next speed.
  check_modes.py rigid_rows EXE PRM OUT BODY [SET ...]
      the harmonic model's rigid_modes.csv: the tied assembly's axial and
      torsional rigid motions at rest, BODY loose once the fit is open.
  check_modes.py refinement_modal EXE PRM OUT CYCLES REFERENCE TOL [SET ...]
  check_modes.py fit_edge EXE PRM OUT EDGE REFERENCE TOL [SET ...]
      the harmonic model's meridian refined adaptively: harmonic 1's first
      mode at rest within TOL of REFERENCE after CYCLES cycles, closer than
      on cycle 0.
"""
import cmath
import csv
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run_test  # noqa: E402
import timoshenko  # noqa: E402


def value(prm_text, entry):
    return float(re.search(r"set\s+" + re.escape(entry) + r"\s*=\s*([-+0-9.eE]+)",
                           prm_text).group(1))


def geometry(prm_text, name):
    line = re.search(r"set Geometry parameters\s*=\s*(.*)", prm_text).group(1)
    return float(re.search(r"\b" + name + r"\s*:\s*([-+0-9.eE]+)", line).group(1))


def rows(out, name="campbell.csv"):
    with open(os.path.join(out, name)) as f:
        return list(csv.DictReader(f))


def speeds(table):
    return sorted({float(r["speed_rpm"]) for r in table})


def at(table, rpm):
    return [r for r in table if float(r["speed_rpm"]) == rpm]


def whirl_pairs(table, rpm):
    """(backward, forward) frequencies of the lateral modes at rpm, paired in
    order of frequency."""
    r = at(table, rpm)
    bw = sorted(float(x["frequency_hz"]) for x in r if x["whirl"] == "backward")
    fw = sorted(float(x["frequency_hz"]) for x in r if x["whirl"] == "forward")
    return list(zip(bw, fw))


# every report() against a reference value: (key, got, expected, rtol)
RESULTS = []


def report(name, got, expected, tol, reference=True):
    """Print and judge got against expected; with REFERENCE (a closed form,
    not another value of the same run) the pair also goes to the expected
    output file (see expected_output)."""
    err = (got - expected) / expected
    ok = abs(err) <= tol
    print(f"{name}: {got:.6g} expected {expected:.6g} error {err:+.3e} "
          f"(tolerance {tol:g}) {'ok' if ok else 'FAILED'}")
    if reference:
        RESULTS.append((re.sub(r"[^A-Za-z0-9.]+", "_", name).strip("_"), got, expected, tol))
    return ok


def expected_output(path, out, command, write):
    """The test's expected output file tests/NAME.output: 'key expected rtol'
    per reference value, computed by this script from the closed forms
    (WRITE: write it). Otherwise the run's values (OUT/check.got) are diffed
    against it line by line with numdiff at the line's tolerance, and the
    file must still hold what the closed forms give (not stale)."""
    if write:
        with open(path, "w") as f:
            f.write(f"# key expected rtol: {os.path.basename(path)[:-7]}, the closed forms of "
                    f"tests/check_modes.py {command} (doc/theory.md 10)\n"
                    f"# regenerate: python3 tests/check_modes.py {command} EXE PRM OUT ... "
                    f"--write-expected tests/{os.path.basename(path)}\n")
            for k, got, e, tol in RESULTS:
                f.write(f"{k} {e:.10g} {tol:g}\n")
        print(f"wrote {path} ({len(RESULTS)} values)")
        return True
    want = {}
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            k, e, tol = line.split()
            want[k] = (float(e), tol)
    got = {k: (g, e) for k, g, e, _ in RESULTS}
    ok = set(want) == set(got)
    if not ok:
        print(f"{path}: keys differ from the run's: missing {sorted(set(want) - set(got))}, "
              f"extra {sorted(set(got) - set(want))}")
    with open(os.path.join(out, "check.got"), "w") as f:
        for k, (g, _) in got.items():
            f.write(f"{k} {g:.10g}\n")
    for k in sorted(set(want) & set(got)):
        e, tol = want[k]
        if abs(got[k][1] - e) > 1e-9 * abs(e):
            print(f"{k}: {path} says {e:.10g}, the closed form {got[k][1]:.10g}: stale file")
            ok = False
        a, b = (os.path.join(out, k + x) for x in (".got", ".want"))
        open(a, "w").write(f"{k} {got[k][0]:.10g}\n")
        open(b, "w").write(f"{k} {e:.10g}\n")
        ok &= run_test.numdiff(a, b, tol, "0") == 0
    print(f"numdiff against {path}:", "ok" if ok else "FAILED")
    return ok


def prepare(prm, out, sets=()):
    """Arguments that run PRM into OUT, with --set SETS (see run_test.case)."""
    return run_test.case(prm, out, sets)


def check_timoshenko(exe, prm, out, tol, fine_h, fine_tol):
    text = open(prm).read()
    E, nu, rho = value(text, "Young's modulus"), value(text, "Poisson's ratio"), value(text, "Density")
    R, L = geometry(text, "R"), geometry(text, "L")
    ref = [w / (2 * math.pi) for w in timoshenko.timoshenko(E, nu, rho, R, L, 2)]
    ok = True
    errors = []
    # the finer mesh: the same Geometry parameters with h = FINE_H (--set);
    # on the section mesher (the harmonic model) its element sizes
    if re.search(r"set Mesher\s*=\s*sections", text):
        fine = (f"Geometry/Sections/Element size={fine_h}", f"Geometry/Sections/Fit element size={fine_h}")
    else:
        line = re.search(r"set Geometry parameters\s*=\s*(.*)", text).group(1).strip()
        fine = ("Geometry/Geometry parameters=" + re.sub(r"\bh\s*:\s*[-+0-9.eE]+", "h: " + fine_h, line),)
    for label, o, sets in (("coarse", out, ()), ("fine", out + "_fine", fine)):
        run_test.run(exe, prepare(prm, o, sets))
        r = at(rows(o), 0.0)
        f = sorted(float(x["frequency_hz"]) for x in r if x["whirl"] != "non-lateral")
        pairs = [0.5 * (f[0] + f[1]), 0.5 * (f[2] + f[3])]
        errors.append([abs(p - q) / q for p, q in zip(pairs, ref)])
        for i in range(2):
            ok &= report(f"{label} mesh, bending mode {i + 1} [Hz]", pairs[i], ref[i],
                         float(tol if label == "coarse" else fine_tol))
    for i in range(2):
        conv = errors[1][i] < errors[0][i]
        print(f"mode {i + 1}: error {errors[0][i]:.3e} -> {errors[1][i]:.3e} "
              f"{'converging' if conv else 'NOT converging'}")
        ok &= conv
    return 0 if ok else 1


def cylinder(text):
    rho, R, L = value(text, "Density"), geometry(text, "R"), geometry(text, "L")
    return timoshenko.cylinder_inertia(rho, R, L)


def check_rigid_rotor(exe, prm, out, tol, crit_tol):
    """Translation, damping and tilt at every speed within TOL of the closed
    forms (doc/theory.md 10d), the 1X critical speeds within CRIT_TOL (None:
    not checked)."""
    tol = float(tol)
    run_test.run(exe, prepare(prm, out))
    text = open(prm).read()
    m, Ip, Id = cylinder(text)
    k, c, L = value(text, "kxx"), value(text, "cxx"), geometry(text, "L")
    # bearings as bands (Axial position): the span is between the band middles
    z = [float(x) for x in re.findall(r"set Axial position\s*=\s*([-+0-9.eE]+)", text)]
    if len(z) == 2:
        L = abs(z[1] - z[0])
    table = rows(out)
    ok = True
    previous = None
    for rpm in speeds(table):
        omega = rpm * math.pi / 30
        wt, wf, wb = timoshenko.rigid_rotor(m, Ip, Id, k, L, omega)
        r = at(table, rpm)
        f = sorted(r, key=lambda x: float(x["frequency_hz"]))
        fw = [x for x in f if x["whirl"] == "forward"]
        bw = [x for x in f if x["whirl"] == "backward"]
        if rpm == 0:
            # at rest the pairs are degenerate: FW = BW
            pairs = whirl_pairs(table, rpm)
            for b, fr in pairs[:2]:
                ok &= report(f"{rpm:g} r/min: forward = backward", fr, b, 1e-4, False)
        freqs = sorted(float(x["frequency_hz"]) for x in f)
        def closest(target, cand):
            return min(cand, key=lambda x: abs(float(x["frequency_hz"]) - target))
        t_fw = closest(wt / (2 * math.pi), fw)
        t_bw = closest(wt / (2 * math.pi), bw)
        ok &= report(f"{rpm:g} r/min translation FW [Hz]", float(t_fw["frequency_hz"]), wt / (2 * math.pi), tol)
        ok &= report(f"{rpm:g} r/min translation BW [Hz]", float(t_bw["frequency_hz"]), wt / (2 * math.pi), tol)
        zeta = c / math.sqrt(2 * k * m)
        ok &= report(f"{rpm:g} r/min translation damping ratio", float(t_bw["damping_ratio"]), zeta, tol)
        tilt_fw = closest(wf / (2 * math.pi), [x for x in fw if x is not t_fw])
        tilt_bw = closest(wb / (2 * math.pi), [x for x in bw if x is not t_bw])
        ok &= report(f"{rpm:g} r/min tilt FW [Hz]", float(tilt_fw["frequency_hz"]), wf / (2 * math.pi), tol)
        ok &= report(f"{rpm:g} r/min tilt BW [Hz]", float(tilt_bw["frequency_hz"]), wb / (2 * math.pi), tol)
        if previous is not None:
            rising = float(tilt_fw["frequency_hz"]) > previous[0]
            falling = float(tilt_bw["frequency_hz"]) < previous[1]
            print(f"{rpm:g} r/min: tilt FW rises {rising}, BW falls {falling}")
            ok &= rising and falling
        previous = (float(tilt_fw["frequency_hz"]), float(tilt_bw["frequency_hz"]))
    if crit_tol is None:
        return 0 if ok else 1
    crit_tol = float(crit_tol)
    # 1X critical speeds (doc/theory.md 10d) of the damped rotor: where the damped
    # translation and tilt frequencies meet the speed (the undamped closed form is
    # off by -zeta^2/2 = -4e-5 at zeta 0.009)
    crit = rows(out, "critical_speeds.csv")
    wt, wb, wf = timoshenko.rigid_rotor_damped_critical(m, Ip, Id, k, c, L)
    expected = [("translation", 30 / math.pi * wt, None),
                ("backward tilt", 30 / math.pi * wb, "backward")]
    if wf is not None:
        expected.append(("forward tilt", 30 / math.pi * wf, "forward"))
    top = speeds(table)[-1]
    for name, s, whirl in expected:
        if s > top:
            continue
        cand = [float(x["speed_rpm"]) for x in crit if int(x["order"]) == 1 and
                (whirl is None or x["whirl"] == whirl)]
        if not cand:
            print(f"critical speed {name}: none found, expected {s:.6g} r/min FAILED")
            ok = False
            continue
        got = min(cand, key=lambda x: abs(x - s))
        ok &= report(f"1X critical speed, {name} [r/min]", got, s, crit_tol)
        if whirl is None:
            # the translation's damping ratio at its crossing: c / sqrt(2 k m)
            row = min(crit, key=lambda x: abs(float(x["speed_rpm"]) - s))
            ok &= report("1X critical speed, translation damping ratio",
                         float(row["damping_ratio"]), zeta, tol)
            ok &= report("1X critical speed, translation amplification factor",
                         float(row["amplification_factor"]), 1 / (2 * zeta), tol)
    # isotropic bearings: unbalance excites the forward crossings only
    for x in crit:
        want = "1" if x["whirl"] != "backward" and int(x["order"]) == 1 else "0"
        good = x["kind"] == "lateral" and x["unbalance_excited"] == want
        print(f"crossing at {float(x['speed_rpm']):.6g} r/min, {x['whirl']}: kind {x['kind']}, "
              f"unbalance_excited {x['unbalance_excited']} (expected lateral, {want})",
              "ok" if good else "FAILED")
        ok &= good
    return 0 if ok else 1


def subsections(text, kind):
    """{name: body text} of the 'subsection KIND name' of each name the list
    'KINDs' of a .prm gives."""
    names = re.search(r"^set " + kind + r"s\s*=(.*)$", text, re.M)
    names = [n.strip() for n in names.group(1).split(",") if n.strip()] if names else []
    return {m.group(1): m.group(2) for m in
            re.finditer(r"subsection " + kind + r" (\w+)\n(.*?)\nend", text, re.S)
            if m.group(1) in names}


def rigid_forced_response(m, Ip, Id, zc, bearings, unbalances, omega):
    """Rigid rotor, isotropic bearings [(z, k, c)], unbalances [(z, m e, phase
    rad)], spin omega: complex (R, Phi) with the lateral displacement
    x + i y = (R + Phi (z - zc)) e^{i omega t} (doc/theory.md 13.4):
      [-m w^2 + sum s_j] R + sum s_j d_j Phi = sum F_u
      sum s_j d_j R + [(Ip - Id) w^2 + sum s_j d_j^2] Phi = sum F_u d_u
    with s_j = k_j + i w c_j, d = z - zc, F_u = m e w^2 e^{i phase}."""
    w = omega
    s = [(z - zc, k + 1j * w * c) for z, k, c in bearings]
    a11 = -m * w * w + sum(x for _, x in s)
    a12 = sum(d * x for d, x in s)
    a22 = (Ip - Id) * w * w + sum(d * d * x for d, x in s)
    f1 = sum(me * w * w * complex(math.cos(ph), math.sin(ph)) for _, me, ph in unbalances)
    f2 = sum((z - zc) * me * w * w * complex(math.cos(ph), math.sin(ph))
             for z, me, ph in unbalances)
    det = a11 * a22 - a12 * a12
    return (f1 * a22 - a12 * f2) / det, (a11 * f2 - a12 * f1) / det


def check_unbalance(exe, prm, out, tol, af_tol, peak_tol=None):
    """Amplitudes within TOL (of each speed's largest), the Jeffcott peak's
    amplification factor within AF_TOL and its speed within PEAK_TOL."""
    tol, af_tol = float(tol), float(af_tol)
    peak_tol = tol if peak_tol is None else float(peak_tol)
    run_test.run(exe, prepare(prm, out))
    text = open(prm).read()
    m, Ip, Id = cylinder(text)
    L = geometry(text, "L")

    def station(body):
        z = re.search(r"set Axial position\s*=\s*([-+0-9.eE]+)", body)
        if z:
            return float(z.group(1))
        return {"end_left": 0.0, "end_right": L}[re.search(r"set Surface\s*=\s*(\w+)", body).group(1)]
    bearings = {n: (station(b), value(b, "kxx"), value(b, "cxx"))
                for n, b in subsections(text, "Bearing").items()}
    unbalances = {n: (station(b), value(b, "Mass eccentricity"),
                      math.radians(value(b, "Phase") if "Phase" in b else 0.0))
                  for n, b in subsections(text, "Unbalance").items()}
    probes = {n: v[0] for n, v in list(bearings.items()) + list(unbalances.items())}
    probes.update({n: station(b) for n, b in subsections(text, "Probe").items()})
    ok = True
    worst = 0.0
    table = rows(out, "response.csv")
    # the largest amplitude of each speed: a probe near a node of the
    # deflected shape is judged against the response level of its speed
    level = {}
    for r in table:
        level[r["speed_rpm"]] = max(level.get(r["speed_rpm"], 0.0), float(r["amplitude_x_m"]))
    for r in table:
        rpm, probe = float(r["speed_rpm"]), r["probe"]
        omega = rpm * math.pi / 30
        if omega == 0:
            continue
        R, Phi = rigid_forced_response(m, Ip, Id, L / 2, list(bearings.values()),
                                       list(unbalances.values()), omega)
        want = R + Phi * (probes[probe] - L / 2)   # X; Y = -i X
        lag = math.radians(float(r["phase_x_deg"]))
        got = float(r["amplitude_x_m"]) * complex(math.cos(lag), -math.sin(lag))
        scale = max(abs(want), level[r["speed_rpm"]])
        err = abs(got - want) / scale
        worst = max(worst, err)
        line_tol = tol * scale / abs(want)
        ok &= report(f"{rpm:g} r/min {probe} x amplitude [m]", abs(got), abs(want), line_tol)
        # phase lags [deg], got unwrapped next to want, both + 360 for a
        # relative tolerance (0.5 % of 360..540 deg: 1.8..2.7 deg)
        w_lag = -math.degrees(cmath.phase(want))
        g_lag = w_lag + (-math.degrees(cmath.phase(got)) - w_lag + 180) % 360 - 180
        ok &= report(f"{rpm:g} r/min {probe} x phase lag + 360 [deg]", g_lag + 360, w_lag + 360,
                     line_tol)
        good = err <= tol and r["whirl"] == "forward" and r["converged"] == "1"
        if not good:
            print(f"{rpm:g} r/min {probe}: complex error {err:.3e} of the speed's largest "
                  f"amplitude, whirl {r['whirl']}, converged {r['converged']} FAILED")
        ok &= good
    print(f"worst complex amplitude error {worst:.3e} of the speed's largest amplitude "
          f"(tolerance {tol:g})")
    ub = list(unbalances.values())
    if len(ub) == 1 and abs(ub[0][0] - L / 2) < 1e-9:
        # Jeffcott: X = m e w^2 / (k - m w^2 + i c w), peak at
        # w_n / sqrt(1 - 2 zeta^2), half-power AF -> 1 / (2 zeta)
        k = sum(b[1] for b in bearings.values())
        c = sum(b[2] for b in bearings.values())
        zeta = c / (2 * math.sqrt(k * m))
        peak_rpm = 30 / math.pi * math.sqrt(k / m) / math.sqrt(1 - 2 * zeta**2)
        peaks = [p for p in rows(out, "response_peaks.csv") if p["probe"] in bearings]
        if len(peaks) != len(bearings):
            print(f"peaks of the bearing probes: {len(peaks)}, expected {len(bearings)} FAILED")
            ok = False
        lo_hi = re.search(r"set Operating speed range\s*=\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)", text)
        for p in peaks:
            af = float(p["amplification_factor"])
            ok &= report(f"{p['probe']} peak speed [r/min]", float(p["speed_rpm"]), peak_rpm, peak_tol)
            ok &= report(f"{p['probe']} amplification factor", af, 1 / (2 * zeta), af_tol)
            if lo_hi:
                lo, hi = float(lo_hi.group(1)), float(lo_hi.group(2))
                n = float(p["speed_rpm"])
                sm = 100 * ((lo - n) / lo if n < lo else (n - hi) / hi)
                req = min(16, 17 * (1 - 1 / (af - 1.5))) if n < lo else \
                    min(26, 10 + 17 * (1 - 1 / (af - 1.5)))
                ok &= report(f"{p['probe']} separation margin [%]",
                             float(p["separation_margin_percent"]), sm, 1e-6, False)
                ok &= report(f"{p['probe']} required margin [%]",
                             float(p["required_margin_percent"]), req, 1e-6, False)
                good = p["margin_ok"] == ("yes" if sm >= req else "no")
                print(f"{p['probe']}: margin_ok {p['margin_ok']}", "ok" if good else "FAILED")
                ok &= good
    return 0 if ok else 1


def check_stability_onset(exe, prm, out, tol):
    tol = float(tol)
    run_test.run(exe, prepare(prm, out))
    text = open(prm).read()
    m, _, _ = cylinder(text)
    table = re.search(r"set Coefficient table\s*=\s*(\S+)", text).group(1)
    data = [r for r in csv.reader(l for l in open(os.path.join(os.path.dirname(prm), table))
                                  if l.strip() and not l.startswith("#"))][1:]
    (n0, k, _, q0, _, c, *_), (n1, _, _, q1, *_) = ([float(x) for x in r] for r in data[:2])
    slope = (q1 - q0) / (n1 - n0)            # N/m per r/min, q0 = 0
    onset = c * math.sqrt(2 * k / m) / slope
    found = rows(out, "stability_onsets.csv")
    ok = len(found) >= 1
    print(f"onsets found: {len(found)}", "ok" if ok else "FAILED")
    if ok:
        o = min(found, key=lambda r: float(r["onset_rpm"]))
        ok &= report("stability onset [r/min]", float(o["onset_rpm"]), onset, tol)
        ok &= report("frequency at the onset [Hz]", float(o["frequency_hz"]),
                     math.sqrt(2 * k / m) / (2 * math.pi), tol)
        good = o["direction"] == "unstable above" and o["whirl"] == "forward" and o["converged"] == "1"
        print(f"direction {o['direction']}, whirl {o['whirl']}, converged {o['converged']}",
              "ok" if good else "FAILED")
        ok &= good
        summary = open(os.path.join(out, "summary.txt")).read()
        good = re.search(r"^modal.first_stability_onset_rpm ([-+0-9.eE]+)$", summary, re.M)
        print("summary.txt names the onset:", "ok" if good else "FAILED")
        ok &= bool(good)
    return 0 if ok else 1


def check_torsion_crossing(exe, prm, out, tol):
    tol = float(tol)
    run_test.run(exe, prepare(prm, out))
    text = open(prm).read()
    E, nu, rho = value(text, "Young's modulus"), value(text, "Poisson's ratio"), value(text, "Density")
    L = geometry(text, "L")
    f_t = math.sqrt(E / (2 * (1 + nu)) / rho) / (2 * L)
    rest = [r for r in at(rows(out), 0.0) if r["whirl"] == "non-lateral"]
    ok = bool(rest)
    if ok:
        got = min((float(r["frequency_hz"]) for r in rest), key=lambda f: abs(f - f_t))
        ok &= report("torsion at rest [Hz]", got, f_t, tol)
    else:
        print("no non-lateral line at rest FAILED")
    crit = rows(out, "critical_speeds.csv")
    torsion = [x for x in crit if abs(float(x["speed_rpm"]) - 60 * f_t) < 0.05 * 60 * f_t]
    good = len(torsion) == 1 and torsion[0]["kind"] == "non-lateral" and \
        torsion[0]["unbalance_excited"] == "0"
    print(f"1X crossing near {60 * f_t:.6g} r/min: {[(x['speed_rpm'], x['kind'], x['unbalance_excited']) for x in torsion]}"
          " (expected one, non-lateral, not excited)", "ok" if good else "FAILED")
    ok &= good
    lateral = [x for x in crit if x not in torsion]
    good = len(lateral) >= 2 and all(x["kind"] == "lateral" for x in lateral)
    print(f"other crossings: {[(x['speed_rpm'], x['whirl'], x['kind']) for x in lateral]} "
          "(expected lateral)", "ok" if good else "FAILED")
    ok &= good
    return 0 if ok else 1


def check_bearing_table(exe, prm, out, tol):
    """Translation mode of the rigid rotor on tabulated bearings: frequency
    sqrt(2 k/m) and damping ratio c/sqrt(2 k m) with k, c interpolated."""
    run_test.run(exe, prepare(prm, out))
    text = open(prm).read()
    m, Ip, Id = cylinder(text)
    table = []
    for line in open(os.path.join(os.path.dirname(prm), "bearing_table.csv")):
        if line.strip() and not line.startswith("#") and "speed" not in line:
            table.append([float(x) for x in line.split(",")])
    def interp(rpm, col):
        if rpm >= table[-1][0]:
            return table[-1][col]
        for a, b in zip(table, table[1:]):
            if a[0] <= rpm <= b[0]:
                t = (rpm - a[0]) / (b[0] - a[0])
                return (1 - t) * a[col] + t * b[col]
        return table[0][col]
    ok = True
    result = rows(out)
    for rpm in speeds(result):
        k, c = interp(rpm, 1), interp(rpm, 5)
        f = math.sqrt(2 * k / m) / (2 * math.pi)
        cand = min(at(result, rpm), key=lambda x: abs(float(x["frequency_hz"]) - f))
        ok &= report(f"{rpm:g} r/min translation [Hz]", float(cand["frequency_hz"]), f, float(tol))
        ok &= report(f"{rpm:g} r/min translation damping ratio", float(cand["damping_ratio"]),
                     c / math.sqrt(2 * k * m), float(tol))
    return 0 if ok else 1


def check_free_spin(exe, prm, out, tol):
    run_test.run(exe, prepare(prm, out))
    text = open(prm).read()
    m, Ip, Id = cylinder(text)
    table = rows(out)
    ok = True
    for rpm in speeds(table):
        if rpm == 0:
            continue
        fw = [float(x["frequency_hz"]) for x in at(table, rpm) if x["whirl"] == "forward"]
        expected = rpm / 60 * Ip / Id
        ok &= report(f"{rpm:g} r/min free forward tilt [Hz]", min(fw, key=lambda f: abs(f - expected)),
                     expected, float(tol))
    # doc/theory.md 10e-3/4 (self-check at the first speed > 0): virial identity of
    # K_sigma on rigid tilt and twist (round-off up to the tiny support
    # reactions of an unsymmetric mesh) and the tilt cancellation against
    # Omega^2 K_theta (exact only on rotationally symmetric meshes)
    summary = dict(l.split(None, 1) for l in open(os.path.join(out, "summary.txt")) if l.strip())
    # recorded 1.6e-7 (tilt; the support reactions' share) and 0 (twist)
    for key, tol_key in (("check.tilt_virial", 7.5e-7), ("check.twist_virial", 1e-9)):
        ok &= report(key, float(summary[key]), 1.0, tol_key)
    c = float(summary["check.tilt_cancellation"])
    # recorded 9e-6 (the tetrahedral mesh's asymmetry, doc/theory.md): 5e-5
    good = abs(c) < 5e-5
    print(f"check.tilt_cancellation: {c:.3e} (|.| < 5e-5) {'ok' if good else 'FAILED'}")
    ok &= good
    return 0 if ok else 1


def check_ring_symmetry(exe, prm, out, n_theta, rtol):
    """Rotational symmetry of the section mesher's hexahedra: the rings map
    onto themselves under a rotation of 2 pi / N_THETA, the O-grid core only
    under pi / 2. So the pairs of a ring (same z, radius and angle within the
    cell) related by pi / 2 open at one speed (pair_openings.csv, to RTOL),
    a whole ring within 1e-4 (the core's share), the contact state is
    symmetric at every speed (asymmetry 0 in contact.csv), the sweep does
    reach a partly open fit, and at rest every whirl pair is a doublet (to
    RTOL)."""
    run_test.run(exe, prepare(prm, out))
    n, rtol, ok = int(n_theta), float(rtol), True
    rings, orbits = {}, {}
    for r in rows(out, "pair_openings.csv"):
        x, y, z = float(r["x_m"]), float(r["y_m"]), float(r["z_m"])
        angle = math.atan2(y, x) + 0.75 * math.pi
        phase = (angle / (2 * math.pi / n)) % 1.0
        key = (round(z, 9), round(math.hypot(x, y), 9), round(phase, 6) % 1.0)
        quarter = round((angle / (0.5 * math.pi)) % 1.0, 6) % 1.0
        rings.setdefault(key, []).append(float(r["opening_rpm"]))
        orbits.setdefault(key[:2] + (quarter,), []).append(float(r["opening_rpm"]))
    spread = lambda groups: max((max(v) - min(v)) / max(v) for v in groups.values())
    sizes = {len(v) for v in rings.values()}
    good = spread(orbits) <= rtol and spread(rings) <= 1e-4 and sizes == {n}
    print(f"{len(rings)} rings of pairs, sizes {sorted(sizes)} (expected {{{n}}}); widest spread "
          f"of opening speeds among pairs pi/2 apart {spread(orbits):.2e} (tolerance {rtol:g}), "
          f"in a ring {spread(rings):.2e} (tolerance 1e-4) {'ok' if good else 'FAILED'}")
    ok &= good
    contact = rows(out, "contact.csv")
    asym = max(float(r["asymmetry"]) for r in contact)
    partly = [float(r["speed_rpm"]) for r in contact if 0 < float(r["contact_fraction"]) < 1]
    good = asym == 0 and len(partly) > 0
    print(f"largest contact asymmetry {asym:g} (expected 0); partly open at {partly} r/min "
          f"{'ok' if good else 'FAILED'}")
    ok &= good
    for bw, fw in whirl_pairs(rows(out), 0.0):
        ok &= report(f"0 r/min doublet {bw:.6g} Hz: forward", fw, bw, rtol, reference=False)
    return 0 if ok else 1


def check_study(exe, study, out, script, tol):
    """The study driver (scripts/study.py) on the plane-strain Lame case on
    hexahedra, three meshes: its Richardson-extrapolated pressure at rest and
    loss-of-fit speed within TOL of the closed forms (tests/lame.py values in
    lame_plane_strain_hex.output), with a positive observed order, and the
    table has a row per run with DOFs, time and memory."""
    subprocess.run([sys.executable, script, study, "--rotorfit", exe, "--output", out], check=True)
    exact = {}
    for line in open(os.path.join(os.path.dirname(study), "lame_plane_strain_hex.output")):
        if line.strip() and not line.startswith("#"):
            key, value = line.split()[:2]
            exact[key] = float(value)
    ext = {r["quantity"]: r for r in rows(out, "extrapolated.csv")}
    ok = True
    for q, key in (("p0_mpa", "interface.fit.mean_pressure_first_speed_Pa"),
                   ("full_open", "interface.fit.loss_of_fit_rpm")):
        scale = 1e-6 if q == "p0_mpa" else 1.0
        ok &= report(f"extrapolated {q}", float(ext[q]["extrapolated"]), exact[key] * scale, float(tol))
        order = float(ext[q]["observed_order"])
        good = order > 1
        print(f"observed order of {q}: {order:.3g} (> 1) {'ok' if good else 'FAILED'}")
        ok &= good
    table = rows(out, "study.csv")
    good = len(table) == 3 and all(int(r["dofs"]) > 0 and float(r["wall_s"]) > 0 and
                                   float(r["peak_mb"]) > 0 for r in table)
    print(f"study.csv: {len(table)} runs with DOFs, time and memory {'ok' if good else 'FAILED'}")
    return 0 if ok and good else 1


def check_refinement(exe, prm, out, cycles, ratio, tol, *sets):
    """Adaptive refinement of the section mesh on the plane-strain Lame case
    (static indicator): after CYCLES cycles the errors of the pressure at rest
    and of the loss-of-fit speed against the closed forms (tests/lame.py, in
    lame_plane_strain_hex.output) are at most RATIO times those of cycle 0,
    and within TOL; every cycle left its results in cycle_<k>/."""
    run_test.run(exe, prepare(prm, out, ["Mesh refinement/Cycles=" + cycles] + list(sets)))
    exact = {}
    for line in open(os.path.join(os.path.dirname(os.path.abspath(prm)), "lame_plane_strain_hex.output")):
        if line.strip() and not line.startswith("#"):
            key, value = line.split()[:2]
            exact[key] = float(value)
    ok = True
    final = dict(l.split(None, 1) for l in open(os.path.join(out, "summary.txt")) if l.strip())
    first = dict(l.split(None, 1) for l in open(os.path.join(out, "cycle_0", "summary.txt")) if l.strip())
    for k in range(int(cycles)):
        good = os.path.exists(os.path.join(out, f"cycle_{k}", "summary.txt"))
        print(f"cycle_{k}/summary.txt {'written' if good else 'MISSING'}")
        ok &= good
    for key in ("interface.fit.mean_pressure_first_speed_Pa", "interface.fit.loss_of_fit_rpm"):
        e0 = abs(float(first[key]) - exact[key]) / exact[key]
        e1 = abs(float(final[key]) - exact[key]) / exact[key]
        good = e1 <= float(ratio) * e0 and e1 <= float(tol)
        print(f"{key}: error {e0:.2e} on cycle 0, {e1:.2e} after {cycles} cycles "
              f"(at most {ratio} x and {tol}) {'ok' if good else 'FAILED'}")
        ok &= good
    return 0 if ok else 1


def first_harmonic_1_at_rest(folder):
    """Harmonic 1's lowest frequency at 0 r/min in FOLDER's campbell.csv."""
    return min(float(r["frequency_hz"]) for r in at(rows(folder), 0.0) if r["harmonic"] == "1")


def harmonic_1_dofs(folder):
    """Harmonic 1's DoF count, the last one FOLDER's log states."""
    return re.findall(r"Harmonic 1: (\d+) DoFs", open(os.path.join(folder, "log.txt")).read())[-1]


def check_refinement_modal(exe, prm, out, cycles, reference, tol, *sets):
    """Adaptive refinement of the harmonic model's meridian with the modal
    indicator on a joint whose frequency converges slowly under uniform
    refinement (TS: the sleeve's edge is a corner singularity): after CYCLES
    cycles harmonic 1's first mode at rest lies within TOL of REFERENCE and
    closer to it than on cycle 0."""
    run_test.run(exe, prepare(prm, out, ["Mesh refinement/Cycles=" + cycles] + list(sets)))

    ref = float(reference)
    e0 = (first_harmonic_1_at_rest(os.path.join(out, "cycle_0")) - ref) / ref
    e1 = (first_harmonic_1_at_rest(out) - ref) / ref
    good = abs(e1) <= float(tol) and abs(e1) < abs(e0)
    print(f"harmonic 1, mode 1 at rest: {e0:+.3e} on cycle 0 ({harmonic_1_dofs(os.path.join(out, 'cycle_0'))} "
          f"DoFs), {e1:+.3e} after {cycles} cycles ({harmonic_1_dofs(out)} DoFs) against {ref} "
          f"(within {tol} and closer) {'ok' if good else 'FAILED'}")
    return 0 if good else 1


def check_fit_edge(exe, prm, out, edge, reference, tol, *sets):
    """The section mesher's grading towards the fits' edges (Geometry/Sections/
    Fit edge element size = EDGE) on a joint whose corner is a stress
    singularity (TS): harmonic 1's first mode at rest lies within TOL of
    REFERENCE with it, and closer than on the same sizes without it."""
    plain, graded = os.path.join(out, "plain"), os.path.join(out, "graded")
    run_test.run(exe, prepare(prm, plain, list(sets)))
    run_test.run(exe, prepare(prm, graded, list(sets) + ["Geometry/Sections/Fit edge element size=" + edge]))

    ref = float(reference)
    e0 = (first_harmonic_1_at_rest(plain) - ref) / ref
    e1 = (first_harmonic_1_at_rest(graded) - ref) / ref
    good = abs(e1) <= float(tol) and abs(e1) < abs(e0)
    print(f"harmonic 1, mode 1 at rest: {e0:+.3e} without grading ({harmonic_1_dofs(plain)} DoFs), {e1:+.3e} "
          f"with {edge} m at the fit's edges ({harmonic_1_dofs(graded)} DoFs) against {ref} (within {tol} and "
          f"closer) {'ok' if good else 'FAILED'}")
    return 0 if good else 1


def check_doublets(exe, prm, out, tol, *sets):
    """Rotational symmetry at rest on the harmonic model: every mode of a
    harmonic n >= 1 at 0 r/min is one of a doublet, written as its backward
    and forward travelling waves of equal frequency (within TOL), and the
    lines continue at the next speed (no line starts there)."""
    run_test.run(exe, prepare(prm, out, list(sets)))
    table = rows(out)
    ok = True
    for n in sorted({r["harmonic"] for r in table if r["harmonic"] != "0"}):
        rest = sorted((r for r in at(table, 0.0) if r["harmonic"] == n),
                      key=lambda r: int(r["mode"]))
        for a, b in zip(rest[0::2], rest[1::2]):
            fa, fb = float(a["frequency_hz"]), float(b["frequency_hz"])
            good = abs(fa - fb) <= float(tol) * fa and (a["travel"], b["travel"]) == \
                ("backward", "forward")
            print(f"harmonic {n}, modes {a['mode']}/{b['mode']}: {fa:.10g} / {fb:.10g} Hz, "
                  f"{a['travel']} / {b['travel']} {'ok' if good else 'FAILED'}")
            ok &= good
        if len(rest) % 2:
            print(f"harmonic {n}: {len(rest)} modes at rest, one without its partner FAILED")
            ok = False
        ids = {r["tracked_id"] for r in rest}
        later = [r for r in table if r["harmonic"] == n and float(r["speed_rpm"]) > 0]
        first_later = min((float(r["speed_rpm"]) for r in later), default=None)
        new = {r["tracked_id"] for r in later if float(r["speed_rpm"]) == first_later} - ids
        good = not new
        print(f"harmonic {n}: lines new at {first_later} r/min: {sorted(new) or 'none'} "
              f"{'ok' if good else 'FAILED'}")
        ok &= good
    return 0 if ok else 1


def check_rigid_rows(exe, prm, out, body, *sets):
    """The harmonic model's rigid_modes.csv on a fit that opens (TS at 0 and
    24,000 r/min): at rest the tied assembly's rigid motions are axial and
    torsional only (harmonic 0, 'rigid', 'assembly'; the bearings hold
    harmonic 1); with the fit fully open BODY is loose in harmonics 0 and 1
    ('loose', BODY), the shaft nowhere in harmonic 1; every row below 1 Hz
    and absent from campbell.csv."""
    run_test.run(exe, prepare(prm, out, list(sets)))
    rigid = rows(out, "rigid_modes.csv")
    speeds_ = sorted({float(r["speed_rpm"]) for r in rigid})
    first, last = 0.0, max(speeds_) if speeds_ else 0.0
    ok = True

    def kinds(rpm, n):
        return {(r["kind"], r["body"]) for r in rigid
                if float(r["speed_rpm"]) == rpm and r["harmonic"] == str(n)}

    checks = [(f"at {first:g} r/min, harmonic 0", kinds(first, 0), {("rigid", "assembly")}),
              (f"at {first:g} r/min, harmonic 1", kinds(first, 1), set()),
              (f"at {last:g} r/min, harmonic 1", kinds(last, 1), {("loose", body)})]
    for what, got, expected in checks:
        good = got == expected
        print(f"{what}: {sorted(got)} (expected {sorted(expected)}) {'ok' if good else 'FAILED'}")
        ok &= good
    good = ("loose", body) in kinds(last, 0)
    print(f"at {last:g} r/min, harmonic 0: {sorted(kinds(last, 0))} includes loose {body} "
          f"{'ok' if good else 'FAILED'}")
    ok &= good
    slow = all(math.hypot(float(r["real_part_per_s"]) / (2 * math.pi), float(r["frequency_hz"])) < 1
               for r in rigid)
    print(f"every row below 1 Hz: {slow}")
    ok &= slow and last > first
    return 0 if ok else 1


def check_locking(exe, prm, out, min_error, *sets):
    """Linear elements on the free-free cylinder (doc/limits.md): the run
    warns, and the warning is earned: the bending pair nearest the
    Timoshenko frequency (tests/timoshenko.py) lies more than MIN_ERROR above
    it (locking)."""
    r = run_test.run(exe, prepare(prm, out, ["Geometry/Element order=1"] + list(sets)))
    text = open(os.path.join(out, "log.txt")).read()
    warned = "linear elements lock in bending" in text
    print(f"warning in log.txt: {warned}")
    t = open(prm).read()
    E, nu, rho = (value(t, k) for k in ("Young's modulus", "Poisson's ratio", "Density"))
    f1 = timoshenko.timoshenko(E, nu, rho, geometry(t, "R"), geometry(t, "L"), 1)[0] / (2 * math.pi)
    got = [float(x["frequency_hz"]) for x in at(rows(out), 0.0) if x["whirl"] in ("forward", "backward", "mixed")]
    near = min(got, key=lambda f: abs(f - f1))
    err = (near - f1) / f1
    good = err > float(min_error)
    print(f"bending pair {near:.6g} Hz against Timoshenko {f1:.6g} Hz: {err:+.3e} "
          f"(more than {min_error}: locking) {'ok' if good else 'FAILED'}")
    return 0 if warned and good else 1


def check_asymmetry(exe, prm, out, speed, *sets):
    """A tetrahedral mesh's closed set in the partly open band is not
    rotationally symmetric (doc/limits.md): contact.csv's asymmetry is above
    0.1 at every partly open speed, and at SPEED above 0.5 with the log's
    warning naming the speed and what to change."""
    run_test.run(exe, prepare(prm, out, list(sets)))
    rows_ = rows(out, "contact.csv")
    partly = [r for r in rows_ if 0 < float(r["contact_fraction"]) < 1]
    ok = len(partly) > 0 and all(float(r["asymmetry"]) > 0.1 for r in partly)
    print("partly open:", [(r["speed_rpm"], r["asymmetry"]) for r in partly],
          "all above 0.1:", ok)
    text = open(os.path.join(out, "log.txt")).read()
    want = f"Warning: the closed set at {speed} r/min is not rotationally symmetric"
    warned = want in text and "Geometry/Mesher = sections" in text
    print(f"warning at {speed} r/min with the remedy: {warned}")
    return 0 if ok and warned else 1


def check_pair_shift(exe, prm_a, out_a, prm_b, out_b, rpm, pair, lo, hi):
    run_test.run(exe, prepare(prm_a, out_a))
    run_test.run(exe, prepare(prm_b, out_b))
    rpm, pair, lo, hi = float(rpm), int(pair), float(lo), float(hi)
    a, b = whirl_pairs(rows(out_a), rpm), whirl_pairs(rows(out_b), rpm)
    ok = True
    for i, name in enumerate(("backward", "forward")):
        d = a[pair - 1][i] - b[pair - 1][i]
        good = lo <= d <= hi
        print(f"pair {pair} {name} at {rpm:g} r/min: {a[pair - 1][i]:.6g} - {b[pair - 1][i]:.6g} = "
              f"{d:+.4g} Hz, expected in [{lo:g}, {hi:g}] {'ok' if good else 'FAILED'}")
        ok &= good
    return 0 if ok else 1


def check_stiffening(exe, prm_on, prm_off, prm_ksig, out, rpm):
    """Consistent stress stiffening (K_sigma with -Omega^2 K_theta) against
    none: whirl pairs 1 and 2 move by less than 0.05 Hz. K_sigma alone: pair 2
    (tilt) rises by 4..10 Hz, and rigid twist becomes a line at 1X (doc/theory.md P2)."""
    rpm = float(rpm)
    tables = {}
    for name, prm in (("on", prm_on), ("off", prm_off), ("ksig", prm_ksig)):
        run_test.run(exe, prepare(prm, out + "_" + name))
        tables[name] = rows(out + "_" + name)
    on, off, ksig = (whirl_pairs(tables[n], rpm) for n in ("on", "off", "ksig"))
    ok = True
    for p in range(2):
        for i, w in enumerate(("backward", "forward")):
            d = on[p][i] - off[p][i]
            good = abs(d) < 0.05
            print(f"consistent stiffening, pair {p + 1} {w}: {on[p][i]:.6f} - {off[p][i]:.6f} = "
                  f"{d:+.2e} Hz (|.| < 0.05) {'ok' if good else 'FAILED'}")
            ok &= good
    for i, w in enumerate(("backward", "forward")):
        d = ksig[1][i] - off[1][i]
        good = 4 <= d <= 10
        print(f"K_sigma alone, pair 2 {w}: {ksig[1][i]:.4f} - {off[1][i]:.4f} = {d:+.3f} Hz "
              f"(4..10) {'ok' if good else 'FAILED'}")
        ok &= good
    twist = [float(r["frequency_hz"]) for r in at(tables["ksig"], rpm) if r["whirl"] == "non-lateral"]
    ok &= report("K_sigma alone: torsion line at 1X [Hz]",
                 min(twist, key=lambda f: abs(f - rpm / 60)) if twist else 0.0, rpm / 60, 5e-4)
    return 0 if ok else 1


def check_loss_of_fit(exe, prm, out, body):
    run_test.run(exe, prepare(prm, out))
    log = open(os.path.join(out, "log.txt")).read()
    table = rows(out)
    last = speeds(table)[-1]
    ok = "not assembly modes" in log
    print("log says the lines are not assembly modes:", ok)
    states = {r["fit_state"] for r in at(table, last)}
    print(f"fit_state at {last:g} r/min: {states}")
    ok &= states == {"open"}
    loose = [r for r in rows(out, "rigid_modes.csv") if r["kind"] == "loose" and r["body"] == body
             and float(r["speed_rpm"]) == last]
    print(f"loose-body modes of {body} at {last:g} r/min: {len(loose)}")
    ok &= len(loose) >= 6
    # the unbalance on the loose sleeve: the shaft's bearing probes see
    # round-off (1e-24 m), which has no whirl direction; the sleeve's rim
    # probe has one; with the fit closed every probe has one
    response = rows(out, "response.csv")
    for r in response:
        rpm, probe, whirl = float(r["speed_rpm"]), r["probe"], r["whirl"]
        expected = "none" if rpm == last and probe in ("left", "right") else ("forward", "backward")
        good = whirl == expected if isinstance(expected, str) else whirl in expected
        print(f"response at {rpm:g} r/min, probe {probe}: major {r['major_m']} m, whirl {whirl} "
              f"({'ok' if good else 'FAILED'})")
        ok &= good
    ok &= len(response) > 0
    return 0 if ok else 1


def check_fixed(exe, prm, out, n_modes):
    """'fixed' ties: every speed has N_MODES whirl modes, none of them a
    loose-body mode, and the rows say fit_state as computed statically."""
    run_test.run(exe, prepare(prm, out))
    table = rows(out)
    ok = True
    for rpm in speeds(table):
        n = len(at(table, rpm))
        good = n == int(n_modes)
        print(f"{rpm:g} r/min: {n} whirl modes (expected {n_modes}) {'ok' if good else 'FAILED'}")
        ok &= good
    loose = [r for r in rows(out, "rigid_modes.csv") if r["kind"] == "loose"]
    print(f"loose-body modes: {len(loose)} (expected 0)")
    ok &= not loose
    # the assembly's first pair carries on (updated contact would jump to the
    # bare shaft's modes once the fit is open: TS 358 -> 501 Hz)
    first, last = speeds(table)[0], speeds(table)[-1]
    a, b = whirl_pairs(table, first), whirl_pairs(table, last)
    for i in range(min(len(a), len(b))):
        print(f"pair {i + 1}: {a[i]} Hz at {first:g} r/min -> {b[i]} Hz at {last:g} r/min")
    for i, w in enumerate(("backward", "forward")):
        change = (b[0][i] - a[0][i]) / a[0][i]
        good = abs(change) < 0.05
        print(f"pair 1 {w}: change {change:+.3%} from {first:g} to {last:g} r/min (|.| < 5 %) "
              f"{'ok' if good else 'FAILED'}")
        ok &= good
    return 0 if ok else 1


def rigid_counts(out):
    """Rigid-body eigenvalues per speed from rigid_modes.csv, counted in state
    space: a row with frequency > 0 stands for a conjugate pair (2), a real
    one for 1 (round-off splits a rigid motion's double zero either way)."""
    counts = {r["speed_rpm"]: 0 for r in rows(out)}
    for r in rows(out, "rigid_modes.csv"):
        if r["kind"] == "rigid":
            counts[r["speed_rpm"]] = counts.get(r["speed_rpm"], 0) + \
                (2 if float(r["frequency_hz"]) != 0 else 1)
    return counts


def check_mpi(exe, prm, out1, out2, rtol, atol):
    """campbell.csv agrees between 1 and 2 ranks, and so does the number of
    rigid-body modes, which is also the same at every speed."""
    run_test.run(exe, prepare(prm, out1), 1)
    run_test.run(exe, prepare(prm, out2), 2)
    c1, c2 = rigid_counts(out1), rigid_counts(out2)
    print("rigid-body modes per speed, 1 rank:", c1, "\n2 ranks:", c2)
    ok = c1 == c2 and len(set(c1.values())) == 1
    print("rigid-body mode count stable:", "ok" if ok else "FAILED")
    status = run_test.numdiff(os.path.join(out1, "campbell.csv"), os.path.join(out2, "campbell.csv"),
                              rtol, atol)
    return status if ok else 1


def summary_number(out, key):
    m = re.search(r"^" + re.escape(key) + r" ([-+0-9.eE]+)$",
                  open(os.path.join(out, "summary.txt")).read(), re.M)
    return float(m.group(1)) if m else None


def worst_differences(a, b, keys):
    """Largest relative differences over KEYS between the campbell.csv rows
    A and B (dicts of rows): frequency, and damping ratio where B's is above
    1e-4 in magnitude."""
    worst_f = worst_z = 0.0
    for k in keys:
        fa, fb = float(a[k]["frequency_hz"]), float(b[k]["frequency_hz"])
        za, zb = float(a[k]["damping_ratio"]), float(b[k]["damping_ratio"])
        worst_f = max(worst_f, abs(fa - fb) / abs(fb))
        if abs(zb) > 1e-4:
            worst_z = max(worst_z, abs(za - zb) / abs(zb))
    return worst_f, worst_z


def check_sweep_speeds(exe, prm, out, speeds_, freq_tol, zeta_tol, *sets):
    """Consistency of two code paths, not a reference value: the sweep of
    PRM (its static path followed through every speed before the eigen
    solves, each speed on its own segment's law) and runs of one speed each
    (SPEEDS_, comma-separated) give the same Campbell rows there (each
    frequency within FREQ_TOL relative, damping ratios above 1e-4 within
    ZETA_TOL relative). A speed handed another speed's static state fails."""
    sweep = os.path.join(out, "sweep")
    run_test.run(exe, prepare(prm, sweep, list(sets)))
    t_sweep = rows(sweep)
    ok = True
    for rpm in [float(x) for x in speeds_.split(",")]:
        alone = os.path.join(out, f"alone_{rpm:g}")
        run_test.run(exe, prepare(prm, alone, list(sets) + [f"Speeds/Start={rpm:g}",
                                                            f"Speeds/End={rpm:g}"]))
        x = {r["mode"]: r for r in at(t_sweep, rpm)}
        y = {r["mode"]: r for r in at(rows(alone), rpm)}
        ok = ok and len(y) > 0 and x.keys() == y.keys()
        worst_f, worst_z = worst_differences(x, y, x.keys() & y.keys())
        good = worst_f <= float(freq_tol) and worst_z <= float(zeta_tol)
        print(f"{rpm:g} r/min: {len(y)} modes, frequency difference {worst_f:.2e} "
              f"(tolerance {freq_tol}), damping ratio {worst_z:.2e} (tolerance {zeta_tol}) "
              f"{'ok' if good else 'FAILED'}")
        ok = ok and good
    return 0 if ok else 1


def check_reduced(exe, prm, out, freq_tol, zeta_tol, *sets):
    """Consistency of two code paths: the sweep on the reduced model
    (Eigenproblem/Reduced model = true, its own error checks) against the
    full solve at every speed. Every whirl frequency within FREQ_TOL
    (relative), every damping ratio above 1e-4 in magnitude within ZETA_TOL
    (relative), the same lines (tracked id, whirl) and critical speeds (speed
    and frequency within FREQ_TOL, damping ratio within ZETA_TOL, every one
    solved); the reduced run must have served speeds from the reduced model
    and the full one none; its largest error estimate within 10 x of the
    observed differences (above their 1e-9 print resolution). With the
    word "gram" among SETS the reduced run must have made the error
    estimates' Gram matrix (doc/theory.md 8.6); every one made must agree
    with the back-substituted estimates within 1e-2 (two code paths). With
    "tie_update" it must have served anchors on a low-rank update of an
    earlier LDL^T (doc/theory.md 8.7). On the axisymmetric model
    (Geometry/Model=axisymmetric among SETS: damped anchors per harmonic,
    doc/theory.md 14.6) rows are matched by harmonic too, the 3D anchors'
    counts are not asked, and the response (solved directly on both) must
    agree to 1e-6 of the speed's largest amplitude."""
    axisymmetric = "Geometry/Model=axisymmetric" in sets
    need_gram = "gram" in sets
    need_update = "tie_update" in sets
    sets = [x for x in sets if x not in ("gram", "tie_update")]
    full, red = os.path.join(out, "full"), os.path.join(out, "reduced")
    run_test.run(exe, prepare(prm, full, [*sets, "Eigenproblem/Reduced model=false"]))
    run_test.run(exe, prepare(prm, red, [*sets, "Eigenproblem/Reduced model=true"]))
    freq_tol, zeta_tol = float(freq_tol), float(zeta_tol)
    ok = True
    served, none = summary_number(red, "eigen.reduced_solves"), summary_number(full, "eigen.reduced_solves")
    good = served is not None and served > 0 and none == 0
    print(f"speeds served by the reduced model: {served} (full run: {none})", "ok" if good else "FAILED")
    ok &= good
    # the anchors are of the kind asked (doc/theory.md 8.7): undamped ones
    # (the default) tried at least once, damped ones alone when asked
    kind = next((x.split("=", 1)[1] for x in sets
                 if x.startswith("Eigenproblem/Reduced anchors=")),
                "damped" if axisymmetric else "undamped")
    undamped = summary_number(red, "eigen.undamped_anchors") or 0
    refused = summary_number(red, "eigen.undamped_anchors_refused") or 0
    good = undamped + refused > 0 if kind == "undamped" else undamped + refused == 0
    print(f"Reduced anchors = {kind}: {undamped} undamped anchors served their speed, {refused} "
          f"refused", "ok" if good else "FAILED")
    ok &= good
    if need_update:
        updated = summary_number(red, "eigen.undamped_anchors_on_tie_updates") or 0
        print(f"anchors on tie updates of an earlier LDL^T: {updated}",
              "ok" if updated > 0 else "FAILED")
        ok &= updated > 0
    # the estimates from the Gram matrix of the residual blocks (checked by
    # the run against back-substitutions where each is made) and the residual
    # norms from the blocks' Euclidean Gram matrix (against the vectors' at
    # its first speed)
    for count_key, difference_key, what in (
            ("eigen.estimate_gram_matrices", "eigen.estimate_gram_worst_difference",
             "Gram matrices of the residual blocks, estimates against the back-substituted ones"),
            ("eigen.residual_norms_from_gram", "eigen.residual_norm_gram_worst_difference",
             "speeds with residual norms from the Gram matrix, against the vectors'")):
        count = summary_number(red, count_key) or 0
        difference = summary_number(red, difference_key) or 0
        good = difference <= 1e-2 and (count > 0 or not need_gram)
        print(f"{what}: {count}, within {difference:.2e} (tolerance 1e-2)",
              "ok" if good else "FAILED")
        ok &= good
    key = lambda r: (r["speed_rpm"], r.get("harmonic", ""), r["mode"])
    a = {key(r): r for r in rows(red)}
    b = {key(r): r for r in rows(full)}
    good = a.keys() == b.keys()
    print(f"campbell.csv rows: {len(a)} reduced, {len(b)} full", "ok" if good else "FAILED")
    ok &= good
    worst_f, worst_z = worst_differences(a, b, a.keys() & b.keys())
    labels = sum((a[k]["whirl"], a[k]["tracked_id"]) != (b[k]["whirl"], b[k]["tracked_id"])
                 for k in a.keys() & b.keys())
    for name, got, tol in (("frequency", worst_f, freq_tol), ("damping ratio", worst_z, zeta_tol)):
        print(f"largest relative {name} difference {got:.3e} (tolerance {tol:g})",
              "ok" if got <= tol else "FAILED")
        ok &= got <= tol
    # the error estimate keeps its promise: |d lambda| / |lambda| <= Reduced
    # tolerance, so frequencies (relative) and damping ratios (absolute)
    # within 10 x that (the estimate is first-order accurate)
    promised = float(next((x.split("=", 1)[1] for x in sets
                           if x.startswith("Eigenproblem/Reduced tolerance=")), "1e-7"))
    worst_dz = max(abs(float(a[k]["damping_ratio"]) - float(b[k]["damping_ratio"]))
                   for k in a.keys() & b.keys())
    good = worst_f <= 10 * promised and worst_dz <= 10 * promised
    print(f"against the Reduced tolerance {promised:g}: frequency {worst_f:.3e}, damping ratio "
          f"{worst_dz:.3e} absolute (limit {10 * promised:g})", "ok" if good else "FAILED")
    ok &= good
    # and it is sharp: a first-order estimate of |d lambda| / |lambda| is of
    # the size of the observed differences, within 10 x, above campbell.csv's
    # resolution (10 significant digits: 1e-9). An estimate far above them
    # (wrong left vectors, say) would refuse speeds the reduced model serves.
    # The sweep's speeds only, whose rows are compared: a critical speed's
    # checked solve may hold two lines within each other's damping (the
    # tutorial disk at 20,562.6 r/min: 342.71 and 342.96 Hz, damping 11 Hz),
    # whose estimates carry the pair's condition (7.5e-8 from a backward
    # error of 3.3e-12, on the anchor's own basis)
    estimate = summary_number(red, "eigen.sweep_worst_error_estimate")
    observed = max(worst_f, worst_dz, 1e-9)
    good = estimate is not None and estimate <= 10 * observed
    print(f"largest error estimate {estimate} against the observed {observed:.3e} (floor 1e-9): "
          f"within 10 x", "ok" if good else "FAILED")
    ok &= good
    print(f"rows with another whirl or line: {labels}", "ok" if labels == 0 else "FAILED")
    ok &= labels == 0
    ca, cb = rows(red, "critical_speeds.csv"), rows(full, "critical_speeds.csv")
    good = len(ca) == len(cb)
    print(f"critical speeds: {len(ca)} reduced, {len(cb)} full", "ok" if good else "FAILED")
    ok &= good
    for x, y in zip(ca, cb):
        d_rpm = abs(float(x["speed_rpm"]) - float(y["speed_rpm"])) / float(y["speed_rpm"])
        d_f = abs(float(x["frequency_hz"]) - float(y["frequency_hz"])) / float(y["frequency_hz"])
        zb = float(y["damping_ratio"])
        d_z = abs(float(x["damping_ratio"]) - zb) / abs(zb) if abs(zb) > 1e-4 else 0.0
        good = d_rpm <= freq_tol and d_f <= freq_tol and d_z <= zeta_tol and \
            x["solved"] == "1" and y["solved"] == "1" and x["whirl"] == y["whirl"]
        print(f"line {x['tracked_id']} {x['whirl']} {x['order']}X: {x['speed_rpm']} vs "
              f"{y['speed_rpm']} r/min ({d_rpm:.2e}), frequency {d_f:.2e}, damping {d_z:.2e}, "
              f"solved {x['solved']}/{y['solved']}", "ok" if good else "FAILED")
        ok &= good
    if os.path.exists(os.path.join(full, "response.csv")):
        # the unbalance response on the reduced model's basis against the one
        # on the speed's modes: complex amplitudes within 1e-6 of the speed's
        # largest (both meet a residual of 1e-8)
        ra, rb = rows(red, "response.csv"), rows(full, "response.csv")
        good = len(ra) == len(rb) and all(x["converged"] == y["converged"] == "1"
                                          for x, y in zip(ra, rb))
        print(f"response.csv rows: {len(ra)} reduced, {len(rb)} full, all converged",
              "ok" if good else "FAILED")
        ok &= good
        amp = lambda r, c: cmath.rect(float(r[f"amplitude_{c}_m"]),
                                      -math.radians(float(r[f"phase_{c}_deg"])))
        largest, worst = {}, 0.0
        for y in rb:
            largest[y["speed_rpm"]] = max(largest.get(y["speed_rpm"], 0.0),
                                          abs(amp(y, "x")), abs(amp(y, "y")))
        for x, y in zip(ra, rb):
            if largest[y["speed_rpm"]] > 0:
                worst = max(worst, *(abs(amp(x, c) - amp(y, c)) / largest[y["speed_rpm"]]
                                     for c in "xy"))
        served = summary_number(red, "response.reduced_speeds")
        good = worst <= 1e-6 and served is not None and served > 0
        print(f"response: largest complex amplitude difference {worst:.3e} of the speed's "
              f"largest (tolerance 1e-6); speeds solved on the reduced basis: {served}",
              "ok" if good else "FAILED")
        ok &= good
        # the kept columns' D and K products from the speed's affine share:
        # used, and never refused by the sparse products' check (a share
        # that does not follow the matrices is refused there)
        if axisymmetric:
            return finish_onsets(red, full, freq_tol, ok)
        shared = summary_number(red, "response.kept_products_speeds")
        refused = summary_number(red, "response.kept_products_refused")
        mismatch = summary_number(red, "response.kept_products_worst_mismatch")
        good = shared is not None and shared > 0 and refused == 0 and mismatch <= 1e-6
        print(f"response: {shared} speeds with the kept products' affine share, "
              f"largest mismatch {mismatch} (tolerance 1e-6), refused {refused}",
              "ok" if good else "FAILED")
        ok &= good
    return finish_onsets(red, full, freq_tol, ok)


def finish_onsets(red, full, freq_tol, ok):
    """check_reduced's last part: the same stability onsets (speed within
    FREQ_TOL, each converged); the exit code with the earlier checks' OK."""
    oa, ob = rows(red, "stability_onsets.csv"), rows(full, "stability_onsets.csv")
    good = len(oa) == len(ob)
    print(f"stability onsets: {len(oa)} reduced, {len(ob)} full", "ok" if good else "FAILED")
    ok &= good
    for x, y in zip(oa, ob):
        d = abs(float(x["onset_rpm"]) - float(y["onset_rpm"])) / float(y["onset_rpm"])
        good = d <= freq_tol and x["converged"] == y["converged"] == "1"
        print(f"onset of line {x['tracked_id']}: {x['onset_rpm']} vs {y['onset_rpm']} r/min "
              f"({d:.2e})", "ok" if good else "FAILED")
        ok &= good
    return 0 if ok else 1


def check_reduced_fallback(exe, prm, out, freq_tol, zeta_tol, *sets):
    """check_reduced where an undamped anchor cannot serve its speed: at
    least one is refused and its speed solved in full (the damped anchor),
    and the sweep still equals the full one."""
    status = check_reduced(exe, prm, out, freq_tol, zeta_tol, *sets)
    red = os.path.join(out, "reduced")
    refused = summary_number(red, "eigen.undamped_anchors_refused") or 0
    full = summary_number(red, "eigen.full_solves") or 0
    good = refused > 0 and full >= refused
    print(f"undamped anchors refused: {refused}, damped full solves: {full}",
          "ok" if good else "FAILED")
    return status if good else 1


def check_failure(exe, prm, out, text):
    args = prepare(prm, out)
    env = dict(os.environ)
    r = subprocess.run([exe] + args, env=env, capture_output=True, text=True)
    print(r.stdout[-2000:], r.stderr[-2000:])
    ok = r.returncode == 2 and text in r.stdout
    print(f"exit code {r.returncode} (expected 2), message found: {text in r.stdout}")
    kept = [x for x in rows(out)]
    print(f"campbell.csv keeps {len(kept)} rows of the speeds done")
    ok &= "Stacktrace" not in r.stdout + r.stderr
    # the failure is in summary.txt (status, where, why) and in the picture's
    # title; campbell.csv's rows are those of the finished speeds only
    status = dict(l.rstrip("\n").split(" ", 1) for l in open(os.path.join(out, "summary.txt"))
                  if l.startswith("run."))
    print("summary.txt:", status)
    ok &= status.get("run.status") == "failed" and status.get("run.exit_code") == "2"
    ok &= "r/min" in status.get("run.stopped_at", "") and text in status.get("run.message", "")
    done = {x["speed_rpm"] for x in kept}
    finished = re.search(r"(\d+) (?:of \d+ )?speeds finished", status.get("run.stopped_at", ""))
    print("speeds in campbell.csv:", len(done), "; finished per summary.txt:",
          finished.group(1) if finished else None)
    ok &= finished is not None and int(finished.group(1)) == len(done)
    return 0 if ok else 1


def check_history(exe, prm, out, rpm, tol, before, short):
    """Consistency (two paths): the modes at RPM after the speeds BEFORE
    (each in the opening band: a contact state of its own, so the stiffness
    K + K_sigma(u_I) has been updated by K_sigma(u_I' - u_I) at each, doc/theory.md
    section 3) against a run of the speeds SHORT, RPM (fewer updates), within
    TOL (relative). (A run of RPM alone is no reference: its contact solve
    from rest can end in another closed set, 98 against 101 of 184 pairs on
    the tutorial disk at 16,500 r/min.)"""
    sets = ("Output/ParaView speeds=none", "Speeds/Mode=list")
    run_test.run(exe, prepare(prm, out, sets + (f"Speeds/List={before}, {rpm}",)))
    run_test.run(exe, prepare(prm, out + "_alone", sets + (f"Speeds/List={short}, {rpm}",)))
    a, b = at(rows(out), float(rpm)), at(rows(out + "_alone"), float(rpm))
    ok = len(a) == len(b) and len(a) > 0
    worst = 0.
    for x, y in zip(a, b):
        for key in ("frequency_hz", "damping_ratio"):
            d = abs(float(x[key]) - float(y[key])) / abs(float(y[key]))
            worst = max(worst, d)
            ok &= x["whirl"] == y["whirl"] and d <= float(tol)
    print(f"{rpm} r/min after {before}: {len(a)} modes against {len(b)} after {short}, "
          f"largest relative difference {worst:.2e} (tolerance {tol}):", "ok" if ok else "FAILED")
    return 0 if ok else 1


def check_models(exe, prm, out, ftol, ztol, *sets):
    """PRM (a harmonic-model case) against the 3D section mesher's hexahedra
    on the same meridian (Geometry/Model=3d, the --set SETS on both): per
    speed the same number of modes, whirl for whirl, frequencies within FTOL
    relative and damping ratios within ZTOL absolute (consistency: the
    harmonic model is the hexahedra's limit in the cells around)."""
    run_test.run(exe, prepare(prm, out, sets))
    run_test.run(exe, prepare(prm, out + "_3d", sets + ("Geometry/Model=3d",
                 "Geometry/Sections/Circumferential cells=32")))
    a, b = rows(out), rows(out + "_3d")
    ok = True
    for rpm in speeds(b):
        x = sorted(at(a, rpm), key=lambda r: float(r["frequency_hz"]))
        y = sorted((r for r in at(b, rpm) if r["whirl"] != "non-lateral"),
                   key=lambda r: float(r["frequency_hz"]))
        x = [r for r in x if r["whirl"] != "non-lateral"][:len(y)]
        good = len(x) == len(y) > 0
        df = max((abs(float(p["frequency_hz"]) / float(q["frequency_hz"]) - 1) for p, q in zip(x, y)), default=1)
        dz = max((abs(float(p["damping_ratio"]) - float(q["damping_ratio"])) for p, q in zip(x, y)), default=1)
        same = all(p["whirl"] == q["whirl"] for p, q in zip(x, y))
        good &= df <= float(ftol) and dz <= float(ztol) and same
        print(f"{rpm:g} r/min: {len(x)} lateral modes against {len(y)}, frequency {df:.2e} "
              f"(tolerance {ftol}), damping ratio {dz:.2e} ({ztol}), whirl {'equal' if same else 'DIFFERENT'}:",
              "ok" if good else "FAILED")
        ok &= good
    return 0 if ok else 1


if __name__ == "__main__":
    mode, args = sys.argv[1], sys.argv[2:]
    expected, write = None, False
    if "--expected" in args or "--write-expected" in args:
        flag = "--expected" if "--expected" in args else "--write-expected"
        i = args.index(flag)
        expected, write = args[i + 1], flag == "--write-expected"
        args = args[:i] + args[i + 2:]
    checks = {"timoshenko": check_timoshenko, "rigid_rotor": check_rigid_rotor,
              "models": check_models,
              "free_spin": check_free_spin, "pair_shift": check_pair_shift,
              "loss_of_fit": check_loss_of_fit, "fixed": check_fixed,
              "stiffening": check_stiffening, "bearing_table": check_bearing_table,
              "unbalance": check_unbalance, "stability_onset": check_stability_onset,
              "torsion_crossing": check_torsion_crossing,
              "ring_symmetry": check_ring_symmetry, "study": check_study,
              "refinement": check_refinement, "refinement_modal": check_refinement_modal,
              "fit_edge": check_fit_edge,
              "doublets": check_doublets, "rigid_rows": check_rigid_rows,
              "locking": check_locking, "asymmetry": check_asymmetry, "mpi": check_mpi, "failure": check_failure,
              "reduced": check_reduced, "reduced_fallback": check_reduced_fallback,
              "sweep_speeds": check_sweep_speeds, "history": check_history}
    if mode not in checks:
        sys.exit(f"unknown mode {mode}")
    status = checks[mode](*args)
    if expected:
        # OUT is the third argument of every mode that has references
        if not expected_output(expected, args[2], mode, write):
            status = 1
    sys.exit(status)
