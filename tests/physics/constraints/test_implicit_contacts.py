"""Point contacts with Coulomb friction solved implicitly (`uvms_pin.physics.constraints`):
a solid sphere in air on a plane tilted 10 and 40 degrees rolls below the friction limit
(a = g sin / (1 + I / (m r^2)), |v| = |w| r) and slides above it (a = g (sin - mu cos)),
without sinking; the contact never adds kinetic energy; a sphere off the plane has no row;
the BlueROV2 + Alpha 5 in water pressed on a seafloor by its end-effector."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.model.resources import shipped_path
from uvms_pin.physics.constraints.contacts import ContactSphere, PlaneContacts, contact_frame
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.constraints.step import constrained_velocity

MASS_KG, RADIUS_M, G, MU, PERIOD_S = 1.0, 0.1, 9.81, 0.2, 2e-3


@pytest.fixture(scope="module")
def ball():
    """A solid sphere (I = 2/5 m r^2) in air: a translation then a spherical joint, so that
    its linear velocity is the world's and semi-implicit Euler moves it on a straight line."""
    model = pin.Model()
    slide = model.addJoint(0, pin.JointModelTranslation(), pin.SE3.Identity(), "translation")
    turn = model.addJoint(slide, pin.JointModelSpherical(), pin.SE3.Identity(), "rotation")
    model.appendBodyToJoint(turn, pin.Inertia.FromSphere(MASS_KG, RADIUS_M), pin.SE3.Identity())
    return model


def _slope(degrees: float) -> tuple[np.ndarray, np.ndarray]:
    """(the outward normal, the downhill direction) of a plane tilted about y."""
    angle = np.radians(degrees)
    return (
        np.array([-np.sin(angle), 0.0, np.cos(angle)]),
        np.array([-np.cos(angle), 0.0, -np.sin(angle)]),
    )


def _roll(model, contacts: PlaneContacts, periods: int):
    data = model.createData()
    q = pin.neutral(model)
    q[:3] = RADIUS_M * contacts.normal_world
    v = np.zeros(model.nv)
    lowest = np.inf
    for _ in range(periods):
        v_free = v + PERIOD_S * pin.aba(model, data, q, v, np.zeros(model.nv))
        mass = pin.crba(model, data, q)
        mass = np.triu(mass) + np.triu(mass, 1).T
        step = constrained_velocity(model, mass, v_free, q, [contacts], PERIOD_S)
        assert step.converged
        assert step.velocity @ mass @ step.velocity <= v_free @ mass @ v_free + 1e-12
        v = step.velocity
        q = pin.integrate(model, q, PERIOD_S * v)
        lowest = min(lowest, contacts.normal_world @ q[:3] - RADIUS_M)
    return v, lowest


@pytest.mark.parametrize("degrees", [10.0, 40.0])
def test_a_sphere_rolls_below_the_friction_limit_and_slides_above(ball, degrees):
    normal, downhill = _slope(degrees)
    contacts = PlaneContacts((ContactSphere(2, np.zeros(3), RADIUS_M),), np.zeros(3), normal, MU)
    periods = 200
    v, lowest = _roll(ball, contacts, periods)
    angle = np.radians(degrees)
    inertia_ratio = 0.4  # I / (m r^2) of a solid sphere
    rolls = MU >= np.tan(angle) * inertia_ratio / (1.0 + inertia_ratio)
    assert rolls == (degrees == 10.0)
    expected = (
        G * np.sin(angle) / (1.0 + inertia_ratio)
        if rolls
        else G * (np.sin(angle) - MU * np.cos(angle))
    )
    acceleration = v[:3] @ downhill / (periods * PERIOD_S)
    assert acceleration == pytest.approx(expected, rel=0.02)
    assert acceleration == pytest.approx(expected, rel=1e-6)  # it is exact in fact
    spin_m_s = np.linalg.norm(v[3:]) * RADIUS_M
    speed_m_s = np.linalg.norm(v[:3])
    if rolls:
        assert spin_m_s == pytest.approx(speed_m_s, rel=1e-6)
    else:
        assert spin_m_s < 0.9 * speed_m_s
    assert lowest >= -1e-8  # it never sinks into the plane


def test_a_frictionless_sphere_slides_without_turning(ball):
    """mu = 0 (a frictionless contact, allowed): on the 10 degree slope where mu = 0.2 rolls
    it, the sphere slides at a = g sin(theta) and does not turn."""
    normal, downhill = _slope(10.0)
    contacts = PlaneContacts((ContactSphere(2, np.zeros(3), RADIUS_M),), np.zeros(3), normal, 0.0)
    periods = 200
    v, lowest = _roll(ball, contacts, periods)
    acceleration = v[:3] @ downhill / (periods * PERIOD_S)
    assert acceleration == pytest.approx(G * np.sin(np.radians(10.0)), rel=1e-6)
    assert np.linalg.norm(v[3:]) < 1e-9
    assert lowest >= -1e-8


