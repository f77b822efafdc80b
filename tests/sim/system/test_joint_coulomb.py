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
from uvms_pin.sim.system.period import integrated_step, period_step

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


@pytest.mark.parametrize("force_N", [0.3, 0.8, 3.0])
def test_the_compiled_step_is_the_references(tmp_path, force_N):
    """The compiled plant steps the joints' friction and limits at each period's end by
    their exact step (src/uvms_core/joint_box.hpp) over the robot's velocity; the
    reference (`integrated_step`: the same compiled dynamics, then Pinocchio's ADMM on the
    `JointCoulombFriction` and `JointLimits` rows) agrees to its tolerance: the left finger
    held (0.3 N against its 0.5 N), sliding (0.8 N) and driven into its limit (3 N), the
    right one, without friction, pushed by the same force to its limit, while the vehicle
    floats."""
    uvms, q = _jaw(tmp_path)
    plant = Plant(
        uvms, free_surface=False, joint_limits=JointLimits.of_uvms(uvms),
        joint_coulomb=JointCoulombFriction.of_uvms(uvms, [COULOMB_N, 0.0]),
    )  # fmt: skip
    system = System(plant)
    assert plant.compiled is not None and len(plant.compiled.joint_coulomb_Nm) == uvms.nv
    compiled_step = period_step(system, RK4(5e-4))
    reference_step = integrated_step(system, RK4(5e-4))
    tau = np.zeros(uvms.nv)
    tau[6:8] = force_N
    state = system.initial_state(q, np.zeros(uvms.nv))
    system.start(state)
    (qc, vc), (qr, vr) = (state.q, state.v), (state.q, state.v)
    for k in range(150):  # 0.3 s
        t0, t1 = k * PERIOD_S, (k + 1) * PERIOD_S
        qc, vc = compiled_step(t0, qc, vc, tau, t1)
        qr, vr = reference_step(t0, qr, vr, tau, t1)
        np.testing.assert_allclose(qc, qr, rtol=0.0, atol=1e-8)
        np.testing.assert_allclose(vc, vr, rtol=0.0, atol=1e-6)
    upper = uvms.model.upperPositionLimit[7:9]
    if force_N < COULOMB_N:
        assert abs(qc[7] - q[7]) < 1e-9  # held by its friction
    else:
        assert qc[7] > q[7] + 1e-3  # slid open
    assert qc[8] == pytest.approx(upper[1], abs=1e-6)  # the frictionless one at its limit
    if force_N > 1.0:
        assert qc[7] == pytest.approx(upper[0], abs=1e-6)


def _squeezed(tmp_path, finger_force_N: tuple[float, float]):
    """The jaw's fingers (0.3 N of Coulomb friction each) pushed by ``finger_force_N`` (left,
    right; negative closes) beside a free ball (2 mm off each pad, 0.5 mm off centre), every
    contact rigid, 200 periods on the compiled system and on the reference: (uvms, [compiled
    run, reference run] (periods, q and v), [their systems])."""
    uvms, q = _jaw(tmp_path)
    data = {
        "scenario": {"name": "squeeze", "model": str(parallel_jaw_urdf(tmp_path)),
                     "duration_s": 0.4},
        "water": {"free_surface": False},
        "joints": {"coulomb_Nm": [0.3, 0.3]},
        "world": {
            "moving_contact": "rigid",
            "objects": [{
                "type": "sphere", "name": "ball", "radius_m": 0.02,
                "position_world_m": [0.0, 0.0005, -5.0 - 0.26 - 0.04],
                "density_kg_m3": 1100.0, "friction_static": 0.5, "friction_kinetic": 0.5,
            }],
        },
        "control": {"period_s": PERIOD_S},
    }  # fmt: skip
    plant = up.scenario_from_dict(data, tmp_path / "squeeze.toml").plant
    assert plant.joint_coulomb is not None
    runs, systems = [], []
    for compiled in (True, False):
        system = System(plant, compiled=compiled)
        integration = system.log.record(RK4(5e-4))["world"]["integration"]
        assert ("one compiled call" in integration) == compiled, integration
        state = system.initial_state(q, np.zeros(uvms.nv))
        system.start(state)
        tau = np.zeros(uvms.nv)
        tau[6:8] = finger_force_N
        q_s, v_s, out = state.q, state.v, []
        for k in range(200):
            t0, t1 = k * PERIOD_S, (k + 1) * PERIOD_S
            q_s, v_s = system.advance(RK4(5e-4), t0, q_s, v_s, tau, t1)
            out.append(np.concatenate([q_s, v_s]))
        runs.append(np.array(out))
        systems.append(system)
    return uvms, runs, systems


