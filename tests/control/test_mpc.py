"""The MPC controller in closed loop with the plant: station keeping in a current.

crocoddyl is in the dev extra; without it these tests skip.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.control.base import ZeroController
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.model.vehicles import bluerov2_heavy
from uvms_pin.physics.contact import LinearSpring
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant

pytest.importorskip("crocoddyl")

from uvms_pin.control.mpc import COLD_START_ITERATIONS, MpcController, MpcForceTask
from uvms_pin.ocp import problems
from uvms_pin.sim.system import System

CURRENT = np.array([0.3, 0.1, 0.0])


def _start(uvms):
    q0 = uvms.neutral_configuration()
    q0[2] = -3.0
    return q0


def _controller(plant_uvms, model_uvms, q0, **kw):
    thrusters = bluerov2_heavy.thrusters()
    b_u = up.input_matrix(thrusters, plant_uvms.nv)
    effort = plant_uvms.model.effortLimit[6:]
    lower = np.r_[[-t.max_reverse_N for t in thrusters], -effort]
    upper = np.r_[[t.max_forward_N for t in thrusters], effort]
    return MpcController(
        model_uvms,
        task="station",
        target=pin.SE3(np.eye(3), q0[:3].copy()),
        posture=q0,
        horizon_s=0.5,
        dt_s=0.05,
        rate_hz=kw.pop("rate_hz", 20.0),
        iterations=2,
        actuators=problems.Actuators(b_u, (lower, upper)),
        flow=up.flow.UniformCurrent(CURRENT),
        **kw,
    ), (lower, upper, b_u)


def _closed_loop(plant_uvms, controller, q0, duration_s=2.0, period_s=0.01):
    """The controller sampled every period (it re-plans at its own rate), RK4 plant."""
    plant = Plant(plant_uvms, CURRENT, free_surface=False)
    integrator = RK4(0.005)
    q, v = q0.copy(), np.zeros(plant_uvms.nv)
    taus, positions = [], []
    for k in range(round(duration_s / period_s)):
        t = k * period_s
        tau = controller.compute(t, Measurement(t, q, v, np.zeros(6)))
        taus.append(tau.copy())
        q, v = System(plant).advance(integrator, t, q, v, tau, t + period_s)
        positions.append(q[:3].copy())
    return np.array(positions), np.array(taus)


def test_mpc_holds_station_in_a_current_and_is_deterministic(reference_uvms):
    """In a 0.32 m/s current, left alone the vehicle drifts 0.34 m in 2 s (from rest); the MPC on the
    plant's own model (knowing the current) keeps it within 2 mm (0.34 mm measured), with
    thrusts inside their limits; a second run gives the same numbers bit for bit."""
    uvms = reference_uvms
    q0 = _start(uvms)
    passive, _ = _closed_loop(uvms, ZeroController(uvms.nv), q0)
    assert np.linalg.norm(passive[-1] - q0[:3]) > 0.3
    controller, (lower, upper, b_u) = _controller(uvms, uvms, q0)
    positions, taus = _closed_loop(uvms, controller, q0)
    drift = np.linalg.norm(positions - q0[:3], axis=1)
    assert drift.max() < 2e-3, drift.max()
    thrusts = np.linalg.lstsq(b_u, taus.T, rcond=None)[0].T
    assert np.all(thrusts >= lower - 1e-6) and np.all(thrusts <= upper + 1e-6)
    controller.reset()
    again, taus_again = _closed_loop(uvms, controller, q0)
    np.testing.assert_array_equal(again, positions)
    np.testing.assert_array_equal(taus_again, taus)


@pytest.mark.parametrize(
    ("solver", "integrator"), [("csqp", "euler"), ("box_fddp", "rk4")], ids=["csqp", "rk4"]
)
def test_mpc_holds_station_with_csqp_or_rk4_nodes_deterministically(
    reference_uvms, solver, integrator
):
    """The same station keeping with mim_solvers' CSQP (the thrust limits as constraints, 2
    SQP iterations per re-plan) or with RK4 nodes: within 2 mm (0.19 mm measured with
    either), the thrusts inside their limits, and a second run after a reset the
    same bit for bit."""
    if solver == "csqp":
        pytest.importorskip("mim_solvers")
    uvms = reference_uvms
    q0 = _start(uvms)
    controller, (lower, upper, b_u) = _controller(
        uvms, uvms, q0, solver=solver, integrator=integrator
    )
    positions, taus = _closed_loop(uvms, controller, q0)
    drift = np.linalg.norm(positions - q0[:3], axis=1)
    assert drift.max() < 2e-3, drift.max()
    thrusts = np.linalg.lstsq(b_u, taus.T, rcond=None)[0].T
    assert np.all(thrusts >= lower - 1e-6) and np.all(thrusts <= upper + 1e-6)
    controller.reset()
    again, taus_again = _closed_loop(uvms, controller, q0)
    np.testing.assert_array_equal(again, positions)
    np.testing.assert_array_equal(taus_again, taus)


def test_mpc_with_a_wrong_model_still_holds_station(reference_uvms):
    """Planned on a model with 30 % more damping and 20 % less added mass than the plant,
    the receding horizon corrects what the model gets wrong: within 1 cm (4 mm measured,
    12x the exact model's)."""
    uvms = reference_uvms
    q0 = _start(uvms)
    wrong = scaled_uvms(uvms, damping_scale=1.3, added_mass_scale=0.8)
    controller, _ = _controller(uvms, wrong, q0)
    positions, _ = _closed_loop(uvms, controller, q0)
    assert np.linalg.norm(positions - q0[:3], axis=1).max() < 0.01


def test_mpc_refuses_bad_settings(reference_uvms):
    q0 = _start(reference_uvms)
    target = pin.SE3.Identity()
    with pytest.raises(ParameterError, match="task"):
        MpcController(reference_uvms, task="dance", target=target, posture=q0)
    with pytest.raises(ParameterError, match="box_fddp, fddp, csqp"):
        MpcController(reference_uvms, task="station", target=target, posture=q0, solver="ipopt")
    with pytest.raises(ParameterError, match="euler, rk4"):
        MpcController(
            reference_uvms, task="station", target=target, posture=q0, integrator="midpoint"
        )
    with pytest.raises(ParameterError, match="rate_hz"):
        MpcController(reference_uvms, task="station", target=target, posture=q0, rate_hz=0.0)
    with pytest.raises(ParameterError, match="one node"):
        MpcController(
            reference_uvms, task="station", target=target, posture=q0, horizon_s=0.01, dt_s=0.02
        )
    with pytest.raises(ParameterError, match="force_task"):
        MpcController(reference_uvms, task="force", target=None, posture=q0)
    force_task = MpcForceTask(LinearSpring(np.full(3, 2.0)), lambda t: np.zeros(3))
    with pytest.raises(ParameterError, match="force_task"):
        MpcController(
            reference_uvms, task="station", target=target, posture=q0, force_task=force_task
        )


def test_the_force_task_previews_the_desired_force_and_places_its_spring(reference_uvms):
    """Each re-plan moves f_d along the horizon (node k: f_d(t + k dt)); the controller's
    own spring is anchored where the tip is at its first plan (the plant's convention), and
    again after a reset; the plant's model object is never touched."""
    uvms = reference_uvms
    q0 = _start(uvms)
    q0[7:] = [-0.2, 1.0, -0.8, 0.2]
    spring = LinearSpring(np.full(3, 2.0))

    def desired(t):
        return np.array([0.4 + 0.4 * np.sin(np.pi * t), 0.0, 0.1 * t])

    controller = MpcController(
        uvms,
        task="force",
        target=None,
        posture=q0,
        horizon_s=0.2,
        dt_s=0.05,
        rate_hz=20.0,
        force_task=MpcForceTask(spring, desired),
    )
    tracking = controller.force_tracking
    assert len(tracking.forces) == controller.problem.T + 1 == 5
    for t in (0.0, 0.05, 0.1):
        controller.compute(t, Measurement(t, q0, np.zeros(uvms.nv), np.zeros(6)))
        for k, term in enumerate(tracking.forces):
            np.testing.assert_allclose(term.target_N, desired(t + 0.05 * k), rtol=0, atol=1e-15)
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, q0)
    np.testing.assert_array_equal(
        controller._contact.model.anchor, data.oMf[uvms.ee_frame_id].translation
    )
    assert spring.anchor is None  # the caller's model stays unplaced
    moved = q0.copy()
    moved[0] += 0.1
    controller.reset()
    controller.compute(0.0, Measurement(0.0, moved, np.zeros(uvms.nv), np.zeros(6)))
    assert controller._contact.model.anchor[0] == pytest.approx(
        data.oMf[uvms.ee_frame_id].translation[0] + 0.1, abs=1e-12
    )