def test_the_planes_normal_is_made_unit_and_a_zero_margin_is_allowed(ball):
    """A normal given at any length is the unit one (the same rows as the unit normal's);
    a margin of 0 solves a sphere only within its reach."""
    data = ball.createData()
    q = pin.neutral(ball)
    q[2] = RADIUS_M + 0.01
    pin.computeJointJacobians(ball, data, q)
    falling = np.abs(np.r_[0.0, 0.0, -6.0, 0.0, 0.0, 0.0])
    sphere = (ContactSphere(2, np.zeros(3), RADIUS_M),)
    unit = PlaneContacts(sphere, np.zeros(3), np.array([0.0, 0.0, 1.0]), MU)
    long = PlaneContacts(sphere, np.zeros(3), np.array([0.0, 0.0, 2.5]), MU)
    np.testing.assert_array_equal(long.normal_world, [0.0, 0.0, 1.0])
    a, b = (c.rows(ball, data, q, falling, PERIOD_S) for c in (unit, long))
    np.testing.assert_allclose(b.gap, a.gap, atol=1e-15)
    np.testing.assert_allclose(b.jacobian, a.jacobian, atol=1e-15)
    exact = PlaneContacts(sphere, np.zeros(3), np.array([0.0, 0.0, 1.0]), MU, margin=0.0)
    assert exact.rows(ball, data, q, falling, PERIOD_S).size == 3  # 12 mm of reach
    assert exact.rows(ball, data, q, falling * 0.5, PERIOD_S).size == 0  # 6 mm: not 10


def test_a_sphere_above_the_plane_has_no_row(ball):
    contacts = PlaneContacts(
        (ContactSphere(2, np.zeros(3), RADIUS_M),), np.zeros(3), np.array([0.0, 0.0, 1.0]), MU
    )
    data = ball.createData()
    q = pin.neutral(ball)
    q[2] = RADIUS_M + 0.01
    pin.computeJointJacobians(ball, data, q)
    falling = np.r_[0.0, 0.0, -6.0, 0.0, 0.0, 0.0]
    assert contacts.rows(ball, data, q, np.abs(falling) * 0, PERIOD_S).size == 0
    rows = contacts.rows(ball, data, q, np.abs(falling), PERIOD_S)  # 12 mm per period: it can touch
    assert rows.size == 3 and rows.gap[2] == pytest.approx(0.01)
    # the rows are the contact frame's axes (t1, t2, n): orthonormal, the normal last
    frame = rows.jacobian[:, :3]
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-15)
    np.testing.assert_allclose(frame[2], [0.0, 0.0, 1.0], atol=1e-15)


def _dropped_on_the_plane(model, joint_id: int, v_free: np.ndarray):
    """One period of the sphere on ``joint_id`` (a free flyer), 2 mm above the plane z = 0,
    moving at ``v_free`` before its contact."""
    contacts = PlaneContacts(
        (ContactSphere(joint_id, np.zeros(3), RADIUS_M),),
        np.zeros(3),
        np.array([0.0, 0.0, 1.0]),
        MU,
    )
    mass = np.diag([MASS_KG] * 3 + [0.4 * MASS_KG * RADIUS_M**2] * 3)
    q = pin.neutral(model)
    q[2] = RADIUS_M + 0.002
    return constrained_velocity(model, mass, v_free, q, [contacts], PERIOD_S)


def test_a_falling_sphere_stops_on_the_plane_without_bouncing(ball):
    step = _dropped_on_the_plane(ball, 2, np.r_[1.0, 0.0, -3.0, 0.0, 0.0, 0.0])
    # lands exactly on the plane at the period's end: v_z = -gap / h
    assert step.velocity[2] == pytest.approx(-0.002 / PERIOD_S, rel=1e-6)
    assert step.impulses["contacts"][2] == pytest.approx(MASS_KG * (3.0 - 1.0), rel=1e-6)
    assert step.units["contacts"] == "N s"


def test_a_sphere_on_no_body_of_the_model_is_refused_naming_it(ball):
    """A contact sphere's joint must be a body of the model: not the universe (joint 0), not
    past the last joint."""
    model = ball
    q, speed = pin.neutral(model), np.zeros(model.nv)
    for joint_id in (0, model.njoints):
        sphere = ContactSphere(joint_id, np.zeros(3), RADIUS_M)
        contacts = PlaneContacts((sphere,), np.zeros(3), np.array([0.0, 0.0, 1.0]), MU)
        with pytest.raises(ParameterError, match=f"contact sphere 0: no joint {joint_id}"):
            contacts.rows(model, model.createData(), q, speed, PERIOD_S)


