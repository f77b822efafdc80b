"""One control period's Jacobians with the plant's RK4 integrator, against the plant.

`up.step_derivatives(..., integrator=RK4(h))` (exact: the stages' forward-dynamics
derivatives chained through the chart, `uvms_pin.physics.derivatives.step`) against 4-point
central differences of the plant's own period (`Plant.advance` with `RK4`), the state moved
along the tangent (pin.integrate) and the end state read in the tangent at the unperturbed
end (pin.difference), on random states of the reference vehicle, shipped models, a mounted
arm and a ball-jointed arm, in a current and in waves (a flow that changes with time). The
semi-implicit Euler period keeps its own tests (tests/physics/test_derivatives.py).
"""

from __future__ import annotations

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
from uvms_pin.errors import CoreFallbackWarning, ParameterError
from uvms_pin.flow import AiryWave, DepthProfileCurrent, UniformCurrent
from uvms_pin.model.resources import shipped_models, shipped_path
from uvms_pin.sim.integrators import RK4, SemiImplicitEuler
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

#: relative agreement of the period's Jacobians with the finite differences of the plant
FD_REL = 1e-7
STEP = 1e-5
PERIOD_S, STEP_S, T0_S = 0.02, 0.01, 0.4  # two RK4 substeps per period

CURRENT = np.array([0.3, -0.2, 0.1])
WAVES = AiryWave(0.4, 5.0, heading_rad=0.5, water_depth_m=15.0) + UniformCurrent([0.2, 0.0, 0.0])


def _relative_error(got: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(got - expected)) / np.max(np.abs(expected)))


def _plant(uvms, water, backend="python") -> Plant:
    current = CURRENT if water == "current" else np.zeros(3)
    flow = WAVES if water == "waves" else None
    return Plant(uvms, current, flow=flow, free_surface=False, backend=backend)


def _flow_arguments(water) -> dict:
    return {
        "current_world": CURRENT if water == "current" else None,
        "flow": WAVES if water == "waves" else None,
    }


def assert_rk4_period_matches_the_plant(uvms, water, rng, backend="python"):
    """The RK4 period's end state and Jacobians against the plant's own period."""
    q, v, tau = random_state(uvms, rng)
    integrator, plant = RK4(step_s=STEP_S), _plant(uvms, water)
    got = up.step_derivatives(
        uvms,
        q,
        v,
        tau,
        PERIOD_S,
        integrator=integrator,
        time_s=T0_S,
        backend=backend,
        **_flow_arguments(water),
    )

    def period(qq, vv, tt):
        return System(plant).advance(integrator, T0_S, qq, vv, tt, T0_S + PERIOD_S)

    q1, v1 = period(q, v, tau)
    # the same stages as the plant's RK4, to rounding (the chart rate in closed form there)
    np.testing.assert_allclose(got.q, q1, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.v, v1, rtol=0, atol=1e-11)
    nv, model = uvms.nv, uvms.model

    def end_state(x):  # x = (dq, v) -> (q+ (-) q1 in the tangent at q1, v+)
        qe, ve = period(pin.integrate(model, q, x[:nv]), x[nv:], tau)
        return np.r_[pin.difference(model, q1, qe), ve]

    def end_state_of_tau(tt):
        qe, ve = period(q, v, tt)
        return np.r_[pin.difference(model, q1, qe), ve]

    fd_x = central_difference(end_state, np.r_[np.zeros(nv), v], 2 * nv, STEP)
    fd_tau = central_difference(end_state_of_tau, tau, nv, 1e-3 * np.abs(tau).max())
    errors = _relative_error(got.dx_dx, fd_x), _relative_error(got.dx_dtau, fd_tau)
    assert max(errors) < FD_REL, f"relative errors (dx, dtau): {errors}"
    return errors


@pytest.fixture(scope="module", params=["reference", "ur5", "z1", "ball"])
def system(request, reference_uvms, tmp_path_factory) -> up.UVMS:
    if request.param == "reference":
        return reference_uvms
    if request.param == "ball":
        return with_spherical_joint(reference_uvms, 3)
    return mount_on_reference_vehicle(request.param, tmp_path_factory.mktemp(request.param))


@pytest.mark.parametrize("water", ["current", "waves"])
def test_rk4_period_jacobians_match_finite_differences_of_the_plant(system, water):
    assert_rk4_period_matches_the_plant(system, water, np.random.default_rng(41))


