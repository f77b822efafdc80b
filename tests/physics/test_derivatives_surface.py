"""The derivatives of the forward dynamics under a free surface that cuts the hulls
(`uvms_pin.physics.derivatives.surface`): against 4-point central differences of the
reference dynamics with the same surface, on random states near z = 0 of shipped models
and mounted arms (boxes, cylinders, spheres; Panda's meshes), in still water, a current and
waves. States within a few difference steps of a kink (a hull starting to touch the
surface, or becoming wholly wet or dry) are skipped: the dynamics are not differentiable
there."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, mount_on_reference_vehicle
from test_free_surface import _near_the_surface as near_the_surface

import uvms_pin as up
from uvms_pin.flow import AiryWave, IrregularSea, UniformCurrent
from uvms_pin.model.resources import example_robot_data_dir, shipped_path
from uvms_pin.physics.derivatives.surface import wetting_jacobian, wetting_vector
from uvms_pin.physics.surface import wet_state

FD_REL = 1e-6
#: small on q: a mesh hull's waterplane has a kink each time the surface crosses a vertex
STEP = 1e-6
STEP_V = 1e-5

FLOWS = {
    "still": None,
    "current": UniformCurrent([0.3, -0.1, 0.05]),
    "wave": AiryWave(0.15, 3.0, heading_rad=0.4) + UniformCurrent([0.1, 0.0, 0.0]),
    "sea": IrregularSea(0.4, 5.0, n_components=12, seed=3),
}


@pytest.fixture(scope="module")
def models(reference_uvms, tmp_path_factory):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        out = {
            "lbv150 + arm": reference_uvms,
            "bluerov2 + alpha5": up.load_uvms(shipped_path("models/uvms_bluerov2_alpha5.urdf")),
            "ur5 mounted": mount_on_reference_vehicle("ur5", tmp_path_factory.mktemp("u")),
        }
        if example_robot_data_dir() is not None:
            out["panda (meshes)"] = mount_on_reference_vehicle(
                "panda", tmp_path_factory.mktemp("p")
            )
    return out


def _near_the_surface(uvms: up.UVMS, rng: np.random.Generator):
    """(q, v, tau): a random attitude and arm, the vehicle's origin within 0.3 m of z = 0
    (test_free_surface's), a random velocity and input."""
    q = near_the_surface(uvms, rng)
    return q, rng.normal(scale=0.5, size=uvms.nv), rng.normal(scale=5.0, size=uvms.nv)


def _cut_states(uvms, flow, rng, count=2, clear_of_kinks=False):
    """``count`` random (q, v, tau) near the surface where it cuts a hull (AssertionError if
    40 draws give fewer)."""
    found = 0
    for _ in range(40):
        q, v, tau = _near_the_surface(uvms, rng)
        fraction = _fractions(uvms, q, flow, 0.7)
        if not np.any((fraction > 0.0) & (fraction < 1.0)):
            continue
        if clear_of_kinks and not _clear_of_kinks(uvms, q, flow, 0.7):
            continue
        yield q, v, tau
        found += 1
        if found == count:
            return
    raise AssertionError("too few states with a cut hull away from the kinks")


def _fractions(uvms, q, flow, time_s):
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q)
    wet = wet_state(uvms, data, flow, time_s)
    return np.ones(len(uvms.surface_bodies)) if wet is None else wet.fraction


def _clear_of_kinks(uvms, q, flow, time_s, reach=3 * 2 * STEP) -> bool:
    """No hull changes between cut and wholly wet or dry within the differences' reach
    (each direction of the tangent, 3 times the widest step). (A mesh's vertex crossings
    are not looked for: at this step one within reach is rare.)"""
    cut = lambda f: (f > 0.0) & (f < 1.0)  # noqa: E731
    at = cut(_fractions(uvms, q, flow, time_s))
    for k in range(uvms.nv):
        for sign in (-1.0, 1.0):
            dq = np.zeros(uvms.nv)
            dq[k] = sign * reach
            moved = _fractions(uvms, pin.integrate(uvms.model, q, dq), flow, time_s)
            if np.any(cut(moved) != at):
                return False
    return True


