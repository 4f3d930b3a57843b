"""sph.run and sph.compare do what `sph run` and `sph compare` do."""
import os

import numpy as np
import pytest

import sph
from conftest import DAM_BREAK, SMALL_2D, run_sph, stats_rows, summary, write_scene


def test_run_writes_what_sph_run_writes(small_2d, tmp_path):
    calls = []
    r = sph.run(small_2d, output=str(tmp_path / "py"), neighbors="adaptive", steps=10, threads=2,
                progress=lambda done, total: calls.append((done, total)))
    assert r["status"] == "completed" and r["steps"] == 10 and r["frames"] == 2
    assert calls == [(k, 10) for k in range(1, 11)]
    path = write_scene(small_2d, tmp_path / "scene.json")
    run_sph("run", path, "-o", tmp_path / "cli", "--neighbors", "adaptive", "--steps", 10, "--threads", 2,
            "--no-progress")
    for name in ("frame_000000.vtu", "frame_000001.vtu"):
        a = sph.read_frame(str(tmp_path / "py" / "frames" / name))
        b = sph.read_frame(str(tmp_path / "cli" / "frames" / name))
        assert set(a) == set(b)
        for k in a:
            assert np.array_equal(a[k], b[k]), (name, k)
    py_rows, cli_rows = stats_rows(tmp_path / "py" / "stats.csv"), stats_rows(tmp_path / "cli" / "stats.csv")
    assert [r["pairs_stored"] for r in py_rows] == [r["pairs_stored"] for r in cli_rows]
    assert summary(tmp_path / "py")["neighbors"] == "adaptive"


def test_read_frame_reads_the_boundary_samples_file(tmp_path):
    scene = sph.load_scene(DAM_BREAK, overrides={**SMALL_2D, "Configuration.boundaryHandling": "particles",
                                                 "Configuration.outputBoundary": True})
    sph.run(scene, output=tmp_path / "run", steps=2)
    b = sph.read_frame(tmp_path / "run" / "boundary.vtu")
    assert set(b) == {"time", "position", "id", "psi"}
    n = len(b["position"])
    assert n > 100 and b["psi"].shape == (n,) and np.all(b["psi"] > 0)
    assert np.array_equal(b["id"], np.arange(n))  # the sample index


def test_run_progress_lines(small_2d, tmp_path, capfd):
    sph.run(small_2d, output=str(tmp_path / "p"), steps=10, progress=True)
    err = capfd.readouterr().err
    assert "step 10 of 10 (100 %)" in err and err.count("\n") == 10
    # A run of CFL steps to stopAt counts in simulated time, as sph run does: its step count is only
    # a bound (a DFSPH dam break to 0.05 s takes a few dozen of its 5,000), and lines by steps
    # printed none at all.
    dfsph = sph.load_scene(os.path.join(os.path.dirname(DAM_BREAK), "..", "dfsph", "dam_break_2d.json"),
                           overrides={"Configuration.stopAt": 0.05})
    r = sph.run(dfsph, output=str(tmp_path / "t"), threads=1, progress=True)
    err = capfd.readouterr().err
    assert r["steps"] < dfsph.steps
    assert "t = 0.05 of 0.05 s (100 %)" in err and err.count("(") == 10, err


def test_run_errors(small_2d, tmp_path):
    with pytest.raises(sph.SceneError):
        sph.run(small_2d, output=str(tmp_path / "x"), neighbors="fastest")
    with pytest.raises(ValueError):
        sph.run(small_2d, output=str(tmp_path / "x"), steps=0)
    with pytest.raises(TypeError):
        sph.run(small_2d, output=str(tmp_path / "x"), progress=3)
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(sph.Error):
        sph.run(small_2d, output=str(blocker / "sub"))
    # The checks sph run makes of -o: not "" or the root, not a directory of the user's own files.
    for out in ("", "/", "//.."):
        with pytest.raises(sph.Error, match="empty directory name|root of the file system"):
            sph.run(small_2d, output=out)
        with pytest.raises(sph.Error, match="empty directory name|root of the file system"):
            sph.compare(small_2d, output=out, steps=2)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "scene.json").write_text("my scene")
    with pytest.raises(sph.Error, match="not the directory of an earlier run .* overwrite=True"):
        sph.run(small_2d, output=str(mine), steps=2)
    assert (mine / "scene.json").read_text() == "my scene"
    # Paths as pathlib.Path, as str.
    write_scene(small_2d, tmp_path / "from_path.json")
    from_path = sph.load_scene(tmp_path / "from_path.json")  # a pathlib.Path
    assert from_path == small_2d
    r = sph.run(from_path, output=tmp_path / "as_path", steps=2)
    assert r["status"] == "completed" and r["output"] == str(tmp_path / "as_path")
    assert sph.read_frame(tmp_path / "as_path" / "frames" / "frame_000000.vtu")["position"].shape[0] > 0


def test_compare(small_2d, tmp_path):
    seen = set()
    r = sph.compare(small_2d, output=str(tmp_path / "cmp"), modes=["adaptive", "verlet"], steps=10, frames=1,
                    progress=lambda label, index, count, done, total: seen.add((label, count)))
    labels = [run["label"] for run in r["runs"]]
    assert labels[0] == "standard" and "adaptive" in labels and "verlet" in labels
    assert {label for label, _ in seen} == set(labels)
    for run in r["runs"]:
        assert run["failure"] == "" and run["steps"] == 10
    verlet = r["runs"][labels.index("verlet")]
    assert verlet["missed_pairs"] == 0  # exact lists (adaptive's approximation misses a few)
    assert all(run["boundary_missed_pairs"] == 0 for run in r["runs"])  # penalty walls: no samples
    assert verlet["final_rms_divergence"] is not None and r["runs"][0]["final_rms_divergence"] is None
    assert os.path.isfile(r["report"])
    assert sph.compare(small_2d, modes=["verlet"], steps=5, audit=False)["output"] is None
    done = []  # at every twentieth of the steps, as python.md says
    sph.compare(small_2d, modes=["verlet"], steps=50, audit=False,
                progress=lambda label, index, count, d, total: done.append(d) if index == 0 else None)
    assert done == list(range(2, 51, 2))
    with pytest.raises(sph.Error, match="too slow to time") as e:
        sph.compare(small_2d, modes=["brute_force"])
    assert e.value.where == "modes"
    with pytest.raises(sph.Error) as e:
        sph.compare(small_2d, modes=["fastest"])
    assert e.value.where == "modes"
    assert "verlet_clusters" in str(e.value) and "brute_force" not in str(e.value)  # the modes compare takes
    with pytest.raises(TypeError, match="perturbation must be a number"):
        sph.compare(small_2d, modes=["verlet"], perturbation=True)  # (pybind11 alone took True as 1.0)
    with pytest.raises(ValueError, match="perturbation must be 0 to 0.1"):
        sph.compare(small_2d, modes=["verlet"], perturbation=0.5)
