#!/usr/bin/env python3
"""The explicit viscosity's stable time step on a lattice (docs/physics.md, "Time-step checks").

The force pass adds a_i = sum_j k_ij (v_j - v_i) with k_ij = nu V k(r): Eq. 6's Laplacian of the
viscosity kernel (the paper's kernels) or Morris et al.'s -2 (x_ij . grad W) / (r^2 + 0.01 h^2)
(the cubic spline and Wendland C2), V the particle volume. On a square or cubic lattice a velocity
wave exp(i q . x) decays at the rate lambda(q) = sum_j k_ij (1 - cos(q . x_j)); forward Euler is
stable while dt lambda <= 2. This prints the largest stable dt, in units of h^2 / nu, over wave
vectors q on a grid of [0, pi]^D, for each kernel, dimension and support (in spacings).

    python3 scripts/viscous_limit.py
"""
import math

import numpy as np


def laplacian_weight(kind, dim, h):
    """k(r) of a pair at distance r (spacing 1, nu 1), as the force pass computes it."""
    if kind == "paper":
        c = 45 / (math.pi * h**6) if dim == 3 else 40 / (math.pi * h**5)
        return lambda r: c * (h - r)
    if kind == "cubic":
        s = 8 / (math.pi * h**3) if dim == 3 else 40 / (7 * math.pi * h**2)

        def grad_factor(r):
            q = r / h
            inner = s / h**2 * (18 * q - 12)
            outer = -6 * s / h**2 * (1 - q) ** 2 / np.maximum(q, 1e-30)
            return np.where(q <= 0.5, inner, outer)
    else:  # wendland
        s = 21 / (2 * math.pi * h**3) if dim == 3 else 7 / (math.pi * h**2)

        def grad_factor(r):
            return -20 * s / h**2 * (1 - r / h) ** 3

    return lambda r: -2 * grad_factor(r) * r**2 / (r**2 + 0.01 * h * h)


def stable_step(kind, dim, support, samples=25):
    n = int(math.ceil(support)) + 1
    grid = np.array(np.meshgrid(*[np.arange(-n, n + 1)] * dim)).reshape(dim, -1).T.astype(float)
    r = np.linalg.norm(grid, axis=1)
    near = (r > 0) & (r < support)
    x, r = grid[near], r[near]
    k = laplacian_weight(kind, dim, support)(r)
    axis = np.linspace(0, math.pi, samples)
    qs = np.array(np.meshgrid(*[axis] * dim)).reshape(dim, -1).T
    rates = (k[None, :] * (1 - np.cos(qs @ x.T))).sum(axis=1)
    return 2 / rates.max() / support**2


print("largest stable explicit step, h^2 / nu (forward Euler, lattice)")
print("| kernel | D | 2 spacings | 2.5 spacings | 3 spacings | 4 spacings |")
print("| --- | --- | ---: | ---: | ---: | ---: |")
for kind in ("paper", "cubic", "wendland"):
    for dim in (2, 3):
        cells = " | ".join(f"{stable_step(kind, dim, s):.4f}" for s in (2.0, 2.5, 3.0, 4.0))
        print(f"| {kind} | {dim} | {cells} |")