def _spy_on_plans(controller) -> list[tuple]:
    """The (x, cold, iterations, warm start, regularization) and the returned preg of each
    re-plan ``controller`` makes from now on (whichever planner solves it)."""
    calls, plan = [], controller._replan

    def spy(x, cold, iterations, warm, regularization):
        guess, cost, preg = plan(x, cold, iterations, warm, regularization)
        calls.append((x, cold, iterations, warm, regularization, preg))
        return guess, cost, preg

    controller._replan = spy
    return calls


@pytest.mark.parametrize("planner", ["core", "python"])
@pytest.mark.parametrize("rate_hz", [20.0, 5.0])
def test_the_warm_start_moves_the_last_plan_on_by_the_time_since_it(
    reference_uvms, rate_hz, planner
):
    """The second plan starts from the first moved on by the time between them in whole
    nodes (dt_s = 0.05: one node at 20 Hz, four at 5 Hz), the measured state first and the
    last node repeated at the end: a plan started from a guess misaligned in time begins
    from where the vehicle was told to be earlier."""
    q0 = _start(reference_uvms)
    controller, _ = _controller(
        reference_uvms, reference_uvms, q0, rate_hz=rate_hz, planner=planner
    )
    assert (controller.planner_path == "compiled") == (planner == "core")
    calls = _spy_on_plans(controller)
    v0 = np.zeros(reference_uvms.nv)
    controller.compute(0.0, Measurement(0.0, q0, v0, np.zeros(6)))
    xs, us = (list(part) for part in controller._guess)
    later = 1.0 / rate_hz
    controller.compute(later, Measurement(later, q0, v0, np.zeros(6)))
    shift = round(later / 0.05)
    start_xs, start_us = calls[1][3]
    assert len(start_xs) == len(xs) and len(start_us) == len(us)
    np.testing.assert_array_equal(start_xs[0], np.r_[q0, v0])
    for k in range(1, len(xs)):
        np.testing.assert_array_equal(start_xs[k], xs[min(k + shift, len(xs) - 1)])
    for k in range(len(us)):
        np.testing.assert_array_equal(start_us[k], us[min(k + shift, len(us) - 1)])


