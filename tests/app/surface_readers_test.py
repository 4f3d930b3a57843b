#!/usr/bin/env python3
"""`sph surface` and `sph run --surface` read back by real readers.

Usage: surface_readers_test.py SPH_BINARY SOURCE_DIR (ctest passes both).

Runs a small 3D and 2D scene (water filling a tank's floor, settling), meshes its frames and checks:
meshio reads the PLY and OBJ meshes (the same vertices and triangles), each 3D mesh is closed
(every edge shared by two triangles, which run along it in opposite directions) and encloses
the water's volume within 3 %; OpenVDB's own Python module (python3-openvdb) reads the .vdb:
one grid named "surface", class level set, voxel size spacing / 2, negative inside the water
and positive outside; the files are byte-identical for 1 and 3 threads (the .vdb's voxels
identical: the file itself carries a fresh UUID); `sph run --surface` writes the same files as
`sph surface`; 2D runs give closed polylines (PLY edges, OBJ lines); bad flags are refused
with exit code 2 and one message, leaving earlier surfaces in place.
"""

import filecmp
import json
import os
import subprocess
import sys
import tempfile

import numpy as np


def fail(message):
    print(f"FAIL: {message}", flush=True)
    sys.exit(1)


try:
    import meshio
    import pyopenvdb as vdb
except ImportError as e:
    fail(f"cannot import meshio or pyopenvdb ({e}); run `bash scripts/setup.sh`")

SPH = sys.argv[1]
SPACING = 0.02


def scene(dim):
    box = [0.4, 0.36, 0.3] if dim == 3 else [0.4, 0.3]
    block = [0.4, 0.24, 0.3] if dim == 3 else [0.2, 0.16]
    return {
        "version": 1, "name": f"surface_{dim}d", "dimension": dim,
        "Configuration": {"timeStepSize": 4e-4, "numberOfSteps": 40, "particleRadius": SPACING / 2,
                          "kernelRadius": 2 * SPACING, "gravitation": [0, -9.81] + ([0] if dim == 3 else []),
                          "outputEveryNSteps": 20},
        "Fluid": {"density0": 1000, "stiffness": 900, "viscosity": 3.0},
        "Container": {"start": [0] * dim, "end": box},
        "FluidBlocks": [{"start": [0] * dim, "end": block}],
    }


def sph(*args, expect=0):
    r = subprocess.run([SPH, *map(str, args)], capture_output=True, text=True)
    if r.returncode != expect:
        fail(f"sph {' '.join(map(str, args))}: exit {r.returncode}, expected {expect}\n{r.stderr}")
    return r.stderr


def check_closed(tri):
    directed = {}
    for t in tri:
        for k in range(3):
            e = (int(t[k]), int(t[(k + 1) % 3]))
            directed[e] = directed.get(e, 0) + 1
    if any(n != 1 for n in directed.values()):
        fail("a directed edge is used twice")
    if any((b, a) not in directed for (a, b) in directed):
        fail("an edge has one triangle: the mesh is open")


def volume(points, tri):
    p = points[tri]
    return np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6


