"""Every exception type of the module, each with the message `sph run` gives for the same input."""
import json
import warnings

import numpy as np
import pytest

import sph
from conftest import DAM_BREAK, SMALL_2D, run_sph


def dam_break_dict():
    with open(DAM_BREAK) as f:
        return json.load(f)


def test_the_error_types():
    assert issubclass(sph.Error, RuntimeError)
    assert issubclass(sph.SceneError, sph.Error) and issubclass(sph.SceneError, ValueError)
    assert issubclass(sph.SimulationError, sph.Error)
    assert issubclass(sph.HealthWarning, UserWarning)


def test_a_misspelt_key_names_its_path_with_the_message_of_sph_run(tmp_path):
    d = dam_break_dict()
    d["Fluid"]["stiffnes"] = d["Fluid"].pop("stiffness")
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))
    with pytest.raises(sph.SceneError) as file_error:
        sph.load_scene(str(path))
    e = file_error.value
    assert e.key == "Fluid.stiffnes"
    assert e.where == f"{path}: Fluid.stiffnes"
    assert str(e) == f"{e.where}: {e.message}" and "stiffness" in e.message  # it names the expected key
    r = run_sph("run", path, "-o", tmp_path / "out", check=False)
    assert r.returncode == 2 and f"sph: error: {e}\n" in r.stderr
    # The same from a dict, named "<dict>".
    with pytest.raises(sph.SceneError) as dict_error:
        sph.Scene.from_dict(d)
    assert dict_error.value.key == "Fluid.stiffnes" and dict_error.value.message == e.message
    assert dict_error.value.where == "<dict>: Fluid.stiffnes"


def test_bad_values_and_overrides(small_2d):
    with pytest.raises(sph.SceneError) as e:
        sph.load_scene(DAM_BREAK, overrides={"Fluid.density0": -5})
    # Named as the argument that gave the value (as "--set KEY" until 2026-12-07, the CLI's flag).
    assert e.value.key == "Fluid.density0" and 'overrides["Fluid.density0"]' in e.value.where
    assert "--set" not in str(e.value)
    with pytest.raises(sph.SceneError) as e:
        sph.load_scene(DAM_BREAK, overrides={"FluidBlocks[3].end": [1, 1]})
    assert str(e.value).startswith('overrides["FluidBlocks[3].end"]: ') and "index 3 does not exist" in str(e.value)
    with pytest.raises(sph.SceneError) as e:
        small_2d.with_overrides({"Configuration.neighbors": "fastest"})
    assert e.value.key == "Configuration.neighbors"
    for mode in sph.NEIGHBOR_MODES:
        assert mode in e.value.message  # the accepted names
    with pytest.raises(sph.SceneError) as e:
        sph.Simulation(small_2d, neighbors="fastest")
    assert e.value.key == "Configuration.neighbors"
    # The name as given, not read as JSON (a backslash escape made "verlet" of this one)
    with pytest.raises(sph.SceneError, match="unknown value"):
        sph.Simulation(small_2d, neighbors="ve\\u0072let")
    with pytest.raises(sph.SceneError, match="NaN or infinite") as e:
        sph.load_scene(DAM_BREAK, overrides={"Fluid.stiffness": float("nan")})
    assert e.value.key == "Fluid.stiffness"  # (the override named, as the reader names one)
    assert e.value.where.endswith('(overrides["Fluid.stiffness"]): Fluid.stiffness')
    with pytest.raises(TypeError, match="dict"):
        sph.load_scene(DAM_BREAK, overrides=["Fluid.stiffness=3"])
    with pytest.raises(TypeError, match="scene value"):
        sph.Scene.from_dict({"version": 1, "name": object()})
    # NumPy numbers are numbers.
    s = sph.load_scene(DAM_BREAK, overrides={"Fluid.stiffness": np.float64(1700), "FluidBlocks[0].end": np.array([0.2, 0.4])})
    assert s.to_dict()["Fluid"]["stiffness"] == 1700


def test_syntax_errors_and_files():
    with pytest.raises(sph.SceneError) as e:
        sph.Scene.from_json('{"version": 1,\n "name": }', source="inline")
    assert e.value.key is None and e.value.where.startswith("inline:2:")
    with pytest.raises(sph.SceneError) as e:
        sph.load_scene("/no/such/scene.json")
    assert e.value.where == "/no/such/scene.json" and e.value.key is None


def test_scene_round_trip(small_2d):
    again = sph.Scene.from_dict(small_2d.to_dict())
    assert again.to_dict() == small_2d.to_dict() and again.source == "<dict>"
    assert again == small_2d  # (equal though read from elsewhere: they run the same way)
    assert small_2d != sph.Scene.from_dict({**small_2d.to_dict(), "name": "other"})
    assert (small_2d == None) is False and small_2d not in [None, 1, "scene"]  # noqa: E711
    assert sph.Scene.from_json(small_2d.to_json(), source=small_2d.source) == small_2d
    assert small_2d.dimension == 2 and small_2d.precision == "double" and small_2d.steps == 20
    assert small_2d.name == "dam_break_2d" and small_2d.source == DAM_BREAK


def test_a_blow_up_raises_simulation_error_and_stops_the_simulation(small_2d):
    sim = sph.Simulation(small_2d)
    v = np.zeros((len(sim), 2))
    v[5] = [400.0, 0.0]  # ten times the speed of sound
    sim.velocities = v
    with pytest.raises(sph.SimulationError) as e:
        sim.step(5)
    assert "supersonic" in e.value.message and "particle id 5" in e.value.message
    assert sim.steps == 1  # the failed step's state
    with pytest.raises(sph.SimulationError, match="failed earlier"):
        sim.step()


