"""The paper's controller in closed loop: funnels, model-freeness, robustness, accuracy.

The two shipped scenarios are simulated once per test session (module fixtures); each
run takes ~30 s of wall time.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.performance import transformation_gain, transformed_error
from uvms_pin.control.ppc import PrescribedPerformanceController
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.kinematics import analytical_jacobian, end_effector_pose, frame_id_from_name
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.actuation import ThrustersAndJointLimits
from uvms_pin.sim.run import Scenario, simulate

PAPER = ROOT / "scenarios" / "paper_force_tracking.toml"
REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


@pytest.fixture(scope="module")
def paper_rollout():
    return simulate(load_scenario(PAPER))


@pytest.fixture(scope="module")
def realistic():
    scenario = load_scenario(REALISTIC)
    return scenario, simulate(scenario)


def _assert_inside_funnels(rollout: up.Rollout, force_rms_fraction: float) -> None:
    s = rollout.signals
    assert rollout.metadata["status"] == "ok"
    assert rollout.time_s[-1] == pytest.approx(rollout.metadata["duration_s"])
    for name in ("e_x", "rho_x", "e_zeta", "rho_zeta", "xi_x", "xi_zeta"):
        assert np.all(np.isfinite(s[name])), name
    assert np.all(np.isfinite(rollout.q)) and np.all(np.isfinite(rollout.v))
    # strictly inside, every component, every logged sample
    assert np.all(np.abs(s["e_x"]) < s["rho_x"])
    assert np.all(np.abs(s["e_zeta"]) < s["rho_zeta"])
    # per force component: the true error's RMS after the transient vs that component's
    # final funnel width
    after = rollout.time_s >= rollout.metrics()["transient_end_s"]
    error = rollout.wrench_contact_world[after, :3] - s["force_desired_world_N"][after]
    rms = np.sqrt(np.mean(error**2, axis=0))
    assert np.all(rms < force_rms_fraction * s["rho_x"][-1, :3]), (rms, s["rho_x"][-1, :3])


def test_paper_scenario_holds_its_funnels(paper_rollout):
    """The paper's literal parameters, continuous time, unlimited input: the funnels hold
    for the whole run. The force error rides near the funnel edge (k_x = 0.2 on a 2 N/m
    spring), so its RMS after the transient is below 0.75 rho_inf, not far below."""
    _assert_inside_funnels(paper_rollout, 0.75)
    # it needs far more than an LBV150 has (~43 N of surge thrust): report, do not hide
    assert paper_rollout.metrics()["vehicle_force_peak_N"] > 200.0


def test_realistic_scenario_holds_its_funnels_within_actuator_limits(realistic):
    """500 Hz, thrust- and torque-limited: the funnels hold; the force error after the
    transient stays below 0.6 rho_inf (0.55 measured: the thrusters saturate during part
    of every force period, see docs/paper.md); no thrust, torque or joint position limit is
    exceeded."""
    scenario, rollout = realistic
    _assert_inside_funnels(rollout, 0.6)
    assert rollout.metrics()["joint_limit_excess_max_rad"] == 0.0
    actuation = scenario.plant.actuation
    assert isinstance(actuation, ThrustersAndJointLimits)
    # applied inputs are what the thrusters and joints can give ...
    thrusts = np.array([actuation.thrusts(tau) for tau in rollout.tau])
    lower = np.array([-t.max_reverse_N for t in actuation.thrusters])
    upper = np.array([t.max_forward_N for t in actuation.thrusters])
    assert np.all(thrusts >= lower - 1e-9) and np.all(thrusts <= upper + 1e-9)
    assert np.all(np.abs(rollout.tau[:, 6:]) <= actuation.joint_effort_limits_Nm + 1e-12)
    # the arm never asks more than its drives give (the thrusters do, part of the time)
    commanded = rollout.signals["tau_commanded"]
    assert np.all(np.abs(commanded[:, 6:]) <= actuation.joint_effort_limits_Nm)
    saturated = np.mean([actuation.saturated(c) for c in commanded])
    assert 0.0 < saturated < 0.6


def test_realistic_run_is_reproducible(realistic):
    """Same scenario and seed: bit-identical rollout."""
    _, rollout = realistic
    again = simulate(load_scenario(REALISTIC, {"scenario.duration_s": 1.0}))
    n = len(again)
    np.testing.assert_array_equal(again.q, rollout.q[:n])
    np.testing.assert_array_equal(again.wrench_measured_world, rollout.wrench_measured_world[:n])


# ---- model-free ---------------------------------------------------------------------------


def _scaled_uvms(uvms: UVMS, factor: float) -> UVMS:
    """Every inertia, the armature, every added mass, damping and volume scaled by factor
    (mass and volume together: the vehicle stays trimmed)."""
    return scaled_uvms(
        uvms,
        mass_scale=factor,
        added_mass_scale=factor,
        damping_scale=factor,
        buoyancy_scale=factor,
    )


def test_controller_output_does_not_depend_on_the_plant(realistic):
    """Same Measurement -> identical tau, whatever the plant's inertia, added mass, damping,
    buoyancy and environment stiffness (the controller only uses kinematics). The
    measurements are 50 samples of the realistic run."""
    _, rollout = realistic
    base = load_scenario(REALISTIC)
    stiff = load_scenario(REALISTIC, {"environment.stiffness_N_m": [2000.0, 2000.0, 2000.0]})
    heavy = _scaled_uvms(base.uvms, 1.7)
    assert up.mass_matrix(heavy, base.q0)[0, 0] > 1.5 * up.mass_matrix(base.uvms, base.q0)[0, 0]
    controllers = [
        base.controller_factory(base.uvms),
        stiff.controller_factory(stiff.uvms),
        base.controller_factory(heavy),
    ]
    for k in np.linspace(0, len(rollout) - 1, 50).astype(int):
        t = float(rollout.time_s[k])
        measurement = Measurement(t, rollout.q[k], rollout.v[k], rollout.wrench_measured_world[k])
        outputs = [c.compute(t, measurement) for c in controllers]
        np.testing.assert_array_equal(outputs[0], rollout.signals["tau_commanded"][k])
        for out in outputs[1:]:
            np.testing.assert_array_equal(out, outputs[0])


def _with_uvms(scenario: Scenario, uvms: UVMS) -> Scenario:
    scenario.plant.uvms = uvms
    return scenario


@pytest.mark.parametrize("factor", [0.7, 1.3])
def test_paper_funnels_hold_with_plant_parameters_off_by_30_percent(factor):
    """The paper's claim: the same gains hold every funnel when all inertial and
    hydrodynamic parameters are 30 % off (4 s: the transient, where the loop is stiffest,
    and two force periods)."""
    scenario = load_scenario(PAPER, {"scenario.duration_s": 4.0})
    scenario = _with_uvms(scenario, _scaled_uvms(scenario.uvms, factor))
    rollout = simulate(scenario)
    assert rollout.metadata["status"] == "ok"
    assert rollout.metrics()["funnel_margin_min_second"] > 0.0


@pytest.mark.parametrize("factor", [0.7, 1.3])
def test_realistic_funnels_hold_with_plant_parameters_off_by_30_percent(factor):
    """The thrust-limited design too: same gains, all inertial and hydrodynamic parameters
    30 % off, every funnel held and every joint inside its limits for the whole run."""
    scenario = load_scenario(REALISTIC)
    scenario = _with_uvms(scenario, _scaled_uvms(scenario.uvms, factor))
    rollout = simulate(scenario)
    assert rollout.metadata["status"] == "ok"
    assert rollout.metrics()["joint_limit_excess_max_rad"] == 0.0


# ---- failure is reported, not hidden ----------------------------------------------------


def test_impossible_specification_stops_with_a_funnel_violation(tmp_path):
    """A force funnel tighter than the sensor noise (rho_inf 0.01 N < noise 0.02 N): the
    run stops with a FunnelViolation. Which funnel goes first depends on the run: the force
    error itself, or a velocity funnel that cannot follow the references the shrinking
    force funnel demands; the shipped scenario (same everything else) holds, so the
    violation is the specification's."""
    scenario = load_scenario(
        REALISTIC,
        {
            "controller.rho_inf_x": [0.01, 0.01, 0.01, 0.2, 0.2, 0.2],
            "controller.rho0_x": [1.0, 1.0, 1.0, 0.9, 0.9, 0.9],
        },
    )
    with pytest.raises(up.FunnelViolation) as info:
        simulate(scenario)
    exc = info.value
    assert exc.level in ("first", "second")
    assert exc.time_s > 0.5  # not the initial condition: the funnel had to shrink first
    assert abs(exc.error) >= exc.bound
    message = str(exc)
    assert exc.component in message and "t = " in message and "rho" in message
    partial = exc.rollout
    assert partial.metadata["status"] == "FunnelViolation"
    assert 0 < len(partial) and partial.time_s[-1] <= exc.time_s
    assert np.all(np.isfinite(partial.q))


