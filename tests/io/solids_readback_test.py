#!/usr/bin/python3
"""Reads the obstacles' surfaces that `sph run` writes with each frame back with VTK's own XML
reader (Debian's python3-vtk9).

Usage (from ctest): /usr/bin/python3 tests/io/solids_readback_test.py <sph binary> <source dir>

Runs the example scenes with moving obstacles for a short time (the 2D flume's oscillating
paddle, the 3D stirred tank's turning plate) and checks that solids.pvd lists one
frames/solids_NNNNNN.vtp per frame at the frames' times, that VTK reads each without an error,
and that each box's corners are where its motion puts it at that time (the paddle's translation,
the plate's rotation about its axis) with its faces turned outwards. Exits non-zero on any
failure.
"""

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from checks import check, run_cases  # noqa: E402  (tests/support/checks.py)

vtk.vtkOutputWindow.SetInstance(vtk.vtkStringOutputWindow())
vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_OFF)


def read_collection(path, what):
    check(os.path.isfile(path), f"{what}: {os.path.basename(path)} missing")
    coll = ET.parse(path).getroot().find("Collection")
    check(coll is not None, f"{what}: {path} has no <Collection>")
    return [(float(d.get("timestep")), d.get("file")) for d in coll.findall("DataSet")]


def read_vtp(path, what):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    check(reader.GetErrorCode() == 0, f"{what}: VTK could not read {path} (error {reader.GetErrorCode()})")
    return reader.GetOutput()


def expected_corners(scene, t):
    """Each obstacle's corners (corner c: bit d picks the upper end along axis d) at time t, from
    the run's scene.json, as docs/physics.md "Moving obstacles" writes the motions."""
    dim = scene["dimension"]
    out = []
    for o in scene["Obstacles"]:
        lo, hi, m = np.array(o["start"], float), np.array(o["end"], float), o["motion"]
        corners = np.array([[hi[d] if c >> d & 1 else lo[d] for d in range(dim)] for c in range(1 << dim)])
        if m["type"] == "oscillation":
            r = min(t / m["rampTime"], 1.0) if m["rampTime"] > 0 else 1.0
            s = m["amplitude"] * r * (math.sin(2 * math.pi * t / m["period"] + m["phase"]) - math.sin(m["phase"]))
            corners = corners + s * np.array(m["direction"], float) / np.linalg.norm(m["direction"])
        elif m["type"] == "rotation":
            w, ramp = m["angularVelocity"], m["rampTime"]
            angle = w * t * t / (2 * ramp) if t < ramp else w * (t - 0.5 * ramp)
            k = np.array(m["axis"], float)
            k /= np.linalg.norm(k)
            c = np.array(m["center"], float)
            rel = corners - c  # Rodrigues' rotation about k
            corners = c + (rel * math.cos(angle) + np.cross(k, rel) * math.sin(angle) +
                           np.outer(rel @ k, k) * (1 - math.cos(angle)))
        out.append(corners)
    return out


