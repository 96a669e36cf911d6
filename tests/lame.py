#!/usr/bin/env python3
"""Closed-form shrink-fit references (THEORY 10a/10b): contact pressure at rest
and loss-of-fit speed of a solid shaft (radius b) in a hub (b..c), plane stress
and plane strain. Prints the numbers the tests compare against.
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


if __name__ == "__main__":
    args = [float(a) for a in sys.argv[1:]] or [0.01, 0.04, 3e-6, 205e9, 0.3, 7850, 68.9e9, 0.33, 2700]
    for k, v in lame(*args).items():
        print(f"{k} {v:.6g}")