def test_cli_saves_and_plots_the_partial_rollout(tmp_path):
    from conftest import run

    scenario = tmp_path / "impossible.toml"
    text = REALISTIC.read_text()  # names its model "uvms_lbv150": the copy finds it
    text = text.replace("duration_s = 10.0", "duration_s = 3.0")
    # tighten the force funnel below the noise in the file itself, shrinking within ~1.5 s
    text = re.sub(r"l_x_per_s = \[[^\]]*\]", "l_x_per_s = [3.0, 3.0, 3.0, 1.0, 1.0, 1.0]", text)
    text = re.sub(r"rho0_x = \[[^\]]*\]", "rho0_x = [1.0, 1.0, 1.0, 0.9, 0.9, 0.9]", text)
    scenario.write_text(
        re.sub(r"rho_inf_x = \[[^\]]*\]", "rho_inf_x = [0.01, 0.01, 0.01, 0.2, 0.2, 0.2]", text)
    )
    out = tmp_path / "out"
    result = run("run", str(scenario), "--out", str(out))
    assert result.returncode == 3, result.stderr
    assert "funnel violated" in result.stderr
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "FunnelViolation"
    for name in ("rollout.npz", "force.png", "first_level_errors.png", "second_level_errors.png"):
        assert (out / name).stat().st_size > 0


