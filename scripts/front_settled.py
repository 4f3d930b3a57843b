#!/usr/bin/env python3
"""The Martin & Moyce front (a/40, boundary particles) started from a column that first settled
behind a gate, against the usual start from an unpressurized lattice (docs/validation.md,
"Boundaries": is the early lead the start's acoustic transient?).

    PYTHONPATH=build/python python3 scripts/front_settled.py SETTLE_SECONDS FRICTION [KEY=VALUE ...]

SETTLE_SECONDS 0 runs the scene as it is. Otherwise the column first runs that long in a
container cut at x = a (its right wall is the gate; boundary friction 0.2 to damp it), then its
particles, at rest, start the full tank's run. Prints max and mean dZ against the experiment over
0.4 <= T <= 3.35, and dZ at each of the experiment's times. The front is sph validate's
(sph.surge_front), sampled every 13 steps.
"""
import json
import sys

import numpy as np
import sph

A = sph.MARTIN_MOYCE_A
G = 9.81
SCENE = "scenes/validation/martin_moyce_2d.json"


def main():
    settle, friction = float(sys.argv[1]), float(sys.argv[2])
    overrides = {"Configuration.boundaryHandling": "particles", "Configuration.boundaryFriction": friction}
    for arg in sys.argv[3:]:
        key, value = arg.split("=", 1)
        try:
            overrides[key] = json.loads(value)
        except ValueError:
            overrides[key] = value
    scene = sph.load_scene(SCENE, overrides=overrides)
    conf = scene.to_dict()["Configuration"]
    dx, h, dt = 2 * conf["particleRadius"], conf["kernelRadius"], conf["timeStepSize"]
    sim = sph.Simulation(scene)
    if settle > 0:
        gated = dict(overrides, **{"Container.end": [A, 0.15], "Configuration.boundaryFriction": 0.2})
        column = sph.Simulation(sph.load_scene(SCENE, overrides=gated))
        column.step(int(round(settle / dt)))
        print(f"kinetic energy behind the gate after {settle} s: {column.kinetic_energy():.3g} J/m", flush=True)
        by_id = np.zeros((len(column), 2))
        by_id[column.ids.astype(np.int64)] = column.positions
        sim.positions = by_id[sim.ids.astype(np.int64)]
        sim.velocities = np.zeros((len(sim), 2))
    T, Z = [], []
    for _ in range(0, scene.steps, 13):
        sim.step(13)
        x = sim.positions
        T.append(sph.martin_moyce_time(sim.time, G))
        Z.append(sph.surge_front(x[:, 0], x[:, 1], 0.0, dx, h) / A)
    errors = [np.interp(t, T, Z) - z for t, z in sph.martin_moyce_1952() if 0.4 <= t <= 3.35]
    print(f"settle {settle} s, friction {friction} {' '.join(sys.argv[3:])}: max |dZ| "
          f"{max(abs(e) for e in errors):.3f}, mean {np.mean(errors):+.3f}; dZ " + " ".join(f"{e:+.2f}" for e in errors))


if __name__ == "__main__":
    main()
