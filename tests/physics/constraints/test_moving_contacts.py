"""Contacts between moving bodies as rigid constraints (`uvms_pin.physics.constraints.
moving_contacts`): the rows join two bodies, a collision of two free objects conserves the
momentum, a robot's hit never adds energy, and the scenario's key."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, body_urdf, hydro_xml
from free_object_helpers import undamped

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.contacts import contact_frame, point_jacobian
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
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
    assert soft.record()["world"]["moving_contact"] == "compliant"
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
