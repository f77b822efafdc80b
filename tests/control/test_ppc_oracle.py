"""The fast PPC gives the pre-optimization controller's outputs to 1e-12 (the oracle).

The oracle is a frozen copy of the controller before it was optimized
(``tests/control/ppc_oracle``). Compared on each call: tau (relative to max |tau|), the
funnel margin, every logged signal, and the exception (type, level, component, values)
when the oracle raises. Inputs: measurements recorded from real runs of both shipped
scenarios (``scripts/record_ppc_measurements.py``), random states on the reference model,
on code-built arms of 0 to 7 joints and on a mounted 7-joint Panda, near-singular
Jacobians (Euler singularity, stretched arm, extreme weights) and the funnel extension.
"""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path
from unittest import mock

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT, mount_on_reference_vehicle, random_configuration
from ppc_oracle import in_place_of_the_package_ppc
from ppc_oracle import performance as oracle_performance
from ppc_oracle.ppc import PrescribedPerformanceController as OraclePPC
from test_ppc import build_test_uvms

import uvms_pin as up
from uvms_pin.control import task_space
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.ppc import PPCParams, PrescribedPerformanceController
from uvms_pin.errors import FunnelViolation, UvmsPinError
from uvms_pin.physics.kinematics import frame_rotation_and_jacobian
from uvms_pin.scenario.load import load_scenario

RECORDED = Path(__file__).resolve().parent / "data" / "ppc_runs.npz"
SCENARIOS = ("paper_force_tracking", "realistic_force_tracking")
TOLERANCE = 1e-12
CLAMP = 1.0 - 1e-6  # the funnel extension's clamp of |xi|
#: the realistic scenario's weights: roll/pitch 1e4, heave 1e3, sway 300, surge/yaw 100
REALISTIC_WEIGHTS = [100.0, 300.0, 1000.0, 1e4, 1e4, 100.0]


def outcome(controller, time_s: float, measurement: Measurement):
    """(tau, margin, signals) of one call, or the exception it raised."""
    try:
        tau = controller.compute(time_s, measurement)
    except UvmsPinError as exc:
        return exc
    return tau.copy(), controller.funnel_margin(), controller.signals()


def assert_same_outcome(
    new, old, oracle, zeta_tolerance: float = TOLERANCE, tau_tolerance: float = TOLERANCE
) -> None:
    """The same exception, or the same tau, margin and signals to 1e-12.

    Signals are compared relative to max(|signal|, 1) (units N, rad, m/s); e_zeta = v -
    zeta_r and xi_zeta = e_zeta / rho relative to max |v|, |zeta_r| (the subtraction's
    scale), with ``zeta_tolerance`` for zeta_r, e_zeta and xi_zeta.

    tau is checked twice: (1) it is the oracle's law evaluated at the fast controller's own
    xi_zeta, to 1e-12; (2) it is the oracle's tau to 1e-12 relative when max |xi_zeta| < 0.99.
    Beyond that the barrier's slope (up to ~1e12 at the funnel extension's clamp) turns a
    1e-16 change of zeta_r (any other order of floating-point operations) into more than
    1e-12 of tau: the inputs of the law are then compared instead.
    """
    if isinstance(old, Exception):
        assert type(new) is type(old), f"oracle raised {old!r}, fast gave {new!r}"
        if isinstance(old, FunnelViolation):
            assert (new.level, new.component, new.time_s) == (old.level, old.component, old.time_s)
            assert new.error == pytest.approx(old.error, rel=TOLERANCE, abs=TOLERANCE)
            assert new.bound == pytest.approx(old.bound, rel=TOLERANCE)
        else:
            assert str(new) == str(old)
        return
    assert not isinstance(new, Exception), f"fast raised {new!r}, the oracle did not"
    (tau_new, margin_new, signals_new), (tau_old, margin_old, signals_old) = new, old
    assert signals_new.keys() == signals_old.keys()
    np.testing.assert_array_equal(signals_new["tau"], tau_new)
    velocity_scale = max(
        np.abs(signals_old["zeta_r"]).max(), np.abs(signals_old["e_zeta"]).max(), 1.0
    )
    # the margin is 1 - max |xi|: xi_zeta's tolerance applies
    margin_tolerance = TOLERANCE * max(abs(margin_old), 1.0) + zeta_tolerance * (
        velocity_scale / signals_old["rho_zeta"].min()
    )
    assert abs(margin_new - margin_old) <= margin_tolerance, (margin_new, margin_old)
    for name, value_old in signals_old.items():
        difference = np.abs(signals_new[name] - value_old).max()
        if name in ("tau", "eps_zeta"):
            continue
        if name in ("zeta_r", "e_zeta", "xi_zeta"):
            scale = velocity_scale / (signals_old["rho_zeta"].min() if name == "xi_zeta" else 1)
            assert difference <= zeta_tolerance * scale, (name, signals_new[name], value_old)
        else:
            scale = max(np.abs(value_old).max(), 1.0)
            assert difference <= TOLERANCE * scale, (name, signals_new[name], value_old)
    xi, rho = signals_new["xi_zeta"], signals_new["rho_zeta"]
    k_zeta = oracle.params.k_zeta
    if oracle._extend_beyond_funnels:
        law = -k_zeta * oracle_performance.barrier_extended(xi, CLAMP) / rho
    else:
        law = -k_zeta * oracle_performance.transformation_gain(xi) * 2.0 * np.arctanh(xi) / rho
    scale = max(np.abs(law).max(), 1.0)
    assert np.abs(tau_new - law).max() <= TOLERANCE * scale, (tau_new, law)
    if np.abs(signals_old["xi_zeta"]).max() < 0.99:
        scale = max(np.abs(tau_old).max(), 1.0)
        assert np.abs(tau_new - tau_old).max() <= tau_tolerance * scale, (tau_new, tau_old)


