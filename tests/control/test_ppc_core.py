"""The compiled PPC law (src/uvms_core/ppc.hpp) against the Python reference (backend="python").

Compared on each call with `test_ppc_oracle.assert_same_outcome` (tau, margin, every signal
to 1e-12 relative, or the same exception): the recorded measurements of both shipped
scenarios, random states on the reference model and on a mounted 7-joint Panda with and
without velocity weights, null-space task and funnel extension; the errors (funnels, bad
measurements, Euler singularity) and the SVD route; a closed loop of the realistic scenario.
Every comparison also checks that the compiled route was the one taken (the kernel falls back
to the reference on exactly the calls the reference raises for or extends beyond the clamp).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import (
    ROOT,
    continuous_joint_urdf,
    mount_on_reference_vehicle,
    random_configuration,
)
from test_ppc_oracle import (
    CLAMP,
    REALISTIC_WEIGHTS,
    RECORDED,
    SCENARIOS,
    assert_same_outcome,
    exact_reference_velocity,
    outcome,
)

import uvms_pin as up
from uvms_pin.control import task_space
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.ppc import PPCParams, PrescribedPerformanceController
from uvms_pin.errors import FunnelViolation, ParameterError, ScenarioError
from uvms_pin.model.arm_joints import ArmJoints
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.scenario.load import load_scenario

STATUS = core_module().PPC_STATUS


def count_reference_calls(controller: PrescribedPerformanceController) -> list:
    """Records each call of ``controller`` that the Python reference evaluated."""
    calls = []
    original = controller._compute_reference

    def counting(*args, **kwargs):
        calls.append(args[0])
        return original(*args, **kwargs)

    controller._compute_reference = counting
    return calls


def reference_needed(python: PrescribedPerformanceController, result) -> bool:
    """Whether the reference must evaluate this call: it raised, or an |xi| reached the
    extension's clamp (the kernel leaves the linear continuation to the reference)."""
    if isinstance(result, Exception):
        return True
    signals = result[2]
    largest = max(np.abs(signals["xi_x"]).max(), np.abs(signals["xi_zeta"]).max())
    return bool(python._extend_beyond_funnels and largest >= CLAMP)


def compare(core, python, time_s, measurement, calls, expected_calls):
    """One call on both backends: same outcome, and the reference used only when needed."""
    before = len(calls)
    old = outcome(python, time_s, measurement)
    assert_same_outcome(outcome(core, time_s, measurement), old, python)
    needed = reference_needed(python, old)
    assert len(calls) - before == needed, (needed, old)
    expected_calls[0] += needed
    return old


# ---------------------------------------------------------------- construction and status


def test_backend_is_validated_and_recorded(reference_uvms):
    frame = reference_uvms.model.frames[reference_uvms.ee_frame_id].name
    with pytest.raises(ParameterError, match="backend"):
        PrescribedPerformanceController(reference_uvms.model, frame, backend="gpu")
    assert PrescribedPerformanceController(reference_uvms.model, frame).backend == "core"
    python = PrescribedPerformanceController(reference_uvms.model, frame, backend="python")
    assert python.backend == "python" and python._kernel is None


@pytest.mark.parametrize("stem", SCENARIOS)
def test_scenario_forwards_the_backend(stem):
    path = ROOT / "scenarios" / f"{stem}.toml"
    default = load_scenario(path)
    assert default.controller_factory(default.uvms).backend == "core"
    python = load_scenario(path, {"controller.backend": "python"})
    assert python.controller_factory(python.uvms).backend == "python"
    assert python.controller_factory.params["backend"] == "python"
    with pytest.raises(ScenarioError, match="backend"):
        load_scenario(path, {"controller.backend": "fortran"})