def _relative_error(got, expected) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


def assert_matches_finite_differences(uvms, q, v, tau, flow, time_s):
    kw = {"flow": flow, "time_s": time_s, "backend": "python", "free_surface": True}

    def accel(qq, vv, tt):
        return up.forward_dynamics(uvms, qq, vv, tt, **kw)

    da_dq, da_dv, da_dtau = up.forward_dynamics_derivatives(uvms, q, v, tau, **kw)
    integrate = lambda x, dx: pin.integrate(uvms.model, x, dx)  # noqa: E731
    nv = uvms.nv
    fd_q = central_difference(lambda x: accel(x, v, tau), q, nv, STEP, integrate)
    fd_v = central_difference(lambda x: accel(q, x, tau), v, nv, STEP_V * max(1, np.abs(v).max()))
    fd_tau = central_difference(lambda x: accel(q, v, x), tau, nv, 1e-3 * np.abs(tau).max())
    errors = [_relative_error(*p) for p in ((da_dq, fd_q), (da_dv, fd_v), (da_dtau, fd_tau))]
    assert max(errors) < FD_REL, f"relative errors (dq, dv, dtau): {errors}"
    return errors


@pytest.mark.parametrize("flow", list(FLOWS), ids=list(FLOWS))
def test_cut_hulls_match_finite_differences(models, flow):
    """Every model, random states with at least one hull cut by the surface."""
    rng = np.random.default_rng(41)
    for uvms in models.values():
        for q, v, tau in _cut_states(uvms, FLOWS[flow], rng, clear_of_kinks=True):
            assert_matches_finite_differences(uvms, q, v, tau, FLOWS[flow], 0.7)


def test_the_surface_terms_are_not_zero(reference_uvms):
    """The cut hulls' own terms matter: without them (the wet values held) the derivatives
    miss the finite differences by far more than the tolerance."""
    from uvms_pin.physics.derivatives import reference

    rng = np.random.default_rng(42)
    for _ in range(40):
        q, v, tau = _near_the_surface(reference_uvms, rng)
        fraction = _fractions(reference_uvms, q, None, 0.0)
        if np.any((fraction > 0.05) & (fraction < 0.95)):
            break
    full = up.forward_dynamics_derivatives(
        reference_uvms, q, v, tau, free_surface=True, backend="python"
    )
    original = reference.wet_term_jacobians
    nj, nv = reference_uvms.model.njoints, reference_uvms.nv
    reference.wet_term_jacobians = lambda *a: (np.zeros((nj, 6, nv)), np.zeros((nj, 6, nv)))
    try:
        held = up.forward_dynamics_derivatives(
            reference_uvms, q, v, tau, free_surface=True, backend="python"
        )
    finally:
        reference.wet_term_jacobians = original
    assert _relative_error(held[0], full[0]) > 1e-2


def test_the_hull_geometry_jacobian_matches_its_differences(reference_uvms):
    """dx/d delta of one cut hull (its volume, moment, fraction, gradient and rate) against
    a 2-point difference at another step: the 4-point formula's own accuracy."""
    uvms = reference_uvms
    bodies = uvms.surface_bodies
    q = uvms.neutral_configuration()
    q[2] = 0.02
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.2, -0.1, 0.3)).coeffs()
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q)
    flow = AiryWave(0.15, 3.0, heading_rad=0.4)
    h = int(np.argmax(_fractions(uvms, q, flow, 0.3) * (_fractions(uvms, q, flow, 0.3) < 1)))
    placement = data.oMi[int(bodies.joint_ids[h])]
    got = wetting_jacobian(bodies.hulls[h], float(bodies.bound_radius_m[h]), placement, flow, 0.3)
    step = 1e-6
    expected = np.column_stack(
        [
            (
                wetting_vector(bodies.hulls[h], placement * pin.exp6(step * e), flow, 0.3)
                - wetting_vector(bodies.hulls[h], placement * pin.exp6(-step * e), flow, 0.3)
            )
            / (2 * step)
            for e in np.eye(6)
        ]
    )
    assert np.abs(got).max() > 0.0
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-6 * np.abs(expected).max())


