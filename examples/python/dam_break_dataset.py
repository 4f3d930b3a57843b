#!/usr/bin/env python3
"""A training-data generator through the Python API: particle trajectories of randomized 2D dam
breaks, deterministic from a seed (the same seed gives the same bytes, for any thread count).

    PYTHONPATH=build/python python3 examples/python/dam_break_dataset.py --seed 1 --count 20 -o out/dataset
    PYTHONPATH=build/python python3 examples/python/dam_break_dataset.py --quick -o out/dataset_quick

Each dam break draws, from numpy's PCG64 generator seeded with --seed: the water column's width
and height (0.1 to 0.3 m, 0.1 to 0.5 m), its left edge (0 to 0.2 m) and the viscosity (0.5 to
4). The tank, spacing and step are those of the paper's dam break (scenes/paper/dam_break_2d.json).

Layout (docs/python.md, "Data sets"):
  OUT/trajectories.npz   for trajectory k (k = 0, 1, ...):
      positions_k      float32 (frames, particles, 2): positions every --every steps, frame 0 the
                       initial state, particles in id order (the simulation reorders its memory;
                       the stored order never changes)
      particle_type_k  int64 (particles,): 5 for every particle (water, as the GNS data sets say)
  OUT/metadata.json      the keys of the GNS data sets' metadata.json (bounds, sequence_length,
                         default_connectivity_radius, dim, dt between frames, vel_mean, vel_std,
                         acc_mean, acc_std over every trajectory, from finite differences of the
                         stored frames) and, under "sph", the seed and each trajectory's scene.
"""
import argparse
import json
import os
import sys

import numpy as np

import sph

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "scenes", "paper", "dam_break_2d.json")
WATER = 5


def draw_overrides(rng):
    """The randomized values of one dam break."""
    width, height = rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.5)
    left = rng.uniform(0.0, 0.2)
    return {"FluidBlocks[0].start": [round(left, 4), 0.0],
            "FluidBlocks[0].end": [round(left + width, 4), round(height, 4)],
            "Fluid.viscosity": round(float(rng.uniform(0.5, 4.0)), 3)}


def trajectory(scene, every, threads):
    """Positions (frames, particles, 2) in id order, every `every` steps of the scene."""
    sim = sph.Simulation(scene, threads=threads)
    frames = []
    while True:
        order = np.argsort(sim.ids, kind="stable")
        frames.append(sim.positions[order].astype(np.float32))
        if sim.steps >= scene.steps:
            break
        sim.step(every)
    return np.stack(frames)


def generate(seed, count, steps, every, output, threads=None, radius=None):
    rng = np.random.Generator(np.random.PCG64(seed))
    base = {"Configuration.numberOfSteps": steps}
    if radius:
        base.update({"Configuration.particleRadius": radius, "Configuration.kernelRadius": 4 * radius})
    arrays, scenes = {}, []
    vel, acc = [], []
    for k in range(count):
        overrides = {**base, **draw_overrides(rng)}
        scene = sph.load_scene(SCENE, overrides=overrides)
        x = trajectory(scene, every, threads)
        arrays[f"positions_{k}"] = x
        arrays[f"particle_type_{k}"] = np.full(x.shape[1], WATER, dtype=np.int64)
        scenes.append(overrides)
        v = np.diff(x.astype(np.float64), axis=0)
        vel.append(v.reshape(-1, 2))
        acc.append(np.diff(v, axis=0).reshape(-1, 2))
        print(f"dam_break_dataset: trajectory {k}: {x.shape[1]} particles, {x.shape[0]} frames", file=sys.stderr)
    config = scene.to_dict()
    frame_dt = every * config["Configuration"]["timeStepSize"]
    vel, acc = np.concatenate(vel), np.concatenate(acc)
    metadata = {
        "bounds": [[config["Container"]["start"][d], config["Container"]["end"][d]] for d in range(2)],
        "sequence_length": int(x.shape[0]),
        "default_connectivity_radius": config["Configuration"]["kernelRadius"],
        "dim": 2,
        "dt": frame_dt,
        "vel_mean": vel.mean(axis=0).tolist(), "vel_std": vel.std(axis=0).tolist(),
        "acc_mean": acc.mean(axis=0).tolist(), "acc_std": acc.std(axis=0).tolist(),
        "sph": {"seed": seed, "scene": os.path.relpath(SCENE, os.path.join(HERE, "..", "..")),
                "every": every, "trajectories": scenes, "version": sph.__version__},
    }
    os.makedirs(output, exist_ok=True)
    np.savez(os.path.join(output, "trajectories.npz"), **arrays)
    with open(os.path.join(output, "metadata.json"), "w") as f:
        json.dump(metadata, f, indent=1)
    return arrays, metadata


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    p.add_argument("-o", "--output", default="out/dam_break_dataset")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--count", type=int, default=20, help="dam breaks")
    p.add_argument("--steps", type=int, default=4000, help="steps of each")
    p.add_argument("--every", type=int, default=20, help="steps between stored frames")
    p.add_argument("--threads", type=int)
    p.add_argument("--quick", action="store_true", help="3 coarse dam breaks of 200 steps (CI)")
    args = p.parse_args(argv)
    if args.quick:
        generate(args.seed, 3, 200, 20, args.output, args.threads, radius=0.01)
    else:
        generate(args.seed, args.count, args.steps, args.every, args.output, args.threads)
    print(f"dam_break_dataset: wrote {args.output}/trajectories.npz and metadata.json", file=sys.stderr)


if __name__ == "__main__":
    main()