def test_the_kernel_reports_each_status(reference_uvms):
    """ok and the five reasons to hand a call to the reference, straight from the kernel."""
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    q = reference_uvms.neutral_configuration()
    q[7:] = [0.1, 0.9, -0.7, 0.3]
    controller = PrescribedPerformanceController(model, frame, desired_rpy=(0.0, 0.0, 0.0))
    kernel = controller._kernel
    zero3, v = np.zeros(3), np.full(model.nv, 0.01)
    wrench = np.r_[0.1, 0.0, 0.0, 0.0, 0.0, 0.0]

    pin.framesForwardKinematics(model, controller.data, q)
    rpy = pin.rpy.matrixToRpy(controller.data.oMf[controller.ee_frame_id].rotation)

    def status(q=q, v=v, wrench=wrench, force=zero3, rpy=rpy, extended=False, kernel=kernel):
        return STATUS[kernel.compute(0.2, q, v, wrench, force, rpy, extended)]

    assert status() == "ok"
    assert status(force=np.array([5.0, 0.0, 0.0])) == "first-level funnel"
    assert status(v=np.full(model.nv, 3.0)) == "second-level funnel"
    assert status(v=np.full(model.nv, 3.0), extended=True) == "second-level funnel"
    # xi_zeta of one component between the extension's clamp and 1: the plain law holds
    # (ok), the extension is the reference's
    zeta_r = kernel.views["zeta_r"].copy()
    rho_zeta = kernel.views["rho_zeta"].copy()
    v_edge = v.copy()
    v_edge[7] = zeta_r[7] + (1.0 - 3e-7) * rho_zeta[7]
    assert status(v=v_edge) == "ok"
    assert np.abs(kernel.views["xi_zeta"][7] - (1.0 - 3e-7)) < 1e-12
    assert status(v=v_edge, extended=True) == "second-level funnel"
    assert status(q=np.r_[q[:-1], np.nan]) == "bad input"
    assert status(v=v[:-1]) == "bad input"
    assert status(wrench=np.r_[wrench[:5], np.inf]) == "bad input"
    assert status(rpy=np.array([0.0, np.nan, 0.0])) == "bad input"
    heavy = PPCParams(velocity_weights=[1e8] * 6 + [1.0] * 4, null_space_gain_per_s=1.0)
    declined = PrescribedPerformanceController(model, frame, heavy)._kernel
    assert status(kernel=declined) == "solver declined"
    # the end-effector at pitch = 90 deg - 0.9e-3 rad: inside the Euler singularity's band
    base = pin.XYZQUATToSE3(q[:7]).rotation
    pin.framesForwardKinematics(model, controller.data, q)
    relative = base.T @ controller.data.oMf[controller.ee_frame_id].rotation
    turned = pin.rpy.rpyToMatrix(np.array([0.3, math.pi / 2 - 0.9e-3, -0.4])) @ relative.T
    q_singular = q.copy()
    q_singular[3:7] = pin.Quaternion(turned).coeffs()
    singular_rpy = np.array([0.3, math.pi / 2 - 0.9e-3, -0.4])
    assert status(q=q_singular, rpy=singular_rpy) == "Euler singularity"
    # a failed call leaves the last ok call's signals
    assert status() == "ok"
    packed = kernel.packed.copy()
    assert status(force=np.array([5.0, 0.0, 0.0])) != "ok"
    np.testing.assert_array_equal(kernel.packed, packed)


# ---------------------------------------------------------------- recorded runs


def recorded(stem: str):
    data = np.load(RECORDED)
    for i in range(data[f"{stem}/time_s"].size):
        yield (
            Measurement(
                float(data[f"{stem}/time_s"][i]),
                data[f"{stem}/q"][i],
                data[f"{stem}/v"][i],
                data[f"{stem}/wrench_world"][i],
            ),
            bool(data[f"{stem}/extended"][i]),
        )


