"""The field views: no copy, read-only, never stale, never dangling (docs/python.md, "Views")."""
import gc

import numpy as np
import pytest

import sph
from conftest import DAM_BREAK, SMALL_2D


def test_views_are_read_only_and_share_the_simulation_memory(small_2d):
    sim = sph.Simulation(small_2d)
    a, b = sim.positions, sim.positions
    assert np.shares_memory(a, b)  # two views of one buffer: no copy
    assert isinstance(a.base, sph._ViewMemory)
    assert a.shape == (len(sim), 2) and a.dtype == np.float64
    assert sim.ids.dtype == np.uint32 and sim.densities.shape == (len(sim),)
    with pytest.raises(ValueError, match="read-only"):
        a[0, 0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        sim.densities[:] = 0
    with pytest.raises(ValueError, match="WRITEABLE"):  # and cannot be made writeable
        a.flags.writeable = True


def test_every_field_of_the_table_is_a_property(small_2d):
    sim = sph.Simulation(small_2d)
    assert sim.field_names == list(sph.FIELDS)
    plural = {"position": "positions", "velocity": "velocities", "density": "densities", "pressure": "pressures",
              "id": "ids", "initial_position": "initial_positions", "acceleration": "accelerations"}
    assert set(plural) == set(sph.FIELDS)
    for name in sph.FIELDS:
        assert np.array_equal(getattr(sim, plural[name]), sim.field(name))
    with pytest.raises(KeyError, match="no particle field"):
        sim.field("temperature")


def test_the_particles_have_the_scenes_one_mass(small_2d):
    sim = sph.Simulation(small_2d)
    sim.step(1)
    # The lattice mass (the default) gives density0 in the block's interior; a 4 % heavier
    # Fluid.particleMass is every particle's, and its densities are 4 % higher, to rounding.
    assert isinstance(sim.particle_mass, float) and sim.particle_mass > 0
    heavier = sph.Simulation(
        sph.load_scene(DAM_BREAK, overrides={**SMALL_2D, "Fluid.particleMass": 1.04 * sim.particle_mass}))
    assert heavier.particle_mass == pytest.approx(1.04 * sim.particle_mass, rel=1e-15)
    heavier.step(1)
    assert np.allclose(heavier.densities[: len(sim)], 1.04 * sim.densities, rtol=1e-3)


def test_a_view_taken_before_a_step_keeps_its_values_and_a_new_one_shows_the_step(small_2d):
    sim = sph.Simulation(small_2d)
    sim.step(1)
    old = sim.positions
    old_slice = sim.velocities[10:20]  # a view of a view
    before, before_slice = old.copy(), old_slice.copy()
    sim.step(3)
    new = sim.positions
    assert np.array_equal(old, before) and np.array_equal(old_slice, before_slice)
    assert not np.array_equal(new, before)  # not stale: the step shows
    assert not np.shares_memory(old, new)
    # The new view is the simulation's state: it matches a simulation that never had views.
    plain = sph.Simulation(small_2d)
    plain.step(4)
    assert new.tobytes() == plain.positions.tobytes()


def test_views_held_across_steps_change_no_result(small_2d):
    held = sph.Simulation(small_2d, neighbors="adaptive")
    plain = sph.Simulation(small_2d, neighbors="adaptive")
    views = []
    for _ in range(10):
        views.append((held.positions, held.velocities, held.densities, held.ids))
        held.step(1)
        plain.step(1)
    assert held.positions.tobytes() == plain.positions.tobytes()
    assert held.velocities.tobytes() == plain.velocities.tobytes()
    assert held.counters["lists_rebuilt"] == plain.counters["lists_rebuilt"]
    # Each held view shows the state of its own step: consecutive ones differ.
    assert all(not np.array_equal(views[k][0], views[k + 1][0]) for k in range(9))


def test_views_outlive_the_simulation(small_2d):
    sim = sph.Simulation(small_2d)
    sim.step(2)
    x, ids = sim.positions, sim.ids
    x_copy, ids_copy = x.copy(), ids.copy()
    del sim
    gc.collect()
    # Memory the simulation freed would be reused by these allocations.
    junk = [np.full(len(x_copy) * 2, 7.0) for _ in range(50)]
    assert np.array_equal(x, x_copy) and np.array_equal(ids, ids_copy)
    assert float(x.sum()) == float(x_copy.sum())
    del junk


def test_views_of_a_simulation_with_emitters_survive_the_growth(tmp_path):
    scene = sph.load_scene(
        __import__("conftest").SOURCE_DIR + "/scenes/paper/tank_fill_3d.json",
        overrides={"Configuration.numberOfSteps": 60})
    sim = sph.Simulation(scene, threads=2)
    views = []
    for _ in range(6):
        views.append((sim.positions, sim.positions.copy()))
        sim.step(10)
    assert len(sim) > len(views[0][0])  # the emitter added particles
    for view, copy in views:
        assert np.array_equal(view, copy)
