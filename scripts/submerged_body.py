#!/usr/bin/env python3
"""A floating box of the water's density, submerged, under each boundary pressure (docs/physics.md,
"DFSPH", "Boundaries").

The scene of tests/run/floating_body_test.cpp's TheWatersDensityNeitherRisesNorSinks: a 2D tank
1.2 m x 0.8 m of water to 0.5 m (spacing 2 cm, h = 2 spacings, the cubic spline, boundary
particles), a 0.4 m x 0.2 m box of density 1000 whose bottom is 0.1 m above the floor (its centre
at 0.2 m). Runs it for 1 s with DFSPH under each Configuration.boundaryPressure, and with weakly
compressible SPH (stiffness 4000, CFL steps) under the extrapolated one, and prints the box's
centre height (m) and vertical velocity (m/s) at 0.05, 0.2, 0.5 and 1 s.

    PYTHONPATH=build/python python3 scripts/submerged_body.py [KEY=VALUE ...]

Each KEY=VALUE (VALUE JSON, as `sph run --set`) is applied to every run, e.g.
`Configuration.cflMaxTimeStepSize=0.001` or `Obstacles[0].density=1100`.
"""
import json
import sys

import sph

SCENE = {
    "version": 1, "name": "submerged_body", "dimension": 2,
    "Configuration": {"precision": "double", "timeStepSize": 0.004, "stopAt": 1.0, "particleRadius": 0.01,
                      "kernelRadius": 0.04, "gravitation": [0, -9.81], "boundaryHandling": "particles",
                      "kernel": "cubic", "simulationMethod": "dfsph", "cflMaxTimeStepSize": 0.01,
                      "outputFps": 10},
    "Fluid": {"density0": 1000, "viscosity": 1.0},
    "Container": {"start": [0, 0], "end": [1.2, 0.8]},
    "FluidBlocks": [{"start": [0, 0], "end": [0.4, 0.5]}, {"start": [0.8, 0], "end": [1.2, 0.5]},
                    {"start": [0.4, 0], "end": [0.8, 0.1]}, {"start": [0.4, 0.3], "end": [0.8, 0.5]}],
    "Obstacles": [{"start": [0.4, 0.1], "end": [0.8, 0.3], "dynamic": True, "density": 1000}],
}

RUNS = [
    ("dfsph, none", {"Configuration.boundaryPressure": "none"}),
    ("dfsph, mirror", {"Configuration.boundaryPressure": "mirror"}),
    ("dfsph, extrapolate", {"Configuration.boundaryPressure": "extrapolate"}),
    ("wcsph, extrapolate", {"Configuration.simulationMethod": "wcsph", "Configuration.cflMethod": "cfl",
                            "Configuration.timeStepSize": 0.0002, "Fluid.stiffness": 4000,
                            "Configuration.boundaryPressure": "extrapolate"}),
]

print("| run | steps | " + " | ".join(f"t = {t} s: y, v_y" for t in (0.05, 0.2, 0.5, 1.0)) + " |")
print("| --- | ---: |" + " ---: |" * 4)
extra = {}
for arg in sys.argv[1:]:
    key, _, value = arg.partition("=")
    try:
        extra[key] = json.loads(value)
    except json.JSONDecodeError:
        extra[key] = value
for label, overrides in RUNS:
    sim = sph.Simulation(sph.Scene.from_dict(SCENE, {**overrides, **extra}))
    cells = []
    for t in (0.05, 0.2, 0.5, 1.0):
        while sim.time < t - 1e-9:
            sim.step(1)
        body = sim.bodies[0]
        cells.append(f"{body['position'][1]:.4f}, {body['velocity'][1]:+.3f}")
    print(f"| {label} | {sim.steps} | " + " | ".join(cells) + " |")
