"""Fixtures of the Python API's tests (ctest runs each test file with pytest: tests/CMakeLists.txt).

The module comes from PYTHONPATH (build/python), the sph program from SPH_EXE, the source tree
from SPH_SOURCE_DIR; ctest sets all three.
"""
import copy
import json
import os
import subprocess

import pytest

import sph

SOURCE_DIR = os.environ.get("SPH_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SPH_EXE = os.environ.get("SPH_EXE", os.path.join(SOURCE_DIR, "build", "sph"))
DAM_BREAK = os.path.join(SOURCE_DIR, "scenes", "paper", "dam_break_2d.json")

# The paper's 2D dam break with a quarter of its column: 800 particles, steps of about a millisecond.
SMALL_2D = {"FluidBlocks[0].end": [0.2, 0.4], "Configuration.numberOfSteps": 20}

# A 3D single-precision block of 6 x 6 x 6 particles falling in a box.
SMALL_3D = {
    "version": 1,
    "name": "small_3d",
    "dimension": 3,
    "Configuration": {
        "precision": "float",
        "timeStepSize": 2e-4,
        "numberOfSteps": 20,
        "particleRadius": 0.01,
        "kernelRadius": 0.04,
        "gravitation": [0, 0, -9.81],
        "neighbors": "adaptive",
    },
    "Fluid": {"density0": 1000, "stiffness": 1000, "viscosity": 1.0},
    "Container": {"start": [0, 0, 0], "end": [0.3, 0.3, 0.3]},
    "FluidBlocks": [{"start": [0.05, 0.05, 0.05], "end": [0.17, 0.17, 0.17]}],
}


@pytest.fixture
def small_2d():
    """The 800-particle dam break (double precision, standard neighbors in the file)."""
    return sph.load_scene(DAM_BREAK, overrides=SMALL_2D)


@pytest.fixture
def small_3d():
    return sph.Scene.from_dict(copy.deepcopy(SMALL_3D))


def run_sph(*args, check=True):
    """Runs the sph program; returns the CompletedProcess (stderr as text)."""
    r = subprocess.run([SPH_EXE, *map(str, args)], capture_output=True, text=True, timeout=300)
    if check and r.returncode != 0:
        raise AssertionError(f"sph {' '.join(map(str, args))} exited {r.returncode}:\n{r.stderr}")
    return r


def write_scene(scene, path):
    """Writes the scene's JSON (every key resolved) to `path`; returns the path."""
    with open(path, "w") as f:
        f.write(scene.to_json())
    return str(path)


def stats_rows(path):
    """The rows of a stats.csv as dicts of strings."""
    with open(path) as f:
        lines = f.read().splitlines()
    names = lines[0].split(",")
    return [dict(zip(names, line.split(","))) for line in lines[1:]]


def summary(run_dir):
    with open(os.path.join(run_dir, "summary.json")) as f:
        return json.load(f)
