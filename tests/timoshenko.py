#!/usr/bin/env python3
"""Closed-form rotordynamics references (doc/theory.md 10c/10d), pure Python (no numpy/scipy).

* free-free bending frequencies of a uniform solid circular cylinder, Timoshenko beam
  theory with the Cowper shear coefficient (doc/theory.md 10c), and the Euler-Bernoulli values;
* rigid rotor on two identical isotropic bearings (doc/theory.md 10d) and solid-cylinder inertia.

Usage: timoshenko.py E nu rho R L [n]   -> first n (default 2) bending frequencies in Hz
       timoshenko.py --selftest         -> reproduce the doc/theory.md 10c example (steel, R=50 mm, L=1 m)
"""
import cmath
import math
import sys

BETA_L_EB = (4.730040745, 7.853204624, 10.99560784, 14.13716549)


def eb_beta_l(n):
    """n-th (1-based) free-free Euler-Bernoulli root beta_n L (asymptotic beyond the table)."""
    return BETA_L_EB[n - 1] if n <= len(BETA_L_EB) else (2 * n + 1) * math.pi / 2


def euler_bernoulli(E, rho, R, L, n=2):
    """First n free-free Euler-Bernoulli bending frequencies [rad/s]."""
    return [eb_beta_l(k) ** 2 * R / (2 * L**2) * math.sqrt(E / rho) for k in range(1, n + 1)]


def _det(m):
    """Determinant by Gaussian elimination with partial pivoting (m is modified)."""
    n, d = len(m), 1.0
    for j in range(n):
        p = max(range(j, n), key=lambda i: abs(m[i][j]))
        if m[p][j] == 0.0:
            return 0.0
        if p != j:
            m[j], m[p], d = m[p], m[j], -d
        d *= m[j][j]
        for i in range(j + 1, n):
            f = m[i][j] / m[j][j]
            m[i] = [x - f * y for x, y in zip(m[i], m[j])]
    return d


def frequency_determinant(omega, E, nu, rho, R, L):
    """Row-scaled determinant of the free-free Timoshenko frequency matrix D(omega)."""
    A, I = math.pi * R**2, math.pi * R**4 / 4
    kG = 6 * (1 + nu) / (7 + 6 * nu) * E / (2 * (1 + nu))
    w2 = omega * omega
    c = rho * w2 / kG
    P = rho * I * w2 * (1 + E / kG)
    Q = rho * A * w2 - rho**2 * I * w2 * w2 / kG
    if Q <= 0:
        raise ValueError("omega above the Timoshenko validity limit sqrt(kappa G A/(rho I))")
    s = math.sqrt(P * P + 4 * E * I * Q)
    al, be = math.sqrt((-P + s) / (2 * E * I)), math.sqrt((P + s) / (2 * E * I))
    a, b = al + c / al, be - c / be
    ch, sh, co, si = math.cosh(al * L), math.sinh(al * L), math.cos(be * L), math.sin(be * L)
    D = [[a * al, 0.0, -b * be, 0.0],
         [0.0, al - a, 0.0, be - b],
         [a * al * ch, a * al * sh, -b * be * co, -b * be * si],
         [(al - a) * sh, (al - a) * ch, -(be - b) * si, (be - b) * co]]
    return _det([[x / max(abs(y) for y in row) for x in row] for row in D])


def timoshenko(E, nu, rho, R, L, n=2):
    """First n nonzero free-free Timoshenko bending frequencies [rad/s] (scan + bisection)."""
    f = lambda w: frequency_determinant(w, E, nu, rho, R, L)
    kG = 6 * (1 + nu) / (7 + 6 * nu) * E / (2 * (1 + nu))
    w_max = math.sqrt(kG * math.pi * R**2 / (rho * math.pi * R**4 / 4)) * (1 - 1e-9)
    eb = euler_bernoulli(E, rho, R, L, n)
    step = eb[0] / 400
    roots, lo = [], 0.01 * eb[0]          # start well above the rigid-body zero
    flo = f(lo)
    while len(roots) < n:
        hi = min(lo + step, w_max)
        if hi <= lo:
            raise ValueError(f"only {len(roots)} roots below the validity limit {w_max:.6g} rad/s")
        fhi = f(hi)
        if flo * fhi < 0:
            a, b, fa = lo, hi, flo
            while b - a > 1e-13 * b:
                m = 0.5 * (a + b)
                fm = f(m)
                if fa * fm <= 0:
                    b = m
                else:
                    a, fa = m, fm
            root = 0.5 * (a + b)
            # a genuine root: |det| tiny compared with the bracket ends (rejects jumps/poles)
            if abs(f(root)) < 1e-6 * max(abs(flo), abs(fhi)):
                roots.append(root)
        lo, flo = hi, fhi
    for k, (wt, we) in enumerate(zip(roots, eb), 1):   # cross-check: Timoshenko below EB
        if wt > we * (1 + 1e-9):
            print(f"warning: Timoshenko mode {k} {wt:.6g} vs Euler-Bernoulli {we:.6g} rad/s",
                  file=sys.stderr)
    return roots


