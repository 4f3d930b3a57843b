#!/usr/bin/python3
"""Reads the frames of `sph run --format vtu,vtk,ply` back with real readers from Debian: VTK's
own readers (vtkXMLUnstructuredGridReader for .vtu, vtkGenericDataObjectReader for legacy .vtk)
and meshio (python3-meshio) for .vtk and .ply.

Usage (from ctest): /usr/bin/python3 tests/io/frame_formats_readback_test.py <sph binary> <source dir>

For every frame, the three files must hold the same points, ids and field values (PLY in single
precision), the same time, and agree with the run: the frame schedule (every N steps or frames per
simulated second), summary.json, the chosen fields and nothing else. Exits non-zero on any failure.
"""

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

import meshio
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from checks import check, run_cases  # noqa: E402  (tests/support/checks.py)

vtk.vtkOutputWindow.SetInstance(vtk.vtkStringOutputWindow())  # VTK's messages are checked, not printed
vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_OFF)

COMPONENTS = {"velocity": 3, "density": 1, "pressure": 1, "id": 1, "initial_position": 3}
PLY_NAMES = {"velocity": ["vx", "vy", "vz"], "density": ["density"], "pressure": ["pressure"], "id": ["id"],
             "initial_position": ["x0", "y0", "z0"]}


def arrays_of(point_data):
    out = {}
    for i in range(point_data.GetNumberOfArrays()):
        a = point_data.GetAbstractArray(i)
        v = vtk_to_numpy(a) if a.GetNumberOfTuples() > 0 else np.zeros((0, a.GetNumberOfComponents()))
        out[a.GetName()] = v.reshape(-1, a.GetNumberOfComponents()) if a.GetNumberOfComponents() > 1 else v.reshape(-1)
    return out