def test_rigid_contacts_with_joint_friction_are_compiled_as_the_reference(tmp_path):
    """The jaw's fingers, each with 0.3 N of Coulomb friction, close on a free ball (2 mm
    off each pad, 0.5 mm off centre) and squeeze it by rigid contacts: the compiled system
    solves the fingers' friction as box rows with the contact rows
    (src/uvms_core/moving_constraints.hpp, projected Gauss-Seidel to 1e-10 m/s); the
    reference solves the same rows by Pinocchio's ADMM (`period.constrained`, 1e-10 with
    joint friction). Over 0.4 s the configurations agree to 1e-6 (measured 2.7e-7 m). The
    velocities agree to 2e-4 m/s only: the reference's ADMM stalls on the squeezed ball (111
    of 200 periods accepted as stalled, residual up to 5.4e-6 m/s), and in such a period its
    fingers creep at up to 1.4e-4 m/s where the compiled solve holds them to 1e-10."""
    # both fingers pushed closed, 1.2 N net of their friction
    uvms, runs, systems = _squeezed(tmp_path, (-1.5, -1.5))
    (compiled_run, reference_run), nq = runs, uvms.nq + 7
    # they closed on the ball and hold it: the pads' inner faces (10 mm + q off the centre
    # line) one diameter apart, q_left + q_right = 40 - 20 mm, to the solve's gap
    assert compiled_run[0, 7:9].sum() > 0.022
    assert compiled_run[-1, 7:9].sum() == pytest.approx(0.02, abs=1e-5)
    assert np.all(np.abs(compiled_run[-1, nq + 6 : nq + 8]) < 1e-9)
    assert systems[0].stalled_solves().count == 0
    np.testing.assert_allclose(compiled_run[:, :nq], reference_run[:, :nq], rtol=0.0, atol=1e-6)
    np.testing.assert_allclose(compiled_run[:, nq:], reference_run[:, nq:], rtol=0.0, atol=2e-4)


def test_a_finger_held_on_its_limit_beside_a_rigid_contact_is_compiled_as_the_reference(tmp_path):
    """The left finger, closing, pushes the ball across against the right one, which is
    driven open onto its limit; the left one ends on its closed limit. The robot's limit
    rows join the contacts' in the coupled solve (a limit the period can reach:
    gap <= h |v| + margin, src/uvms_core/moving_constraints.cpp); both fingers end on their
    limits, never past them, on the compiled system as on the reference (measured: 7e-13
    m, configurations agreeing to 6e-9 m, velocities 9e-8 m/s). The margin subtracted
    there instead of added left the resting fingers without rows: 1 mm past the limit and a
    run 0.3 m from the reference's."""
    uvms, (compiled_run, reference_run), _ = _squeezed(tmp_path, (-1.5, 1.5))
    lower, upper = uvms.model.lowerPositionLimit[7:9], uvms.model.upperPositionLimit[7:9]
    for run in (compiled_run, reference_run):
        assert np.all(run[:, 7:9] >= lower - 1e-9) and np.all(run[:, 7:9] <= upper + 1e-9)
        np.testing.assert_allclose(run[-1, 7:9], [lower[0], upper[1]], rtol=0, atol=1e-9)
    ball_y = uvms.nq + 1
    assert compiled_run[-1, ball_y] < -0.015  # pushed along by the closing finger
    np.testing.assert_allclose(compiled_run, reference_run, rtol=0.0, atol=1e-6)