def test_deep_and_dry_states_are_unchanged(reference_uvms):
    """Deep under the surface: exactly the derivatives without a top. Wholly out of the
    water (every hull dry): those of the model in air, buoyancy, added mass and damping gone
    (finite differences agree: away from the kink nothing is wet)."""
    rng = np.random.default_rng(43)
    q, v, tau = _near_the_surface(reference_uvms, rng)
    q[2] = -6.0
    kw = {"backend": "python"}
    with_top = up.forward_dynamics_derivatives(reference_uvms, q, v, tau, free_surface=True, **kw)
    without = up.forward_dynamics_derivatives(reference_uvms, q, v, tau, **kw)
    for a, b in zip(with_top, without, strict=True):
        np.testing.assert_array_equal(a, b)
    q[2] = 5.0
    assert np.all(_fractions(reference_uvms, q, None, 0.0) == 0.0)
    assert_matches_finite_differences(reference_uvms, q, v, tau, None, 0.0)


#: the compiled Jacobians against the reference's (max |error| / max |entry|): both take the
#: hull geometry's pose Jacobian by differences at a step of 1e-6 of its radius, which turns
#: the two implementations' rounding of the hull (1e-16; a mesh's sums over its faces) into
#: 1e-12 to 2e-9 of da/dq (measured; da/dv and da/dtau agree to 1e-14)
CORE_REL = 5e-9


@pytest.mark.parametrize("flow", list(FLOWS), ids=list(FLOWS))
def test_the_core_matches_the_reference_at_the_surface(models, flow):
    rng = np.random.default_rng(44)
    kw = {"flow": FLOWS[flow], "time_s": 0.7, "free_surface": True}
    for name, uvms in models.items():
        for q, v, tau in _cut_states(uvms, FLOWS[flow], rng):
            expected = up.forward_dynamics_derivatives(uvms, q, v, tau, backend="python", **kw)
            got = up.forward_dynamics_derivatives(uvms, q, v, tau, backend="core", **kw)
            errors = [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]
            assert max(errors) < CORE_REL, f"{name}: {errors}"


def test_one_control_period_at_the_surface(reference_uvms):
    """`up.step_derivatives` with the surface cutting the vehicle: against central
    differences of the plant's semi-implicit Euler over the period, the surface included."""
    from uvms_pin.sim.integrators import SemiImplicitEuler

    uvms, model, nv = reference_uvms, reference_uvms.model, reference_uvms.nv
    period, step, t0 = 0.02, 0.005, 0.3
    q, v, tau = next(_cut_states(uvms, None, np.random.default_rng(45), 1, True))

    def period_end(qq, vv):
        def rhs(t, q_, v_):
            return up.forward_dynamics(uvms, q_, v_, tau, time_s=t, free_surface=True)

        return SemiImplicitEuler(step_s=step).advance(model, rhs, t0, qq, vv, t0 + period)

    got = up.step_derivatives(uvms, q, v, tau, period, step_s=step, time_s=t0, free_surface=True)
    q1, _ = period_end(q, v)

    def end_state(x):
        qe, ve = period_end(pin.integrate(model, q, x[:nv]), x[nv:])
        return np.r_[pin.difference(model, q1, qe), ve]

    fd = central_difference(end_state, np.r_[np.zeros(nv), v], 2 * nv, STEP_V)
    assert _relative_error(got.dx_dx, fd) < FD_REL
