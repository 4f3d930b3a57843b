#!/usr/bin/env python3
"""The 3D DFSPH hydrostatic tank started from a face-centred cubic lattice instead of the simple
cubic one (docs/validation.md, "DFSPH": why the 3D tank reads 2-5 % high).

    PYTHONPATH=build/python python3 scripts/fcc_tank.py [KERNEL_RADIUS_M]

The scene `scenes/validation/hydrostatic_3d_dfsph.json` (a 0.1 m cube of water at rest in its
container, DFSPH, boundary particles, the cubic spline) is loaded with three fluid blocks that
make 8,788 particles, and the particles are then placed on an FCC lattice filling the same
0.1 m cube: 13 cubic cells of edge a = 0.1 / 13 m per side, 4 particles a cell, the first
lattice planes a / 4 from the walls and the floor (as the simple cubic lattice starts half a
spacing in). That is 9.8 % more particles per cubic metre than the scene's 8,000; their
"equivalent spacing" (a^3 / 4)^(1/3) is 4.85 mm against 5 mm. The particle mass is the one that
gives each particle of the infinite lattice exactly rho0 (sph's cubic spline, support h), and
the kernel radius is 2.15 equivalent spacings (the scene's ratio) unless given.

Prints tank_bins.py's bins for the scene (the run's last tenth averaged; the surface is the
columns' top particles plus a / 4, half the lattice's plane spacing), and the kinetic
energy against its early peak (the largest of the first twentieth of the steps) at a few times, and
the last time it was above 1 % of it: whether the tank settles.
"""
import itertools
import math
import os
import sys

import numpy as np
import sph

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tank_bins import average_last_tenth, print_bins, surface_of, tank_geometry, wall_distance  # noqa: E402

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "validation",
                     "hydrostatic_3d_dfsph.json")
CELLS = 13  # cubic cells per side of the 0.1 m cube
SIDE = 0.1
BASIS = np.array([(0, 0, 0), (0.5, 0.5, 0), (0.5, 0, 0.5), (0, 0.5, 0.5)])


def cubic_spline(r, h):
    q = r / h
    s = 8 / (math.pi * h**3)
    return np.where(q <= 0.5, s * (6 * q**3 - 6 * q**2 + 1), np.where(q <= 1, 2 * s * (1 - q) ** 3, 0.0))


def main():
    a = SIDE / CELLS
    spacing = (a**3 / 4) ** (1 / 3)
    h = float(sys.argv[1]) if len(sys.argv) > 1 else 2.15 * spacing
    cells = np.array(list(itertools.product(range(CELLS), repeat=3)), float)
    positions = ((cells[:, None, :] + BASIS[None, :, :]).reshape(-1, 3) + 0.25) * a
    around = np.array(list(itertools.product(range(-4, 5), repeat=3)), float)
    lattice = (around[:, None, :] + BASIS[None, :, :]).reshape(-1, 3) * a
    mass = 1000.0 / float(np.sum(cubic_spline(np.linalg.norm(lattice, axis=1), h)))
    print(f"{len(positions)} particles, cell edge {a:.6f} m, equivalent spacing {spacing:.6f} m, "
          f"h {h:.6f} m ({h / spacing:.3f} spacings), mass {mass:.6e} kg")
    # 8,000 + 780 + 8 = 8,788 particles from the scene's reader, placed anew below.
    overrides = {
        "Configuration.kernelRadius": h,
        "Fluid.particleMass": mass,
        "FluidBlocks": [{"start": [0, 0, 0], "end": [0.1, 0.1, 0.1]},
                        {"start": [0, 0.1, 0], "end": [0.1, 0.115, 0.065]},
                        {"start": [0, 0.115, 0.07], "end": [0.01, 0.125, 0.08]}],
    }
    scene = sph.load_scene(SCENE, overrides=overrides)
    sim = sph.Simulation(scene)
    if len(sim.positions) != len(positions):
        sys.exit(f"the scene made {len(sim.positions)} particles, not {len(positions)}")
    sim.positions = positions
    dim, dx, g, rho0, lo, hi, end = tank_geometry(scene)
    energy = []
    while sim.time < 0.9 * end:
        sim.step(1)
        energy.append((sim.time, sim.counters["kinetic_energy"], sim.counters["max_speed"]))
    p, x, rho, n = average_last_tenth(
        sim, end, lambda *_: energy.append((sim.time, sim.counters["kinetic_energy"], sim.counters["max_speed"])))
    print_bins(p, x, rho, n, surface_of(x, dim, dx, a / 4), wall_distance(x, dim, lo, hi), dx, rho0, g)
    energy = np.array(energy)
    peak = float(np.max(energy[: max(10, len(energy) // 20), 1]))
    for t in (0.05, 0.1, 0.2, 0.3, 0.4, 0.6, 1.0, 1.5):
        i = int(np.searchsorted(energy[:, 0], t))
        if i < len(energy):
            print(f"t {energy[i, 0]:.2f} s  kinetic energy {energy[i, 1]:.2e} J "
                  f"({100 * energy[i, 1] / peak:.1f} % of the early peak), fastest {energy[i, 2]:.4f} m/s")
    above = np.nonzero(energy[:, 1] > 0.01 * peak)[0]
    print(f"largest after 0.1 s: {100 * float(np.max(energy[energy[:, 0] > 0.1, 1])) / peak:.1f} % of the early peak; "
          f"last above 1 %: {energy[above[-1], 0]:.3f} s (settled, as sph validate reads it, from the step after)")


if __name__ == "__main__":
    main()
