#!/usr/bin/env python3
"""Euler elastica of a cantilever under a dead transverse end load: the reference for
configs/cantilever_strip_3d.yaml (the cantilever strip of Sze, Liu & Lo 2004, problem 3.1).

Sample run:
    python3 bench/solid/elastica.py                 # L = 10, EI = 100, P = 4 (PL^2/EI = 4)
    python3 bench/solid/elastica.py --load 1 2 3 4

The beam lies on [0, L] along x, clamped at x = 0, loaded at its tip by P along +y (a dead
load: it keeps its direction). With theta the slope angle along the arc length s:
    x' = cos theta,  y' = sin theta,  EI theta'' = -P cos theta,
    theta(0) = 0,    theta'(L) = 0   (no moment at the tip).
Shooting on the root curvature theta'(0) (bisection, classical Runge-Kutta with N steps, the
result checked against N/2: the printed digits are converged). Inextensible, no shear: the
limit of a thin strip (h/L = 0.01 there) with nu = 0.
"""
import argparse
import math


def integrate(kappa0, alpha, length, steps):
    """Returns (x, y, theta, kappa) at s = L for theta'(0) = kappa0, alpha = P/EI."""
    h = length / steps

    def f(state):
        x, y, th, k = state
        return (math.cos(th), math.sin(th), k, -alpha * math.cos(th))

    s = (0.0, 0.0, 0.0, kappa0)
    for _ in range(steps):
        k1 = f(s)
        k2 = f(tuple(a + 0.5 * h * b for a, b in zip(s, k1)))
        k3 = f(tuple(a + 0.5 * h * b for a, b in zip(s, k2)))
        k4 = f(tuple(a + h * b for a, b in zip(s, k3)))
        s = tuple(a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(s, k1, k2, k3, k4))
    return s


def tip(load, ei, length, steps):
    """Tip displacement (u_x, u_y) and rotation of the elastica."""
    alpha = load / ei
    lo, hi = 0.0, alpha * length  # root moment P * x_tip lies in [0, P L]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if integrate(mid, alpha, length, steps)[3] > 0:  # tip curvature left: too much root moment
            hi = mid
        else:
            lo = mid
    x, y, th, _ = integrate(0.5 * (lo + hi), alpha, length, steps)
    return x - length, y, th


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--length", type=float, default=10.0)
    p.add_argument("--ei", type=float, default=1.2e6 * 1.0 * 0.1**3 / 12, help="E b h^3 / 12")
    p.add_argument("--load", type=float, nargs="+", default=[4.0])
    p.add_argument("--steps", type=int, default=4000)
    a = p.parse_args()
    print("P       PL^2/EI  u_x (tip)      u_y (tip)      rotation (rad)  |change from N/2 steps|")
    for load in a.load:
        ux, uy, th = tip(load, a.ei, a.length, a.steps)
        ux2, uy2, _ = tip(load, a.ei, a.length, a.steps // 2)
        print(f"{load:<7g} {load * a.length**2 / a.ei:<8.4g} {ux:<14.7f} {uy:<14.7f} {th:<15.7f} "
              f"{max(abs(ux - ux2), abs(uy - uy2)):.1e}")


if __name__ == "__main__":
    main()