def run_sph(sph, args, what):
    p = subprocess.run([sph, "run", *args, "--no-progress"], capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        print(p.stdout, p.stderr)
    check(p.returncode == 0, f"{what}: sph run exited with {p.returncode}")


def check_run(out, what):
    with open(os.path.join(out, "scene.json")) as fh:
        scene = json.load(fh)
    dim = scene["dimension"]
    frames = read_collection(os.path.join(out, "frames.pvd"), what)
    solids = read_collection(os.path.join(out, "solids.pvd"), what)
    check(len(solids) == len(frames) >= 3, f"{what}: {len(solids)} solids for {len(frames)} frames")
    for (tf, _), (ts, f) in zip(frames, solids):
        check(tf == ts, f"{what}: solids at t = {ts}, frame at t = {tf}")
        poly = read_vtp(os.path.join(out, f), what)
        pts = vtk_to_numpy(poly.GetPoints().GetData())
        boxes = expected_corners(scene, ts)
        per_box = 1 << dim
        check(pts.shape == (per_box * len(boxes), 3), f"{what}: {f} has {pts.shape} points")
        for k, corners in enumerate(boxes):
            err = np.abs(pts[k * per_box:(k + 1) * per_box, :dim] - corners).max()
            check(err < 1e-9, f"{what}: {f}: obstacle {k}'s corners are {err:.3g} m from where its motion puts them")
        check(poly.GetNumberOfPolys() == len(boxes) * (6 if dim == 3 else 1), f"{what}: {f}: polygon count")
        ply = os.path.join(out, f[:-4] + ".ply")
        if "ply" in scene["Configuration"]["outputFormats"]:
            # The PLY mesh beside the PLY frames: the same corners and quads.
            with open(ply) as fh:
                lines = fh.read().splitlines()
            check(lines[0] == "ply" and any(l.startswith("comment time ") and float(l.split()[2]) == ts
                                            for l in lines[:8]), f"{what}: {ply} has no time {ts} in its header")
            end = lines.index("end_header")
            nv = int(next(l for l in lines if l.startswith("element vertex")).split()[2])
            nf = int(next(l for l in lines if l.startswith("element face")).split()[2])
            verts = np.array([[float(v) for v in l.split()] for l in lines[end + 1:end + 1 + nv]])
            check(np.array_equal(verts, pts), f"{what}: {ply}'s vertices differ from the .vtp's points")
            check(nf == poly.GetNumberOfPolys() and all(l.startswith("4 ") for l in lines[end + 1 + nv:]),
                  f"{what}: {ply}: {nf} faces")
        else:
            check(not os.path.exists(ply), f"{what}: {ply} written without the ply format")
        ids = vtk_to_numpy(poly.GetCellData().GetArray("obstacle"))
        check(sorted(set(ids.tolist())) == list(range(len(boxes))), f"{what}: {f}: obstacle ids {set(ids.tolist())}")
        if dim == 3:
            # Outward faces: each face's normal points away from its box's centre.
            normals = vtk.vtkPolyDataNormals()
            normals.SetInputData(poly)
            normals.ComputeCellNormalsOn()
            normals.ComputePointNormalsOff()
            normals.AutoOrientNormalsOff()
            normals.ConsistencyOff()
            normals.SplittingOff()
            normals.Update()
            n = vtk_to_numpy(normals.GetOutput().GetCellData().GetNormals())
            cells = poly.GetPolys()
            idl = vtk.vtkIdList()
            cells.InitTraversal()
            for c in range(poly.GetNumberOfPolys()):
                cells.GetNextCell(idl)
                q = np.array([pts[idl.GetId(j)] for j in range(idl.GetNumberOfIds())])
                centre = pts[ids[c] * per_box:(ids[c] + 1) * per_box].mean(axis=0)
                check(np.dot(n[c], q.mean(axis=0) - centre) > 0, f"{what}: {f}: face {c} turned inwards")


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    sph, src = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    examples = os.path.join(src, "scenes", "examples")
    cases = [
        dict(what="wave_flume_2d", scene="wave_flume_2d.json",
             extra=["--set", "Configuration.stopAt=0.6", "--set", 'Configuration.outputFormats=["vtu", "ply"]']),
        dict(what="stirred_tank_3d", scene="stirred_tank_3d_wcsph.json",
             extra=["--set", "Configuration.stopAt=0.05", "--set", "Configuration.outputFps=100"]),
    ]

    def run(c):
        tmp = tempfile.mkdtemp(prefix="sph_solids_")
        try:
            out = os.path.join(tmp, "out")
            print(f"== {c['what']}", flush=True)
            run_sph(sph, [os.path.join(examples, c["scene"]), *c["extra"], "-o", out], c["what"])
            check_run(out, c["what"])
        finally:
            shutil.rmtree(tmp, ignore_errors=True)

    return run_cases("solids_readback", cases, run)


if __name__ == "__main__":
    sys.exit(main())
