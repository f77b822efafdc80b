"""Contacts between moving bodies as rigid constraints (`uvms_pin.physics.constraints.
moving_contacts`): the rows join two bodies, a collision of two free objects conserves the
momentum, a robot's hit never adds energy, and the scenario's key."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, G, body_urdf, hydro_xml
from free_object_helpers import undamped

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.contacts import contact_frame, point_jacobian
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

PERIOD_S = 2e-3


def _pusher(load_body, mass=4.0, radius=0.1):
    """A one-body 'UVMS': a neutrally buoyant sphere without added mass or damping."""
    inertia = (0.4 * mass * radius**2,) * 3
    urdf = body_urdf(
        mass=mass, inertia=inertia, hydro=hydro_xml(mass / RHO),
        collision=f'<sphere radius="{radius}"/>',
    )  # fmt: skip
    return load_body(urdf)


def _ball(name, position, velocity=None, radius=0.2, density=RHO, friction=(0.5, 0.4)):
    """A free sphere without drag (its added mass kept): neutral at the water's density."""
    return undamped(
        free_object(
            name, "sphere", {"radius_m": radius}, (np.asarray(position, float), np.zeros(3)),
            density_kg_m3=density, water_density_kg_m3=RHO, friction=friction,
            velocity_body=velocity,
        )
    )  # fmt: skip


def _system(pusher, balls, contact="rigid") -> System:
    world = World(pusher, [], ContactLaw(), balls, moving_contact=contact)
    return System(Plant(pusher, world=world, free_surface=False))


def _run(system: System, q, v, periods: int):
    """The system's (q, v) after each period from the robot's (q, v)."""
    state = system.initial_state(q, v)
    system.start(state)
    q_s, v_s, out = state.q, state.v, [(state.q, state.v)]
    tau = np.zeros(system.plant.uvms.nv)
    for k in range(periods):
        t0 = k * PERIOD_S
        q_s, v_s = system.advance(RK4(5e-4), t0, q_s, v_s, tau, t0 + PERIOD_S)
        out.append((q_s, v_s))
    return out


def _momentum_world(uvms, q, v):
    """The linear momentum (body and entrained water) of a one-body UVMS, world axes."""
    return pin.Quaternion(q[3:7]).matrix() @ (up.mass_matrix(uvms, q) @ v)[:3]


def _bodies(system: System, q, v):
    """(uvms, q, v) of each body of the system."""
    uvms = [system.plant.uvms, *(o.uvms for o in system.objects)]
    return [(u, *s) for u, s in zip(uvms, system.layout.split(q, v), strict=True)]


def test_the_rows_of_a_pair_are_the_relative_velocity_of_its_points(load_body):
    a = _ball("a", [0.0, 0.0, -5.0])
    b = _ball("b", [0.3985, 0.03, -5.0])  # 0.37 mm inside a, off the line
    system = _system(_pusher(load_body), [a, b])
    q = system.plant.uvms.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]
    state = system.initial_state(q, np.zeros(6))
    model, data = system.model, system.model.createData()
    pin.computeJointJacobians(model, data, state.q)
    rows = system.moving_constraints.rows(model, data, state.q, np.zeros(model.nv), PERIOD_S)
    assert rows.size == 3 and rows.labels == ("a|b t1", "a|b t2", "a|b n")
    (solved,) = rows.where
    x, n = solved.point.point_world_m, solved.point.normal_world
    centres = b.q0[:3] - a.q0[:3]
    np.testing.assert_allclose(n, -centres / np.linalg.norm(centres), atol=1e-9)
    assert solved.point.gap_m == pytest.approx(np.linalg.norm(centres) - 0.4, abs=1e-9)
    first = system.plant.uvms.model.njoints  # a's free-flyer, then b's
    relative = point_jacobian(model, data, first, x) - point_jacobian(model, data, first + 1, x)
    np.testing.assert_allclose(rows.jacobian, contact_frame(n).T @ relative, atol=1e-12)


def test_two_free_objects_colliding_conserve_momentum_and_never_gain_energy(load_body):
    """Two neutral balls without drag (no net weight, nothing damps) collide off-centre,
    friction acting: the rigid contact exchanges equal and opposite impulses."""
    a = _ball("a", [0.0, 0.0, -5.0], velocity=[0.6, 0, 0, 0, 0, 0.5])
    b = _ball("b", [0.45, 0.12, -5.0], velocity=[-0.2, 0, 0, 0, 0, 0])
    system = _system(_pusher(load_body), [a, b])
    q = system.plant.uvms.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]  # far away
    states = _run(system, q, np.zeros(6), 150)
    momentum = [
        sum(_momentum_world(u, q_b, v_b) for u, q_b, v_b in _bodies(system, *s)[1:]) for s in states
    ]
    energy = [
        sum(up.kinetic_energy(u, q_b, v_b) for u, q_b, v_b in _bodies(system, *s)[1:])
        for s in states
    ]
    touched = [len(f) for f in system.moving.moving.rigid_pair_forces]
    assert np.max(np.abs(np.array(momentum) - momentum[0])) <= 1e-9 * np.linalg.norm(momentum[0])
    assert np.all(np.diff(energy) <= 1e-9)
    assert energy[-1] < energy[0] - 1e-3  # the impact took some: inelastic, no bounce
    _, (q_a, v_a), (q_b, v_b) = system.layout.split(*states[-1])
    b_world = pin.Quaternion(q_b[3:7]).matrix() @ v_b[:3]
    assert abs(b_world[1]) > 1e-3  # hit off the line: a sideways part
    a_world = pin.Quaternion(q_a[3:7]).matrix() @ v_a[:3]
    assert a_world[0] < 0.5 and not any(touched)  # slowed, and apart again at the end


