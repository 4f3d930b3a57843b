#!/usr/bin/env python3
"""A very viscous column collapsing, the explicit viscosity against the implicit one
(docs/physics.md, "Implicit viscosity").

The validation's 2D DFSPH tank scene with a 0.2 m x 0.2 m column (1,600 particles, spacing
5 mm, h = 2 spacings, the cubic spline, boundary samples without a pressure of their own:
boundaryPressure "none", DFSPH's default) of viscosity MU Pa s in a 0.6 m x 0.3 m tank, run to T
seconds with each solver and each largest step given (`None`: the scene's CFL steps; `fixed`
after it: every step that long). Prints,
per run, the steps, the wall seconds, the front (largest x) and top (largest y) at the end, the
kinetic energy, the viscosity solve's mean iterations and the health warnings.

    PYTHONPATH=build/python python3 scripts/viscous_column.py [MU] [T] [SOLVER:MAXSTEP[:fixed] ...]
    (defaults: 100 0.2 explicit:2e-5 explicit:None implicit:None)
"""
import sys
import time
import warnings

import sph

mu = float(sys.argv[1]) if len(sys.argv) > 1 else 100.0
end = float(sys.argv[2]) if len(sys.argv) > 2 else 0.2
runs = sys.argv[3:] or ["explicit:2e-5", "explicit:None", "implicit:None"]
print(f"| solver | largest step (s) | steps | wall s | front (m) | top (m) | kinetic energy (J) | "
      f"viscosity iterations per step | warnings |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
for run in runs:
    solver, cap, *fixed = run.split(":")
    overrides = {"Container.end": [0.6, 0.3], "FluidBlocks": [{"start": [0, 0], "end": [0.2, 0.2]}],
                 "Configuration.kernelRadius": 0.01, "Configuration.stopAt": end, "Fluid.viscosity": mu,
                 "Fluid.viscositySolver": solver, "Configuration.boundaryPressure": "none"}
    if cap != "None":
        overrides["Configuration.cflMaxTimeStepSize"] = float(cap)
        if fixed:
            overrides["Configuration.cflMinTimeStepSize"] = float(cap)
    sim = sph.Simulation(sph.load_scene("scenes/validation/hydrostatic_2d_dfsph.json", overrides))
    steps = iterations = 0
    start = time.perf_counter()
    failure = ""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            while sim.time < end * (1 - 1e-12):
                sim.step()
                steps += 1
                iterations += sim.counters["viscosity_iterations"]
        except sph.SimulationError as e:
            failure = f"failed: {e}"
    wall = time.perf_counter() - start
    x = sim.positions
    said = "; ".join(str(w.message)[:70] for w in caught[:1]) or "none"
    print(f"| {solver} | {cap}{' (fixed)' if fixed else ''} | {steps} | {wall:.2f} | {x[:, 0].max():.4f} | {x[:, 1].max():.4f} | "
          f"{sim.kinetic_energy():.3f} | {iterations / max(steps, 1):.1f} | {failure or said} |")
