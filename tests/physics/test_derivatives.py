"""The derivatives of the forward dynamics against finite differences of the dynamics.

`up.forward_dynamics_derivatives` (the Python reference, backend="python") against 4-point
central differences of `up.forward_dynamics` (the reference), q moved along the tangent
(pin.integrate), on random states of every shipped model, three mounted example-robot-data
arms and a ball-jointed arm, in still water, a current, regular and irregular waves, and a
sheared current. Steps: 1e-5 on q (m, rad) and on v, tau scaled by their size (the
quadratic damping |x| x is C1: a relative velocity within 2 steps of zero would show it).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import (
    central_difference,
    mount_on_reference_vehicle,
    random_state,
    with_spherical_joint,
)

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.flow import AiryWave, DepthProfileCurrent, FlowField, IrregularSea, UniformCurrent
from uvms_pin.model.resources import shipped_models, shipped_path

#: relative agreement with the finite differences (max |error| / max |entry| per matrix)
FD_REL = 1e-7
STEP = 1e-5

FLOWS = {
    "still": None,
    "current": UniformCurrent([0.3, -0.2, 0.1]),
    "airy+current": AiryWave(0.4, 5.0, heading_rad=0.5, water_depth_m=15.0)
    + UniformCurrent([0.2, 0.0, 0.0]),
    "irregular": IrregularSea(1.5, 7.0, n_components=30, seed=4, spreading_exponent=3.0),
    "sheared": DepthProfileCurrent([0.4, 0.1, 0.05], [0.0, 10.0], [1.0, 0.2]),
}


def _relative_error(got: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


def assert_matches_finite_differences(uvms, q, v, tau, flow, time_s=0.4, tau_ext=None):
    """The three derivatives of the reference against central differences of its dynamics."""
    kw = {"flow": flow, "time_s": time_s, "backend": "python"}

    def accel(qq, vv, tt):
        return up.forward_dynamics(uvms, qq, vv, tt, tau_ext=tau_ext, **kw)

    da_dq, da_dv, da_dtau = up.forward_dynamics_derivatives(uvms, q, v, tau, tau_ext=tau_ext, **kw)
    nv = uvms.nv
    integrate = lambda x, dx: pin.integrate(uvms.model, x, dx)  # noqa: E731
    fd_q = central_difference(lambda x: accel(x, v, tau), q, nv, STEP, integrate)
    fd_v = central_difference(lambda x: accel(q, x, tau), v, nv, STEP * max(1, np.abs(v).max()))
    fd_tau = central_difference(lambda x: accel(q, v, x), tau, nv, 1e-3 * np.abs(tau).max())
    errors = [_relative_error(*p) for p in ((da_dq, fd_q), (da_dv, fd_v), (da_dtau, fd_tau))]
    assert max(errors) < FD_REL, f"relative errors (dq, dv, dtau): {errors}"
    assert da_dq.shape == da_dv.shape == da_dtau.shape == (nv, nv)
    return errors


@pytest.fixture(scope="module", params=["reference", "ur5", "panda", "z1", "ball"])
def system(request, reference_uvms, tmp_path_factory) -> up.UVMS:
    if request.param == "reference":
        return reference_uvms
    if request.param == "ball":
        return with_spherical_joint(reference_uvms, 3)
    return mount_on_reference_vehicle(request.param, tmp_path_factory.mktemp(request.param))


@pytest.mark.parametrize("flow", list(FLOWS), ids=list(FLOWS))
def test_derivatives_match_finite_differences(system, flow):
    rng = np.random.default_rng(24)
    for _ in range(2):
        q, v, tau = random_state(system, rng)
        assert_matches_finite_differences(system, q, v, tau, FLOWS[flow])


@pytest.mark.parametrize("name", shipped_models())
def test_every_shipped_model_matches_finite_differences(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        uvms = up.load_uvms(shipped_path(f"models/{name}.urdf"))
    rng = np.random.default_rng(25)
    for flow in (None, FLOWS["airy+current"]):
        q, v, tau = random_state(uvms, rng)
        assert_matches_finite_differences(uvms, q, v, tau, flow)


def test_a_held_generalized_force_moves_only_the_point_of_linearisation(reference_uvms):
    """tau_ext is held fixed: the derivatives are those at the acceleration it produces."""
    rng = np.random.default_rng(26)
    q, v, tau = random_state(reference_uvms, rng)
    tau_ext = rng.normal(scale=3.0, size=reference_uvms.nv)
    assert_matches_finite_differences(reference_uvms, q, v, tau, FLOWS["current"], tau_ext=tau_ext)
    _, _, with_ext = up.forward_dynamics_derivatives(
        reference_uvms, q, v, tau, tau_ext=tau_ext, backend="python"
    )
    np.testing.assert_allclose(
        with_ext @ up.mass_matrix(reference_uvms, q, backend="python"),
        np.eye(reference_uvms.nv),
        atol=1e-9,
    )


def test_rigid_body_in_air_matches_pinocchio_aba_derivatives(load_body):
    """With no water (no volume, no added mass, no damping) the derivatives are Pinocchio's
    own computeABADerivatives."""
    from conftest import body_urdf, hydro_xml

    uvms = load_body(body_urdf(com=(0.01, -0.02, 0.03), hydro=hydro_xml(0.0)))
    rng = np.random.default_rng(27)
    q, v, tau = random_state(uvms, rng)
    data = uvms.model.createData()  # the results are views into it: keep it alive
    expected = [np.array(m) for m in pin.computeABADerivatives(uvms.model, data, q, v, tau)]
    expected[2] = np.triu(expected[2]) + np.triu(expected[2], 1).T  # Minv: upper triangle
    got = up.forward_dynamics_derivatives(uvms, q, v, tau, backend="python")
    for g, e in zip(got, expected, strict=True):
        np.testing.assert_allclose(g, e, rtol=0, atol=1e-10 * np.abs(e).max())


def test_still_water_derivatives_do_not_depend_on_position(reference_uvms):
    """In still (or uniformly flowing) water nothing depends on where the vehicle is: the
    columns of da/dq along the vehicle's translation are zero (a physics check that finite
    differences share, here exactly)."""
    rng = np.random.default_rng(28)
    q, v, tau = random_state(reference_uvms, rng)
    for flow in (None, FLOWS["current"]):
        da_dq, _, _ = up.forward_dynamics_derivatives(
            reference_uvms, q, v, tau, flow=flow, backend="python"
        )
        assert np.abs(da_dq[:, :3]).max() < 1e-12 * np.abs(da_dq).max()
    # in waves the flow varies in space: the same columns are not zero
    da_dq, _, _ = up.forward_dynamics_derivatives(
        reference_uvms, q, v, tau, flow=FLOWS["airy+current"], backend="python"
    )
    assert np.abs(da_dq[:, :3]).max() > 1e-3 * np.abs(da_dq).max()


def test_a_flow_without_second_order_kinematics_is_refused(reference_uvms):
    class Swirl(FlowField):
        def velocity(self, time_s, points_world):
            return np.zeros((len(points_world), 3))

        def local_acceleration(self, time_s, points_world):
            return np.zeros((len(points_world), 3))

        def velocity_gradient(self, time_s, points_world):
            return np.zeros((len(points_world), 3, 3))

        def __repr__(self):
            return "Swirl()"

    q = reference_uvms.neutral_configuration()
    zero = np.zeros(reference_uvms.nv)
    with pytest.raises(ParameterError, match=r"Swirl\(\).*gradient_kinematics"):
        up.forward_dynamics_derivatives(reference_uvms, q, zero, zero, flow=Swirl())


@pytest.mark.parametrize("backend", ["core", "python"])
def test_bad_vectors_name_what_is_wrong(reference_uvms, backend):
    """Shapes and values are checked by the reference and by the core alike (and through
    the core's fallback to the reference in a flow it has no counterpart of)."""
    q = reference_uvms.neutral_configuration()
    zero = np.zeros(reference_uvms.nv)
    bad = zero.copy()
    bad[2] = math.nan
    for flow in (None, FLOWS["sheared"]):
        kw = {"backend": backend, "flow": flow}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", up.errors.CoreFallbackWarning)
            with pytest.raises(ParameterError, match="v must have shape"):
                up.forward_dynamics_derivatives(reference_uvms, q, zero[:3], zero, **kw)
            with pytest.raises(ParameterError, match=r"tau.*non-finite"):
                up.forward_dynamics_derivatives(reference_uvms, q, zero, bad, **kw)
            with pytest.raises(ParameterError, match="tau_ext must have shape"):
                up.forward_dynamics_derivatives(
                    reference_uvms, q, zero, zero, tau_ext=zero[:4], **kw
                )
            with pytest.raises(ParameterError, match="q must have shape"):
                up.forward_dynamics_derivatives(reference_uvms, q[:5], zero, zero, **kw)


def test_bad_arguments_name_what_is_wrong(reference_uvms):
    q = reference_uvms.neutral_configuration()
    zero = np.zeros(reference_uvms.nv)
    with pytest.raises(ParameterError, match="either current_world or flow"):
        up.forward_dynamics_derivatives(
            reference_uvms, q, zero, zero, current_world=np.ones(3), flow=FLOWS["current"]
        )
    with pytest.raises(ParameterError, match="time_s"):
        up.forward_dynamics_derivatives(reference_uvms, q, zero, zero, time_s=math.nan)


def test_the_public_call_checks_q_on_the_manifold_and_returns_its_own_arrays(reference_uvms):
    """The public call's one compiled call (`CompiledDynamics.public_derivatives`): a q whose
    quaternion is off the unit sphere is refused naming the joint, as the reference refuses
    it; a list is read as an array; each call returns new arrays (a later call leaves an
    earlier result as it was), equal to the core object's."""
    q = reference_uvms.neutral_configuration()
    q[3:7] = [0.1, 0.2, 0.3, 0.9]
    zero = np.zeros(reference_uvms.nv)
    for backend in ("core", "python"):
        with pytest.raises(ParameterError, match=r"quaternion of norm .* not 1"):
            up.forward_dynamics_derivatives(reference_uvms, q, zero, zero, backend=backend)
    q = pin.normalize(reference_uvms.model, q)
    rng = np.random.default_rng(3)
    v, tau = rng.normal(size=reference_uvms.nv), rng.normal(size=reference_uvms.nv)
    first = up.forward_dynamics_derivatives(
        reference_uvms, list(q), v, tau, current_world=[0.2, 0, 0]
    )
    kept = [a.copy() for a in first]
    up.forward_dynamics_derivatives(reference_uvms, q, -v, 2 * tau, current_world=[0.2, 0, 0])
    for a, b in zip(first, kept, strict=True):
        np.testing.assert_array_equal(a, b)
    dynamics = up.physics.dynamics.dynamics_of(reference_uvms)
    flow = dynamics.flow_struct(up.flow.UniformCurrent([0.2, 0.0, 0.0]))
    expected = dynamics._core_derivatives(q, v, tau, flow, 0.0, None, False)
    for a, b in zip(first, expected, strict=True):
        np.testing.assert_array_equal(a, b)


# ---- the compiled core against the reference ---------------------------------------------

#: compiled against Python: the same formulas summed in another order
CORE_REL = 1e-10


@pytest.mark.parametrize("flow", ["still", "current", "airy+current", "irregular"])
def test_compiled_derivatives_match_the_reference(system, flow):
    rng = np.random.default_rng(29)
    for _ in range(3):
        q, v, tau = random_state(system, rng)
        tau_ext = rng.normal(size=system.nv)
        kw = {"flow": FLOWS[flow], "time_s": 0.7, "tau_ext": tau_ext}
        expected = up.forward_dynamics_derivatives(system, q, v, tau, backend="python", **kw)
        got = up.forward_dynamics_derivatives(system, q, v, tau, backend="core", **kw)
        for g, e, name in zip(got, expected, ("da_dq", "da_dv", "da_dtau"), strict=True):
            assert _relative_error(g, e) < CORE_REL, name


def test_compiled_derivatives_in_a_flow_without_core_counterpart_fall_back(reference_uvms):
    rng = np.random.default_rng(30)
    q, v, tau = random_state(reference_uvms, rng)
    kw = {"flow": FLOWS["sheared"], "time_s": 0.2}
    with pytest.warns(up.errors.CoreFallbackWarning, match="derivatives"):
        got = up.forward_dynamics_derivatives(reference_uvms, q, v, tau, **kw)
    expected = up.forward_dynamics_derivatives(reference_uvms, q, v, tau, backend="python", **kw)
    for g, e in zip(got, expected, strict=True):
        np.testing.assert_array_equal(g, e)


# ---- the free surface ------------------------------------------------------------------------


@pytest.mark.parametrize("backend", ["python", "core"])
def test_free_surface_deep_bodies_have_the_deep_derivatives(reference_uvms, backend):
    """Every body deep under the surface: the dynamics are those without a top, and so are
    the derivatives (with waves too: the surface is far above)."""
    rng = np.random.default_rng(31)
    q, v, tau = random_state(reference_uvms, rng)
    q[2] = -6.0
    for flow in (None, FLOWS["airy+current"]):
        kw = {"flow": flow, "time_s": 0.3, "backend": backend}
        with_top = up.forward_dynamics_derivatives(
            reference_uvms, q, v, tau, free_surface=True, **kw
        )
        without = up.forward_dynamics_derivatives(reference_uvms, q, v, tau, **kw)
        for a, b in zip(with_top, without, strict=True):
            np.testing.assert_array_equal(a, b)


# the surface cutting a hull: tests/physics/test_derivatives_surface.py


# ---- one control period ----------------------------------------------------------------------


def _euler_period(uvms, q, v, tau, period_s, step_s, flow, time_s):
    """The plant's semi-implicit Euler over a period (uvms_pin.sim.integrators)."""
    from uvms_pin.sim.integrators import SemiImplicitEuler

    def rhs(t, qq, vv):
        return up.forward_dynamics(uvms, qq, vv, tau, flow=flow, time_s=t, backend="python")

    return SemiImplicitEuler(step_s=step_s).advance(
        uvms.model, rhs, time_s, q, v, time_s + period_s
    )


@pytest.mark.parametrize("flow", ["current", "airy+current"])
def test_step_derivatives_match_finite_differences_of_the_period(reference_uvms, flow):
    uvms, water = reference_uvms, FLOWS[flow]
    rng = np.random.default_rng(32)
    q, v, tau = random_state(uvms, rng)
    period, step, t0 = 0.02, 0.005, 0.4
    got = up.step_derivatives(
        uvms, q, v, tau, period, step_s=step, flow=water, time_s=t0, backend="python"
    )
    q1, v1 = _euler_period(uvms, q, v, tau, period, step, water, t0)
    # the plant's integrator, to rounding (the same formulas, the flow summed differently)
    np.testing.assert_allclose(got.q, q1, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(got.v, v1, rtol=1e-13, atol=1e-13)
    nv, model = uvms.nv, uvms.model

    def end_state(x):  # x = (dq, v, tau) -> (q+ - q1 in the tangent at q1, v+)
        dq, vv, tt = x[:nv], x[nv : 2 * nv], x[2 * nv :]
        qe, ve = _euler_period(uvms, pin.integrate(model, q, dq), vv, tt, period, step, water, t0)
        return np.r_[pin.difference(model, q1, qe), ve]

    x0 = np.r_[np.zeros(nv), v, tau]
    fd = central_difference(end_state, x0, 3 * nv, STEP)
    fd_tau = central_difference(
        lambda t: end_state(np.r_[np.zeros(nv), v, t]), tau, nv, 1e-3 * np.abs(tau).max()
    )
    # d(q+ (-) q1)/d(q+) is the identity at q1: the columns are the tangent Jacobians
    assert _relative_error(got.dx_dx, fd[:, : 2 * nv]) < FD_REL
    assert _relative_error(got.dx_dtau, fd_tau) < FD_REL


def test_input_matrix_chains_the_thrusters_into_the_step(reference_uvms):
    """dx+/du = dx+/dtau B_u for u = (thrust forces, joint torques): against finite
    differences in u, with tau = B_u u; B_u's vehicle block is the allocation matrix."""
    from uvms_pin.model.thruster import Thruster

    uvms = reference_uvms
    thrusters = [
        Thruster(
            f"t{k}", np.r_[np.cos(k), np.sin(k), 0.1 * k], np.r_[np.sin(k), 1.0, k % 2], 80, 60
        )
        for k in range(8)
    ]
    b_u = up.input_matrix(thrusters, uvms.nv)
    assert b_u.shape == (uvms.nv, 8 + uvms.nv - 6)
    np.testing.assert_array_equal(
        b_u[:6, :8], np.column_stack([t.wrench_column for t in thrusters])
    )
    rng = np.random.default_rng(33)
    q, v, _ = random_state(uvms, rng)
    u = rng.normal(scale=5.0, size=b_u.shape[1])
    got = up.step_derivatives(uvms, q, v, b_u @ u, 0.01, step_s=0.005, backend="python")

    def end_velocity(uu):
        return up.step_derivatives(uvms, q, v, b_u @ uu, 0.01, step_s=0.005, backend="python").v

    fd = central_difference(end_velocity, u, len(u), 1e-3 * np.abs(u).max())
    assert _relative_error(got.dx_du(b_u)[uvms.nv :], fd) < FD_REL
    with pytest.raises(ParameterError, match="at least one thruster"):
        up.input_matrix([], uvms.nv)


@pytest.mark.parametrize("bad", [0.0, -0.1, math.inf, math.nan])
@pytest.mark.parametrize("backend", ["core", "python"])
def test_step_derivatives_refuse_a_bad_period(reference_uvms, bad, backend):
    """A period or a step that is not positive and finite is named (a negative one would
    otherwise run one substep backwards in time)."""
    q = reference_uvms.neutral_configuration()
    zero = np.zeros(reference_uvms.nv)
    with pytest.raises(ParameterError, match="period_s must be positive and finite"):
        up.step_derivatives(reference_uvms, q, zero, zero, bad, backend=backend)
    with pytest.raises(ParameterError, match="step_s must be positive and finite"):
        up.step_derivatives(reference_uvms, q, zero, zero, 0.1, step_s=bad, backend=backend)