@pytest.mark.parametrize("name", shipped_models())
def test_rk4_period_of_every_shipped_model_matches_the_plant(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        uvms = up.load_uvms(shipped_path(f"models/{name}.urdf"))
    assert_rk4_period_matches_the_plant(uvms, "waves", np.random.default_rng(42), backend="core")


@pytest.mark.parametrize("method", ["rk4", "semi_implicit_euler"])
@pytest.mark.parametrize("ball", [False, True], ids=["revolute", "ball"])
def test_the_compiled_period_is_the_reference(reference_uvms, method, ball):
    """backend="core" (the whole period in one compiled call, step_derivatives.hpp) gives
    the reference's end state and Jacobians, in waves, with a held tau_ext."""
    uvms = with_spherical_joint(reference_uvms, 3) if ball else reference_uvms
    rng = np.random.default_rng(43)
    q, v, tau = random_state(uvms, rng)
    kw = {
        "integrator": method,
        "step_s": STEP_S,
        "time_s": T0_S,
        "flow": WAVES,
        "tau_ext": rng.normal(size=uvms.nv),
    }
    python = up.step_derivatives(uvms, q, v, tau, PERIOD_S, backend="python", **kw)
    core = up.step_derivatives(uvms, q, v, tau, PERIOD_S, backend="core", **kw)
    for name in ("q", "v", "dx_dx", "dx_dtau"):
        got, expected = getattr(core, name), getattr(python, name)
        error = np.max(np.abs(got - expected)) / max(1.0, np.max(np.abs(expected)))
        assert error < 1e-10, f"{name}: {error}"


def test_a_deep_period_under_a_free_surface_is_the_period_without_one(reference_uvms):
    """free_surface=True runs the stages from Python (each checked deep) on the compiled
    stage derivatives: deep, the same period as the compiled call without a surface."""
    q, v, tau = random_state(reference_uvms, np.random.default_rng(45))
    q[2] = -6.0
    kw = {"integrator": RK4(step_s=STEP_S), "time_s": T0_S, "flow": WAVES}
    surface = up.step_derivatives(reference_uvms, q, v, tau, PERIOD_S, free_surface=True, **kw)
    deep = up.step_derivatives(reference_uvms, q, v, tau, PERIOD_S, **kw)
    for name in ("q", "v", "dx_dx", "dx_dtau"):
        got, expected = getattr(surface, name), getattr(deep, name)
        assert np.max(np.abs(got - expected)) < 1e-10 * max(1.0, np.max(np.abs(expected)))


def test_a_flow_without_core_counterpart_runs_the_period_from_python(reference_uvms):
    """A sheared current (no core counterpart): the Python loop on the reference, warned."""
    q, v, tau = random_state(reference_uvms, np.random.default_rng(46))
    sheared = DepthProfileCurrent([0.4, 0.1, 0.05], [0.0, 10.0], [1.0, 0.2])
    kw = {"integrator": "rk4", "step_s": STEP_S, "time_s": T0_S, "flow": sheared}
    with pytest.warns(CoreFallbackWarning):
        core = up.step_derivatives(reference_uvms, q, v, tau, PERIOD_S, **kw)
    python = up.step_derivatives(reference_uvms, q, v, tau, PERIOD_S, backend="python", **kw)
    np.testing.assert_allclose(core.dx_dx, python.dx_dx, rtol=0, atol=1e-12)


def test_the_integrator_is_named_or_given(reference_uvms):
    """An integrator object is its method and its substep; Euler stays the default."""
    q, v, tau = random_state(reference_uvms, np.random.default_rng(44))
    args = (reference_uvms, q, v, tau, 0.01)
    for obj, name in ((RK4(step_s=0.005), "rk4"), (SemiImplicitEuler(step_s=0.005), None)):
        by_object = up.step_derivatives(*args, integrator=obj, backend="python")
        named = {} if name is None else {"integrator": name}
        by_name = up.step_derivatives(*args, step_s=0.005, backend="python", **named)
        np.testing.assert_array_equal(by_object.dx_dx, by_name.dx_dx)
        np.testing.assert_array_equal(by_object.dx_dtau, by_name.dx_dtau)
    euler = up.step_derivatives(*args, step_s=0.005, backend="python")
    rk4 = up.step_derivatives(*args, step_s=0.005, integrator="rk4", backend="python")
    assert not np.allclose(euler.v, rk4.v, rtol=0, atol=1e-12)  # two different periods


def test_bad_integrators_are_refused(reference_uvms):
    q = reference_uvms.neutral_configuration()
    zero = np.zeros(reference_uvms.nv)
    with pytest.raises(ParameterError, match="'rk5'"):
        up.step_derivatives(reference_uvms, q, zero, zero, 0.01, integrator="rk5")
    with pytest.raises(ParameterError, match="not both"):
        up.step_derivatives(reference_uvms, q, zero, zero, 0.01, step_s=0.01, integrator=RK4())


@pytest.mark.parametrize("backend", ["python", "core"])
def test_a_period_of_more_substeps_than_one_call_takes_is_refused(reference_uvms, backend):
    """1e4 s in steps of 1 us (1e10 substeps, beyond an int): the core's count was an
    undefined conversion that gave one step of the whole period, returned at once as if
    right; the reference's a hang. Both refuse more than MAX_SUBSTEPS by name, as the
    plant's own advance does; MAX_SUBSTEPS of them are taken (the check is not the loop)."""
    from uvms_pin.physics.compiled.extension import core_module
    from uvms_pin.physics.derivatives.step import MAX_SUBSTEPS, substeps

    assert core_module().MAX_SUBSTEPS == MAX_SUBSTEPS
    q = reference_uvms.neutral_configuration()
    zero = np.zeros(reference_uvms.nv)
    for period_s, step_s in ((1e4, 1e-6), (1e9, 1e-3), (1.0, 1e-300)):
        with pytest.raises(ParameterError, match=r"substeps, more than 1e\+07 in one call"):
            up.step_derivatives(
                reference_uvms, q, zero, zero, period_s, step_s=step_s, backend=backend
            )
    assert substeps(MAX_SUBSTEPS * 1e-3, 1e-3)[0] == MAX_SUBSTEPS
    plant = Plant(reference_uvms, backend=backend)
    with pytest.raises(ParameterError, match="substeps"):
        RK4(step_s=1e-6).advance(
            reference_uvms.model, plant.acceleration, 0.0, q, zero, 1e4
        )  # the Python loop's advance, the same split
    if backend == "core":  # the core's own split (its plant's advance)
        core = core_module()
        fixed = core.FixedStep()
        fixed.method, fixed.step_s = core.Method.rk4, 1e-6
        with pytest.raises(ParameterError, match="more than 1e7 substeps in one call"):
            plant.compiled.advance(0.0, q, zero, zero, 1e4, fixed)


@pytest.mark.parametrize("integrator", [RK4(step_s=STEP_S), SemiImplicitEuler(step_s=STEP_S)])
@pytest.mark.parametrize("backend", ["python", "core"])
def test_a_period_not_a_multiple_of_the_step_ends_where_the_plant_does(
    reference_uvms, integrator, backend
):
    """A period of 2.5 substeps is taken in 3 equal substeps (the fewest no longer than
    step_s), as the plant's integrator takes it: the same end state, to rounding."""
    q, v, tau = random_state(reference_uvms, np.random.default_rng(47))
    period_s = 2.5 * STEP_S
    got = up.step_derivatives(
        reference_uvms,
        q,
        v,
        tau,
        period_s,
        integrator=integrator,
        time_s=T0_S,
        flow=WAVES,
        backend=backend,
    )
    plant = Plant(reference_uvms, np.zeros(3), flow=WAVES, free_surface=False, backend="python")
    q1, v1 = System(plant).advance(integrator, T0_S, q, v, tau, T0_S + period_s)
    np.testing.assert_allclose(got.q, q1, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.v, v1, rtol=0, atol=1e-11)


def test_a_current_reaches_the_compiled_period_and_the_default_step_is_1ms(reference_uvms):
    """current_world is the same water on both backends (the compiled period in a current
    is the reference's, and not the still-water one); without step_s or an integrator
    object the substep is 1 ms."""
    q, v, tau = random_state(reference_uvms, np.random.default_rng(48))
    kw = {"integrator": "rk4", "step_s": STEP_S, "time_s": T0_S, "current_world": CURRENT}
    python = up.step_derivatives(reference_uvms, q, v, tau, PERIOD_S, backend="python", **kw)
    core = up.step_derivatives(reference_uvms, q, v, tau, PERIOD_S, backend="core", **kw)
    still = up.step_derivatives(
        reference_uvms, q, v, tau, PERIOD_S, backend="core", integrator="rk4", step_s=STEP_S
    )
    for name in ("v", "dx_dx", "dx_dtau"):
        got, expected = getattr(core, name), getattr(python, name)
        assert np.max(np.abs(got - expected)) < 1e-10 * max(1.0, np.max(np.abs(expected)))
    assert np.max(np.abs(core.dx_dx - still.dx_dx)) > 1e-6
    default = up.step_derivatives(reference_uvms, q, v, tau, 0.01, backend="python")
    fine = up.step_derivatives(reference_uvms, q, v, tau, 0.01, step_s=1e-3, backend="python")
    np.testing.assert_array_equal(default.dx_dx, fine.dx_dx)
