"""The compiled end-effector contact derivatives (src/uvms_core/derivatives_task_contact.cpp,
through `Plant.acceleration_derivatives` on the core: src/uvms_core/plant_derivatives.cpp)
against their Python reference (`uvms_pin.physics.derivatives.task_contact`, and the same
plant on ``backend="python"``) to 1e-10 relative: a stretched spring, a tilted plane pushed
into, a plane the tip is inside of but leaving faster than the spring pushes (no force), a
plane not touched; in a current with the joint stops and friction, on the reference vehicle,
a mounted UR5 and the BlueROV2 + Alpha 5. The compiled derivatives against central
differences of the compiled `Plant.acceleration`; the core takes the compiled path (the
Python contact derivatives are not called), the contact's terms are far above the
tolerance (an error in them is seen), and a user's contact model is refused by name."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, mount_on_reference_vehicle

import uvms_pin as up
from uvms_pin.errors import CoreFallbackWarning, ParameterError
from uvms_pin.physics.contact import CompliantPlane, LinearSpring
from uvms_pin.physics.derivatives.task_contact import TaskContact, contact_derivatives
from uvms_pin.physics.joint_friction import JointFriction
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.sim import plant_derivatives
from uvms_pin.sim.plant import Plant

CORE_REL = 1e-10  # the compiled derivatives against the reference's
FD_REL = 1e-6  # against central differences of the plant's acceleration
KINDS = ["spring", "plane", "leaving", "apart"]


@pytest.fixture(scope="module", params=["reference", "ur5", "bluerov_alpha5"])
def uvms(request, reference_uvms, tmp_path_factory):
    if request.param == "reference":
        return reference_uvms
    if request.param == "ur5":
        return mount_on_reference_vehicle("ur5", tmp_path_factory.mktemp("ur5"))
    from uvms_pin.model.resources import shipped_path

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        return up.load_uvms(shipped_path("models/uvms_bluerov2_alpha5.urdf"))


def _state(uvms, seed):
    rng = np.random.default_rng(seed)
    q = uvms.neutral_configuration()
    q[:3] = [0.4, -0.3, -3.0]
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.normal(scale=0.3, size=3))).coeffs()
    lower, upper = uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:]
    q[7:] = rng.uniform(np.maximum(lower, -1.0) + 0.1, np.minimum(upper, 1.0) - 0.1)
    v = rng.normal(scale=0.2, size=uvms.nv)
    return q, v, rng.normal(scale=5.0, size=uvms.nv)


def _tip(uvms, q, v):
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q, v)
    position = pin.updateFramePlacement(uvms.model, data, uvms.ee_frame_id).translation.copy()
    velocity = pin.getFrameVelocity(uvms.model, data, uvms.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
    return position, velocity.linear.copy()


def _contact(uvms, q, v, kind):
    """A spring stretched a few cm; a tilted plane the tip is 2 cm into, moving deeper
    ("plane": pushing), or out of it faster than k d / c ("leaving": inside, no force); a
    plane 3 cm away ("apart")."""
    tip, tip_velocity = _tip(uvms, q, v)
    if kind == "spring":
        return LinearSpring(np.array([400.0, 250.0, 600.0]), tip + np.array([0.03, -0.02, 0.04]))
    normal = np.array([0.3, -0.2, 1.0]) / np.linalg.norm([0.3, -0.2, 1.0])
    if tip_velocity @ normal > 0:
        normal = -normal  # the tip moves against the normal: deeper in
    if kind == "plane":
        return CompliantPlane(normal, 800.0, 30.0, point_world_m=tip + 0.02 * normal)
    if kind == "leaving":  # moving out along -normal at |rate|: k d + c d_dot < 0
        rate = abs(tip_velocity @ normal)
        return CompliantPlane(-normal, 800.0, 30.0, point_world_m=tip - 0.02 * rate * normal)
    return CompliantPlane(normal, 800.0, 30.0, point_world_m=tip - 0.03 * normal)


def _plant(uvms, contact, backend) -> Plant:
    n = uvms.nv - 6
    return Plant(
        uvms,
        current_world_m_s=np.array([0.2, -0.1, 0.05]),
        contact=contact,
        joint_stops=JointStops.of_model(uvms.model, 300.0, 3.0),
        joint_friction=JointFriction(np.full(n, 0.8), np.full(n, 1.5), np.full(n, 0.2)),
        backend=backend,
    )


def _relative_error(got, expected) -> float:
    scale = max(float(np.max(np.abs(expected))), 1e-300)
    return float(np.max(np.abs(got - expected))) / scale


@pytest.mark.parametrize("kind", KINDS)
def test_the_compiled_contact_derivatives_match_the_reference(uvms, kind):
    """lambda, tau_ext and their q, v derivatives, term by term (exactly zero apart or
    leaving)."""
    q, v, _ = _state(uvms, 81)
    contact = _contact(uvms, q, v, kind)
    compiled = _plant(uvms, contact, "core").compiled
    assert compiled is not None
    got = compiled.contact_derivatives(q, v)
    task = TaskContact(uvms.ee_frame_id, contact)
    state, jacobians = contact_derivatives(task, uvms.model, uvms.model.createData(), q, v)
    expected = {
        "wrench_world": state.wrench_world,
        "tau_ext": state.tau_ext,
        "wrench_dq": jacobians.wrench_dq,
        "wrench_dv": jacobians.wrench_dv,
        "tau_dq": jacobians.tau_dq,
        "tau_dv": jacobians.tau_dv,
    }
    pushing = kind in ("spring", "plane")
    assert (np.linalg.norm(state.wrench_world) > 1.0) == pushing  # the case is the one named
    for name, value in expected.items():
        if pushing:
            assert _relative_error(got[name], value) < CORE_REL, name
        else:
            assert not np.any(got[name]) and not np.any(value), name


@pytest.mark.parametrize("kind", KINDS)
def test_the_plant_derivatives_match_the_reference_plant(uvms, kind):
    q, v, tau = _state(uvms, 82)
    contact = _contact(uvms, q, v, kind)
    got = _plant(uvms, contact, "core").acceleration_derivatives(0.2, q, v, tau)
    expected = _plant(uvms, contact, "python").acceleration_derivatives(0.2, q, v, tau)
    errors = [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]
    assert max(errors) < CORE_REL, errors


@pytest.mark.parametrize("kind", ["spring", "plane", "apart"])
def test_the_compiled_derivatives_match_finite_differences(uvms, kind):
    q, v, tau = _state(uvms, 83)
    plant = _plant(uvms, _contact(uvms, q, v, kind), "core")
    nv = uvms.nv
    accel = plant.acceleration
    integrate = lambda x, dx: pin.integrate(uvms.model, x, dx)  # noqa: E731
    expected = (
        central_difference(lambda x: accel(0.2, x, v, tau), q, nv, 1e-6, integrate),
        central_difference(lambda x: accel(0.2, q, x, tau), v, nv, 1e-6),
    )
    got = plant.acceleration_derivatives(0.2, q, v, tau)
    errors = [_relative_error(g, e) for g, e in zip(got[:2], expected, strict=True)]
    assert max(errors) < FD_REL, errors


def test_the_contact_terms_are_far_above_the_tolerance(uvms):
    """M^-1 d tau_ext/dq and M^-1 d tau_ext/dv, and the plane's damping part of the latter
    alone, are many times 1e-10 of the whole: an error in any of them fails the agreement
    with the reference above."""
    q, v, tau = _state(uvms, 82)
    contact = _contact(uvms, q, v, "plane")
    plant = _plant(uvms, contact, "core")
    compiled = plant.compiled
    whole = compiled.acceleration_derivatives(0.2, q, v, tau, plant.friction)
    terms = compiled.contact_derivatives(q, v)
    inverse_mass = whole.da_dtau
    assert (
        _relative_error(whole.da_dq - inverse_mass @ terms["tau_dq"], whole.da_dq) > 1e4 * CORE_REL
    )
    assert (
        _relative_error(whole.da_dv - inverse_mass @ terms["tau_dv"], whole.da_dv) > 1e4 * CORE_REL
    )
    jacobian = pin.computeFrameJacobian(
        uvms.model, uvms.model.createData(), q, uvms.ee_frame_id, pin.LOCAL_WORLD_ALIGNED
    )
    normal = contact.normal_world
    damping = -contact.damping_N_s_m * jacobian[:3].T @ np.outer(normal, normal) @ jacobian[:3]
    assert np.max(np.abs(inverse_mass @ damping)) > 1e4 * CORE_REL * np.max(np.abs(whole.da_dv))


def test_the_core_takes_the_compiled_path(reference_uvms, monkeypatch):
    """With a spring or a plane the Python contact derivatives are not called on the core."""
    q, v, tau = _state(reference_uvms, 84)

    def refused(*args, **kwargs):
        raise AssertionError("the Python contact derivatives were called")

    monkeypatch.setattr(plant_derivatives, "contact_derivatives", refused)
    for kind in ("spring", "plane"):
        plant = _plant(reference_uvms, _contact(reference_uvms, q, v, kind), "core")
        assert all(np.all(np.isfinite(d)) for d in plant.acceleration_derivatives(0.2, q, v, tau))


class _Wall(CompliantPlane):
    """A contact model of the user's own (a compliant plane's subclass: no derivatives)."""


def test_a_users_contact_model_is_refused_by_name_on_the_core(reference_uvms):
    """A subclass has no compiled counterpart (the plant falls back, warned) and no
    derivatives (refused by the reference, naming it)."""
    q, v, tau = _state(reference_uvms, 85)
    plane = _contact(reference_uvms, q, v, "plane")
    wall = _Wall(plane.normal_world, plane.stiffness_N_m, point_world_m=plane.point)
    plant = _plant(reference_uvms, wall, "core")
    with (
        pytest.warns(CoreFallbackWarning, match="_Wall"),  # no compiled plant for it
        pytest.raises(ParameterError, match="_Wall"),
    ):
        plant.acceleration_derivatives(0.2, q, v, tau)


@pytest.mark.parametrize("what", ["free object", "self-collision"])
def test_free_objects_or_self_collision_alone_are_refused(reference_uvms, what):
    """Each of the two terms without derivatives is refused on its own, by name, before
    anything is computed."""
    from uvms_pin.physics.world.free_object import free_object
    from uvms_pin.physics.world.world import World

    uvms = reference_uvms
    if what == "free object":
        ball = free_object("ball", "sphere", {"radius_m": 0.1}, ([3.0, 0.0, -5.0], [0, 0, 0]),
                           density_kg_m3=2000.0, water_density_kg_m3=1025.0)  # fmt: skip
        world = World(uvms, [], free=[ball])
    else:
        world = World(uvms, [], self_collision=True)
    plant = Plant(uvms, free_surface=False, world=world)
    q, v, tau = _state(uvms, 86)
    with pytest.raises(ParameterError, match="free objects and self-collision are not"):
        plant.acceleration_derivatives(0.2, q, v, tau)
