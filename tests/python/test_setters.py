"""The setters of positions and velocities: what they refuse, and what they change."""
import warnings

import numpy as np
import pytest

import sph


def test_setting_velocities_changes_the_state_and_rebuilds_the_lists(small_2d):
    sim = sph.Simulation(small_2d, neighbors="adaptive")
    sim.step(5)
    assert sim.counters["lists_rebuilt"] < len(sim)  # adaptive: a few lists a step
    old = sim.velocities
    before = old.copy()
    v = np.zeros_like(before)
    v[:, 0] = 0.5
    sim.velocities = v
    assert np.array_equal(sim.velocities, v)
    assert np.array_equal(old, before)  # a view taken before keeps its values
    # The state set by hand is where the run starts from now: the energy watch compares with its
    # energy (until 2026-12-08 it kept the first state's: the push warned of an energy gain, and a
    # push of 10 m/s failed the run at its next step as if it had blown up).
    with warnings.catch_warnings():
        warnings.simplefilter("error", sph.HealthWarning)
        sim.step(1)
    assert sim.counters["lists_rebuilt"] == len(sim)  # every list, after the change
    assert np.mean(sim.velocities[:, 0]) == pytest.approx(0.5, abs=0.1)
    fast = sph.Simulation(small_2d)
    v = np.zeros((len(fast), 2))
    v[:, 0] = 10.0
    fast.velocities = v
    with warnings.catch_warnings():
        warnings.simplefilter("error", sph.HealthWarning)
        fast.step(3)
    assert fast.steps == 3


def test_setting_positions_moves_the_particles(small_2d):
    sim = sph.Simulation(small_2d)
    x = sim.positions.copy()
    x[:, 0] += 0.3
    sim.positions = x
    assert np.array_equal(sim.positions, x)
    sim.step(1)
    assert np.all(sim.positions[:, 0] > 0.29)


def test_float32_is_accepted_by_a_double_scene_exactly(small_2d):
    sim = sph.Simulation(small_2d)
    x = sim.positions.astype(np.float32)
    sim.positions = x
    assert sim.positions.dtype == np.float64 and np.array_equal(sim.positions, x.astype(np.float64))
    sim.positions = x.tolist()  # a list becomes float64 for a double scene
    assert np.array_equal(sim.positions, x.astype(np.float64))


@pytest.mark.parametrize("shape", [(799, 2), (801, 2), (800, 3), (800,), (2, 800), (800, 2, 1)])
def test_bad_shapes_are_refused(small_2d, shape):
    sim = sph.Simulation(small_2d)
    assert len(sim) == 800
    before = sim.positions.copy()
    with pytest.raises(ValueError, match=r"shape \(800, 2\)"):
        sim.positions = np.zeros(shape)
    assert np.array_equal(sim.positions, before)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_values_are_refused_naming_the_particle(small_2d, bad):
    sim = sph.Simulation(small_2d)
    v = np.zeros((800, 2))
    v[123, 1] = bad
    with pytest.raises(ValueError, match=r"\[123, 1\] is (nan|infinite)"):
        sim.velocities = v
    assert np.all(np.isfinite(sim.velocities))


@pytest.mark.parametrize("dtype", [np.int64, np.int32, np.bool_, np.complex128, np.float16, object])
def test_wrong_dtypes_are_refused(small_2d, dtype):
    sim = sph.Simulation(small_2d)
    with pytest.raises(TypeError, match="dtype"):
        sim.positions = np.zeros((800, 2), dtype=dtype)


def test_a_float_scene_refuses_float64(small_3d):
    sim = sph.Simulation(small_3d)
    x = sim.positions.astype(np.float64)
    with pytest.raises(TypeError, match="float32"):
        sim.positions = x
    sim.positions = x.astype(np.float32)


def test_fields_other_than_positions_and_velocities_cannot_be_set(small_2d):
    sim = sph.Simulation(small_2d)
    with pytest.raises(AttributeError):
        sim.densities = np.zeros(800)
    with pytest.raises(AttributeError):
        sim.ids = np.zeros(800, dtype=np.uint32)
