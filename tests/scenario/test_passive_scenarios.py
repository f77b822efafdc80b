"""The shipped passive scenarios (no input) behave as their physics says, not only load.

- ``passive_still_water``: damping and restoring only, so the mechanical energy E = T + U
  (added mass in T, gravity and buoyancy in U) decreases at every logged sample and the
  motion dies out; made lighter or heavier than the water it displaces, it rises or sinks.
- ``passive_current``: a uniform, steady current is still water seen from a frame moving
  with it (Galilean invariance: the fluid forces depend on the relative velocity only, and
  the rigid body's laws are those of any inertial frame), so the energy of the motion
  relative to the water, T(q, v - v_c) + U, decreases, and the vehicle ends up moving with
  the water; the energy seen from the ground need not (the current does work).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

from uvms_pin.physics.dynamics import kinetic_energy, potential_energy
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

STILL = ROOT / "scenarios" / "passive_still_water.toml"
CURRENT = ROOT / "scenarios" / "passive_current.toml"


def _world_velocity_m_s(rollout) -> np.ndarray:
    """(n, 3) vehicle velocity in the world frame (v holds it in the body frame)."""
    return np.array(
        [
            pin.Quaternion(q[3:7]).toRotationMatrix() @ v[:3]
            for q, v in zip(rollout.q, rollout.v, strict=True)
        ]
    )


@pytest.fixture(scope="module")
def still():
    return simulate(load_scenario(STILL), progress=False)


def test_still_water_energy_decreases_at_every_sample_and_the_motion_dies_out(still):
    energy = still.kinetic_energy_J + still.potential_energy_J
    # dissipation dominates RK4's error at every 0.02 s step (the smallest loss: ~6e-5 J)
    assert np.all(np.diff(energy) < 0.0), np.diff(energy).max()
    assert still.metrics()["energy_max_increase_J"] < 0.0
    assert still.kinetic_energy_J[-1] < 0.01 * still.kinetic_energy_J[0]  # 2.65 J -> 5 mJ


@pytest.mark.parametrize("density_kg_m3", [1010.0, 1040.0])
def test_still_water_a_lighter_or_heavier_vehicle_rises_or_sinks(still, density_kg_m3):
    """The neutral vehicle (net buoyancy 1e-4 N) at 1025 kg/m^3; in lighter water it weighs
    more than it displaces and sinks, in denser water it rises, settling to a steady
    vertical speed of that sign, its energy (buoyancy's potential included) still falling."""
    scenario = load_scenario(STILL, {"water.density_kg_m3": density_kg_m3})
    net_N = scenario.uvms.net_buoyancy_N
    assert abs(net_N) > 1.0  # +-1.7 N
    rollout = simulate(scenario, progress=False)
    sign = np.sign(net_N)
    assert sign == np.sign(density_kg_m3 - 1025.0)
    assert sign * (rollout.q[-1, 2] - still.q[-1, 2]) > 0.5  # 0.8 m above or below in 10 s
    vertical = _world_velocity_m_s(rollout)[-50:, 2]  # the last second
    assert np.all(sign * vertical > 0.1)
    assert np.ptp(vertical) < 0.05 * np.abs(vertical).max()  # steady: within 5 %
    energy = rollout.kinetic_energy_J + rollout.potential_energy_J
    assert np.all(np.diff(energy) < 0.0)


def test_current_relative_energy_decreases_and_the_vehicle_ends_moving_with_the_water():
    scenario = load_scenario(CURRENT)
    current = np.asarray(scenario.plant.current_world_m_s, dtype=float)
    assert np.linalg.norm(current) > 0.3
    rollout = simulate(scenario, progress=False)
    relative = []
    for q, v in zip(rollout.q, rollout.v, strict=True):
        v_r = v.copy()
        v_r[:3] -= pin.Quaternion(q[3:7]).toRotationMatrix().T @ current
        relative.append(kinetic_energy(scenario.uvms, q, v_r) + potential_energy(scenario.uvms, q))
    assert np.all(np.diff(relative) < 0.0), np.diff(relative).max()
    ground = rollout.kinetic_energy_J + rollout.potential_energy_J
    assert np.diff(ground).max() > 0.0  # the current does work on the vehicle
    slip = np.linalg.norm(_world_velocity_m_s(rollout) - current, axis=1)
    assert slip[0] > 0.1 and slip[-1] < 1e-3  # 0.12 m/s at release, 0.3 mm/s after 20 s