def scenario_pair(stem: str):
    scenario = load_scenario(ROOT / "scenarios" / f"{stem}.toml")
    fast = scenario.controller_factory(scenario.uvms)
    with mock.patch(
        "uvms_pin.scenario.ppc.PrescribedPerformanceController", in_place_of_the_package_ppc
    ):
        oracle = scenario.controller_factory(scenario.uvms)
    assert isinstance(fast, PrescribedPerformanceController)
    assert isinstance(oracle, OraclePPC)
    return fast, oracle


def recorded(stem: str):
    data = np.load(RECORDED)
    for i in range(data[f"{stem}/time_s"].size):
        measurement = Measurement(
            float(data[f"{stem}/time_s"][i]),
            data[f"{stem}/q"][i],
            data[f"{stem}/v"][i],
            data[f"{stem}/wrench_world"][i],
        )
        yield measurement, bool(data[f"{stem}/extended"][i]), data[f"{stem}/tau"][i]


@pytest.fixture
def count_svd_fallbacks(monkeypatch):
    """Counts the fast controller's calls of the exact SVD route."""
    calls = []
    original = task_space.pseudo_inverse  # the exact SVD route of J^#

    def counting(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(task_space, "pseudo_inverse", counting)
    return calls


# ---------------------------------------------------------------- recorded runs


@pytest.mark.parametrize("stem", SCENARIOS)
def test_oracle_still_gives_the_recorded_outputs(stem):
    """Guards the oracle itself: it reproduces what it gave when recorded, to 1e-12 (not bit
    for bit: its SVD's last bits move with the numpy / LAPACK build)."""
    _, oracle = scenario_pair(stem)
    for measurement, extended, tau in recorded(stem):
        oracle.set_funnel_extension(extended)
        got = oracle.compute(measurement.time_s, measurement)
        np.testing.assert_allclose(got, tau, rtol=1e-12, atol=1e-12 * np.max(np.abs(tau)))


@pytest.mark.parametrize("stem", SCENARIOS)
def test_recorded_runs_match_the_oracle(stem, count_svd_fallbacks):
    fast, oracle = scenario_pair(stem)
    n_extended = 0
    for measurement, extended, _ in recorded(stem):
        fast.set_funnel_extension(extended)
        oracle.set_funnel_extension(extended)
        n_extended += extended
        assert_same_outcome(
            outcome(fast, measurement.time_s, measurement),
            outcome(oracle, measurement.time_s, measurement),
            oracle,
        )
    assert not count_svd_fallbacks, "the fast route must be the one compared here"
    if stem == "paper_force_tracking":  # LSODA trial stages: the barrier's extension
        assert n_extended > 100


# ---------------------------------------------------------------- random states


def _pair(model, frame, params, desired_force, desired_rpy):
    return (
        PrescribedPerformanceController(model, frame, params, desired_force, desired_rpy),
        OraclePPC(model, frame, params, desired_force, desired_rpy),
    )


def _compare_random_states(model, frame, params, rng, n_states, q_sampler, spread=0.9):
    """Random q; force, orientation and velocity errors at |xi| up to ``spread``."""
    target = {"rpy": np.zeros(3)}
    fast, oracle = _pair(
        model,
        frame,
        params,
        lambda t: np.array([0.4 * math.sin(math.pi * t) + 0.4, 0.0, 0.0]),
        lambda t: target["rpy"],
    )
    data = model.createData()
    frame_id = model.getFrameId(frame)
    outcomes = {"ok": 0, "raised": 0}
    for _ in range(n_states):
        q = q_sampler(rng)
        time_s = rng.uniform(0.0, 3.0)
        rho = fast.performance_x.value(time_s)
        pin.framesForwardKinematics(model, data, q)
        rpy = pin.rpy.matrixToRpy(data.oMf[frame_id].rotation)
        target["rpy"] = rpy - rng.uniform(-spread, spread, 3) * rho[3:]
        force = fast._desired_force(time_s) + rng.uniform(-spread, spread, 3) * rho[:3]
        wrench = np.r_[force, rng.normal(size=3)]
        probe = Measurement(time_s, q, np.zeros(model.nv), wrench)
        first = outcome(oracle, time_s, probe)
        zeta_r = oracle.last_signals.zeta_r if not isinstance(first, Exception) else 0.0
        rho_zeta = fast.performance_zeta.value(time_s)
        v = zeta_r + rng.uniform(-spread, spread, model.nv) * rho_zeta
        for extended in (False, True):
            fast.set_funnel_extension(extended)
            oracle.set_funnel_extension(extended)
            measurement = Measurement(time_s, q, v, wrench)
            old = outcome(oracle, time_s, measurement)
            assert_same_outcome(outcome(fast, time_s, measurement), old, oracle)
            outcomes["raised" if isinstance(old, Exception) else "ok"] += 1
    return outcomes


@pytest.mark.parametrize(
    "overrides",
    [
        {},  # the paper's: plain J^+
        {"velocity_weights": REALISTIC_WEIGHTS + [1.0] * 4, "null_space_gain_per_s": 3.0},
        {"velocity_weights": REALISTIC_WEIGHTS + [2.0] * 4, "k_zeta": 20.0, "k_x": 0.5},
    ],
    ids=["paper", "weighted+null-space", "weighted-gains"],
)
def test_random_states_on_the_reference_model(reference_uvms, overrides):
    rng = np.random.default_rng(2017)
    frame = reference_uvms.model.frames[reference_uvms.ee_frame_id].name
    outcomes = _compare_random_states(
        reference_uvms.model,
        frame,
        PPCParams(**overrides),
        rng,
        60,
        lambda r: random_configuration(reference_uvms, r),
    )
    assert outcomes["ok"] >= 100  # mostly inside the funnels: the values are compared


@pytest.mark.parametrize("n_joints", [0, 2, 6, 7])
def test_random_states_on_arms_of_any_size(n_joints):
    model = build_test_uvms(n_joints)
    rng = np.random.default_rng(n_joints)
    params = PPCParams(
        velocity_weights=[*REALISTIC_WEIGHTS, *[1.0] * n_joints], null_space_gain_per_s=1.0
    )

    def sampler(r):
        quaternion = r.normal(size=4)
        return np.r_[
            r.uniform(-1, 1, 3),
            quaternion / np.linalg.norm(quaternion),
            r.uniform(-2.4, 2.4, n_joints),
        ]

    outcomes = _compare_random_states(model, "ee", params, rng, 25, sampler)
    assert outcomes["ok"] >= 40


def test_random_states_on_a_mounted_7_joint_panda(tmp_path):
    uvms = mount_on_reference_vehicle("panda", tmp_path)
    assert uvms.n_arm_joints == 7
    params = PPCParams(velocity_weights=[*REALISTIC_WEIGHTS, *[1.0] * 7], null_space_gain_per_s=3.0)
    frame = uvms.model.frames[uvms.ee_frame_id].name
    rng = np.random.default_rng(7)
    outcomes = _compare_random_states(
        uvms.model, frame, params, rng, 30, lambda r: random_configuration(uvms, r)
    )
    assert outcomes["ok"] >= 50


def test_funnel_extension_beyond_the_clamp_and_violations(reference_uvms):
    """|xi| up to 1.5: plain mode raises the same FunnelViolation, the extension continues
    the barrier linearly, identically."""
    rng = np.random.default_rng(11)
    frame = reference_uvms.model.frames[reference_uvms.ee_frame_id].name
    outcomes = _compare_random_states(
        reference_uvms.model,
        frame,
        PPCParams(velocity_weights=REALISTIC_WEIGHTS + [1.0] * 4, null_space_gain_per_s=3.0),
        rng,
        60,
        lambda r: random_configuration(reference_uvms, r),
        spread=1.5,
    )
    assert outcomes["raised"] >= 20 and outcomes["ok"] >= 20


# ---------------------------------------------------------------- near-singular Jacobians


def _rotate_vehicle_to_ee_rpy(model, q, frame_id, rpy_target) -> np.ndarray:
    """q with the vehicle turned so that the end-effector has the Euler angles rpy_target."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    base = pin.XYZQUATToSE3(q[:7]).rotation
    relative = base.T @ data.oMf[frame_id].rotation
    rotation = pin.rpy.rpyToMatrix(np.asarray(rpy_target)) @ relative.T
    out = q.copy()
    out[3:7] = pin.Quaternion(rotation).coeffs()
    return out


def _solve_exactly(matrix: list[list[Fraction]], rhs: list[Fraction]) -> list[Fraction]:
    """Gauss-Jordan elimination in exact rational arithmetic (small SPD systems)."""
    n = len(rhs)
    rows = [[*matrix[i], rhs[i]] for i in range(n)]
    for k in range(n):
        pivot = next(i for i in range(k, n) if rows[i][k] != 0)
        rows[k], rows[pivot] = rows[pivot], rows[k]
        for i in range(n):
            if i != k and rows[i][k] != 0:
                factor = rows[i][k] / rows[k][k]
                rows[i] = [a - factor * b for a, b in zip(rows[i], rows[k], strict=True)]
    return [rows[i][n] / rows[i][i] for i in range(n)]


def exact_reference_velocity(controller, q: np.ndarray) -> np.ndarray:
    """zeta_r of the last call in exact rational arithmetic, from the float inputs.

    J zeta = xdot with J = diag(I, E^-1) J^lwa has the solutions of J^lwa zeta =
    [xdot_p; E xdot_o], so zeta_r = zeta_0 + W^-1 J^T (J W^-1 J^T)^-1 (b - J zeta_0) with
    J = J^lwa; every float (J^lwa, cos and sin of the angles, xdot_r, zeta_0) is taken as
    exact. The error of a float evaluation against this is its forward error.
    """
    signals = controller.last_signals
    _, jacobian = frame_rotation_and_jacobian(
        controller.model, controller.model.createData(), q, controller.ee_frame_id
    )
    _, pitch, yaw = signals.rpy_ee
    cp, sp, cy, sy = (
        Fraction(f(x))
        for f, x in ((math.cos, pitch), (math.sin, pitch), (math.cos, yaw), (math.sin, yaw))
    )
    xdot = [Fraction(x) for x in signals.xdot_r]
    rates = xdot[3:]
    b = [
        *xdot[:3],
        cy * cp * rates[0] - sy * rates[1],
        sy * cp * rates[0] + cy * rates[1],
        rates[2] - sp * rates[0],
    ]
    J = [[Fraction(x) for x in row] for row in jacobian]
    w_inv = [1 / Fraction(w) for w in controller.params.velocity_weights]
    zeta_0 = [Fraction(z) for z in controller.null_space_velocity(q)]
    n = len(w_inv)
    b = [b[i] - sum(J[i][k] * zeta_0[k] for k in range(n)) for i in range(6)]
    gram = [
        [sum(J[i][k] * w_inv[k] * J[j][k] for k in range(n)) for j in range(6)] for i in range(6)
    ]
    y = _solve_exactly(gram, b)
    return np.array(
        [float(zeta_0[k] + w_inv[k] * sum(J[i][k] * y[i] for i in range(6))) for k in range(n)]
    )


@pytest.mark.parametrize("cos_pitch", [0.3, 0.02, 2e-3, 1.001e-3, 0.999e-3, 1e-4])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_near_the_euler_singularity(reference_uvms, cos_pitch, sign):
    """Pitch near +-90 deg: the same ParameterError below |cos(pitch)| = 1e-3; above it, the
    fast route (which never inverts E) is within 1e-13 of the exact minimum-norm solution,
    and agrees with the oracle to 1e-12 or to the oracle's own error against the exact
    solution (its J has rows ~1 / cos(pitch), its SVD loses ~cond(J) 1e-16), whichever is
    larger."""
    model = reference_uvms.model
    frame_id = reference_uvms.ee_frame_id
    frame = model.frames[frame_id].name
    q0 = reference_uvms.neutral_configuration()
    q0[7:] = [-0.2, 1.0, -0.8, 0.2]
    rpy = np.array([0.3, sign * math.acos(cos_pitch), -0.4])
    q = _rotate_vehicle_to_ee_rpy(model, q0, frame_id, rpy)
    for params in (
        PPCParams(),
        PPCParams(velocity_weights=REALISTIC_WEIGHTS + [1.0] * 4, null_space_gain_per_s=3.0),
    ):
        fast, oracle = _pair(model, frame, params, (0.0, 0.0, 0.0), rpy + 0.01)
        for v_scale in (0.0, 0.05):
            measurement = Measurement(0.2, q, np.full(model.nv, v_scale), np.r_[0.1, 0, 0, 0, 0, 0])
            old = outcome(oracle, 0.2, measurement)
            new = outcome(fast, 0.2, measurement)
            if cos_pitch < 1e-3:
                assert isinstance(old, up.ParameterError) and "Euler singularity" in str(old)
                assert_same_outcome(new, old, oracle)
                continue
            exact = exact_reference_velocity(fast, q)
            scale = np.abs(exact).max()
            fast_error = np.abs(fast.last_signals.zeta_r - exact).max() / scale
            oracle_error = np.abs(oracle.last_signals.zeta_r - exact).max() / scale
            assert fast_error <= 1e-13
            tolerance = max(TOLERANCE, 2.0 * oracle_error)
            assert_same_outcome(
                new, old, oracle, zeta_tolerance=tolerance, tau_tolerance=10 * tolerance
            )


def test_stretched_arm_singularity(reference_uvms, count_svd_fallbacks):
    """Arm at a kinematic singularity (all joints 0): the vehicle keeps J full rank, the fast
    route is taken and agrees."""
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    q = reference_uvms.neutral_configuration()
    params = PPCParams(velocity_weights=REALISTIC_WEIGHTS + [1.0] * 4, null_space_gain_per_s=3.0)
    fast, oracle = _pair(model, frame, params, (0.2, 0.0, 0.0), (0.05, -0.05, 0.1))
    measurement = Measurement(0.1, q, np.full(model.nv, 0.02), np.r_[0.3, -0.1, 0.1, 0, 0, 0])
    assert_same_outcome(outcome(fast, 0.1, measurement), outcome(oracle, 0.1, measurement), oracle)
    assert not count_svd_fallbacks


@pytest.mark.parametrize(
    ("vehicle_weight", "expect_fallback"),
    [(1e3, False), (1e5, None), (1e8, True), (1e14, True), (1e30, True)],
)
def test_extreme_weights_fall_back_to_the_svd(
    reference_uvms, count_svd_fallbacks, vehicle_weight, expect_fallback
):
    """Vehicle weights up to 1e30 against 1 on 4 joints: J W^-1/2 is nearly rank 4 (the SVD
    may cut singular values). The solver declines and the exact SVD route is taken."""
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    q = reference_uvms.neutral_configuration()
    q[7:] = [0.1, 0.9, -0.7, 0.3]
    params = PPCParams(velocity_weights=[vehicle_weight] * 6 + [1.0] * 4, null_space_gain_per_s=1.0)
    fast, oracle = _pair(model, frame, params, (0.2, 0.0, 0.0), (0.0, 0.0, 0.0))
    measurement = Measurement(0.1, q, np.full(model.nv, 0.01), np.r_[0.3, -0.1, 0.1, 0, 0, 0])
    assert_same_outcome(outcome(fast, 0.1, measurement), outcome(oracle, 0.1, measurement), oracle)
    if expect_fallback is not None:
        assert bool(count_svd_fallbacks) == expect_fallback


# ---------------------------------------------------------------- bad input and bookkeeping


@pytest.mark.parametrize(
    "field",
    ["q_position", "q_quaternion", "v", "force", "torque", "short_v", "desired_force"],
)
def test_bad_input_raises_the_same_error(reference_uvms, field):
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    q = reference_uvms.neutral_configuration()
    v = np.zeros(model.nv)
    wrench = np.zeros(6)
    force = (0.0, 0.0, 0.0)
    if field == "q_position":
        q[0] = np.nan
    elif field == "q_quaternion":
        q[4] = np.inf
    elif field == "v":
        v[8] = np.nan
    elif field == "force":
        wrench[1] = -np.inf
    elif field == "torque":
        wrench[5] = np.nan
    elif field == "short_v":
        v = v[:-1]
    else:
        force = lambda t: (0.0, np.nan, 0.0)  # noqa: E731
    fast, oracle = _pair(model, frame, PPCParams(), force, None)
    measurement = Measurement(0.0, q, v, wrench)
    old = outcome(oracle, 0.0, measurement)
    assert isinstance(old, up.ParameterError)
    assert_same_outcome(outcome(fast, 0.0, measurement), old, oracle)


@pytest.mark.filterwarnings("error")
def test_huge_finite_inputs_are_not_rejected(reference_uvms):
    """The one-line finiteness test (a sum) overflows for entries near 1e308; the exact
    check then admits them, without a warning (here 1.5e308 N m, which the law does not
    use)."""
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    fast, oracle = _pair(model, frame, PPCParams(), (0.0, 0.0, 0.0), None)
    q = reference_uvms.neutral_configuration()
    measurement = Measurement(0.0, q, np.zeros(model.nv), np.r_[0.1, 0, 0, 1.5e308, 1.5e308, 0])
    assert_same_outcome(outcome(fast, 0.0, measurement), outcome(oracle, 0.0, measurement), oracle)


def test_signals_are_those_of_the_last_successful_call(reference_uvms):
    """A call that raises leaves the previous signals; the returned tau is not aliased."""
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    fast, _ = _pair(model, frame, PPCParams(), (0.0, 0.0, 0.0), None)
    q = reference_uvms.neutral_configuration()
    good = Measurement(0.0, q, np.full(model.nv, 0.05), np.r_[0.2, 0, 0, 0, 0, 0])
    tau = fast.compute(0.0, good)
    before = fast.signals()
    np.testing.assert_array_equal(before["tau"], tau)
    tau[:] = 0.0  # the caller owns the returned array
    with pytest.raises(FunnelViolation):
        fast.compute(0.5, Measurement(0.5, q, np.full(model.nv, 0.05), np.r_[2.0, 0, 0, 0, 0, 0]))
    after = fast.signals()
    assert after.keys() == before.keys()
    for name in before:
        np.testing.assert_array_equal(after[name], before[name])
    assert fast.last_signals.time_s == 0.0
    fast.reset()
    assert fast.last_signals is None and fast.signals() == {}


def test_the_svd_route_with_the_joint_limit_pull_is_the_exact_solution(
    reference_uvms, monkeypatch, count_svd_fallbacks
):
    """Where the Cholesky solver declines (an ill-conditioned J), the exact SVD route gives
    the same zeta_r = zeta_0 + J^# (xdot_r - J zeta_0), the joint-limit pull zeta_0 kept in
    the null space: forced here on a well-conditioned pose, it is the exact rational
    solution to 1e-12 of its size."""
    monkeypatch.setattr(task_space.MinimumNormSolver, "solve", lambda self, jacobian, rhs: None)
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    q = reference_uvms.neutral_configuration()
    q[7:] = [-0.2, 1.0, -0.8, 0.2]
    params = PPCParams(velocity_weights=REALISTIC_WEIGHTS + [1.0] * 4, null_space_gain_per_s=3.0)
    # the Python law (the compiled kernel has its own routes, checked against it elsewhere)
    fast = PrescribedPerformanceController(
        model, frame, params, (0.2, 0.0, 0.0), (0.05, -0.05, 0.1), backend="python"
    )
    measurement = Measurement(0.1, q, np.full(model.nv, 0.02), np.r_[0.3, -0.1, 0.1, 0, 0, 0])
    assert not isinstance(outcome(fast, 0.1, measurement), Exception)
    assert count_svd_fallbacks  # the SVD route was taken
    assert np.abs(fast.null_space_velocity(q)).max() > 1e-3  # and the pull acts
    exact = exact_reference_velocity(fast, q)
    error = np.abs(fast.last_signals.zeta_r - exact).max() / np.abs(exact).max()
    assert error <= 1e-12
