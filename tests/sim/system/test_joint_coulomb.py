"""Joint Coulomb friction as a constraint in the period step (`uvms_pin.sim.system.period`,
`uvms_pin.physics.constraints.joint_friction`): a joint loaded below its friction does not
move at all, above it it turns with the acceleration of the net load; and the scenario's
``[joints] coulomb`` key."""

from __future__ import annotations

import numpy as np
import pytest
from jaw_helpers import parallel_jaw_urdf

import uvms_pin as up
from uvms_pin.hydro.params import HydroParams
from uvms_pin.physics.constraints.joint_friction import JointCoulombFriction
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

PERIOD_S = 2e-3
COULOMB_N = 0.5  # the left finger's (a prismatic joint: N)


def _jaw(folder):
    """The parallel jaw (tests/jaw_helpers.py) without drag, so that a joint's load is the
    only thing that moves it; the left finger with Coulomb friction, the right without."""
    uvms = up.load_uvms(parallel_jaw_urdf(folder))
    uvms = uvms.with_hydro(
        lambda b: HydroParams(
            b.params.volume_m3, b.params.center_of_buoyancy_m, b.params.added_mass,
            np.zeros(6), np.zeros(6),
        )
    )  # fmt: skip
    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -5.0]
    q[7:] = [0.012, 0.012]  # mid-travel: no limit near
    return uvms, q


def _pushed(uvms, q, force_N: float, periods: int) -> np.ndarray:
    """The left finger's position after each period, pushed open by ``force_N``."""
    plant = Plant(
        uvms, free_surface=False, joint_limits=JointLimits.of_uvms(uvms),
        joint_coulomb=JointCoulombFriction.of_uvms(uvms, [COULOMB_N, 0.0]),
    )  # fmt: skip
    system = System(plant)
    state = system.initial_state(q, np.zeros(uvms.nv))
    system.start(state)
    tau = np.zeros(uvms.nv)
    tau[6] = force_N
    q_s, v_s, out = state.q, state.v, []
    for k in range(periods):
        q_s, v_s = system.advance(RK4(5e-4), k * PERIOD_S, q_s, v_s, tau, (k + 1) * PERIOD_S)
        out.append(q_s[7])
    return np.array(out)


def test_a_joint_loaded_below_its_friction_does_not_move(tmp_path):
    uvms, q = _jaw(tmp_path)
    left = _pushed(uvms, q, 0.95 * COULOMB_N, 500)  # 1 s
    assert np.max(np.abs(left - q[7])) < 1e-9


def test_a_joint_loaded_above_its_friction_accelerates_with_the_net_load(tmp_path):
    uvms, q = _jaw(tmp_path)
    left = _pushed(uvms, q, 1.05 * COULOMB_N, 25)  # 50 ms
    net = np.zeros(uvms.nv)
    net[6] = 0.05 * COULOMB_N  # the load less the friction, along the motion
    expected = up.forward_dynamics(uvms, q, np.zeros(uvms.nv), net)[6]
    # semi-implicit Euler: the last period's displacement is h v_n, v_n = n h a
    measured = (left[-1] - left[-2]) / (25 * PERIOD_S**2)
    assert expected > 0.0 and measured == pytest.approx(expected, rel=0.02)


def test_the_scenario_chooses_the_constraint_with_a_control_period(tmp_path):
    data = {
        "scenario": {"name": "jaw", "model": str(parallel_jaw_urdf(tmp_path)), "duration_s": 0.1},
        "water": {"free_surface": False},
        "joints": {"coulomb_Nm": [0.5, 0.5]},
        "control": {"period_s": 0.002},
    }
    plant = up.scenario_from_dict(data, tmp_path / "jaw.toml").plant
    assert plant.joint_coulomb is not None and plant.joint_friction is None
    data["joints"]["coulomb"] = "smooth"
    plant = up.scenario_from_dict(data, tmp_path / "jaw.toml").plant
    assert plant.joint_coulomb is None
    assert plant.joint_friction.coulomb_Nm.tolist() == [0.5, 0.5]