@pytest.mark.parametrize("stem", SCENARIOS)
def test_recorded_runs_match_the_python_reference(stem):
    path = ROOT / "scenarios" / f"{stem}.toml"
    scenario = load_scenario(path)
    core = scenario.controller_factory(scenario.uvms)
    python = load_scenario(path, {"controller.backend": "python"}).controller_factory(scenario.uvms)
    calls, expected = count_reference_calls(core), [0]
    n = 0
    for measurement, extended in recorded(stem):
        core.set_funnel_extension(extended)
        python.set_funnel_extension(extended)
        compare(core, python, measurement.time_s, measurement, calls, expected)
        n += 1
    assert n >= 300
    # the compiled route is the one compared, except the paper run's LSODA trial stages
    # beyond the extension's clamp (110 of its 300 records)
    assert len(calls) == expected[0] <= (n // 2 if stem == "paper_force_tracking" else 0)


# ---------------------------------------------------------------- random states

VARIANTS = {
    "paper": {},
    "weights": {"velocity_weights": REALISTIC_WEIGHTS},
    "null-space": {"null_space_gain_per_s": 3.0},
    "weights+null-space": {"velocity_weights": REALISTIC_WEIGHTS, "null_space_gain_per_s": 3.0},
    "weights+null-space+target+gains": {
        "velocity_weights": REALISTIC_WEIGHTS,
        "null_space_gain_per_s": 1.5,
        "null_space_target": "mid+0.2",
        "k_zeta": 20.0,
        "k_x": 0.5,
    },
}


def variant_params(name: str, model: pin.Model) -> PPCParams:
    n_joints = model.nv - 6
    fields = dict(VARIANTS[name])
    if "velocity_weights" in fields:
        fields["velocity_weights"] = [*fields["velocity_weights"], *[1.0] * n_joints]
    if fields.get("null_space_target") == "mid+0.2":  # 0.2 for a joint without limits
        arm = ArmJoints.of(model)
        lower, upper = (np.where(arm.limited, x, 0.0) for x in (arm.lower, arm.upper))
        fields["null_space_target"] = 0.5 * (lower + upper) + 0.2
    return PPCParams(**fields)


def compare_random_states(model, frame, params, rng, n_states, q_sampler, spread=0.9):
    """Random q, force, orientation and velocity errors at |xi| up to ``spread``, each with
    the funnel extension off and on; returns how many calls were ok and raised."""
    target = {"rpy": np.zeros(3)}

    def desired_force(t):
        return np.array([0.4 * math.sin(math.pi * t) + 0.4, 0.0, 0.0])

    def desired_rpy(t):
        return target["rpy"]

    core = PrescribedPerformanceController(model, frame, params, desired_force, desired_rpy)
    python = PrescribedPerformanceController(
        model, frame, params, desired_force, desired_rpy, backend="python"
    )
    calls, expected = count_reference_calls(core), [0]
    data, frame_id = model.createData(), model.getFrameId(frame)
    outcomes = {"ok": 0, "raised": 0}
    for _ in range(n_states):
        q = q_sampler(rng)
        time_s = rng.uniform(0.0, 3.0)
        rho = python.performance_x.value(time_s)
        pin.framesForwardKinematics(model, data, q)
        rpy = pin.rpy.matrixToRpy(data.oMf[frame_id].rotation)
        target["rpy"] = rpy - rng.uniform(-spread, spread, 3) * rho[3:]
        wrench = np.r_[desired_force(time_s) + rng.uniform(-spread, spread, 3) * rho[:3], 0, 0, 0]
        python.set_funnel_extension(False)
        probe = outcome(python, time_s, Measurement(time_s, q, np.zeros(model.nv), wrench))
        zeta_r = 0.0 if isinstance(probe, Exception) else python.last_signals.zeta_r
        v = zeta_r + rng.uniform(-spread, spread, model.nv) * python.performance_zeta.value(time_s)
        for extended in (False, True):
            core.set_funnel_extension(extended)
            python.set_funnel_extension(extended)
            measurement = Measurement(time_s, q, v, np.r_[wrench[:3], rng.normal(size=3)])
            old = compare(core, python, time_s, measurement, calls, expected)
            outcomes["raised" if isinstance(old, Exception) else "ok"] += 1
    assert len(calls) == expected[0]
    return outcomes


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_random_states_on_the_reference_model(reference_uvms, variant):
    model = reference_uvms.model
    outcomes = compare_random_states(
        model,
        model.frames[reference_uvms.ee_frame_id].name,
        variant_params(variant, model),
        np.random.default_rng(17),
        50,
        lambda r: random_configuration(reference_uvms, r),
    )
    assert outcomes["ok"] >= 45  # of 100 calls; the others raise (compared too)


@pytest.fixture(scope="module")
def panda_uvms(tmp_path_factory):
    uvms = mount_on_reference_vehicle("panda", tmp_path_factory.mktemp("panda"))
    assert uvms.n_arm_joints == 7
    return uvms


@pytest.mark.parametrize("variant", ["paper", "weights", "weights+null-space+target+gains"])
def test_random_states_on_a_mounted_7_joint_panda(panda_uvms, variant):
    model = panda_uvms.model
    outcomes = compare_random_states(
        model,
        model.frames[panda_uvms.ee_frame_id].name,
        variant_params(variant, model),
        np.random.default_rng(7),
        30,
        lambda r: random_configuration(panda_uvms, r),
    )
    assert outcomes["ok"] >= 25  # of 60 calls


@pytest.mark.parametrize("variant", ["paper", "weights+null-space+target+gains"])
def test_random_states_with_continuous_joints(tmp_path, variant):
    """Joints 1 and 3 continuous (q holds their cos and sin, nq = 12 + 1 != nv = 10); the
    null-space pull acts on the limited joints 2 and 4 only."""
    path = continuous_joint_urdf(tmp_path, ("arm_joint1", "arm_joint3"))
    uvms = up.load_uvms(path)
    model = uvms.model
    assert (model.nq, model.nv) == (13, 10)
    outcomes = compare_random_states(
        model,
        model.frames[uvms.ee_frame_id].name,
        variant_params(variant, model),
        np.random.default_rng(19),
        40,
        lambda r: random_configuration(uvms, r),
    )
    assert outcomes["ok"] >= 30  # of 80 calls


def test_beyond_the_funnels_the_same_errors_and_extension(reference_uvms):
    """|xi| up to 1.5: without the extension the same FunnelViolation, with it the same
    linear continuation (both evaluated by the reference for the core)."""
    model = reference_uvms.model
    outcomes = compare_random_states(
        model,
        model.frames[reference_uvms.ee_frame_id].name,
        variant_params("weights+null-space", model),
        np.random.default_rng(11),
        60,
        lambda r: random_configuration(reference_uvms, r),
        spread=1.5,
    )
    assert outcomes["raised"] >= 20 and outcomes["ok"] >= 20


# ---------------------------------------------------------------- errors and routes


@pytest.fixture
def reference_pair(reference_uvms):
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    q = reference_uvms.neutral_configuration()
    q[7:] = [0.1, 0.9, -0.7, 0.3]

    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    rpy_ee = pin.rpy.matrixToRpy(data.oMf[reference_uvms.ee_frame_id].rotation)

    def build(params=None, desired_force=(0.2, 0.0, 0.0), desired_rpy=rpy_ee + 0.02):
        params = params or variant_params("weights+null-space", model)
        core = PrescribedPerformanceController(model, frame, params, desired_force, desired_rpy)
        python = PrescribedPerformanceController(
            model, frame, params, desired_force, desired_rpy, backend="python"
        )
        return core, python, count_reference_calls(core)

    return model, q, build


@pytest.mark.parametrize(
    ("wrench_x", "v_scale", "level"),
    [(5.0, 0.01, "first"), (0.2, 2.0, "second"), (0.2, -2.0, "second")],
)
def test_funnel_violations_are_the_same(reference_pair, wrench_x, v_scale, level):
    model, q, build = reference_pair
    core, python, calls = build()
    measurement = Measurement(0.1, q, np.full(model.nv, v_scale), np.r_[wrench_x, 0, 0, 0, 0, 0])
    old = outcome(python, 0.1, measurement)
    assert isinstance(old, FunnelViolation) and old.level == level
    assert_same_outcome(outcome(core, 0.1, measurement), old, python)
    assert len(calls) == 1


def _nan_force(t):
    return (0.0, np.nan, 0.0)


@pytest.mark.parametrize(
    "case",
    [
        "q_nan",
        "q_quaternion_inf",
        "v_nan",
        "wrench_inf",
        "short_v",
        "long_q",
        "q_2d",
        "desired_force_nan",
        "desired_force_nan_and_short_v",
    ],
)
def test_bad_measurements_give_the_same_errors(reference_pair, case):
    model, q, build = reference_pair
    v, wrench = np.full(model.nv, 0.01), np.r_[0.1, 0, 0, 0, 0, 0]
    force = _nan_force if case.startswith("desired_force") else (0.2, 0.0, 0.0)
    q = q.copy()
    if case == "q_nan":
        q[0] = np.nan
    elif case == "q_quaternion_inf":
        q[4] = np.inf
    elif case == "v_nan":
        v[8] = np.nan
    elif case == "wrench_inf":
        wrench[1] = -np.inf
    elif case in ("short_v", "desired_force_nan_and_short_v"):
        v = v[:-1]
    elif case == "long_q":
        q = np.r_[q, 0.0]
    elif case == "q_2d":
        q = q[None, :]
    core, python, calls = build(desired_force=force)
    measurement = Measurement(0.0, q, v, wrench)
    old = outcome(python, 0.0, measurement)
    assert isinstance(old, ParameterError)
    if case == "desired_force_nan_and_short_v":
        assert "measurement.v" in str(old)  # the measurement is checked first
    assert_same_outcome(outcome(core, 0.0, measurement), old, python)
    # the kernel hands each to the reference (f_d(t) fails before the kernel is called)
    assert len(calls) == (not case.startswith("desired_force"))


def test_lists_and_integer_arrays_are_accepted_like_float_arrays(reference_pair):
    model, q, build = reference_pair
    core, python, _ = build()
    v, wrench = [0.01] * model.nv, [0, 0, 0, 0, 0, 0]  # a list, and integers
    measurement = Measurement(0.1, list(q), v, np.array(wrench))
    assert_same_outcome(outcome(core, 0.1, measurement), outcome(python, 0.1, measurement), python)
    converted = Measurement(0.1, q, np.array(v), np.array(wrench, dtype=int))
    assert_same_outcome(outcome(core, 0.1, converted), outcome(python, 0.1, converted), python)


@pytest.mark.parametrize("cos_pitch", [0.02, 1.001e-3, 0.999e-3, 1e-4])
def test_near_the_euler_singularity(reference_pair, cos_pitch):
    """The same ParameterError below |cos(pitch)| = 1e-3, the same tau above it."""
    model, q0, build = reference_pair
    data = model.createData()
    frame_id = model.getFrameId(build()[0].ee_frame_name)
    pin.framesForwardKinematics(model, data, q0)
    relative = pin.XYZQUATToSE3(q0[:7]).rotation.T @ data.oMf[frame_id].rotation
    rpy = np.array([0.3, math.acos(cos_pitch), -0.4])
    q = q0.copy()
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(rpy) @ relative.T).coeffs()
    core, python, calls = build(desired_rpy=rpy + 0.01, desired_force=(0.0, 0.0, 0.0))
    measurement = Measurement(0.2, q, np.full(model.nv, 0.05), np.r_[0.1, 0, 0, 0, 0, 0])
    old = outcome(python, 0.2, measurement)
    if cos_pitch < 1e-3:
        assert isinstance(old, ParameterError) and "Euler singularity" in str(old)
    # away from it the kernel's J^# is within 1e-13 of the exact one, as the reference's
    assert_same_outcome(outcome(core, 0.2, measurement), old, python, zeta_tolerance=1e-11)
    assert len(calls) == (cos_pitch < 1e-3)


