#!/usr/bin/env python3
"""A resting tank's pressure profile, bin by bin, through the Python module (docs/validation.md,
"DFSPH": where the pressure misses rho0 g d).

    PYTHONPATH=build/python python3 scripts/tank_bins.py SCENE [KEY=VALUE ...]

Runs the scene (KEY=VALUE as --set) and averages each particle's pressure, density and position
over the steps of the run's last tenth, as sph validate does. The free surface is the mean of each
column's top particle plus half a spacing. Prints, for each 2-spacing depth bin below the second
layer, the mean p / (rho0 g d) of the whole bin and of its interior (the particles at least 3
spacings from the side walls), with their counts; then the first ten layers (bins of one spacing
from the surface, the whole tank), with their mean density: under the free surface the pressure
alternates from layer to layer by about 0.3 to 0.6 rho0 g dx, which the two-spacing bins average
out. Then how one step's pressure differs from the
averaged one: the least and the largest of each step's interior mean p / (rho0 g d), over the
same steps (the interior below the second layer and above the floor's two layers).
"""
import json
import sys

import numpy as np
import sph


def tank_geometry(scene):
    """What the measures need of a tank's scene: dimension, spacing, g, rho0, container corners,
    end time."""
    d = scene.to_dict()
    c = d["Configuration"]
    end = c["stopAt"] if "stopAt" in c else c["numberOfSteps"] * c["timeStepSize"]
    return (d["dimension"], 2 * c["particleRadius"], -c["gravitation"][1], d["Fluid"]["density0"],
            d["Container"]["start"], d["Container"]["end"], end)


def surface_of(x, dim, dx, above):
    """The free surface: the mean of each column's (dx wide) top particle, plus `above`."""
    tops = {}
    for xx in x:
        key = (int(np.floor(xx[0] / dx)), int(np.floor(xx[2] / dx)) if dim == 3 else 0)
        tops[key] = max(tops.get(key, -np.inf), xx[1])
    return float(np.mean(list(tops.values()))) + above


def wall_distance(x, dim, lo, hi):
    """Each particle's distance to the nearest side wall."""
    wall = np.full(len(x), np.inf)
    for a in [0] + ([2] if dim == 3 else []):
        wall = np.minimum(wall, np.minimum(x[:, a] - lo[a], hi[a] - x[:, a]))
    return wall


def average_last_tenth(sim, end, each_step=None):
    """Runs sim to `end`, averaging each particle's pressure, position and density (by particle id)
    over the steps of the last tenth; `each_step(pressures, positions)` sees each of those steps'.
    Returns p, x, rho and the number of steps averaged."""
    while sim.time < 0.9 * end:
        sim.step(1)
    sums, n = None, 0
    while sim.time < end * (1 - 1e-12):
        sim.step(1)
        order = np.argsort(np.asarray(sim.ids))
        now = [np.asarray(a)[order] for a in (sim.pressures, sim.positions, sim.densities)]
        sums = now if sums is None else [s + a for s, a in zip(sums, now)]
        n += 1
        if each_step:
            each_step(now[0], now[1])
    p, x, rho = (s / n for s in sums)
    return p, x, rho, n


def print_bins(p, x, rho, n, surface, wall, dx, rho0, g):
    """The averages' summary line and each 2-spacing depth bin below the second layer: the mean
    p / (rho0 g d) of the whole bin and of its interior (at least 3 spacings from the side walls)."""
    depth = surface - x[:, 1]
    print(f"{n} steps averaged, surface {surface:.4f} m, mean |rho - rho0| / rho0 "
          f"{np.mean(np.abs(rho - rho0)) / rho0:.2e}")
    deep = depth > 2 * dx
    bins = np.floor((depth - 2 * dx) / (2 * dx)).astype(int)
    for k in np.unique(bins[deep]):
        whole = deep & (bins == k)
        inner = whole & (wall > 3 * dx)
        ratio = p[whole].mean() / (rho0 * g * depth[whole].mean())
        inside = p[inner].mean() / (rho0 * g * depth[inner].mean()) if inner.any() else float("nan")
        print(f"bin {k:2d}  depth {depth[whole].mean():.4f} m  whole {ratio:.3f} ({whole.sum()})  "
              f"interior {inside:.3f} ({inner.sum()})")


def main():
    overrides = {}
    for arg in sys.argv[2:]:
        key, value = arg.split("=", 1)
        try:
            overrides[key] = json.loads(value)
        except ValueError:
            overrides[key] = value
    scene = sph.load_scene(sys.argv[1], overrides=overrides)
    dim, dx, g, rho0, lo, hi, end = tank_geometry(scene)
    sim = sph.Simulation(scene)
    steps = []

    def interior_mean(p, x):  # one step's interior mean p / (rho0 g d)
        d = surface_of(x, dim, dx, dx / 2) - x[:, 1]
        inner = (d > 2 * dx) & (wall_distance(x, dim, lo, hi) > 3 * dx) & (x[:, 1] - lo[1] > 2 * dx)
        steps.append(np.mean(p[inner] / (rho0 * g * d[inner])))

    p, x, rho, n = average_last_tenth(sim, end, interior_mean)
    surface = surface_of(x, dim, dx, dx / 2)
    depth = surface - x[:, 1]
    print_bins(p, x, rho, n, surface, wall_distance(x, dim, lo, hi), dx, rho0, g)
    # Layer by layer (bins of one spacing from the surface): what the two-spacing bins average out.
    layers = np.floor(depth / dx).astype(int) + 1
    for k in range(1, 11):
        whole = layers == k
        if not whole.any():
            continue
        offset = (p[whole].mean() - rho0 * g * depth[whole].mean()) / (rho0 * g * dx)
        print(f"layer {k:2d}  depth {depth[whole].mean():.4f} m  whole "
              f"{p[whole].mean() / (rho0 * g * depth[whole].mean()):.3f} ({whole.sum()})  "
              f"p - rho0 g d = {offset:+.2f} rho0 g dx  density {rho[whole].mean():.1f}")
    print(f"one step's interior mean p / (rho0 g d): {min(steps):.3f} to {max(steps):.3f} over {n} steps")


if __name__ == "__main__":
    main()