def test_a_health_warning_is_a_python_warning(small_2d):
    sim = sph.Simulation(small_2d)
    v = np.zeros((len(sim), 2))
    v[5] = [20.0, 0.0]  # Mach 0.5: past the warning level 0.3, below the failure level 1
    sim.velocities = v
    with pytest.warns(sph.HealthWarning) as given:
        sim.step(1)
    texts = [str(w.message) for w in given]
    assert texts == sim.warnings
    assert any(w.startswith("Mach 0.49") for w in texts)
    with warnings.catch_warnings(record=True) as later:
        warnings.simplefilter("always")
        sim.step(2)
    assert not {str(w.message) for w in later} & set(texts)  # each kind once
    assert sim.steps == 3


def test_argument_errors(small_2d):
    with pytest.raises(ValueError, match="threads"):
        sph.Simulation(small_2d, threads=0)
    sim = sph.Simulation(small_2d)
    with pytest.raises(ValueError, match="0 or more"):
        sim.step(-1)
    with pytest.raises(TypeError):
        sim.step("two")
    with pytest.raises(ValueError, match="threads"):
        sim.threads = 0
    # Named, not pybind11's "Unable to cast Python instance to C++ type".
    for threads, error in ((2.5, TypeError), (True, TypeError), (10**12, ValueError)):
        with pytest.raises(error, match="threads must be a whole number from 1 to 4096"):
            sph.Simulation(small_2d, threads=threads)
        with pytest.raises(error, match="threads must be a whole number from 1 to 4096"):
            sim.threads = threads
    assert sim.threads >= 1
    with pytest.raises(TypeError, match="checkpoint_every must be a whole number"):
        sph.run(small_2d, output="x", steps=2, checkpoint_every=2.5)
    with pytest.raises(ValueError, match="checkpoint_every must be a whole number"):
        sph.run(small_2d, output="x", steps=2, checkpoint_every=-1)
    with pytest.raises(TypeError, match="frames must be a whole number from 1 to 100"):
        sph.compare(small_2d, frames="3")
    with pytest.raises(ValueError, match="frames must be a whole number from 1 to 100"):
        sph.compare(small_2d, frames=0)
    sim.step(1)
    with pytest.raises(TypeError, match="fields must be a list of names"):
        sim.write_frame("x.vtu", fields="velocity")
    with pytest.raises(TypeError, match="modes must be a list of names"):
        sph.compare(small_2d, modes="adaptive")
    with pytest.raises(TypeError, match="output must be a path"):
        sph.compare(small_2d, output=5)
    with pytest.raises(TypeError, match="steps must be a whole number"):
        sph.run(small_2d, output="x", steps=2.0)


def test_frame_errors(tmp_path):
    with pytest.raises(sph.Error) as e:
        sph.read_frame(str(tmp_path / "none.vtu"))
    assert e.value.where == str(tmp_path / "none.vtu")
    bad = tmp_path / "bad.vtu"
    bad.write_text("<VTKFile>not a frame</VTKFile>")
    with pytest.raises(sph.Error):
        sph.read_frame(str(bad))


def test_analysis_helpers_refuse_what_they_cannot_measure():
    x = np.linspace(0.0, 0.1, 11)
    y = np.zeros(11)
    assert sph.surge_front(x, y, floor=0.0, spacing=0.01, h=0.02) == pytest.approx(0.095)  # 0.09 has 3 within h
    for kwargs, text in ((dict(y=y[:5]), "one value per particle each, got 11 and 5"),
                         (dict(h=0.0), "h must be a positive length"),
                         (dict(spacing=-1.0), "spacing must be a positive length"),
                         (dict(min_neighbors=-1), "min_neighbors must be 0 or more")):
        args = dict(x=x, y=y, floor=0.0, spacing=0.01, h=0.02)
        args.update(kwargs)
        with pytest.raises(ValueError, match=text):
            sph.surge_front(**args)
    assert sph.martin_moyce_time(0.1, 9.81) == pytest.approx(0.1 * np.sqrt(2 * 9.81 / sph.MARTIN_MOYCE_A))
    with pytest.raises(ValueError, match="g must be the positive magnitude"):
        sph.martin_moyce_time(0.1, -9.81)
    with pytest.raises(ValueError, match="a must be the column's positive base width"):
        sph.martin_moyce_time(0.1, 9.81, 0.0)


def test_numpy_numbers_are_numbers_and_bools_are_not(small_2d, tmp_path):
    # (NumPy's scalars were refused with "must be a whole number ..., got 1", which they are)
    sim = sph.Simulation(small_2d, threads=np.int64(1))
    assert sim.threads == 1
    sim.step(np.int32(2))
    assert len(sim.surface(iso=np.float32(0.5), resolution=np.int64(2))["vertices"]) > 0
    r = sph.run(small_2d, output=str(tmp_path / "r"), steps=np.int64(3), threads=np.int16(1))
    assert r["steps"] == 3
    for bad in (True, np.bool_(True), 1.5, "2"):
        with pytest.raises(TypeError, match=r"threads must be a whole number from 1 to 4096, got .* \("):
            sph.Simulation(small_2d, threads=bad)
    for bad in (np.bool_(False), "0.5", None):
        with pytest.raises(TypeError, match=r"iso must be a number, got .* \("):
            sim.surface(iso=bad)