@pytest.mark.parametrize(("vehicle_weight", "declined"), [(1e3, False), (1e8, True)])
def test_the_svd_route_when_the_solver_declines(
    reference_pair, monkeypatch, vehicle_weight, declined
):
    model, q, build = reference_pair
    svd_calls = []
    original = task_space.pseudo_inverse  # the exact SVD route of J^# (the PPC's reference)
    monkeypatch.setattr(
        task_space, "pseudo_inverse", lambda *a, **k: svd_calls.append(1) or original(*a, **k)
    )
    params = PPCParams(velocity_weights=[vehicle_weight] * 6 + [1.0] * 4, null_space_gain_per_s=1)
    core, python, calls = build(params)
    measurement = Measurement(0.1, q, np.full(model.nv, 0.01), np.r_[0.3, -0.1, 0.1, 0, 0, 0])
    old = outcome(python, 0.1, measurement)
    python_svd = len(svd_calls)
    assert python_svd == declined
    assert_same_outcome(outcome(core, 0.1, measurement), old, python)
    assert len(calls) == declined and len(svd_calls) == 2 * python_svd


@pytest.mark.parametrize("vehicle_weight", [1e4, 1e5, 1e6])
def test_ill_conditioned_solves_stay_exact(reference_pair, vehicle_weight):
    """Vehicle weights 1e4..1e6 against 1 on the joints: the certified bound of cond(J W^-1/2)^2
    is 1e5..1e7, still accepted; the kernel's refinement step keeps zeta_r within 1e-13 of the
    exact minimum-norm solution (rational arithmetic), as the reference's SVD is. (Without it
    the error is ~bound * 1e-16: 1e-12 to 1e-11 here.)"""
    model, q, build = reference_pair
    params = PPCParams(velocity_weights=[vehicle_weight] * 6 + [1.0] * 4, null_space_gain_per_s=1)
    core, python, calls = build(params)
    measurement = Measurement(0.1, q, np.full(model.nv, 0.01), np.r_[0.3, -0.1, 0.1, 0, 0, 0])
    assert_same_outcome(outcome(core, 0.1, measurement), outcome(python, 0.1, measurement), python)
    assert not calls
    exact = exact_reference_velocity(core, q)
    error = np.abs(core.last_signals.zeta_r - exact).max() / np.abs(exact).max()
    assert error <= 1e-13


