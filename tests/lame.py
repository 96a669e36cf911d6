#!/usr/bin/env python3
"""Closed-form shrink-fit references (doc/theory.md 10a/10b): contact pressure at rest
and loss-of-fit speed of a solid shaft (radius b) in a hub (b..c), plane stress
and plane strain; and the plane-strain loss of fit with spin softening (the
centrifugal load on the deformed radius, rho Omega^2 (r + u)), from the exact
Bessel-function solution u = -r + A J1(beta r) + B Y1(beta r),
beta^2 = rho Omega^2 / (lambda + 2 mu). Prints the numbers the tests compare against.
Usage: lame.py b c delta Es nus rhos Eh nuh rhoh"""
import math
import sys


def lame(b, c, delta, Es, nus, rhos, Eh, nuh, rhoh):
    C_ps = b * (1 / Eh * ((c**2 + b**2) / (c**2 - b**2) + nuh) + (1 - nus) / Es)
    C_pe = b * ((1 + nuh) / Eh * (c**2 + (1 - 2 * nuh) * b**2) / (c**2 - b**2)
                + (1 + nus) * (1 - 2 * nus) / Es)
    w_ps = 4 * delta / (b * (rhoh / Eh * ((3 + nuh) * c**2 + (1 - nuh) * b**2)
                             - rhos / Es * (1 - nus) * b**2))
    w_pe = 4 * delta / (b * (rhoh * (1 + nuh) / Eh * ((3 - 2 * nuh) * c**2 + (1 - 2 * nuh) * b**2)
                             - rhos * (1 + nus) * (1 - 2 * nus) / Es * b**2))
    rpm = lambda w2: math.sqrt(w2) * 60 / (2 * math.pi)
    return {"pressure_plane_stress_Pa": delta / C_ps,
            "pressure_plane_strain_Pa": delta / C_pe,
            "loss_of_fit_plane_stress_rpm": rpm(w_ps),
            "loss_of_fit_plane_strain_rpm": rpm(w_pe)}


# Bessel functions J1, Y1 and their derivatives by their power series (the
# arguments here are below 0.1: a few terms reach round-off)
def j1(x):
    s = ds = 0.0
    for k in range(30):
        c = (-1) ** k / (math.factorial(k) * math.factorial(k + 1))
        s += c * (x / 2) ** (2 * k + 1)
        ds += c * (2 * k + 1) / 2 * (x / 2) ** (2 * k)
    return s, ds

def y1(x):
    j, dj = j1(x)
    s = ds = 0.0
    psi = [-0.5772156649015329]
    for n in range(1, 32):
        psi.append(psi[-1] + 1 / n)
    for k in range(30):
        c = (-1) ** k * (psi[k] + psi[k + 1]) / (math.factorial(k) * math.factorial(k + 1))
        s += c * (x / 2) ** (2 * k + 1)
        ds += c * (2 * k + 1) / 2 * (x / 2) ** (2 * k)
    y = -2 / (math.pi * x) + 2 / math.pi * math.log(x / 2) * j - s / math.pi
    dy = 2 / (math.pi * x * x) + 2 / math.pi * (j / x + math.log(x / 2) * dj) - ds / math.pi
    return y, dy
def solve4(A, b):
    n = len(b)
    M = [row[:] + [bi] for row, bi in zip(A, b)]
    for i in range(n):
        p = max(range(i, n), key=lambda r: abs(M[r][i]))
        M[i], M[p] = M[p], M[i]
        for r in range(i + 1, n):
            f = M[r][i] / M[i][i]
            for c in range(i, n + 1):
                M[r][c] -= f * M[i][c]
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (M[i][n] - sum(M[i][c] * x[c] for c in range(i + 1, n))) / M[i][i]
    return x

def lame_consts(E, nu):
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    return lam, mu

def pressure_plane_strain(b, c, delta, Es, nus, rhos, Eh, nuh, rhoh, omega, softening):
    """contact pressure of the plane-strain shrink fit at omega [rad/s]"""
    def basis(E, nu, rho, r):
        # returns list of (u, sigma_r) for [particular, hom1, hom2]
        lam, mu = lame_consts(E, nu)
        beta2 = rho * omega**2 / (lam + 2 * mu)
        out = []
        if softening and beta2 > 0:
            beta = math.sqrt(beta2)
            funcs = [(-r, -1.0)]
            j, dj = j1(beta * r); y, dy = y1(beta * r)
            funcs += [(j, beta * dj), (y, beta * dy)]
        else:
            funcs = [(-beta2 * r**3 / 8, -3 * beta2 * r**2 / 8), (r, 1.0), (1 / r, -1 / r**2)]
        return [(u, (lam + 2 * mu) * du + lam * u / r) for u, du in funcs]
    # unknowns: A_s (hom1 shaft), A_h, B_h, p
    sb = basis(Es, nus, rhos, b)
    hb = basis(Eh, nuh, rhoh, b)
    hc = basis(Eh, nuh, rhoh, c)
    A = [[0, hc[1][1], hc[2][1], 0],          # sigma_r hub(c) = 0
         [0, hb[1][1], hb[2][1], 1],          # sigma_r hub(b) = -p
         [sb[1][1], 0, 0, 1],                 # sigma_r shaft(b) = -p
         [-sb[1][0], hb[1][0], hb[2][0], 0]]  # u_h - u_s = delta
    rhs = [-hc[0][1], -hb[0][1], -sb[0][1], delta - hb[0][0] + sb[0][0]]
    return solve4(A, rhs)[3]

def loss_of_fit_rpm(args, softening):
    """Speed [r/min] at which the plane-strain contact pressure vanishes."""
    lo, hi = 1.0, 1e6
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        if pressure_plane_strain(*args, mid, softening) > 0: lo = mid
        else: hi = mid
    return lo * 30 / math.pi


if __name__ == "__main__":
    args = [float(a) for a in sys.argv[1:]] or [0.01, 0.04, 3e-6, 205e9, 0.3, 7850, 68.9e9, 0.33, 2700]
    for k, v in lame(*args).items():
        print(f"{k} {v:.6g}")
    print(f"loss_of_fit_plane_strain_spin_softening_rpm {loss_of_fit_rpm(args, True):.8g}")
