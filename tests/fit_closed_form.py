#!/usr/bin/env python3
"""Closed-form shrink fit of a shaft (solid, or hollow with bore radius a) in a hub (b..c),
both thin disks (plane stress), spinning at Omega (doc/theory.md 10f): the contact pressure,
the friction capacity, the bore stresses of hub and shaft (radial, hoop, von Mises), the loss
of fit, the slip speed, DIN 7190's mounting temperature, all from the Lame solution of a
rotating annular disk,

    u(r) = A r + B / r - (1 - nu^2) rho Omega^2 r^3 / (8 E),

with the radial stress zero on the free radii and -p on the fit, and the fit's compatibility
u_hub(b) - u_shaft(b) = delta_eff, where delta_eff = delta - b (alpha_h dT_h - alpha_s dT_s)
(free thermal expansion of each body, u = alpha dT r, is stress-free).

Usage: fit_closed_form.py a b c L delta Es nus rhos Eh nuh rhoh [options]
  --mu MU --torque T --axial F       friction coefficient, loads to carry
  --rpm R1,R2,...                    speeds to print (default 0)
  --alpha-s A --alpha-h A --dT-s K --dT-h K   expansion coefficients and temperature rises
  --clearance RATIO                  DIN 7190 assembly clearance / diameter (default 0.001)
Prints "key value" lines (SI units)."""
import argparse
import math


def disk(a, c, E, nu, rho, w2, p_in, p_out):
    """A, B of u = A r + B/r - k r^3 for an annulus a..c (a = 0: solid, B = 0) with
    sigma_r(a) = -p_in, sigma_r(c) = -p_out."""
    k = (1 - nu**2) * rho * w2 / (8 * E)
    f = E / (1 - nu**2)
    # sigma_r = f [(1+nu) A - (1-nu) B / r^2 - (3+nu) k r^2]
    if a == 0:
        A = (-p_out / f + (3 + nu) * k * c**2) / (1 + nu)
        return A, 0.0, k
    # two equations in A, B
    m = [[(1 + nu), -(1 - nu) / a**2], [(1 + nu), -(1 - nu) / c**2]]
    r = [-p_in / f + (3 + nu) * k * a**2, -p_out / f + (3 + nu) * k * c**2]
    det = m[0][0] * m[1][1] - m[0][1] * m[1][0]
    A = (r[0] * m[1][1] - m[0][1] * r[1]) / det
    B = (m[0][0] * r[1] - r[0] * m[1][0]) / det
    return A, B, k


def stresses(A, B, k, E, nu, r):
    f = E / (1 - nu**2)
    u = A * r + (B / r if r > 0 else 0) - k * r**3
    du = A - (B / r**2 if r > 0 else 0) - 3 * k * r**2
    ur = u / r if r > 0 else du
    sr = f * (du + nu * ur)
    st = f * (ur + nu * du)
    vm = math.sqrt(sr**2 + st**2 - sr * st)
    return u, sr, st, vm


def fit(args, w2, delta):
    """Pressure and bore stresses at Omega^2 = w2 (p < 0: the fit would pull; open)."""
    a, b, c = args.a, args.b, args.c
    # u at b is affine in p: solve u_h(b) - u_s(b) = delta
    def gap(p):
        As, Bs, ks = disk(a, b, args.Es, args.nus, args.rhos, w2, 0.0, p)
        Ah, Bh, kh = disk(b, c, args.Eh, args.nuh, args.rhoh, w2, p, 0.0)
        return (stresses(Ah, Bh, kh, args.Eh, args.nuh, b)[0]
                - stresses(As, Bs, ks, args.Es, args.nus, b)[0] - delta)
    g0, g1 = gap(0.0), gap(1.0)
    p = -g0 / (g1 - g0)
    As, Bs, ks = disk(a, b, args.Es, args.nus, args.rhos, w2, 0.0, p)
    Ah, Bh, kh = disk(b, c, args.Eh, args.nuh, args.rhoh, w2, p, 0.0)
    hub = stresses(Ah, Bh, kh, args.Eh, args.nuh, b)
    shaft = stresses(As, Bs, ks, args.Es, args.nus, a)
    return p, hub, shaft


def main():
    ap = argparse.ArgumentParser()
    for n in ("a", "b", "c", "L", "delta", "Es", "nus", "rhos", "Eh", "nuh", "rhoh"):
        ap.add_argument(n, type=float)
    ap.add_argument("--mu", type=float, default=0.0)
    ap.add_argument("--torque", type=float, default=0.0)
    ap.add_argument("--axial", type=float, default=0.0)
    ap.add_argument("--rpm", default="0")
    ap.add_argument("--alpha-s", type=float, default=0.0)
    ap.add_argument("--alpha-h", type=float, default=0.0)
    ap.add_argument("--dT-s", type=float, default=0.0)
    ap.add_argument("--dT-h", type=float, default=0.0)
    ap.add_argument("--clearance", type=float, default=1e-3)
    args = ap.parse_args()
    delta = args.delta - args.b * (args.alpha_h * args.dT_h - args.alpha_s * args.dT_s)
    area = 2 * math.pi * args.b * args.L
    print(f"radial_interference_effective_m {delta:.10g}")
    if delta <= 0:
        print("loose_at_rest 1\nloss_of_fit_rpm 0")
        return
    p0 = fit(args, 0.0, delta)[0]
    # p is affine in Omega^2: the loss of fit where it vanishes (the slope
    # taken over 1e6 rad^2/s^2, far above the rounding of p)
    W = 1e6
    p1 = fit(args, W, delta)[0]
    w_loss = W * p0 / (p0 - p1)
    print(f"loss_of_fit_rpm {math.sqrt(w_loss) * 30 / math.pi:.10g}")
    if args.mu > 0 and (args.torque > 0 or args.axial > 0):
        # safety 1/hypot(T/(mu p A b), F/(mu p A)) = 1 where p = p_slip
        p_slip = math.hypot(args.torque / args.b, args.axial) / (args.mu * area)
        w_slip = W * (p0 - p_slip) / (p0 - p1)
        print(f"slip_rpm {math.sqrt(max(w_slip, 0)) * 30 / math.pi:.10g}")
    for rpm in (float(x) for x in args.rpm.split(",")):
        w2 = (rpm * math.pi / 30) ** 2
        p, hub, shaft = fit(args, w2, delta)
        tag = f"{rpm:g}rpm"
        print(f"pressure_{tag}_Pa {p:.10g}")
        print(f"torque_capacity_{tag}_Nm {args.mu * p * area * args.b:.10g}")
        print(f"axial_capacity_{tag}_N {args.mu * p * area:.10g}")
        print(f"hub_bore_hoop_{tag}_Pa {hub[2]:.10g}")
        print(f"hub_bore_von_mises_{tag}_Pa {hub[3]:.10g}")
        print(f"shaft_bore_hoop_{tag}_Pa {shaft[2]:.10g}")
        print(f"shaft_bore_von_mises_{tag}_Pa {shaft[3]:.10g}")
    if args.alpha_h > 0:
        # DIN 7190: hub heated until its bore clears the shaft by the assembly clearance
        U = 2 * args.delta
        d = 2 * args.b
        print(f"mounting_temperature_above_reference_K {(U + args.clearance * d) / (args.alpha_h * d):.10g}")


if __name__ == "__main__":
    main()