# ---------------------------------------------------------------- signals and bookkeeping


def test_signals_margin_and_reset_follow_the_last_successful_call(reference_pair):
    model, q, build = reference_pair
    core, python, calls = build()
    assert core.last_signals is None and core.signals() == {} and core.funnel_margin() == np.inf
    good = Measurement(0.0, q, np.full(model.nv, 0.05), np.r_[0.2, 0, 0, 0, 0, 0])
    tau = core.compute(0.0, good)
    python.compute(0.0, good)
    assert isinstance(core.funnel_margin(), float)
    assert core.funnel_margin() == pytest.approx(python.funnel_margin(), rel=1e-12)
    held = core.last_signals
    before = core.signals()
    np.testing.assert_array_equal(before["tau"], tau)
    tau[:] = 0.0  # the caller owns the returned array
    # another ok call rewrites the kernel's buffers: what was read stays
    other = Measurement(0.3, q, np.full(model.nv, -0.05), np.r_[0.3, 0, 0, 0, 0, 0])
    core.compute(0.3, other)
    assert held.time_s == 0.0
    np.testing.assert_array_equal(held.tau, before["tau"])
    np.testing.assert_array_equal(held.zeta_r, before["zeta_r"])
    assert core.last_signals.time_s == 0.3
    # a call that raises leaves the last ok call's signals and margin
    after_ok = core.signals()
    margin = core.funnel_margin()
    with pytest.raises(FunnelViolation):
        core.compute(0.5, Measurement(0.5, q, np.full(model.nv, 0.05), np.r_[5.0, 0, 0, 0, 0, 0]))
    assert core.funnel_margin() == margin
    for name, value in core.signals().items():
        np.testing.assert_array_equal(value, after_ok[name])
    # a call the reference evaluated, then one the kernel did: the signals follow
    core.set_funnel_extension(True)
    beyond = Measurement(0.4, q, np.full(model.nv, 1.5), np.r_[0.2, 0, 0, 0, 0, 0])
    core.compute(0.4, beyond)
    assert core.last_signals.time_s == 0.4 and core.funnel_margin() < 0.0
    core.compute(0.3, other)
    assert core.last_signals.time_s == 0.3 and core.funnel_margin() > 0.0
    assert len(calls) == 2  # the violation and the extension beyond the clamp
    core.reset()
    assert core.last_signals is None and core.signals() == {} and core.funnel_margin() == np.inf


