#!/usr/bin/python3
"""Reads the output of `sph run` back with VTK's own XML reader (Debian's python3-vtk9).

Usage (from ctest): /usr/bin/python3 tests/io/vtk_readback_test.py <sph binary> <source dir>

Runs three paper scenes for a few steps (2D double, 3D float, 3D double with an emitter) and
checks frames.pvd, every .vtu frame it lists, stats.csv and summary.json against each other
and against what the scene implies. Exits non-zero on any failure.
"""

import csv
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

# Must equal kStatsColumns in src/sph/io/run_output.h.
STATS_COLUMNS = ("step,time,particles,kinetic_energy,max_speed,mean_neighbors,lists_rebuilt,pairs_stored,"
                 "pairs_within_h,missed_pairs,particles_missing,max_missed_penetration,"
                 "t_grid,t_lists,t_density,t_forces,t_integrate,t_output,"
                 "outside,outside_depth,inside_solid,inside_depth,max_mach,rho_min,rho_max,energy,"
                 "boundary_pairs_stored,boundary_missed_pairs,"
                 "entries_rebuilt,list_insertions,list_removals,list_overflows,skin,dt,solver_iterations,density_error,"
                 "divergence_iterations,divergence_error,t_solve,viscosity_iterations,viscosity_error")
PHASES = ("grid", "lists", "density", "forces", "integrate", "solve", "output")
POINT_FIELDS = {"velocity": 3, "density": 1, "pressure": 1, "id": 1, "initial_position": 3}


# ---- VTK error capture ------------------------------------------------------------------------

class ErrorObserver:
    """Collects ErrorEvent/WarningEvent messages of a VTK object."""

    def __init__(self):
        self.messages = []

    def __call__(self, obj, event, calldata=None):
        self.messages.append(f"{event}: {calldata if calldata is not None else obj.GetClassName()}")


ErrorObserver.__call__.CallDataType = vtk.VTK_STRING

# Everything VTK would print (e.g. errors of the reader's internal XML parser, which has no
# observer of ours) goes into this string instead of the terminal.
_output_window = vtk.vtkStringOutputWindow()
vtk.vtkOutputWindow.SetInstance(_output_window)
# VTK also logs errors to stderr through vtkLogger; they are already captured above (and
# printed by the failing check), so keep the negative controls below quiet.
vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_OFF)


def read_vtu(path):
    """Reads a .vtu; returns (output, list of error/warning messages)."""
    start = len(_output_window.GetOutput() or "")
    reader = vtk.vtkXMLUnstructuredGridReader()
    obs = ErrorObserver()
    reader.AddObserver("ErrorEvent", obs)
    reader.AddObserver("WarningEvent", obs)
    reader.SetFileName(str(path))
    reader.Update()
    errors = list(obs.messages)
    if reader.GetErrorCode() != 0:
        errors.append(f"error code {reader.GetErrorCode()}")
    text = (_output_window.GetOutput() or "")[start:].strip()
    if text:
        errors.append(text)
    return reader.GetOutput(), errors


# ---- helpers ----------------------------------------------------------------------------------