def read_vtk_file(reader, path):
    reader.SetFileName(path)
    reader.Update()
    check(reader.GetErrorCode() == 0, f"{path}: VTK reader error code {reader.GetErrorCode()}")
    out = reader.GetOutput()
    check(isinstance(out, vtk.vtkUnstructuredGrid), f"{path}: read as {type(out).__name__}, expected an unstructured grid")
    n = out.GetNumberOfPoints()
    pts = vtk_to_numpy(out.GetPoints().GetData()).reshape(-1, 3) if n > 0 else np.zeros((0, 3))
    tv = out.GetFieldData().GetArray("TimeValue")
    check(tv is not None and tv.GetNumberOfTuples() == 1, f"{path}: no TimeValue field data")
    check(out.GetNumberOfCells() == n, f"{path}: {out.GetNumberOfCells()} cells for {n} points")
    if n:
        types = {out.GetCellType(i) for i in range(0, n, max(1, n // 50))}
        check(types == {vtk.VTK_VERTEX}, f"{path}: cell types {types}, expected vertices")
    return out.GetPoints().GetDataType() if n else None, pts, tv.GetValue(0), arrays_of(out.GetPointData())


def ply_header(path):
    with open(path, "rb") as fh:
        data = fh.read()
    end = data.find(b"end_header\n")
    check(end > 0, f"{path}: no end_header")
    return data[:end].decode("ascii").splitlines()


def run_case(sph, scene, *, what, args, dim, precision, steps, dt, frame_steps, fields, formats):
    tmp = tempfile.mkdtemp(prefix="sph_formats_")
    try:
        out = os.path.join(tmp, "out")
        cmd = [sph, "run", scene, "--steps", str(steps), "--no-progress", "-o", out, *args]
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        check(p.returncode == 0, f"{what}: `{' '.join(cmd)}` exited with {p.returncode}: {p.stderr}")
        with open(os.path.join(out, "summary.json")) as fh:
            summary = json.load(fh)
        check(summary["frames"] == len(frame_steps), f"{what}: summary frames {summary['frames']}, expected {len(frame_steps)}")
        check(os.path.exists(os.path.join(out, "frames.pvd")) == ("vtu" in formats),
              f"{what}: frames.pvd present = {os.path.exists(os.path.join(out, 'frames.pvd'))} with formats {formats}")
        names = sorted(os.listdir(os.path.join(out, "frames")))
        want = sorted(f"frame_{k:06d}.{ext}" for k in range(len(frame_steps)) for ext in formats)
        check(names == want, f"{what}: frame files {names[:6]}..., expected {want[:6]}...")
        real_type = vtk.VTK_FLOAT if precision == "float" else vtk.VTK_DOUBLE
        for k, step in enumerate(frame_steps):
            stem = os.path.join(out, "frames", f"frame_{k:06d}")
            fw = f"{what}: frame {k} (step {step})"
            t_expected = step * dt
            ref = None  # (points, time, arrays) of the first format read, in double precision
            if "vtu" in formats:
                typ, pts, t, arr = read_vtk_file(vtk.vtkXMLUnstructuredGridReader(), stem + ".vtu")
                check(typ in (None, real_type), f"{fw}: .vtu points of VTK type {typ}, expected {real_type}")
                ref = (pts.astype(np.float64), t, arr)
            if "vtk" in formats:
                reader = vtk.vtkGenericDataObjectReader()
                typ, pts, t, arr = read_vtk_file(reader, stem + ".vtk")
                check(typ in (None, real_type), f"{fw}: .vtk points of VTK type {typ}, expected {real_type}")
                if ref is not None:
                    check(np.array_equal(pts, ref[0]), f"{fw}: .vtk points differ from .vtu points")
                    check(t == ref[1], f"{fw}: .vtk time {t!r} != .vtu time {ref[1]!r}")
                    check(sorted(arr) == sorted(ref[2]), f"{fw}: .vtk fields {sorted(arr)} != .vtu fields {sorted(ref[2])}")
                    for name in arr:
                        check(np.array_equal(arr[name].astype(np.float64), ref[2][name].astype(np.float64)),
                              f"{fw}: .vtk {name} differs from .vtu")
                ref = ref or (pts.astype(np.float64), t, arr)
                # meshio's own reader of the legacy format.
                m = meshio.read(stem + ".vtk")
                check(np.array_equal(m.points.astype(np.float64), ref[0]), f"{fw}: meshio .vtk points differ")
                check(sorted(m.point_data) == sorted(fields), f"{fw}: meshio .vtk fields {sorted(m.point_data)}")
                for name in fields:
                    check(np.array_equal(np.asarray(m.point_data[name], dtype=np.float64).reshape(ref[2][name].shape),
                                         ref[2][name].astype(np.float64)), f"{fw}: meshio .vtk {name} differs")
                n_cells = sum(len(c.data) for c in m.cells)
                check(n_cells == len(m.points) and all(c.type == "vertex" for c in m.cells),
                      f"{fw}: meshio .vtk cells {[(c.type, len(c.data)) for c in m.cells]}")
            pts, t, arr = ref if ref is not None else (None, None, None)
            if "ply" in formats:
                header = ply_header(stem + ".ply")
                times = [line.split()[2] for line in header if line.startswith("comment time ")]
                check(len(times) == 1, f"{fw}: .ply header has no single 'comment time' line: {header}")
                t_ply = float(times[0])
                m = meshio.read(stem + ".ply")
                expected_props = ["x", "y", "z"] + [p for f in fields for p in PLY_NAMES[f]]
                props = [line.split()[2] for line in header if line.startswith("property ")]
                check(props == expected_props, f"{fw}: .ply properties {props}, expected {expected_props}")
                check(sorted(m.point_data) == sorted(expected_props[3:]),
                      f"{fw}: meshio .ply attributes {sorted(m.point_data)}")
                if ref is not None:
                    check(t_ply == t, f"{fw}: .ply time {t_ply!r} != {t!r}")
                    check(np.array_equal(m.points, pts.astype(np.float32)), f"{fw}: .ply points != the run's, in float")
                    for name in fields:
                        cols = [m.point_data[p] for p in PLY_NAMES[name]]
                        got = np.stack(cols, axis=1) if len(cols) > 1 else cols[0]
                        want_v = arr[name].astype(np.uint32) if name == "id" else arr[name].astype(np.float32)
                        check(np.array_equal(got, want_v), f"{fw}: .ply {name} != the run's")
                    check(m.point_data.get("id", np.zeros(0, np.uint32)).dtype == np.uint32, f"{fw}: .ply id not uint32")
                else:
                    t, pts = t_ply, m.points.astype(np.float64)
                    arr = {"id": m.point_data["id"]} if "id" in fields else {}
            check(math.isclose(t, t_expected, rel_tol=1e-12, abs_tol=1e-15), f"{fw}: time {t}, expected {t_expected}")
            n = len(pts)
            if dim == 2:
                check(np.all(pts[:, 2] == 0), f"{fw}: 2D points with z != 0")
            if "id" in fields:
                check(np.array_equal(np.sort(arr["id"].astype(np.int64)), np.arange(n)), f"{fw}: ids not a permutation")
            if k == len(frame_steps) - 1:
                check(n == summary["particles"], f"{fw}: {n} points in the last frame, summary says {summary['particles']}")
        print(f"  {what}: {len(frame_steps)} frames x {formats} agree", flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    sph = os.path.abspath(sys.argv[1])
    scenes = os.path.join(os.path.abspath(sys.argv[2]), "scenes", "paper")
    every = lambda n, steps: sorted(set(range(0, steps + 1, n)) | {steps})
    all_fields = list(COMPONENTS)
    cases = [
        # dt = 1.5e-4 s at 1000 frames/s: the first step whose time reaches k / 1000 s.
        dict(what="dam_break_2d fps", scene="dam_break_2d.json", args=["--format", "vtu,vtk,ply", "--fps", "1000"],
             dim=2, precision="double", steps=30, dt=1.5e-4, frame_steps=[0, 7, 14, 20, 27, 30], fields=all_fields,
             formats=["vtu", "vtk", "ply"]),
        dict(what="block_3d float", scene="block_3d.json",
             args=["--format", "ply,vtk,vtu", "--every", "4", "--set", "Configuration.precision=float"],
             dim=3, precision="float", steps=10, dt=4e-4, frame_steps=every(4, 10), fields=all_fields,
             formats=["vtu", "vtk", "ply"]),
        # The tank's emitter: frame 0 holds no particle yet.
        dict(what="tank_fill_3d fields", scene="tank_fill_3d.json",
             args=["--format", "vtk,ply,vtu", "--every", "10", "--fields", "density,id"],
             dim=3, precision="double", steps=40, dt=3e-4, frame_steps=every(10, 40), fields=["density", "id"],
             formats=["vtu", "vtk", "ply"]),
        dict(what="dam_break_2d ply only", scene="dam_break_2d.json", args=["--format", "ply", "--every", "5",
                                                                            "--fields", "none"],
             dim=2, precision="double", steps=12, dt=1.5e-4, frame_steps=every(5, 12), fields=[], formats=["ply"]),
        dict(what="dam_break_2d vtk only", scene="dam_break_2d.json",
             args=["--format", "vtk", "--every", "6", "--fields", "velocity,id,initial_position"],
             dim=2, precision="double", steps=12, dt=1.5e-4, frame_steps=every(6, 12),
             fields=["velocity", "id", "initial_position"], formats=["vtk"]),
    ]
    def run(c):
        print(f"== {c['what']}", flush=True)
        c = dict(c)
        run_case(sph, os.path.join(scenes, c.pop("scene")), **c)

    return run_cases("frame_formats_readback", cases, run)


if __name__ == "__main__":
    sys.exit(main())