@pytest.mark.parametrize("backend", ["core", "python"])
def test_a_copy_computes_the_same_and_keeps_the_last_signals(reference_pair, backend):
    model, q, build = reference_pair
    controller = build()[0 if backend == "core" else 1]
    measurement = Measurement(0.1, q, np.full(model.nv, 0.05), np.r_[0.3, 0, 0, 0, 0, 0])
    tau = controller.compute(0.1, measurement)
    clone = copy.deepcopy(controller)
    assert clone.backend == backend and (clone._kernel is None) == (backend == "python")
    assert clone.funnel_margin() == controller.funnel_margin()
    for name, value in controller.signals().items():
        np.testing.assert_array_equal(clone.signals()[name], value)
    np.testing.assert_array_equal(clone.compute(0.1, measurement), tau)
    other = Measurement(0.2, q, np.full(model.nv, -0.05), np.r_[0.1, 0, 0, 0, 0, 0])
    clone.compute(0.2, other)  # the clone's buffers are its own
    assert controller.last_signals.time_s == 0.1 and clone.last_signals.time_s == 0.2


# ---------------------------------------------------------------- closed loop


def test_realistic_closed_loop_is_the_same_on_both_controller_backends():
    path = ROOT / "scenarios" / "realistic_force_tracking.toml"
    rollouts = {}
    for backend in ("core", "python"):
        scenario = load_scenario(path, {"scenario.duration_s": 1.0, "controller.backend": backend})
        assert scenario.controller_factory(scenario.uvms).backend == backend
        rollouts[backend] = up.simulate(scenario, progress=False)
    fast, slow = rollouts["core"], rollouts["python"]
    assert fast.metadata["status"] == slow.metadata["status"] == "ok"
    assert len(fast) == len(slow) == 101
    for name in ("q", "v", "tau"):
        a, b = getattr(fast, name), getattr(slow, name)
        scale = np.max(np.abs(b), axis=0) + 1.0
        assert np.max(np.abs(a - b) / scale) < 1e-9, name
    assert np.abs(slow.tau).max() > 0.1  # the controller acted