def test_a_robot_hitting_a_free_ball_never_adds_energy(load_body):
    ball = _ball("ball", [0.0, 0.0, -5.0], friction=(0.8, 0.6))
    system = _system(_pusher(load_body), [ball])
    q = system.plant.uvms.neutral_configuration()
    q[:3] = [-0.35, 0.1, -5.0]  # 5 cm apart, 10 cm off the line of centres
    v = np.array([0.5, 0.0, 0.0, 0.0, 0.0, 2.0])  # spinning: the friction acts at once
    states = _run(system, q, v, 150)
    energy = [
        sum(up.kinetic_energy(u, q_b, v_b) for u, q_b, v_b in _bodies(system, *s)) for s in states
    ]
    assert np.all(np.diff(energy) <= 1e-9)
    ball_speed = np.linalg.norm(system.layout.split(*states[-1])[1][1][:3])
    assert ball_speed > 0.02  # it was hit


def test_the_scenario_key_chooses_the_moving_contacts(load_body):
    ball = _ball("ball", [0.0, 0.0, -5.0])
    pusher = _pusher(load_body)
    assert _system(pusher, [ball]).moving_constraints is not None
    soft = _system(pusher, [ball], "compliant")
    assert soft.moving_constraints is None
    assert soft.log.record()["world"]["moving_contact"] == "compliant"
    with pytest.raises(ParameterError, match="moving_contact must be one of compliant, rigid"):
        World(pusher, [], ContactLaw(), [ball], moving_contact="soft")


@pytest.mark.parametrize("mover", ["a", "b"])
def test_a_pair_closing_at_the_speed_of_either_body_alone_is_solved(load_body, mover):
    """The broad phase reaches both bodies' points over the period: of balls a and b 5 mm
    apart, one at rest and the other coming at 5 m/s (10 mm a 2 ms period), the pair is
    solved, its rows under the set's name (the key of its impulses in the step's result),
    in N s; nothing moving, the same pair (over the 1 mm margin) is not, and a pair at rest
    0.5 mm apart (within the margin) is."""
    coming = [5.0 if mover == "a" else -5.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    a = _ball("a", [0.0, 0.0, -5.0], velocity=coming if mover == "a" else None)
    b = _ball("b", [0.405, 0.0, -5.0], velocity=coming if mover == "b" else None)
    system = _system(_pusher(load_body), [a, b])
    q = system.plant.uvms.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]
    state = system.initial_state(q, np.zeros(6))
    assert np.abs(state.v).max() == pytest.approx(5.0)  # the mover's velocity, nothing else
    model, data = system.model, system.model.createData()
    pin.computeJointJacobians(model, data, state.q)
    constraints = system.moving_constraints
    rows = constraints.rows(model, data, state.q, np.abs(state.v), PERIOD_S)
    assert rows.size == 3 and rows.gap[2] == pytest.approx(0.005, abs=1e-9)
    assert rows.name == constraints.name and rows.unit == "N s"
    still = constraints.rows(model, data, state.q, np.zeros(model.nv), PERIOD_S)
    assert still.size == 0 and still.name == constraints.name
    near = _system(
        _pusher(load_body), [_ball("a", [0.0, 0.0, -5.0]), _ball("b", [0.4005, 0.0, -5.0])]
    )
    state = near.initial_state(q, np.zeros(6))
    model, data = near.model, near.model.createData()
    pin.computeJointJacobians(model, data, state.q)
    rows = near.moving_constraints.rows(model, data, state.q, np.zeros(model.nv), PERIOD_S)
    assert rows.size == 3 and rows.gap[2] == pytest.approx(0.0005, abs=1e-9)


