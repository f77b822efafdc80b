"""The compiled derivatives of the joint stops and the drives' friction
(src/uvms_core/derivatives_joint_limits.hpp, through `Plant.acceleration_derivatives` on the
core: src/uvms_core/plant_derivatives.cpp) against their Python reference
(`uvms_pin.physics.derivatives.joint_limits`, the plant on ``backend="python"``) to 1e-10
relative, stops engaged on both sides (pushing and letting go) with the friction in its steep
part, in a current with a disturbance; the compiled derivatives against central differences
of the compiled `Plant.acceleration`; a planted sign error in the reference is seen."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, mount_on_reference_vehicle

from uvms_pin.physics.contact import LinearSpring
from uvms_pin.physics.derivatives.joint_limits import joint_stop_jacobians
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.physics.joint_friction import JointFriction
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.sim import plant_derivatives
from uvms_pin.sim.plant import Plant

CORE_REL = 1e-10
FD_REL = 1e-6


@pytest.fixture(scope="module", params=["reference", "ur5"])
def uvms(request, reference_uvms, tmp_path_factory):
    if request.param == "reference":
        return reference_uvms
    return mount_on_reference_vehicle("ur5", tmp_path_factory.mktemp("ur5"))


def _plant(uvms, backend, **kw) -> Plant:
    n = uvms.nv - 6
    friction = JointFriction(np.full(n, 0.8), np.full(n, 1.5), np.full(n, 0.2))
    return Plant(
        uvms,
        current_world_m_s=np.array([0.2, -0.1, 0.0]),
        joint_stops=JointStops.of_model(uvms.model, 300.0, 3.0),
        joint_friction=friction,
        backend=backend,
        **kw,
    )


def _both_sides(uvms, rng):
    """Each stopped joint 0.02-0.05 rad past its upper or its lower limit (alternately),
    moving out (the stop pushing) or in fast enough that it lets go; joint rates within
    the Coulomb ramp."""
    q = uvms.neutral_configuration()
    q[2] = -3.0
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.normal(scale=0.3, size=3))).coeffs()
    v = rng.normal(scale=0.3, size=uvms.nv)
    stops = JointStops.of_model(uvms.model, 300.0, 3.0)
    for k, (iq, iv) in enumerate(zip(stops.q_index, stops.v_index, strict=True)):
        lo, hi = stops.lower_rad[k], stops.upper_rad[k]
        past = rng.uniform(0.02, 0.05)
        outward = 1.0 if k % 3 else -1.0  # every third one moving back in, fast: let go
        speed = rng.uniform(0.1, 0.4) if outward > 0 else rng.uniform(6.0, 8.0)
        if k % 2 == 0 and np.isfinite(hi):
            q[iq], v[iv] = hi + past, outward * speed
        elif np.isfinite(lo):
            q[iq], v[iv] = lo - past, -outward * speed
    return q, v, rng.normal(scale=5.0, size=uvms.nv)


def _relative_error(got, expected) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


def _errors(python, core, q, v, tau, time_s=0.2) -> list[float]:
    expected = python.acceleration_derivatives(time_s, q, v, tau)
    got = core.acceleration_derivatives(time_s, q, v, tau)
    return [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]


def test_stops_on_both_sides_and_friction_match_the_reference(uvms):
    rng = np.random.default_rng(81)
    disturbance = SinusoidalDisturbance(np.full(6, 2.0), 0.5)
    python = _plant(uvms, "python", disturbance=disturbance)
    core = _plant(uvms, "core", disturbance=disturbance)
    for _ in range(3):
        q, v, tau = _both_sides(uvms, rng)
        by_q = np.diag(joint_stop_jacobians(python.joint_stops, q, v)[0])
        stops = python.joint_stops
        upper = q[stops.q_index] > stops.upper_rad
        lower = q[stops.q_index] < stops.lower_rad
        pushing = by_q[stops.v_index] != 0.0
        assert np.any(pushing & upper) and np.any(pushing & lower)  # both sides push
        assert np.any(~pushing & (upper | lower))  # and one past its limit lets go
        errors = _errors(python, core, q, v, tau)
        assert max(errors) < CORE_REL, errors


def test_the_compiled_derivatives_match_finite_differences(uvms):
    rng = np.random.default_rng(82)
    core = _plant(uvms, "core")
    q, v, tau = _both_sides(uvms, rng)
    model = uvms.model
    accel = core.acceleration
    integrate = lambda x, dx: pin.integrate(model, x, dx)  # noqa: E731
    expected = (
        central_difference(lambda x: accel(0.2, x, v, tau), q, model.nv, 1e-6, integrate),
        central_difference(lambda x: accel(0.2, q, x, tau), v, model.nv, 1e-6),
        central_difference(lambda x: accel(0.2, q, v, x), tau, model.nv, 1e-3),
    )
    got = core.acceleration_derivatives(0.2, q, v, tau)
    errors = [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]
    assert max(errors) < FD_REL, errors


def test_a_planted_sign_error_in_the_reference_is_seen(reference_uvms, monkeypatch):
    """The stop's damping term, or the friction's slope, with the wrong sign in the
    reference: far outside CORE_REL of the compiled derivatives."""
    rng = np.random.default_rng(83)
    python, core = _plant(reference_uvms, "python"), _plant(reference_uvms, "core")
    q, v, tau = _both_sides(reference_uvms, rng)
    assert max(_errors(python, core, q, v, tau)) < CORE_REL
    stops = plant_derivatives.joint_stop_jacobians
    monkeypatch.setattr(
        plant_derivatives,
        "joint_stop_jacobians",
        lambda s, q, v: (stops(s, q, v)[0], -stops(s, q, v)[1]),
    )
    assert _errors(python, core, q, v, tau)[1] > 1e3 * CORE_REL
    monkeypatch.undo()
    friction = plant_derivatives.joint_friction_jacobian
    monkeypatch.setattr(plant_derivatives, "joint_friction_jacobian", lambda f, v: -friction(f, v))
    assert _errors(python, core, q, v, tau)[1] > 1e3 * CORE_REL


def test_an_end_effector_contact_on_the_core_equals_the_reference(reference_uvms):
    """With the end-effector's spring the plant's derivatives take the Python contact
    Jacobians around the compiled water derivatives: equal to the reference's."""
    q, v, tau = _both_sides(reference_uvms, np.random.default_rng(84))
    data = reference_uvms.model.createData()
    pin.forwardKinematics(reference_uvms.model, data, q)
    tip = pin.updateFramePlacement(reference_uvms.model, data, reference_uvms.ee_frame_id)
    anchor = tip.translation + np.array([0.02, 0.03, -0.04])
    plants = [
        _plant(reference_uvms, backend, contact=LinearSpring(np.full(3, 300.0), anchor))
        for backend in ("python", "core")
    ]
    assert max(_errors(*plants, q, v, tau)) < CORE_REL