@pytest.mark.parametrize("planner", ["core", "python"])
def test_the_mpc_replans_at_its_rate_cold_longer_then_from_the_last_regularization(
    reference_uvms, planner
):
    """At 20 Hz sampled every 10 ms: a plan at 0 and 0.05 s only, tau held in between; the
    first (cold) plan runs COLD_START_ITERATIONS, the warm one ``iterations`` (2) from the
    regularization the first ended with."""
    q0 = _start(reference_uvms)
    controller, _ = _controller(reference_uvms, reference_uvms, q0, rate_hz=20.0, planner=planner)
    calls = _spy_on_plans(controller)
    v0 = np.zeros(reference_uvms.nv)
    taus = [
        controller.compute(t, Measurement(t, q0, v0, np.zeros(6)))
        for t in (0.0, 0.01, 0.02, 0.03, 0.04, 0.05)
    ]
    assert len(calls) == 2
    for tau in taus[1:5]:
        np.testing.assert_array_equal(tau, taus[0])
    (
        (*_, cold, cold_iterations, _, cold_start, cold_end),
        (*_, warm, warm_iterations, _, warm_start, _),
    ) = calls
    assert (cold, warm) == (True, False)
    assert (cold_iterations, warm_iterations) == (COLD_START_ITERATIONS, 2)
    assert cold_start is None and warm_start == cold_end