def run_sph(sph, args, what):
    cmd = [sph, "run", *args, "--no-progress"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        print(p.stdout)
        print(p.stderr)
    check(p.returncode == 0, f"{what}: `{' '.join(cmd)}` exited with {p.returncode}")


def read_pvd(out, what):
    pvd = os.path.join(out, "frames.pvd")
    check(os.path.isfile(pvd), f"{what}: frames.pvd missing")
    root = ET.parse(pvd).getroot()
    check(root.tag == "VTKFile" and root.get("type") == "Collection",
          f"{what}: frames.pvd root is {root.tag} type={root.get('type')}, expected VTKFile type=Collection")
    coll = root.find("Collection")
    check(coll is not None, f"{what}: frames.pvd has no <Collection>")
    entries = [(float(d.get("timestep")), d.get("file")) for d in coll.findall("DataSet")]
    check(len(entries) > 0, f"{what}: frames.pvd lists no frames")
    times = [t for t, _ in entries]
    check(times[0] == 0.0, f"{what}: first frame time is {times[0]}, expected 0")
    check(all(b > a for a, b in zip(times, times[1:])), f"{what}: frame times do not increase: {times}")
    for t, f in entries:
        check(f is not None and os.path.isfile(os.path.join(out, f)), f"{what}: frame file {f} (t={t}) missing")
    return entries


def read_stats(out, what):
    path = os.path.join(out, "stats.csv")
    check(os.path.isfile(path), f"{what}: stats.csv missing")
    with open(path, newline="") as fh:
        lines = fh.read().splitlines()
    check(lines and lines[0] == STATS_COLUMNS,
          f"{what}: stats.csv header is {lines[0] if lines else '(empty)'!r}, expected {STATS_COLUMNS!r}")
    rows = list(csv.DictReader(lines))
    ncols = len(STATS_COLUMNS.split(","))
    for i, line in enumerate(lines[1:]):
        check(len(line.split(",")) == ncols, f"{what}: stats.csv line {i + 2} has {len(line.split(','))} columns")
    return rows


def read_summary(out, what):
    path = os.path.join(out, "summary.json")
    check(os.path.isfile(path), f"{what}: summary.json missing")
    with open(path) as fh:
        return json.load(fh)


# ---- one run ----------------------------------------------------------------------------------

def check_run(out, *, what, dim, precision, steps, every, dt, expected_particles):
    """expected_particles(steps_done) -> particle count after that many steps."""
    float_type = vtk.VTK_FLOAT if precision == "float" else vtk.VTK_DOUBLE
    float_name = "Float32" if precision == "float" else "Float64"

    # summary.json
    summary = read_summary(out, what)
    check(summary.get("status") == "completed", f"{what}: summary status is {summary.get('status')!r}")
    check(summary.get("steps") == steps, f"{what}: summary steps {summary.get('steps')} != {steps}")
    check(summary.get("particles") == expected_particles(steps),
          f"{what}: summary particles {summary.get('particles')} != {expected_particles(steps)}")
    check(summary.get("dimension") == dim, f"{what}: summary dimension {summary.get('dimension')} != {dim}")
    check(summary.get("precision") == precision, f"{what}: summary precision {summary.get('precision')!r}")
    check(math.isclose(summary.get("time_step", -1), dt, rel_tol=1e-12), f"{what}: summary time_step != {dt}")
    check(math.isclose(summary.get("simulated_time", -1), steps * dt, rel_tol=1e-9),
          f"{what}: summary simulated_time {summary.get('simulated_time')} != {steps * dt}")
    phases = summary.get("phase_seconds")
    check(isinstance(phases, dict) and set(phases) == set(PHASES),
          f"{what}: summary phase_seconds keys {sorted(phases) if isinstance(phases, dict) else phases}, "
          f"expected {sorted(PHASES)}")
    check(all(isinstance(v, (int, float)) and v >= 0 and math.isfinite(v) for v in phases.values()),
          f"{what}: phase_seconds not all finite and >= 0: {phases}")

    # stats.csv
    rows = read_stats(out, what)
    check(len(rows) == steps, f"{what}: stats.csv has {len(rows)} rows, expected {steps}")
    for i, r in enumerate(rows):
        step = int(r["step"])
        t = float(r["time"])
        n = int(r["particles"])
        check(step == i + 1, f"{what}: stats.csv row {i} has step {step}, expected the steps done {i + 1}")
        check(math.isclose(t, (i + 1) * dt, rel_tol=1e-8), f"{what}: stats.csv step {i} time {t} != {(i + 1) * dt}")
        check(n == expected_particles(i + 1), f"{what}: stats.csv step {i} particles {n} != {expected_particles(i + 1)}")
        mn = float(r["mean_neighbors"])
        check(mn > 0 and math.isfinite(mn), f"{what}: stats.csv step {i} mean_neighbors {mn} not > 0")
        pairs = int(r["pairs_stored"])
        check(math.isclose(mn, pairs / n, rel_tol=1e-5), f"{what}: step {i} mean_neighbors {mn} != pairs/particles")
        ke = float(r["kinetic_energy"])
        ms = float(r["max_speed"])
        check(math.isfinite(ke) and ke >= 0 and math.isfinite(ms) and ms >= 0,
              f"{what}: stats.csv step {i} kinetic_energy {ke} / max_speed {ms}")
        for c in ("t_grid", "t_lists", "t_density", "t_forces", "t_integrate", "t_solve", "t_output"):
            check(float(r[c]) >= 0, f"{what}: stats.csv step {i} {c} = {r[c]} < 0")
    check(int(rows[-1]["particles"]) == summary["particles"],
          f"{what}: last stats row particles {rows[-1]['particles']} != summary {summary['particles']}")
    check(math.isclose(float(rows[-1]["kinetic_energy"]), summary["kinetic_energy"], rel_tol=1e-8),
          f"{what}: last stats kinetic_energy != summary kinetic_energy")

    # frames.pvd and every frame
    entries = read_pvd(out, what)
    expected_steps = sorted(set(list(range(0, steps + 1, every)) + [steps]))
    check(len(entries) == len(expected_steps),
          f"{what}: frames.pvd lists {len(entries)} frames, expected {len(expected_steps)} (steps {expected_steps})")
    check(summary.get("frames") == len(entries), f"{what}: summary frames {summary.get('frames')} != {len(entries)}")
    last_n = None
    for k, ((t, f), s) in enumerate(zip(entries, expected_steps)):
        fw = f"{what}: {f}"
        check(math.isclose(t, s * dt, rel_tol=1e-8, abs_tol=1e-15), f"{fw}: timestep {t}, expected {s * dt} (step {s})")
        if s > 0:
            row = rows[s - 1]
            check(math.isclose(float(row["time"]), t, rel_tol=1e-8), f"{fw}: stats row {s - 1} time != frame time {t}")
            n_expected = int(row["particles"])
        else:
            n_expected = expected_particles(0)
        check(n_expected == expected_particles(s), f"{fw}: expected count mismatch")

        grid, errors = read_vtu(os.path.join(out, f))
        check(not errors, f"{fw}: VTK reader reported: {errors}")
        n = grid.GetNumberOfPoints()
        check(n == n_expected, f"{fw}: {n} points, expected {n_expected}")
        check(grid.GetNumberOfCells() == n, f"{fw}: {grid.GetNumberOfCells()} cells, expected {n}")
        if last_n is not None:
            check(n >= last_n and (n - last_n) % 36 == 0,
                  f"{fw}: particle count went from {last_n} to {n} (expected growth by batches of 36)")
        last_n = n

        pts = grid.GetPoints()
        check(pts is not None, f"{fw}: no points")
        check(pts.GetDataType() == float_type,
              f"{fw}: points are {pts.GetData().GetDataTypeAsString()}, expected {float_name}")
        pos = vtk_to_numpy(pts.GetData()).reshape(-1, 3) if n > 0 else np.zeros((0, 3))
        pd = grid.GetPointData()
        arrays = {}
        for name, comps in POINT_FIELDS.items():
            a = pd.GetArray(name)
            check(a is not None, f"{fw}: point field {name!r} missing")
            check(a.GetNumberOfComponents() == comps,
                  f"{fw}: {name} has {a.GetNumberOfComponents()} components, expected {comps}")
            check(a.GetNumberOfTuples() == n, f"{fw}: {name} has {a.GetNumberOfTuples()} tuples, expected {n}")
            if name == "id":
                check(a.GetDataType() in (vtk.VTK_UNSIGNED_LONG_LONG, vtk.VTK_UNSIGNED_LONG) and
                      a.GetDataTypeSize() == 8, f"{fw}: id is {a.GetDataTypeAsString()}, expected UInt64")
            else:
                check(a.GetDataType() == float_type, f"{fw}: {name} is {a.GetDataTypeAsString()}, expected {float_name}")
            v = vtk_to_numpy(a) if n > 0 else np.zeros((0,) if comps == 1 else (0, comps))
            arrays[name] = v.reshape(-1, comps) if comps > 1 else v.reshape(-1)

        ids = arrays["id"]
        check(np.array_equal(np.sort(ids), np.arange(n, dtype=np.uint64)), f"{fw}: ids are not a permutation of 0..{n - 1}")
        for name in ("velocity", "initial_position", "density", "pressure"):
            check(np.all(np.isfinite(arrays[name])), f"{fw}: {name} has non-finite values")
        check(np.all(np.isfinite(pos)), f"{fw}: positions have non-finite values")
        if dim == 2:
            check(np.all(pos[:, 2] == 0), f"{fw}: 2D positions have z != 0")
            check(np.all(arrays["velocity"][:, 2] == 0), f"{fw}: 2D velocities have z != 0")
            check(np.all(arrays["initial_position"][:, 2] == 0), f"{fw}: 2D initial positions have z != 0")
        if k == 0:
            check(np.array_equal(arrays["initial_position"], pos), f"{fw}: first frame initial_position != position")
        dens = arrays["density"]
        # Every frame, frame 0 included (the simulation computes the initial densities).
        check(np.all(dens > 0), f"{fw}: densities not all positive (min {dens.min() if n else None})")
        check(np.all(arrays["pressure"] >= 0), f"{fw}: negative pressure with negativePressure=clamp")
        if n > 0:
            print(f"  {fw}: {n} points, density {dens.min():.1f}..{dens.max():.1f} (mean {dens.mean():.1f}), "
                  f"max speed {np.linalg.norm(arrays['velocity'], axis=1).max():.3f} m/s")

    check(last_n == summary["particles"], f"{what}: last frame has {last_n} points, summary says {summary['particles']}")
    return entries


def check_reader_catches_corruption(out, entry_file, what):
    """Negative controls: damaged copies of a frame must be reported by the error capture."""
    src = os.path.join(out, entry_file)
    bad = os.path.join(out, "damaged.vtu")
    with open(src, "rb") as fh:
        data = fh.read()
    n = read_vtu(src)[0].GetNumberOfPoints()
    damaged = {
        "truncated to half": data[: len(data) // 2],
        "NumberOfPoints off by one": data.replace(f'NumberOfPoints="{n}"'.encode(), f'NumberOfPoints="{n + 1}"'.encode(), 1),
    }
    for how, content in damaged.items():
        check(content != data, f"{what}: could not build the damaged frame ({how})")
        with open(bad, "wb") as fh:
            fh.write(content)
        _, errors = read_vtu(bad)
        check(errors, f"{what}: reading a frame {how} reported no error; the error capture does not work")


# ---- main -------------------------------------------------------------------------------------

def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    sph = os.path.abspath(sys.argv[1])
    src = os.path.abspath(sys.argv[2])
    scenes = os.path.join(src, "scenes", "paper")

    cases = [
        dict(what="dam_break_2d", scene="dam_break_2d.json", dim=2, precision="double", steps=20, every=10, dt=1.5e-4,
             extra=[], expected_particles=lambda s: 3200),
        dict(what="block_3d(float)", scene="block_3d.json", dim=3, precision="float", steps=10, every=5, dt=4e-4,
             extra=["--set", "Configuration.precision=float"], expected_particles=lambda s: 4000),
        # Emitter: a 6 x 6 layer at the start of steps 0, 16, 32, ...
        dict(what="tank_fill_3d", scene="tank_fill_3d.json", dim=3, precision="double", steps=40, every=10, dt=3e-4,
             extra=[], expected_particles=lambda s: 36 * ((s + 15) // 16)),
    ]
    def run(c):
        tmp = tempfile.mkdtemp(prefix=f"sph_vtk_{c['what'].split('(')[0]}_")
        try:
            out = os.path.join(tmp, "out")
            print(f"== {c['what']}: {c['steps']} steps, a frame every {c['every']}", flush=True)
            run_sph(sph, [os.path.join(scenes, c["scene"]), "--steps", str(c["steps"]),
                          "--set", f"Configuration.outputEveryNSteps={c['every']}", *c["extra"], "-o", out], c["what"])
            entries = check_run(out, what=c["what"], dim=c["dim"], precision=c["precision"], steps=c["steps"],
                                every=c["every"], dt=c["dt"], expected_particles=c["expected_particles"])
            check_reader_catches_corruption(out, entries[-1][1], c["what"])
        finally:
            shutil.rmtree(tmp, ignore_errors=True)

    return run_cases("vtk_readback", cases, run)


if __name__ == "__main__":
    sys.exit(main())
