#!/usr/bin/env python3
"""The Python binding's per-step overhead (docs/performance.md, "The Python module's overhead").

Steps the paper's 2D dam break (scenes/paper/dam_break_2d.json, 3,200 particles) through
`sph run` and through the module, and compares wall seconds per step with the step's own phase
seconds (stats.csv's t_grid .. t_integrate, Simulation.counters' same columns), whose difference is
what a step costs outside the solver (the loop, the output or the binding, the Python code):
  sph run            sph run SCENE --steps N --every 0 --no-progress (stats.csv, no frames)
  sim.step(N)        one call
  sim.step(1) xN     one call per step, reading sim.positions and sim.counters after each
Each figure is the median over --repeats runs (each a fresh process for sph run, a fresh
Simulation for the module, after a 20-step warm-up in the module's case, which sph run's first
steps include).

    PYTHONPATH=build/python GOMP_SPINCOUNT=1000 python3 scripts/python_overhead.py [--steps 400] [--repeats 7] [--threads 1]

(With GOMP_SPINCOUNT set, sph run keeps it, and both sides spin alike; with neither it nor
OMP_WAIT_POLICY set, sph run calibrates its own count, about 30 us of spinning. libgomp reads it
when it loads, so the module takes it from the environment.)
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import sph

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SCENE = os.path.join(ROOT, "scenes", "paper", "dam_break_2d.json")
PHASES = ("t_grid", "t_lists", "t_density", "t_forces", "t_integrate")


def sph_run(exe, steps, threads, neighbors):
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([exe, "run", SCENE, "-o", d, "--steps", str(steps), "--every", "0", "--no-progress",
                        "--threads", str(threads), "--neighbors", neighbors], check=True, capture_output=True)
        with open(os.path.join(d, "summary.json")) as f:
            wall = json.load(f)["wall_seconds"]
        with open(os.path.join(d, "stats.csv")) as f:
            phases = sum(sum(float(r[p]) for p in PHASES) for r in csv.DictReader(f))
    return wall / steps, phases / steps


def module_run(scene, steps, threads, neighbors, one_by_one):
    sim = sph.Simulation(scene, neighbors=neighbors, threads=threads)
    sim.step(20)
    phases = 0.0
    t0 = time.perf_counter()
    if one_by_one:
        for _ in range(steps):
            sim.step(1)
            x = sim.positions  # a view, as a script reads it
            c = sim.counters
            phases += sum(c[p] for p in PHASES)
        del x
    else:
        sim.step(steps)
    wall = time.perf_counter() - t0
    if not one_by_one:
        phases = float("nan")  # (the counters hold the last step only)
    return wall / steps, phases / steps


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--steps", type=int, default=400)
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--neighbors", default="adaptive")
    p.add_argument("--sph", default=os.path.join(ROOT, "build", "sph"))
    a = p.parse_args()
    scene = sph.load_scene(SCENE, overrides={"Configuration.numberOfSteps": a.steps + 20})
    rows = {"sph run": [], "sim.step(N)": [], "sim.step(1) xN": []}
    for _ in range(a.repeats):  # interleaved, so that a slow spell of the machine hits every variant
        rows["sph run"].append(sph_run(a.sph, a.steps, a.threads, a.neighbors))
        rows["sim.step(N)"].append(module_run(scene, a.steps, a.threads, a.neighbors, False))
        rows["sim.step(1) xN"].append(module_run(scene, a.steps, a.threads, a.neighbors, True))
    base = statistics.median(w for w, _ in rows["sph run"])
    print(f"{scene.name}: 3,200 particles, {a.neighbors}, {a.steps} steps, {a.threads} thread(s), "
          f"median of {a.repeats}")
    print("| variant | wall ms/step | phases ms/step | wall - phases, us/step | wall vs sph run |")
    print("|---|---|---|---|---|")
    for name, values in rows.items():
        wall = statistics.median(w for w, _ in values)
        if values[0][1] == values[0][1]:  # (NaN: not measured)
            phases = f"{1e3 * statistics.median(ph for _, ph in values):.3f}"
            outside = f"{1e6 * statistics.median(w - ph for w, ph in values):.1f}"
        else:
            phases = outside = "-"
        print(f"| {name} | {1e3 * wall:.3f} | {phases} | {outside} | {wall / base:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