def test_refusals():
    with pytest.raises(ParameterError, match="radius"):
        ContactSphere(2, np.zeros(3), -0.1)
    with pytest.raises(ParameterError, match="normal"):
        PlaneContacts((), np.zeros(3), np.zeros(3), MU)
    with pytest.raises(ParameterError, match="friction"):
        PlaneContacts((), np.zeros(3), np.array([0.0, 0.0, 1.0]), -0.1)


def test_the_alpha5_pressed_on_the_seafloor_in_water():
    """The BlueROV2 + Alpha 5 in water, pushed down (20 N) with its end-effector 2 cm
    above a seafloor (mu = 0.5) and its joints limited: the end-effector lands and stays on
    the floor (1e-6 m), no impulse adds kinetic energy, with the added mass in M."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        uvms = up.load_uvms(shipped_path("models/uvms_bluerov2_alpha5.urdf"))
    model, data = uvms.model, uvms.model.createData()
    ee = model.frames[uvms.ee_frame_id]
    q = uvms.neutral_configuration()
    q[7:] = uvms.arm_joints.configuration(np.array([-0.2, 0.8, 2.2, 0.2]))
    pin.framesForwardKinematics(model, data, q)
    floor_m = data.oMf[uvms.ee_frame_id].translation[2] - 0.02
    floor = PlaneContacts(
        (ContactSphere(ee.parentJoint, ee.placement.translation, 0.0),),
        np.array([0.0, 0.0, floor_m]),
        np.array([0.0, 0.0, 1.0]),
        0.5,
    )
    constraints = [JointLimits.of_uvms(uvms), floor]
    tau = np.zeros(uvms.nv)
    tau[2] = -20.0  # N, down in the vehicle's frame
    v, lowest_m, touching = np.zeros(uvms.nv), np.inf, 0
    for _ in range(300):
        v_free = v + PERIOD_S * up.forward_dynamics(uvms, q, v, tau)
        mass = up.mass_matrix(uvms, q)
        step = constrained_velocity(model, mass, v_free, q, constraints, PERIOD_S)
        assert step.converged
        assert step.velocity @ mass @ step.velocity <= v_free @ mass @ v_free + 1e-12
        touching += bool(step.impulses["contacts"].size and step.impulses["contacts"][2] > 1e-9)
        v = step.velocity
        q = pin.integrate(model, q, PERIOD_S * v)
        pin.framesForwardKinematics(model, data, q)
        lowest_m = min(lowest_m, data.oMf[uvms.ee_frame_id].translation[2] - floor_m)
    assert lowest_m >= -1e-6
    assert touching > 200
    assert np.abs(v).max() < 10.0


def test_a_sphere_on_the_models_first_joint_lands_on_the_plane():
    """Joint 1 is a body like any other (the vehicle's free-flyer in a UVMS): a sphere on
    it gets its rows, and a free-floating ball (one free-flyer joint) falling at 3 m/s
    lands on the plane exactly at the period's end, v_z+ = -gap / h, with the normal
    impulse m (3 - gap / h)."""
    model = pin.Model()
    body = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "vehicle")
    model.appendBodyToJoint(body, pin.Inertia.FromSphere(MASS_KG, RADIUS_M), pin.SE3.Identity())
    step = _dropped_on_the_plane(model, body, np.r_[0.0, 0.0, -3.0, 0.0, 0.0, 0.0])
    assert step.velocity[2] == pytest.approx(-0.002 / PERIOD_S, rel=1e-6)
    assert step.impulses["contacts"][2] == pytest.approx(MASS_KG * (3.0 - 1.0), rel=1e-6)


@pytest.mark.parametrize(
    "normal",
    [(0, 0, 1), (0, 0, -1), (1, 0, 0), (0, 1, 0), (1, 0, 1), (0, 1, 1), (1, 1, 0), (1, 1, 1),
     (-1, 0, 1), (0.95, 0.3, 0.0), (0.3, 0.95, 0.1)],
)  # fmt: skip
def test_the_contact_frame_is_a_rotation_with_the_normal_last(normal):
    """C = (t1, t2, n) for any unit normal n, whichever helper axis it picks: C^T C = I,
    det C = +1 (t1 x t2 = n), and n its third column."""
    n = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    frame = contact_frame(n)
    np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-14)
    assert np.linalg.det(frame) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(frame[:, 2], n, atol=1e-15)
