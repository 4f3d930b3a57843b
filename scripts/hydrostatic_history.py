#!/usr/bin/env python3
"""A hydrostatic tank's pressure profile over time, through the Python module (docs/validation.md,
"Boundaries": why the 3D tank's worst bin grows after it settles).

    PYTHONPATH=build/python python3 scripts/hydrostatic_history.py DIM SAMPLES [KEY=VALUE ...]

Prints, SAMPLES times over the run: the kinetic energy, the free surface (mean of each column's
top particle plus half a spacing, as sph validate), the worst depth bin's |p / (rho0 g d) - 1|
below the second layer over the whole tank, and the ratio in the top, middle and bottom bins.
"""
import json
import sys

import numpy as np
import sph


def profile(sim, dim, dx, rho0, g):
    x, p = sim.positions, sim.pressures
    tops = {}
    for xx in x:
        key = (int(np.floor(xx[0] / dx)), int(np.floor(xx[2] / dx)) if dim == 3 else 0)
        tops[key] = max(tops.get(key, -np.inf), xx[1])
    surface = float(np.mean(list(tops.values()))) + dx / 2
    depth = surface - x[:, 1]
    deep = depth > 2 * dx
    bins = np.floor((depth[deep] - 2 * dx) / (2 * dx)).astype(int)
    out = []
    for k in np.unique(bins):
        s = bins == k
        out.append((p[deep][s].mean() / (rho0 * g * depth[deep][s].mean()), int(s.sum())))
    median = np.median([c for _, c in out])
    worst = max(abs(r - 1) for r, c in out if c >= max(3, median // 2))
    return surface, worst, out


def main():
    dim, samples = int(sys.argv[1]), int(sys.argv[2])
    overrides = {}
    for arg in sys.argv[3:]:
        key, value = arg.split("=", 1)
        try:
            overrides[key] = json.loads(value)
        except ValueError:
            overrides[key] = value
    scene = sph.load_scene(f"scenes/validation/hydrostatic_{dim}d.json", overrides=overrides)
    d = scene.to_dict()
    dx = 2 * d["Configuration"]["particleRadius"]
    g = -d["Configuration"]["gravitation"][1]
    rho0 = d["Fluid"]["density0"]
    sim = sph.Simulation(scene)
    for _ in range(samples):
        sim.step(scene.steps // samples)
        v = sim.velocities  # (every particle has the one mass, sim.particle_mass)
        kinetic = 0.5 * sim.particle_mass * float((v * v).sum())
        surface, worst, out = profile(sim, dim, dx, rho0, g)
        print(f"t {sim.time:.2f} s  KE {kinetic:.2e} J  surface {surface:.5f} m  worst bin {worst:.3f}  "
              f"top {out[0][0]:.3f} middle {out[len(out) // 2][0]:.3f} bottom {out[-1][0]:.3f}", flush=True)


if __name__ == "__main__":
    main()