@pytest.mark.parametrize("contact", ["rigid", "compliant"])
@pytest.mark.parametrize("compiled", [False, True], ids=["python", "core"])
def test_a_ball_thrown_along_a_free_slab_slides_at_the_kinetic_friction_then_rolls(
    load_body, compiled, contact
):
    """A ball (density 2000 kg/m^3, no drag) thrown at 1 m/s along a free slab resting on the
    seafloor: the pair slides, so its friction is mu_k N (N = W - B, the net weight) from
    its second period (its first, the pair's memory still stuck, has mu_s): the ball's speed
    falls at mu_k (m - rho V) g / (m + m_a) (m_a = rho V / 2, a sphere's added mass; its
    spin does not add to it) until its contact point stops, then it rolls at
    v0 (m + m_a) / (m + m_a + 2 m / 5) (its linear momentum and its angular momentum about
    the contact point kept from the start). The slab, pushed by mu_k N and held by the
    seafloor's mu_s on both weights, does not move. Rigid pairs: all of it to 1e-6. Compliant
    pairs (the ball set at the depth N / k that carries it): the normal spring's ripple
    leaves the deceleration 6e-4 off, and the stick spring keeps some of the speed when the
    ball starts rolling (0.5 %); with mu_s for mu_k it would fall 25 % faster."""
    radius, law = 0.1, ContactLaw()
    volume = 4.0 / 3.0 * np.pi * radius**3
    m, added = 2000.0 * volume, 0.5 * RHO * volume
    net_N = (m - RHO * volume) * G
    sunk_m = 0.0 if contact == "rigid" else net_N / law.stiffness_N_m
    ball = _ball(
        "ball", [0.0, 0.0, -9.8 + radius - sunk_m], velocity=[1.0, 0, 0, 0, 0, 0],
        radius=radius, density=2000.0, friction=(0.5, 0.4),
    )  # fmt: skip
    slab = undamped(
        free_object(
            "slab", "box", {"size_m": [2.0, 1.0, 0.2]}, (np.array([0.3, 0.0, -9.9]), np.zeros(3)),
            density_kg_m3=2000.0, water_density_kg_m3=RHO, friction=(0.5, 0.4),
        )
    )  # fmt: skip
    pusher = _pusher(load_body)
    floor = plane("seafloor", [0.0, 0.0, -10.0], [0.0, 0.0, 1.0], 0.5, 0.4)
    world = World(pusher, [floor], law, [ball, slab], moving_contact=contact)
    system = System(Plant(pusher, world=world, free_surface=False))
    system.compiled_allowed = compiled
    q = pusher.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]  # far away
    speed, spin, slab_speed = [], [], []
    for state in _run(system, q, np.zeros(6), 100):
        _, (q_a, v_a), (_, v_b) = system.layout.split(*state)
        rotation = pin.Quaternion(q_a[3:7]).matrix()
        speed.append((rotation @ v_a[:3])[0])
        spin.append((rotation @ v_a[3:])[1])
        slab_speed.append(np.abs(v_b).max())
    speed, t = np.array(speed), PERIOD_S * np.arange(len(speed))
    slip = speed - radius * np.array(spin)  # the contact point's speed over the slab
    sliding = slip > 0.05
    assert sliding[:50].all() and not np.abs(slip[-20:]).max() > 0.05  # it slid, then rolled
    late = sliding & (t > 0.01)  # from the fifth period
    deceleration = -np.polyfit(t[late], speed[late], 1)[0]
    rigid = contact == "rigid"
    expected = 0.4 * net_N / (m + added)
    assert deceleration == pytest.approx(expected, rel=1e-6 if rigid else 1e-3)
    rolling = (m + added) / (m + added + 0.4 * m)
    assert speed[-1] == pytest.approx(rolling, rel=1e-6 if rigid else 1e-2)
    if rigid:
        np.testing.assert_allclose(slip[-20:], 0.0, atol=1e-8)
    assert max(slab_speed) < 1e-6


@pytest.mark.parametrize("radius_m", [0.05, 0.5, 2.0])
def test_a_pieces_reach_speed_bounds_every_point_of_its_bounding_sphere(reference_uvms, radius_m):
    """The speed bound that chooses which pairs may close in a period: when each velocity
    coordinate moves at most |v_i|, no point within the piece's bounding sphere (of any
    radius, 5 cm to 2 m) moves faster than it (points on the sphere, random states)."""
    import dataclasses

    from uvms_pin.physics.constraints.moving_contacts import _reach_speed
    from uvms_pin.physics.world.robot_geometry import robot_pieces

    model = reference_uvms.model
    data = model.createData()
    rng = np.random.default_rng(4)
    names = [f"hull{k}" for k in range(len(reference_uvms.surface_bodies.hulls))]
    pieces = [
        dataclasses.replace(p, bound_radius_m=radius_m) for p in robot_pieces(reference_uvms, names)
    ]
    for _ in range(5):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        q[3:7] /= np.linalg.norm(q[3:7])
        v = rng.normal(size=model.nv)
        pin.forwardKinematics(model, data, q, v)
        pin.computeJointJacobians(model, data, q)
        for piece in pieces:
            bound = _reach_speed(model, data, piece, np.abs(v))
            centre = data.oMi[piece.joint_id] * piece.placement_in_joint
            twist = pin.getVelocity(model, data, piece.joint_id, pin.LOCAL_WORLD_ALIGNED)
            directions = rng.normal(size=(50, 3))
            directions /= np.linalg.norm(directions, axis=1, keepdims=True)
            points = centre.translation + radius_m * directions
            # v(p) = v(o_j) + w x (p - o_j), o_j the joint's origin, LOCAL_WORLD_ALIGNED
            arms = points - data.oMi[piece.joint_id].translation
            speeds = np.linalg.norm(twist.linear + np.cross(twist.angular, arms), axis=1)
            assert speeds.max() <= bound * (1 + 1e-12)
