"""A test campaign on `up.forward_dynamics_derivatives` as a user with other models meets it.

Models beyond those of tests/physics/test_derivatives.py: a bare vehicle (nv = 6), a
uuv_simulator vehicle and a gz-sim vehicle through `up.import_model` (the LRAUV's fins have
5e-5 kg m^2 of inertia: M's condition number is 5e6), an example-robot-data arm with a
continuous wrist (Kinova Jaco2) mounted on the reference vehicle, and the reference arm with
continuous joints (nq != nv). States: random q on the manifold, brisk velocities, v = 0 in
a current. Each: the reference against 4-point central differences of the reference
dynamics (q along the tangent) and the compiled core against the reference. Then bad input:
off-manifold configurations, times that are not numbers, arrays of any layout.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import (
    REFERENCE_URDF,
    central_difference,
    continuous_joint_urdf,
    model_beyond_the_reference,
    random_state,
)

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.flow import AiryWave, FlowField, UniformCurrent

#: relative agreement with central differences, and of the core with the reference
FD_REL, CORE_REL = 1e-7, 1e-10
CURRENT = UniformCurrent([0.3, -0.2, 0.1])
WAVE = AiryWave(0.4, 5.0, heading_rad=0.5, water_depth_m=15.0) + UniformCurrent([0.2, 0.0, 0.0])


MODELS = ["bluerov2_heavy", "rexrov", "lrauv", "continuous", "kinova"]


@pytest.fixture(scope="module", params=MODELS)
def model(request, tmp_path_factory) -> up.UVMS:
    if request.param == "kinova":
        from uvms_pin.model.mount.catalog import available_arms

        if "kinova" not in available_arms():
            pytest.skip("example-robot-data is not installed")
    return model_beyond_the_reference(request.param, tmp_path_factory.mktemp(request.param))


def _relative_error(got: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


def check(uvms, q, v, tau, flow, q_step=1e-5, v_step=1e-5) -> tuple[float, float]:
    """(worst relative error against central differences, core against the reference)."""
    kw = {"flow": flow, "time_s": 0.4}
    expected = up.forward_dynamics_derivatives(uvms, q, v, tau, backend="python", **kw)
    got = up.forward_dynamics_derivatives(uvms, q, v, tau, backend="core", **kw)

    def accel(qq, vv, tt):
        return up.forward_dynamics(uvms, qq, vv, tt, backend="python", **kw)

    nv = uvms.nv
    integrate = lambda x, dx: pin.integrate(uvms.model, x, dx)  # noqa: E731
    fd = (
        central_difference(lambda x: accel(x, v, tau), q, nv, q_step, integrate),
        central_difference(lambda x: accel(q, x, tau), v, nv, v_step * max(1.0, np.abs(v).max())),
        central_difference(lambda x: accel(q, v, x), tau, nv, 1e-3 * np.abs(tau).max()),
    )
    assert all(m.shape == (nv, nv) for m in (*expected, *got))
    fd_error = max(_relative_error(e, f) for e, f in zip(expected, fd, strict=True))
    core_error = max(_relative_error(g, e) for g, e in zip(got, expected, strict=True))
    return fd_error, core_error


def _steps(uvms: up.UVMS) -> dict[str, float]:
    # the LRAUV's fins (5e-5 kg m^2) make M ill-conditioned: rounding dominates a 1e-5 step
    return {"q_step": 1e-3, "v_step": 1e-3} if uvms.nv == 8 else {}


@pytest.mark.parametrize("flow", [CURRENT, WAVE], ids=["current", "airy+current"])
def test_random_states_match_finite_differences_and_the_core(model, flow):
    rng = np.random.default_rng(240)
    q, v, tau = random_state(model, rng, depth_m=-3.0)
    fd_error, core_error = check(model, q, v, tau, flow, **_steps(model))
    assert fd_error < FD_REL and core_error < CORE_REL, (fd_error, core_error)


def test_brisk_velocities_match(model):
    """4 m/s and 4 rad/s of scale (quadratic damping and C_A dominate)."""
    q, v, tau = random_state(model, np.random.default_rng(241), speed=4.0, depth_m=-3.0)
    fd_error, core_error = check(model, q, v, tau, WAVE, **_steps(model))
    assert fd_error < FD_REL and core_error < CORE_REL, (fd_error, core_error)


def test_at_rest_in_a_current_matches(model):
    """v = 0 in a current: the vehicle's angular relative velocity is 0, the kink of the
    quadratic damping |x| x (derivative 0 on both sides). A central difference across it is
    off by (2/3) h D_quad: the error falls linearly with the velocity step h (10x per
    decade), i.e. the differences converge to the derivative returned."""
    q, _, tau = random_state(model, np.random.default_rng(242), depth_m=-3.0)
    v, q_step = np.zeros(model.nv), _steps(model).get("q_step", 1e-5)
    coarse, core_error = check(model, q, v, tau, CURRENT, q_step=q_step, v_step=1e-4)
    fine, _ = check(model, q, v, tau, CURRENT, q_step=q_step, v_step=1e-5)
    assert core_error < CORE_REL
    assert fine < 1e-4 and 8.0 < coarse / fine < 12.0, (coarse, fine)


def test_the_mass_matrix_inverse_is_symmetric_and_inverts_the_mass_matrix(model):
    q, v, tau = random_state(model, np.random.default_rng(243), depth_m=-3.0)
    for backend in ("core", "python"):
        da_dtau = up.forward_dynamics_derivatives(model, q, v, tau, flow=CURRENT, backend=backend)[
            2
        ]
        mass = up.mass_matrix(model, q, backend=backend)
        scale = np.abs(da_dtau).max()
        assert np.abs(da_dtau - da_dtau.T).max() < 1e-12 * scale
        np.testing.assert_allclose(da_dtau @ mass, np.eye(model.nv), atol=1e-8)


# ---- bad input -------------------------------------------------------------------------


@pytest.fixture(scope="module")
def reference() -> up.UVMS:
    return up.load_uvms(REFERENCE_URDF)


def _state(uvms: up.UVMS):
    q = uvms.neutral_configuration()
    q[2], q[7:] = -3.0, [-0.2, 1.0, -0.8, 0.2]
    return q, np.full(uvms.nv, 0.1), np.ones(uvms.nv)


@pytest.mark.parametrize("backend", ["core", "python"])
@pytest.mark.parametrize("scale", [2.0, 1.001, 0.0])
def test_a_quaternion_off_the_unit_sphere_is_refused(reference, backend, scale):
    """Off the manifold the dynamics are not defined: before, a norm of 1.001 gave da/dq
    off by 5e-3 (core) and 2e-3 (reference), the two backends disagreeing, and a norm of 2
    a SimulationError ('mass matrix is not positive definite') on the core."""
    q, v, tau = _state(reference)
    q[3:7] = np.array([0.1, -0.2, 0.3, 0.9]) / np.linalg.norm([0.1, -0.2, 0.3, 0.9]) * scale
    with pytest.raises(ParameterError, match=r"q.*root_joint.*norm"):
        up.forward_dynamics_derivatives(reference, q, v, tau, backend=backend)
    with pytest.raises(ParameterError, match=r"q.*root_joint.*norm"):
        up.step_derivatives(reference, q, v, tau, 0.02, step_s=0.01, backend=backend)


def test_a_continuous_joint_off_its_circle_is_refused(tmp_path):
    uvms = up.load_uvms(continuous_joint_urdf(tmp_path))
    q = uvms.neutral_configuration()
    q[2] = -3.0
    q[9:11] *= 1.01  # arm_joint2's (cos, sin)
    zero = np.zeros(uvms.nv)
    for backend in ("core", "python"):
        with pytest.raises(ParameterError, match=r"q.*arm_joint2.*norm"):
            up.forward_dynamics_derivatives(uvms, q, zero, zero, backend=backend)


def test_a_unit_quaternion_to_rounding_is_accepted(reference):
    """What pin.integrate and a normalisation in numpy give (|norm - 1| ~ 1e-16) passes."""
    q, v, tau = _state(reference)
    quat = np.array([0.1, -0.2, 0.3, 0.9])
    q[3:7] = quat / np.linalg.norm(quat) * (1.0 + 1e-13)
    for backend in ("core", "python"):
        out = up.forward_dynamics_derivatives(reference, q, v, tau, backend=backend)
        assert all(np.all(np.isfinite(m)) for m in out)


@pytest.mark.parametrize("value", ["yes", 1, None], ids=["str", "int", "None"])
def test_a_free_surface_flag_that_is_not_a_bool_is_named(reference, value):
    """Before, "yes" was read by its truth on the reference and a nanobind TypeError on the
    core; every entry point of the dynamics now names it."""
    q, v, tau = _state(reference)
    calls = {
        "mass_matrix": lambda b: up.mass_matrix(reference, q, backend=b, free_surface=value),
        "bias_forces": lambda b: up.bias_forces(reference, q, v, backend=b, free_surface=value),
        "forward_dynamics": lambda b: up.forward_dynamics(
            reference, q, v, tau, backend=b, free_surface=value
        ),
        "forward_dynamics_derivatives": lambda b: up.forward_dynamics_derivatives(
            reference, q, v, tau, backend=b, free_surface=value
        ),
        "step_derivatives": lambda b: up.step_derivatives(
            reference, q, v, tau, 0.02, step_s=0.01, backend=b, free_surface=value
        ),
    }
    for name, call in calls.items():
        for backend in ("core", "python"):
            with pytest.raises(ParameterError, match="free_surface must be True or False"):
                call(backend)
                pytest.fail(f"{name} ({backend}) took free_surface={value!r}")
    with pytest.raises(ParameterError, match="free_surface must be True or False"):
        up.potential_energy(reference, q, free_surface=value)  # "yes" was read as True
    flag = np.bool_(True)  # numpy's bool is one
    up.forward_dynamics(reference, q, v, tau, free_surface=flag)


@pytest.mark.parametrize("time_s", ["soon", None, np.array([0.1, 0.2]), math.inf])
def test_a_time_that_is_not_a_finite_number_is_named(reference, time_s):
    q, v, tau = _state(reference)
    for backend in ("core", "python"):
        with pytest.raises(ParameterError, match="time_s"):
            up.forward_dynamics_derivatives(reference, q, v, tau, time_s=time_s, backend=backend)
        with pytest.raises(ParameterError, match="time_s"):
            up.step_derivatives(reference, q, v, tau, 0.02, time_s=time_s, backend=backend)


@pytest.mark.parametrize("backend", [np.array(["core"]), ["core"], None])
def test_a_backend_that_is_not_a_name_is_refused_by_name(reference, backend):
    """(an array or a list was a TypeError of the cache's lookup: unhashable)"""
    q, v, tau = _state(reference)
    with pytest.raises(ParameterError, match="backend must be one of"):
        up.forward_dynamics(reference, q, v, tau, backend=backend)
    with pytest.raises(ParameterError, match="backend must be one of"):
        up.mass_matrix(reference, q, backend=backend)


@pytest.mark.parametrize("integrator", [None, 0.01, "euler"])
def test_an_integrator_that_is_neither_a_name_nor_an_integrator_is_named(reference, integrator):
    """(None or a number was an AttributeError on core_method)"""
    q, v, tau = _state(reference)
    with pytest.raises(ParameterError, match="integrator must be one of"):
        up.step_derivatives(reference, q, v, tau, 0.02, integrator=integrator)


@pytest.mark.parametrize("name", ["period_s", "step_s"])
@pytest.mark.parametrize("value", ["0.02", [0.02]], ids=["str", "list"])
def test_a_period_or_step_that_is_not_a_number_is_named(reference, name, value):
    q, v, tau = _state(reference)
    kw = {"period_s": 0.02, "step_s": 0.005, name: value}
    with pytest.raises(ParameterError, match=name):
        up.step_derivatives(reference, q, v, tau, kw.pop("period_s"), **kw)


def _layouts(x: np.ndarray):
    """x as a list, integers where exact, a strided view, read-only, float32 where exact."""
    yield list(x)
    wide = np.zeros((len(x), 3))
    wide[:, 1] = x
    yield wide[:, 1]  # not contiguous
    frozen = x.copy()
    frozen.flags.writeable = False
    yield frozen
    yield np.asfortranarray(x)


@pytest.mark.parametrize("backend", ["core", "python"])
def test_any_array_layout_gives_the_same_derivatives(reference, backend):
    q, v, tau = _state(reference)
    tau = np.array([3.0, -2.0, 1.0, 0.0, 1.0, -1.0, 2.0, 0.0, 1.0, -3.0])  # integers
    expected = up.forward_dynamics_derivatives(reference, q, v, tau, flow=WAVE, backend=backend)
    calls = [(qq, v, tau) for qq in _layouts(q)]
    calls += [(q, vv, tau) for vv in _layouts(v)]
    calls += [(q, v, tt) for tt in _layouts(tau)] + [(q, v, tau.astype(int))]
    for args in calls:
        got = up.forward_dynamics_derivatives(reference, *args, flow=WAVE, backend=backend)
        for g, e in zip(got, expected, strict=True):
            np.testing.assert_array_equal(g, e)


class ShearedByHand(FlowField):
    """A user's own flow, u = (0.1 z, 0, 0) with its second-order kinematics: the core has
    no counterpart of it."""

    def velocity(self, time_s, points_world):
        p = np.atleast_2d(points_world)
        return np.column_stack([0.1 * p[:, 2], np.zeros(len(p)), np.zeros(len(p))])

    def local_acceleration(self, time_s, points_world):
        return np.zeros((len(np.atleast_2d(points_world)), 3))

    def velocity_gradient(self, time_s, points_world):
        gradient = np.zeros((len(np.atleast_2d(points_world)), 3, 3))
        gradient[:, 0, 2] = 0.1
        return gradient

    def gradient_kinematics(self, time_s, points_world):
        n = len(np.atleast_2d(points_world))
        return np.zeros((n, 3, 3)), np.zeros((n, 3, 3, 3))

    def __repr__(self):
        return "ShearedByHand()"


def test_a_users_flow_unknown_to_the_core_falls_back_and_matches_differences(reference):
    q, v, tau = random_state(reference, np.random.default_rng(244), depth_m=-3.0)
    with pytest.warns(up.errors.CoreFallbackWarning):
        got = up.forward_dynamics_derivatives(reference, q, v, tau, flow=ShearedByHand())
    expected = up.forward_dynamics_derivatives(
        reference, q, v, tau, flow=ShearedByHand(), backend="python"
    )
    for g, e in zip(got, expected, strict=True):
        np.testing.assert_array_equal(g, e)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.errors.CoreFallbackWarning)
        fd_error, _ = check(reference, q, v, tau, ShearedByHand())
    assert fd_error < FD_REL
    # the shear is seen: da/dq has columns along the vehicle's position
    assert np.abs(got[0][:, 2]).max() > 1e-3 * np.abs(got[0]).max()