# ---- integrator accuracy ------------------------------------------------------------------


def test_paper_force_trajectory_converges_with_the_tolerance():
    """LSODA at rtol 1e-6 (shipped) vs 1e-8 over the first 2 s (the transient, the stiffest
    part): the true contact force differs by less than 2 mN (1 % of rho_inf)."""
    coarse = simulate(load_scenario(PAPER, {"scenario.duration_s": 2.0}))
    fine = simulate(
        load_scenario(
            PAPER, {"scenario.duration_s": 2.0, "integrator.rtol": 1e-8, "integrator.atol": 1e-10}
        )
    )
    diff = np.abs(coarse.wrench_contact_world[:, :3] - fine.wrench_contact_world[:, :3]).max()
    assert diff < 2e-3, diff


def test_realistic_force_trajectory_converges_with_the_step():
    """RK4 at the shipped step vs half of it, same 500 Hz control: the true force differs
    by less than 2 mN over 3 s."""
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 3.0})
    step = scenario.settings.integrator.step_s
    coarse = simulate(scenario)
    fine = simulate(
        load_scenario(REALISTIC, {"scenario.duration_s": 3.0, "integrator.step_s": step / 2})
    )
    diff = np.abs(coarse.wrench_contact_world[:, :3] - fine.wrench_contact_world[:, :3]).max()
    assert diff < 2e-3, diff


def test_controller_runs_for_any_arm_and_frame():
    """The law is sized by the model (a 2-joint arm, the sensor frame as its end-effector)
    and is the paper's there, recomputed from its signals and the reduced model's own
    Jacobian: xdot_r = -k_x eps(e_x / rho_x), zeta_r = J^+ xdot_r (unit weights, no
    null-space task), tau = -K_zeta P^-1 R(xi_zeta) eps(xi_zeta) / rho_zeta."""
    base = load_scenario(REALISTIC)
    model = base.uvms.model
    reduced = pin.buildReducedModel(
        model, [model.getJointId("arm_joint3"), model.getJointId("arm_joint4")], base.q0
    )
    q = np.delete(base.q0, [9, 10])
    frame = frame_id_from_name(reduced, "ft_sensor")
    rpy_now = end_effector_pose(reduced, reduced.createData(), q, frame)[1]
    controller = PrescribedPerformanceController(
        reduced, "ft_sensor", desired_force_world_N=[0.4, 0, 0], desired_rpy=rpy_now + 0.05
    )
    time_s = 0.3
    v = 0.02 * np.random.default_rng(5).normal(size=8)
    force = np.array([0.1, -0.05, 0.2])
    tau = controller.compute(time_s, Measurement(time_s, q, v, np.r_[force, 0.0, 0.0, 0.0]))
    assert tau.shape == (8,)
    assert controller.second_level_names[6:] == ("arm_joint1", "arm_joint2")
    s, p = controller.last_signals, controller.params
    rho_x = (p.rho0_x - p.rho_inf_x) * np.exp(-p.l_x_per_s * time_s) + p.rho_inf_x
    np.testing.assert_allclose(s.rho_x, rho_x, rtol=1e-14)
    np.testing.assert_allclose(s.e_x, np.r_[force - [0.4, 0.0, 0.0], [-0.05] * 3], atol=1e-12)
    np.testing.assert_allclose(s.xdot_r, -p.k_x * transformed_error(s.e_x / rho_x), rtol=1e-14)
    jacobian = analytical_jacobian(reduced, reduced.createData(), q, frame)
    np.testing.assert_allclose(s.zeta_r, np.linalg.pinv(jacobian) @ s.xdot_r, atol=1e-12)
    np.testing.assert_allclose(s.e_zeta, v - s.zeta_r, atol=1e-15)
    rho_zeta = (p.rho0_zeta - p.rho_inf_zeta) * np.exp(-p.l_zeta_per_s * time_s) + p.rho_inf_zeta
    np.testing.assert_allclose(s.rho_zeta, rho_zeta, rtol=1e-14)
    xi = s.e_zeta / rho_zeta
    expected = -p.k_zeta * transformation_gain(xi) * transformed_error(xi) / rho_zeta
    np.testing.assert_allclose(tau, expected, rtol=1e-12, atol=1e-14)
