"""Runs under a free surface: a vehicle that surfaces floats at its waterline, one above the
water falls, the stop at the surface is an option, and the run reports time out of water."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.apps.outputs import write_outputs
from uvms_pin.physics.floating import floating_equilibrium
from uvms_pin.results.metrics import surface_metrics
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

SURFACING = ROOT / "scenarios" / "surfacing.toml"


def test_the_lbv150_rises_breaks_the_surface_and_floats_at_its_waterline(tmp_path):
    """The shipped scenario: the run ends ok, at rest at the floating equilibrium (1 mm),
    energy never grows, the metrics say how long the hull was partly out of the water, and
    the waterline figure is written."""
    scenario = load_scenario(SURFACING)
    assert scenario.plant.free_surface and not scenario.plant.stop_at_surface
    rollout = simulate(scenario)
    assert rollout.metadata["status"] == "ok"
    resting = floating_equilibrium(scenario.uvms, rollout.q[-1])
    assert rollout.q[-1, 2] == pytest.approx(resting[2], abs=1e-3)
    assert -0.3 < resting[2] < 0.0  # its hull's top breaks the surface: partly dry
    metrics = rollout.metrics()
    assert 10.0 < metrics["time_partly_out_of_water_s"] < 60.0
    assert metrics["time_wholly_out_of_water_s"] == 0.0
    assert 0.9 < metrics["wet_fraction_min"] < 1.0
    fractions = rollout.signals["wet_fraction"][:, 0]
    assert np.all((fractions >= 0.0) & (fractions <= 1.0))
    assert np.all(fractions[rollout.q[:, 2] < -1.0] == 1.0)  # deep: wholly wet
    assert metrics["energy_max_increase_J"] < 1e-6
    assert rollout.metadata["hull_names"] == ["base_link"]
    assert rollout.metadata["world"]["free_surface"] is True
    written = write_outputs(rollout, tmp_path)
    assert tmp_path / "surface.png" in written


def test_without_a_free_surface_the_vehicle_rises_through_z_0():
    """``free_surface = false``: water without a top (the model before the free surface)."""
    overrides = {"water.free_surface": False, "scenario.duration_s": 30.0}
    rollout = simulate(load_scenario(SURFACING, overrides))
    assert rollout.q[-1, 2] > 0.5
    assert "wet_fraction" not in rollout.signals


def test_stop_at_surface_ends_the_run_when_a_centre_of_buoyancy_reaches_it():
    overrides = {"water.stop_at_surface": True}
    scenario = load_scenario(SURFACING, overrides)
    assert not scenario.plant.free_surface  # the submerged model unless asked for
    with pytest.raises(up.SimulationError, match="reached the free surface") as info:
        simulate(scenario)
    rollout = info.value.rollout
    assert 5.0 < rollout.time_s[-1] < 30.0
    # it stops at the surface (z = 0), not beyond: the last logged sample (at most a log
    # period before the stop, rising at a few cm/s) has every centre of buoyancy just below
    model, data = scenario.uvms.model, scenario.uvms.model.createData()
    pin.forwardKinematics(model, data, rollout.q[-1])
    highest = max(
        data.oMi[b.joint_id].act(b.placement_in_joint.act(b.params.center_of_buoyancy_m))[2]
        for b in scenario.uvms.hydro_bodies
        if b.params.volume_m3 > 0.0
    )
    assert -0.01 < highest <= 0.0
    assert "m above the surface (eta = 0 m)" in str(info.value)


def test_a_vehicle_above_the_water_falls_under_gravity_alone():
    """Released at z = +5 m: z = 5 - g t^2 / 2 until it reaches the water."""
    overrides = {"initial.position_world_m": [0.0, 0.0, 5.0], "scenario.duration_s": 0.6}
    rollout = simulate(load_scenario(SURFACING, overrides))
    t = rollout.time_s
    np.testing.assert_allclose(rollout.q[:, 2], 5.0 - 0.5 * 9.81 * t**2, atol=1e-9)
    assert np.all(rollout.signals["wet_fraction"] == 0.0)
    assert rollout.metrics()["time_wholly_out_of_water_s"] == pytest.approx(t[-1])


def test_the_time_out_of_the_water_counts_each_sample_until_the_next():
    rollout = Rollout.allocate(5, 7, 6)
    rollout.time_s[:] = [0.0, 0.5, 1.0, 2.0, 3.0]
    fractions = rollout.signal("wet_fraction", 2)
    fractions[:] = [[1, 1], [1, 0.5], [1, 0.0], [1, 1], [0.2, 1]]
    metrics = surface_metrics(rollout)
    assert metrics["time_partly_out_of_water_s"] == pytest.approx(0.5 + 1.0)
    assert metrics["time_wholly_out_of_water_s"] == pytest.approx(1.0)
    assert metrics["wet_fraction_min"] == 0.0