def cylinder_inertia(rho, R, L):
    """Solid cylinder: (mass, polar moment Ip, diametral moment Id about the centre)."""
    m = rho * math.pi * R**2 * L
    return m, m * R**2 / 2, m * (3 * R**2 + L**2) / 12


def rigid_rotor(m, Ip, Id, k, Lb, Omega):
    """Rigid rotor on two isotropic bearings k at z = +-Lb/2, spin Omega [rad/s]:
    (translation, tilt forward, tilt backward) natural frequencies [rad/s]."""
    kt = 2 * k * (Lb / 2) ** 2
    g = Omega * Ip / (2 * Id)
    r = math.sqrt(g * g + kt / Id)
    return math.sqrt(2 * k / m), g + r, -g + r


def rigid_rotor_damped_critical(m, Ip, Id, k, c, Lb):
    """The same rotor with damping c at each bearing: the speeds [rad/s] where the damped
    translation, backward tilt and forward tilt (None if Id <= Ip) frequencies equal the
    speed (1X crossings). Translation: m z'' + 2c z' + 2k z = 0; tilt, psi = theta_x +
    i theta_y: Id psi'' + (c_t - i Ip Omega) psi' + k_t psi = 0, c_t = 2 c (Lb/2)^2,
    forward roots Im > 0, backward Im < 0; each crossing by bisection."""
    kt, ct = 2 * k * (Lb / 2) ** 2, 2 * c * (Lb / 2) ** 2
    translation = math.sqrt(2 * k / m - (c / m) ** 2)

    def tilt(Omega, sign):
        b = complex(ct, -Ip * Omega)
        d = cmath.sqrt(b * b - 4 * Id * kt)
        roots = [(-b + d) / (2 * Id), (-b - d) / (2 * Id)]
        return max(sign * r.imag for r in roots)   # the frequency of that whirl

    def crossing(sign):
        lo, hi = 0.0, 10 * math.sqrt(kt / abs(Id - Ip)) if Id != Ip else 1e9
        if tilt(hi, sign) - hi > 0:
            return None
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if tilt(mid, sign) - mid > 0 else (lo, mid)
        return 0.5 * (lo + hi)
    return translation, crossing(-1), crossing(+1) if Id > Ip else None


def selftest():
    E, nu, rho, R, L = 210e9, 0.3, 7850.0, 0.05, 1.0
    ref = (2819.44, 7440.15, 13789.6)
    ok = True
    print("Timoshenko free-free, steel E=210 GPa nu=0.3 rho=7850 R=50 mm L=1 m [rad/s]:")
    for k, (w, wr, we) in enumerate(zip(timoshenko(E, nu, rho, R, L, 3), ref,
                                        euler_bernoulli(E, rho, R, L, 3)), 1):
        good = f"{w:.5g}" == f"{wr:.5g}"
        ok &= good
        print(f"  mode {k}: {w:.6f} (ref {wr}, EB {we:.6g}, {w / (2 * math.pi):.6g} Hz) "
              f"{'ok' if good else 'MISMATCH'}")
    m, Ip, Id = cylinder_inertia(rho, R, L)
    print(f"cylinder: m={m:.6g} kg Ip={Ip:.6g} Id={Id:.6g} kg m^2")
    for Om in (0.0, 300.0, 1500.0):
        wt, wf, wb = rigid_rotor(m, Ip, Id, 1e7, 0.8, Om)
        ok &= abs(wf * wb - 2 * 1e7 * 0.4**2 / Id) < 1e-9 * wf * wb    # product = kt/Id
        print(f"rigid rotor k=1e7 N/m Lb=0.8 m Omega={Om:g}: translation {wt:.6g} "
              f"FW {wf:.6g} BW {wb:.6g} rad/s")
    print("selftest", "passed" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    if sys.argv[1:] == ["--selftest"]:
        sys.exit(selftest())
    if len(sys.argv) not in (6, 7):
        sys.exit("usage: timoshenko.py E nu rho R L [n] | --selftest")
    E, nu, rho, R, L = (float(x) for x in sys.argv[1:6])
    n = int(sys.argv[6]) if len(sys.argv) == 7 else 2
    try:
        roots = timoshenko(E, nu, rho, R, L, n)
    except ValueError as e:
        sys.exit(f"timoshenko.py: {e}")
    for w in roots:
        print(f"{w / (2 * math.pi):.9g}")
