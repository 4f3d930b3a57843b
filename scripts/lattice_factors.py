#!/usr/bin/env python3
"""What a kernel gives on the initial lattice (docs/validation.md, "DFSPH": why the 3D tank's
pressure misses rho0 g d).

    python3 scripts/lattice_factors.py [KERNEL_RADIUS_IN_SPACINGS ...]   (default: 2.0 2.15 2.5 3.0)

For each dimension (2, 3), each kernel (cubic spline, Wendland C2, spiky) and each support h in
particle spacings, on the square (cubic) lattice of spacing 1 with one particle at the origin:
- "sum": sum_j V W(r_j) with V = 1, the self term included (sph's default mass is rho0 V / sum,
  so that a lattice particle has exactly rho0; spiky, the paper's pressure kernel, is not a
  density kernel);
- "gradient": sum_j V |W'(r_j)| x_j^2 / r_j, the lattice's factor on the gradient of a linear
  field (1 in the continuum);
- "sum / gradient": what a resting tank on its initial lattice reads as p / (rho0 g d) in its
  interior.
Then the same in 3D for the face-centred cubic lattice at the same number of particles per unit
volume (cubic cells of edge 4^(1/3), 4 particles each), h in the same unit (scripts/fcc_tank.py
starts the 3D DFSPH tank from it). With the default mass m = rho0 V / sum, a symmetric pressure force
  -sum_j m (p_i + p_j) / rho0^2 grad W_ij on a linear p of gradient G is G (m / V) gradient /
  rho0^2 = G gradient / (rho0 sum), which balances g where G = rho0 g sum / gradient.
"""
import itertools
import math
import sys

import numpy as np


def sigma(kind, h, dim):
    if kind == "cubic":
        return 8 / (math.pi * h**3) if dim == 3 else 40 / (7 * math.pi * h**2)
    if kind == "wendland":
        return 21 / (2 * math.pi * h**3) if dim == 3 else 7 / (math.pi * h**2)
    return 15 / (math.pi * h**6) if dim == 3 else 10 / (math.pi * h**5)  # spiky


def kernel(kind, r, h, dim):
    q = r / h
    s = sigma(kind, h, dim)
    if kind == "cubic":
        return np.where(q <= 0.5, s * (6 * q**3 - 6 * q**2 + 1), np.where(q <= 1, 2 * s * (1 - q) ** 3, 0.0))
    if kind == "wendland":
        return np.where(q < 1, s * (1 - q) ** 4 * (1 + 4 * q), 0.0)
    return np.where(r < h, s * (h - r) ** 3, 0.0)


def derivative(kind, r, h, dim):
    q = r / h
    s = sigma(kind, h, dim)
    if kind == "cubic":
        return np.where(q <= 0.5, s * (18 * q**2 - 12 * q) / h, np.where(q <= 1, -6 * s * (1 - q) ** 2 / h, 0.0))
    if kind == "wendland":
        return np.where(q < 1, -20 * s * q * (1 - q) ** 3 / h, 0.0)
    return np.where(r < h, -3 * s * (h - r) ** 2, 0.0)


def main():
    supports = [float(a) for a in sys.argv[1:]] or [2.0, 2.15, 2.5, 3.0]
    print("| dimension | h (spacings) | kernel | sum | gradient | sum / gradient |")
    print("| ---: | ---: | --- | ---: | ---: | ---: |")
    for dim in (2, 3):
        for h in supports:
            n = int(math.ceil(h)) + 1
            points = np.array([p for p in itertools.product(range(-n, n + 1), repeat=dim) if any(p)], float)
            r = np.linalg.norm(points, axis=1)
            for kind in ("cubic", "wendland", "spiky"):
                total = float(np.sum(kernel(kind, r, h, dim)) + kernel(kind, np.array(0.0), h, dim))
                grad = float(np.sum(-derivative(kind, r, h, dim) * points[:, 0] ** 2 / r))
                if kind == "spiky":  # (the paper's density is poly6's: no sum, no ratio)
                    print(f"| {dim} | {h:g} | {kind} | - | {grad:.4f} | - |")
                else:
                    print(f"| {dim} | {h:g} | {kind} | {total:.4f} | {grad:.4f} | {total / grad:.4f} |")
    print()
    print("| lattice | h (spacings) | kernel | sum | gradient | sum / gradient |")
    print("| --- | ---: | --- | ---: | ---: | ---: |")
    edge = 4 ** (1 / 3)
    basis = [(0, 0, 0), (0.5, 0.5, 0), (0.5, 0, 0.5), (0, 0.5, 0.5)]
    for h in supports:
        n = int(math.ceil(h / edge)) + 1
        points = np.array([[edge * (c[k] + b[k]) for k in range(3)] for c in itertools.product(range(-n, n + 1), repeat=3)
                           for b in basis if any(c) or any(b)], float)
        r = np.linalg.norm(points, axis=1)
        for kind in ("cubic", "wendland"):
            total = float(np.sum(kernel(kind, r, h, 3)) + kernel(kind, np.array(0.0), h, 3))
            grad = float(np.sum(-derivative(kind, r, h, 3) * points[:, 0] ** 2 / r))
            print(f"| fcc | {h:g} | {kind} | {total:.4f} | {grad:.4f} | {total / grad:.4f} |")


if __name__ == "__main__":
    main()