with tempfile.TemporaryDirectory() as tmp:
    # --- 3D ---
    s3 = os.path.join(tmp, "s3.json")
    json.dump(scene(3), open(s3, "w"))
    run3 = os.path.join(tmp, "run3")
    sph("run", s3, "-o", run3, "--surface", "--no-progress")
    a, b = os.path.join(tmp, "a"), os.path.join(tmp, "b")
    sph("surface", run3, "-o", a, "--threads", "1", "--no-progress")
    sph("surface", run3, "-o", b, "--threads", "3", "--no-progress")
    frames = sorted(os.listdir(os.path.join(run3, "frames")))
    frames = [f for f in frames if f.endswith(".vtu")]
    if len(frames) != 3:
        fail(f"expected 3 frames, found {frames}")
    n = int(round(0.4 * 0.24 * 0.3 / SPACING**3))
    for k in range(3):
        stem = f"surface_{k:06d}"
        for ext in ("ply", "obj"):
            if not filecmp.cmp(os.path.join(a, f"{stem}.{ext}"), os.path.join(b, f"{stem}.{ext}"), shallow=False):
                fail(f"{stem}.{ext} differs between 1 and 3 threads")
            if not filecmp.cmp(os.path.join(a, f"{stem}.{ext}"), os.path.join(run3, "surface", f"{stem}.{ext}"),
                               shallow=False):
                fail(f"{stem}.{ext} of sph run --surface differs from sph surface's")
        ply = meshio.read(os.path.join(a, f"{stem}.ply"))
        obj = meshio.read(os.path.join(a, f"{stem}.obj"))
        tri = ply.cells_dict["triangle"]
        if not np.array_equal(tri, obj.cells_dict["triangle"]) or not np.allclose(ply.points, obj.points, atol=1e-6):
            fail(f"{stem}: the PLY and OBJ meshes differ")
        if len(tri) < 100:
            fail(f"{stem}: only {len(tri)} triangles")
        check_closed(tri)
        v = volume(ply.points.astype(np.float64), tri)
        if abs(v / (n * SPACING**3) - 1) > 0.03:
            fail(f"{stem}: encloses {v:.6g} m^3, the water is {n * SPACING**3:.6g} m^3 (more than 3 % off)")
        normals = np.stack([ply.point_data[c] for c in ("nx", "ny", "nz")], axis=1)
        if not np.allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-4):
            fail(f"{stem}: normals are not unit vectors")
        # The level set, read by OpenVDB itself.
        grids = [vdb.readAll(os.path.join(d, f"{stem}.vdb"))[0] for d in (a, b)]
        for gl in grids:
            if len(gl) != 1:
                fail(f"{stem}.vdb holds {len(gl)} grids, expected 1")
        g, g3 = grids[0][0], grids[1][0]
        if g.name != "surface" or g.gridClass != vdb.GridClass.LEVEL_SET:
            fail(f"{stem}.vdb: grid {g.name!r} of class {g.gridClass}, expected 'surface', level set")
        if not np.allclose(g.transform.voxelSize(), SPACING / 2):
            fail(f"{stem}.vdb: voxel size {g.transform.voxelSize()}, expected {SPACING / 2}")
        lo, hi = g.evalActiveVoxelBoundingBox()
        shape = tuple(int(h - l + 1) for l, h in zip(lo, hi))
        x, x3 = np.zeros(shape, np.float32), np.zeros(shape, np.float32)
        g.copyToArray(x, ijk=lo)
        g3.copyToArray(x3, ijk=lo)
        if not np.array_equal(x, x3):
            fail(f"{stem}.vdb: the voxels differ between 1 and 3 threads")
        acc = g.getConstAccessor()
        inside = tuple(int(round(c / (SPACING / 2))) for c in (0.2, 0.1, 0.15))
        outside = tuple(int(round(c / (SPACING / 2))) for c in (0.2, 0.34, 0.15))
        if not acc.getValue(inside) < 0 < acc.getValue(outside):
            fail(f"{stem}.vdb: {acc.getValue(inside)} inside the water, {acc.getValue(outside)} outside; expected "
                 "negative inside, positive outside")

    # --- 2D: polylines ---
    s2 = os.path.join(tmp, "s2.json")
    json.dump(scene(2), open(s2, "w"))
    run2 = os.path.join(tmp, "run2")
    sph("run", s2, "-o", run2, "--no-progress")
    out2 = os.path.join(tmp, "c")
    sph("surface", run2, "-o", out2, "--frames", "last", "--no-progress")
    if sorted(os.listdir(out2)) != ["surface_000002.obj", "surface_000002.ply"]:
        fail(f"2D surface files: {sorted(os.listdir(out2))}")
    ply2 = meshio.read(os.path.join(out2, "surface_000002.ply"))
    seg = ply2.cells_dict["line"]
    if not (np.bincount(seg[:, 0], minlength=len(ply2.points)) == 1).all() or not (
            np.bincount(seg[:, 1], minlength=len(ply2.points)) == 1).all():
        fail("2D: the surface segments do not form closed polylines")
    p = ply2.points
    area = 0.5 * (p[seg[:, 0], 0] * p[seg[:, 1], 1] - p[seg[:, 1], 0] * p[seg[:, 0], 1]).sum()
    n2 = int(round(0.2 * 0.16 / SPACING**2))
    if abs(area / (n2 * SPACING**2) - 1) > 0.03:
        fail(f"2D: the polylines enclose {area:.6g} m^2, the water is {n2 * SPACING**2:.6g} m^2")
    lines = [l.split()[1:] for l in open(os.path.join(out2, "surface_000002.obj")) if l.startswith("l ")]
    if len(lines) != 1 or lines[0][0] != lines[0][-1] or len(lines[0]) != len(seg) + 1:
        fail(f"2D: the OBJ holds {len(lines)} lines, expected one closed loop of {len(seg)} segments")

    # --- bad input: one message, exit 2, earlier surfaces kept ---
    before = sorted(os.listdir(a))
    for args, words in ((["--resolution", "0"], "--resolution: expected a number from 0.5 to 8"),
                        (["--resolution", "abc"], "--resolution: expected a number from 0.5 to 8"),
                        (["--smoothing", "9"], "--smoothing: expected a number from 1 to 4"),
                        (["--format", "stl"], 'unknown surface format "stl"'),
                        (["--format", "ply,ply"], "given twice"),
                        (["--frames", "7"], "frame 7 does not exist")):
        err = sph("surface", run3, "-o", a, *args, expect=2)
        if words not in err or err.count("error") != 1:
            fail(f"sph surface {' '.join(args)}: expected one error saying {words!r}, got:\n{err}")
    for formats in ("vdb", "ply,vdb"):  # (vdb listed with others was dropped without a word)
        err = sph("surface", run2, "--format", formats, expect=2)
        if "no level set" not in err:
            fail(f"2D --format {formats}: {err}")
    err = sph("surface", os.path.join(tmp, "missing"), expect=2)
    if sorted(os.listdir(a)) != before:
        fail("a refused call changed the earlier surfaces")

print("surface readers: meshio (PLY, OBJ), OpenVDB, thread-count determinism, 2D polylines and bad input all pass")
