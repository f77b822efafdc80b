"""`Plant.acceleration_derivatives` with the end-effector's compliant contact (the paper's
spring, a compliant plane pushed into): against central differences of the plant's own
`Plant.acceleration`, on the core and on the Python reference, in a current with the joint
stops and friction; the contact's term is needed (without it the derivatives miss); a model
without derivatives is refused, naming it."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, mount_on_reference_vehicle

from uvms_pin.errors import ParameterError
from uvms_pin.physics.contact import CompliantPlane, ContactModel, LinearSpring
from uvms_pin.physics.joint_friction import JointFriction
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.sim import plant_derivatives
from uvms_pin.sim.plant import Plant

FD_REL = 1e-6
STEP = 1e-6


@pytest.fixture(scope="module", params=["reference", "ur5"])
def uvms(request, reference_uvms, tmp_path_factory):
    if request.param == "reference":
        return reference_uvms
    return mount_on_reference_vehicle("ur5", tmp_path_factory.mktemp("ur5"))


def _state(uvms, rng):
    q = uvms.neutral_configuration()
    q[2] = -3.0
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.normal(scale=0.2, size=3))).coeffs()
    lower, upper = uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:]
    q[7:] = rng.uniform(np.maximum(lower, -1.0) + 0.1, np.minimum(upper, 1.0) - 0.1)
    v = rng.normal(scale=0.2, size=uvms.nv)
    return q, v, rng.normal(scale=5.0, size=uvms.nv)


def _tip(uvms, q, v):
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q, v)
    placement = pin.updateFramePlacement(uvms.model, data, uvms.ee_frame_id)
    velocity = pin.getFrameVelocity(uvms.model, data, uvms.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
    return placement.translation.copy(), velocity.linear.copy()


def _contacts(uvms, q, v) -> dict[str, ContactModel]:
    """A spring stretched 5 cm and a plane the tip is 2 cm into and moving deeper into
    (pushing: k d + c d_dot > 0), with a tilted normal."""
    tip, tip_velocity = _tip(uvms, q, v)
    normal = np.array([0.3, -0.2, 1.0]) / np.linalg.norm([0.3, -0.2, 1.0])
    if tip_velocity @ normal > 0:
        normal = -normal  # the tip moves against the normal: deeper in
    return {
        "spring": LinearSpring(
            np.array([400.0, 250.0, 600.0]), anchor_world_m=tip + np.array([0.03, -0.02, 0.04])
        ),
        "plane": CompliantPlane(normal, 800.0, 30.0, point_world_m=tip + 0.02 * normal),
    }


def _plant(uvms, contact, backend) -> Plant:
    n = uvms.nv - 6
    return Plant(
        uvms,
        current_world_m_s=np.array([0.2, -0.1, 0.0]),
        contact=contact,
        joint_stops=JointStops.of_model(uvms.model, 300.0, 3.0),
        joint_friction=JointFriction(np.full(n, 0.8), np.full(n, 1.5), np.full(n, 0.2)),
        backend=backend,
    )


def _finite_differences(plant, q, v, tau, time_s=0.2):
    nv = plant.uvms.nv
    integrate = lambda x, dx: pin.integrate(plant.uvms.model, x, dx)  # noqa: E731
    accel = plant.acceleration
    return (
        central_difference(lambda x: accel(time_s, x, v, tau), q, nv, STEP, integrate),
        central_difference(lambda x: accel(time_s, q, x, tau), v, nv, STEP),
        central_difference(lambda x: accel(time_s, q, v, x), tau, nv, 1e-3),
    )


def _relative_error(got, expected) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


@pytest.mark.parametrize("backend", ["core", "python"])
@pytest.mark.parametrize("kind", ["spring", "plane"])
def test_the_contact_derivatives_match_finite_differences(uvms, kind, backend):
    rng = np.random.default_rng(61)
    q, v, tau = _state(uvms, rng)
    plant = _plant(uvms, _contacts(uvms, q, v)[kind], backend)
    assert np.linalg.norm(plant.contact_wrench(q, v)[:3]) > 1.0  # the contact is in the test
    got = plant.acceleration_derivatives(0.2, q, v, tau)
    expected = _finite_differences(plant, q, v, tau)
    errors = [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]
    assert max(errors) < FD_REL, errors


def test_without_the_contact_term_the_derivatives_miss(uvms, monkeypatch):
    """The contact's own Jacobians are needed: with them zeroed the q and v derivatives
    differ from the differences far beyond the tolerance (on the Python reference, whose
    contact term is the function patched here; the core's own term is checked against it
    in tests/physics/derivatives/test_task_contact_core.py)."""
    rng = np.random.default_rng(62)
    q, v, tau = _state(uvms, rng)
    plant = _plant(uvms, _contacts(uvms, q, v)["plane"], "python")
    expected = _finite_differences(plant, q, v, tau)
    derivatives = plant_derivatives.contact_derivatives

    def without_jacobians(*args, **kwargs):
        state, jacobians = derivatives(*args, **kwargs)
        return state, type(jacobians)(
            jacobians.wrench_dq, jacobians.wrench_dv, 0 * jacobians.tau_dq, 0 * jacobians.tau_dv
        )

    monkeypatch.setattr(plant_derivatives, "contact_derivatives", without_jacobians)
    got = plant.acceleration_derivatives(0.2, q, v, tau)
    assert _relative_error(got[0], expected[0]) > 1e3 * FD_REL
    assert _relative_error(got[1], expected[1]) > 1e3 * FD_REL


class _Wall(CompliantPlane):
    """A contact model of the user's own, with no derivatives."""


def test_a_contact_model_without_derivatives_is_refused_naming_it(reference_uvms):
    rng = np.random.default_rng(63)
    q, v, tau = _state(reference_uvms, rng)
    plane = _contacts(reference_uvms, q, v)["plane"]
    wall = _Wall(plane.normal_world, plane.stiffness_N_m, point_world_m=plane.point)
    plant = _plant(reference_uvms, wall, "python")
    with pytest.raises(ParameterError, match="_Wall"):
        plant.acceleration_derivatives(0.2, q, v, tau)
