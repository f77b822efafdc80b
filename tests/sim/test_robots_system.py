"""Several robots in one sea (uvms_pin.sim.system.robots): the robots' momentum is kept by
their contacts, each robot alone steps as it would alone, the joined model stacks the
robots' coordinates."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, ROOT, body_urdf, hydro_xml
from free_object_helpers import undamped

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.robot_reach import reach_sphere
from uvms_pin.physics.world.world import World
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System, SystemState
from uvms_pin.sim.system.robots import Robots, joined_model


def _sphere(load_body, mass=4.0, radius=0.1):
    """A one-body robot: a neutrally buoyant sphere without added mass or damping (its
    weight and buoyancy cancel at its centre: no gravity and no water in effect)."""
    inertia = (0.4 * mass * radius**2,) * 3
    collision = f'<sphere radius="{radius}"/>'
    urdf = body_urdf(mass=mass, inertia=inertia, hydro=hydro_xml(mass / RHO), collision=collision)
    return load_body(urdf)


def _momentum_world(uvms, q, v):
    return pin.Quaternion(q[3:7]).matrix() @ (up.mass_matrix(uvms, q) @ v)[:3]


def _two_spheres(load_body):
    a, b = _sphere(load_body), _sphere(load_body, mass=6.0, radius=0.15)
    plants = [Plant(u, free_surface=False) for u in (a, b)]
    return Robots([System(p) for p in plants], ["a", "b"])


def test_two_robots_pushing_each_other_keep_their_total_momentum(load_body):
    """Robot a (4 kg) runs at 0.5 m/s into robot b (6 kg) 5 cm off the line of centres:
    they touch (friction too) and part; the total linear momentum stays to 1e-6."""
    robots = _two_spheres(load_body)
    a, b = (s.plant.uvms for s in robots.systems)
    q_a, q_b = a.neutral_configuration(), b.neutral_configuration()
    q_a[:3], q_b[:3] = [-0.5, 0.05, -5.0], [0.0, 0.0, -5.0]
    v_a = np.zeros(6)
    v_a[0] = 0.5
    state = robots.layout.join([(q_a, v_a), (q_b, np.zeros(6))])
    robots.start(state)
    q, v = state
    integrator, period, zero = RK4(step_s=5e-4), 1e-2, [np.zeros(6), np.zeros(6)]
    momentum, together = [], 0
    for k in range(150):
        together += robots.near(q, v, period)
        q, v = robots.advance(integrator, k * period, (q, v), zero, (k + 1) * period)
        (qa, va), (qb, vb) = robots.split(q, v)
        momentum.append(_momentum_world(a, qa, va) + _momentum_world(b, qb, vb))
    momentum = np.array(momentum)
    p0 = 4.0 * 0.5
    assert together > 0  # they met
    assert np.max(np.abs(momentum - np.array([p0, 0.0, 0.0]))) <= 1e-6 * p0
    (qa, va), (qb, vb) = robots.split(q, v)
    assert vb[0] > 0.1 and abs(vb[1]) > 1e-3  # b was pushed, and sideways (off-centre)
    assert np.linalg.norm(qb[:3] - qa[:3]) > 0.25  # apart again


def test_each_robot_logs_the_force_on_itself_equal_and_opposite(load_body):
    robots = _two_spheres(load_body)
    q_a, q_b = (s.plant.uvms.neutral_configuration() for s in robots.systems)
    q_a[:3], q_b[:3] = [-0.24, 0.0, -5.0], [0.0, 0.0, -5.0]  # 1 cm deep
    state = robots.layout.join([(q_a, np.zeros(6)), (q_b, np.zeros(6))])
    robots.start(state)
    on_a, on_b = (s["robot_contact"] for s in robots.contact_signals(*state))
    assert robots.contact_pair_names(0) == robots.contact_pair_names(1) == ["a/body|b/body"]
    assert on_a[0] < -1.0 and np.allclose(on_a[1:3], 0.0)  # b pushes a towards -x
    assert np.array_equal(on_b[:3], -on_a[:3]) and np.array_equal(on_b[3:], on_a[3:])
    assert on_a[3:6] == pytest.approx([-0.145, 0.0, -5.0], abs=0.01)  # between the two


def test_the_core_finds_the_robots_contacts_as_the_reference_does(load_body):
    """With the compiled backend every pair set of several robots (between robots, and the
    first robot's with its free objects) is searched by the core (`search_compiled`): at a
    touching state with friction anchors it finds the reference's pairs, points and
    forces (the same arithmetic: to 1e-12); the "python" backend keeps the reference's."""
    a, b = _sphere(load_body), _sphere(load_body, mass=6.0, radius=0.15)
    ball = free_object(
        "ball", "sphere", {"radius_m": 0.05}, ([-0.14, 0.0, -4.86], [0.0, 0.0, 0.0]),
        density_kg_m3=2000.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    first = System(Plant(a, world=World(a, [], ContactLaw(), [ball]), free_surface=False))
    robots = Robots([first, System(Plant(b, free_surface=False))], ["a", "b"])
    sets = [*robots.contacts.sets, *robots.systems[0].moving.moving.sets]
    assert sets and all(s.search is not None for s in sets)
    q_a, q_b = a.neutral_configuration(), b.neutral_configuration()
    q_a[:3], q_b[:3] = [-0.24, 0.0, -5.0], [0.0, 0.003, -5.0]  # 1 cm deep, off-centre
    v_a = np.array([0.2, 0.05, 0.0, 0.0, 0.0, 0.3])
    state = robots.layout.join([first.initial_state(q_a, v_a), (q_b, np.zeros(6))])
    for system, part in zip(robots.systems, robots.split(*state), strict=True):
        system.start(SystemState(*part))
    robots.start(state)  # anchors set: the next search has friction stretch
    q, v = robots.advance(RK4(step_s=5e-4), 0.0, state, [np.zeros(6)] * 2, 2e-3)
    datas = robots._kinematics(q, v)
    found = robots.contacts.found(datas)
    reference = [s.pairs.forces(datas[s.a], datas[s.b], s.memory) for s in robots.contacts.sets]
    assert sum(len(c.pair) for c in found) > 0
    for core, ref in zip(found, reference, strict=True):
        assert np.array_equal(core.pair, ref.pair)
        np.testing.assert_allclose(core.force_world_N, ref.force_world_N, rtol=0, atol=1e-12)
        np.testing.assert_allclose(
            core.touch.point_world_m, ref.touch.point_world_m, rtol=0, atol=1e-12
        )
    python = Robots(
        [System(Plant(u, free_surface=False, backend="python")) for u in (a, b)], ["a", "b"]
    )
    assert all(s.search is None for s in python.contacts.sets)


def _touching_with_a_ball(load_body, backend: str = "core"):
    """Robots a (4 kg sphere, holding a ball in its world) and b (6 kg) 1 cm into each
    other, b against the ball, a moving: (robots, state, a, b)."""
    a, b = _sphere(load_body), _sphere(load_body, mass=6.0, radius=0.15)
    ball = free_object(
        "ball", "sphere", {"radius_m": 0.05}, ([-0.14, 0.0, -4.86], [0.0, 0.0, 0.0]),
        density_kg_m3=2000.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    plant = Plant(a, world=World(a, [], ContactLaw(), [ball]), free_surface=False, backend=backend)
    first = System(plant)
    robots = Robots([first, System(Plant(b, free_surface=False, backend=backend))], ["a", "b"])
    q_a, q_b = a.neutral_configuration(), b.neutral_configuration()
    q_a[:3], q_b[:3] = [-0.24, 0.0, -5.0], [0.0, 0.003, -5.0]
    v_a = np.array([0.2, 0.05, 0.0, 0.0, 0.0, 0.3])
    state = robots.layout.join([first.initial_state(q_a, v_a), (q_b, np.zeros(6))])
    for system, part in zip(robots.systems, robots.split(*state), strict=True):
        system.start(SystemState(*part))
    robots.start(state)
    return robots, state


def test_the_core_integrates_the_robots_together_as_the_reference(load_body):
    """While they touch, one core call integrates the period (`RobotsSystem`): its
    acceleration at a touching state with anchors is the reference's (the contacts between
    robots and with the objects as point forces, the reference's J^T f in the input) and a
    period of it ends where the Python integrator does, to rounding."""
    robots, state = _touching_with_a_ball(load_body)
    core, _ = robots.compiled
    robots.advance(RK4(step_s=5e-4), 0.0, state, [np.zeros(6)] * 2, 2e-3)  # anchors stretched
    q, v = robots.advance(RK4(step_s=5e-4), 2e-3, state, [np.zeros(6)] * 2, 4e-3)
    taus = [np.linspace(-1.0, 1.0, 6), np.linspace(2.0, -0.5, 6)]
    memories = [s.memory for s in robots.contacts.sets]
    assert sum(len(c.pair) for c in robots.contacts.found(robots._kinematics(q, v))) > 0
    reference = robots.acceleration(0.0, q, v, taus)
    compiled = core.acceleration(0.0, q, v, taus, robots._memories(), memories)
    np.testing.assert_allclose(compiled, reference, rtol=0.0, atol=1e-9 * np.abs(reference).max())
    python = RK4(step_s=5e-4).advance(
        robots.model, lambda t, q_, v_: robots.acceleration(t, q_, v_, taus), 0.0, q, v, 2e-3
    )
    ends = robots._integrate(RK4(step_s=5e-4), 0.0, q, v, taus, 2e-3)
    np.testing.assert_allclose(ends[0], python[0], rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(ends[1], python[1], rtol=0.0, atol=1e-9)
    assert robots.integration(RK4(step_s=5e-4)) is None


def test_the_python_backend_integrates_the_robots_in_python(load_body):
    """On the Python backend the robots' periods together are the reference's integration:
    from a touching state, a period ends where the compiled one does."""
    robots, state = _touching_with_a_ball(load_body, backend="python")
    assert robots.integration(RK4(step_s=5e-4)) == "the Python backend"
    compiled_robots, compiled_state = _touching_with_a_ball(load_body)
    assert robots.near(*state, 2e-3)  # together
    taus = [np.zeros(6)] * 2
    q, v = robots.advance(RK4(step_s=5e-4), 0.0, state, taus, 2e-3)
    q_c, v_c = compiled_robots.advance(RK4(step_s=5e-4), 0.0, compiled_state, taus, 2e-3)
    assert np.abs(v - state.v).max() > 1e-3  # the contacts pushed
    np.testing.assert_allclose(q, q_c, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(v, v_c, rtol=0.0, atol=1e-9)


def test_the_second_robot_meets_each_free_object_as_itself(load_body):
    """Two free balls in the first robot's world: the second robot has a pair with each
    ball, each pair's second side that ball (not another side), and resting against the
    second ball (1 cm deep) it is pushed by it alone, along the line from the ball."""
    balls = [
        undamped(
            free_object(
                name, "sphere", {"radius_m": 0.2}, (position, [0, 0, 0]),
                density_kg_m3=RHO, water_density_kg_m3=RHO,
            )
        )
        for name, position in (("ball", [0.0, 3.0, -5.0]), ("ball2", [0.0, 0.0, -5.0]))
    ]  # fmt: skip
    a, b = _sphere(load_body), _sphere(load_body, mass=6.0, radius=0.15)
    law = ContactLaw(stiffness_N_m=2e4, dissipation_s_m=2.0)
    first = System(Plant(a, world=World(a, [], law, balls), free_surface=False))
    second = System(Plant(b, world=World(b, [], law), free_surface=False))
    robots = Robots([first, second], ["a", "b"])
    assert robots.contact_pair_names(1) == ["a/body|b/body", "b/body|ball", "b/body|ball2"]
    q_a, q_b = a.neutral_configuration(), b.neutral_configuration()
    q_a[:3], q_b[:3] = [5.0, 0.0, -5.0], [0.34, 0.0, -5.0]  # b 1 cm into ball2
    state = robots.layout.join([first.initial_state(q_a, np.zeros(6)), (q_b, np.zeros(6))])
    for system, part in zip(robots.systems, robots.split(*state), strict=True):
        system.start(SystemState(*part))
    robots.start(state)
    q, v = robots.advance(RK4(5e-4), 0.0, tuple(state), [np.zeros(6)] * 2, 0.01)
    (_, v_b), (_, v_ball), (_, v_ball2) = robots.sides(q, v)[1:]
    assert v_b[0] > 1e-3 and abs(v_b[1]) < 1e-9 * v_b[0]  # pushed off ball2, along x
    assert v_ball2[0] < 0.0 and np.all(v_ball == 0.0)  # ball2 pushed back, ball untouched


def test_a_robot_pushes_a_free_object_into_another_robot_and_momentum_stays(load_body):
    """Robot b runs into a free ball that the first robot's system holds; the ball runs on
    into robot a: b's pairs with the ball are the robots' own, a's its system's; the total
    linear momentum of the three (their added mass included) stays to 1e-6."""
    ball = undamped(
        free_object(
            "ball", "sphere", {"radius_m": 0.2}, ([0.0, 0.0, -5.0], [0, 0, 0]),
            density_kg_m3=RHO, water_density_kg_m3=RHO,
        )
    )  # fmt: skip
    a, b = _sphere(load_body), _sphere(load_body, mass=6.0, radius=0.15)
    law = ContactLaw(stiffness_N_m=2e4, dissipation_s_m=2.0)
    first = System(Plant(a, world=World(a, [], law, [ball]), free_surface=False))
    second = System(Plant(b, world=World(b, [], law), free_surface=False))
    robots = Robots([first, second], ["a", "b"])
    assert robots.contact_pair_names(1) == ["a/body|b/body", "b/body|ball"]
    q_a, q_b = a.neutral_configuration(), b.neutral_configuration()
    q_a[:3], q_b[:3] = [0.45, 0.02, -5.0], [-0.6, 0.0, -5.0]
    v_b = np.zeros(6)
    v_b[0] = 0.8
    state = robots.layout.join([first.initial_state(q_a, np.zeros(6)), (q_b, v_b)])
    for system, part in zip(robots.systems, robots.split(*state), strict=True):
        system.start(SystemState(*part))
    robots.start(state)
    q, v = state
    integrator, period, zero = RK4(step_s=5e-4), 1e-2, [np.zeros(6), np.zeros(6)]
    momentum = []
    for k in range(200):
        q, v = robots.advance(integrator, k * period, (q, v), zero, (k + 1) * period)
        (qa, va), (qb, vb), (qo, vo) = robots.sides(q, v)
        momentum.append(
            _momentum_world(a, qa, va)
            + _momentum_world(b, qb, vb)
            + _momentum_world(ball.uvms, qo, vo)
        )
    momentum = np.array(momentum)
    p0 = 6.0 * 0.8
    assert np.max(np.abs(momentum - np.array([p0, 0.0, 0.0]))) <= 1e-6 * p0
    (qa, va), (qb, vb), (qo, vo) = robots.sides(q, v)
    assert va[0] > 0.05  # the ball reached a
    assert qo[0] > 0.01  # and moved on from where b hit it


def test_robots_apart_step_each_as_alone(load_body):
    """No robot within reach of another: each robot's period is its own system's, bit for
    bit."""
    robots = _two_spheres(load_body)
    alone = [System(Plant(s.plant.uvms, free_surface=False)) for s in robots.systems]
    starts = []
    for k, system in enumerate(robots.systems):
        q = system.plant.uvms.neutral_configuration()
        q[:3] = [3.0 * k, 0.0, -5.0]
        starts.append((q, np.full(6, 0.1)))
    taus = [np.array([1.0, 0, 0, 0, 0, 0.2]), np.array([0, -2.0, 0, 0.1, 0, 0])]
    state = robots.layout.join(starts)
    robots.start(state)
    integrator = RK4(step_s=2.5e-3)
    q, v = robots.advance(integrator, 0.0, state, taus, 0.01)
    for system, (q0, v0), tau, (q1, v1) in zip(
        alone, starts, taus, robots.split(q, v), strict=True
    ):
        q_alone, v_alone = system.advance(integrator, 0.0, q0, v0, tau, 0.01)
        assert np.array_equal(q1, q_alone) and np.array_equal(v1, v_alone)


def test_the_joined_model_stacks_the_robots_coordinates(load_body):
    robots = _two_spheres(load_body)
    model = robots.model
    assert (model.nq, model.nv) == (14, 12)
    assert [model.names[j] for j in range(1, model.njoints)] == ["a/root_joint", "b/root_joint"]
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    dv = np.arange(12) * 0.01
    stacked = np.concatenate(
        [pin.integrate(s.plant.uvms.model, q[a], dv[b]) for s, a, b in zip(
            robots.systems, robots.layout.q_slices, robots.layout.v_slices, strict=True)]
    )  # fmt: skip
    assert np.allclose(pin.integrate(model, q, dv), stacked, atol=1e-15)
    assert joined_model([], []).nq == 0


def test_each_robots_tree_hangs_from_the_universe_in_the_joined_model(reference_uvms):
    """Two UVMS of several links joined: each robot's root joint under the universe, its
    other joints under their own parents, shifted past the joints before it."""
    model = reference_uvms.model
    joined = joined_model([model, model], ["a", "b"])
    shift = model.njoints - 1
    own = list(model.parents)[1:]
    assert own.count(0) == 1 and len(own) > 2  # one root joint, and an arm below it
    second = [0 if parent == 0 else parent + shift for parent in own]
    assert list(joined.parents) == [0, *own, *second]


def test_robots_need_distinct_names(load_body):
    system = System(Plant(_sphere(load_body), free_surface=False))
    with pytest.raises(ParameterError, match="one distinct name per robot"):
        Robots([system, system], ["a", "a"])


def test_robots_near_but_not_touching_step_together_as_each_alone():
    """Two BlueROV2 Heavy + Alpha 5 0.7 m apart: within each other's reach sphere (the
    period is integrated for both at once, in Python around the compiled dynamics), nothing
    touches: each robot ends where its own compiled period step takes it, to 1e-9."""
    scenario = load_scenario(
        ROOT / "scenarios" / "two_robots.toml",
        {"robots[1].initial.position_world_m": [0.0, -0.8, -2.0]},
    )
    plants = [r.plant for r in scenario.robots]
    robots = Robots([System(p) for p in plants], scenario.names)
    alone = [System(p) for p in plants]
    starts = [(r.q0, np.full(r.uvms.nv, 0.05)) for r in scenario.robots]
    state = robots.layout.join(starts)
    for system, part in zip(robots.systems, robots.split(*state), strict=True):
        system.start(SystemState(*part))
    robots.start(state)
    assert robots.near(*state, 0.01)
    taus = [np.r_[1.0, 0.0, 2.0, 0.0, 0.0, 0.1, 0.05, 0.0, 0.0, 0.0] for _ in starts]
    integrator = scenario.settings.integrator
    q, v = robots.advance(integrator, 0.0, state, taus, 0.01)
    assert not np.any(robots.contact_signals(q, v)[0]["robot_contact"])
    for system, (q0, v0), tau, (q1, v1) in zip(
        alone, starts, taus, robots.split(q, v), strict=True
    ):
        q_alone, v_alone = system.advance(integrator, 0.0, q0, v0, tau, 0.01)
        assert np.max(np.abs(q1 - q_alone)) < 1e-9 and np.max(np.abs(v1 - v_alone)) < 1e-9
        assert np.max(np.abs(v1 - v0)) > 1e-3  # it moved


def test_the_core_robots_refuse_bad_inputs_by_name(load_body):
    robots, state = _touching_with_a_ball(load_body)
    core, _ = robots.compiled
    memories = [s.memory for s in robots.contacts.sets]
    q, v = state
    good = [np.zeros(6), np.zeros(6)]
    for taus, match in (
        ([np.zeros(6)], "one input tau per robot"),
        ([np.zeros(6), np.zeros(5)], "robot 1's tau"),
        ([np.zeros(6), np.full(6, np.nan)], "robot 1's tau"),
    ):
        with pytest.raises(ParameterError, match=match):
            core.acceleration(0.0, q, v, taus, robots._memories(), memories)
    with pytest.raises(ParameterError, match=r"q \(21,\) and v \(18,\) expected"):
        step = integrator_to_core(RK4(5e-4), core_module())
        core.integrate(0.0, q[:-1], v, good, 2e-3, step, robots._memories(), memories)
    with pytest.raises(ParameterError, match="one list of memories per robot"):
        core.acceleration(0.0, q, v, good, robots._memories()[:1], memories)


def _memories_equal(a, b, atol: float) -> bool:
    """Two friction memories hold the same anchors, material points and slipping patches."""
    if a.anchors.keys() != b.anchors.keys() or a.material.keys() != b.material.keys():
        return False
    same = [np.allclose(a.anchors[k], b.anchors[k], rtol=0, atol=atol) for k in a.anchors]
    same += [np.allclose(a.material[k], b.material[k], rtol=0, atol=atol) for k in a.material]
    return all(same) and a.slipping == b.slipping


def test_the_core_crosses_the_robots_period_as_the_reference(load_body):
    """While they touch, one core call crosses the whole period (`RobotsSystem.advance`):
    the integration, every anchor moved at its end, each system's constraints. Over ten
    periods of contact (b against a and the ball) it stays with the reference
    (`Robots.together_reference`: the same integration, the anchors moved in Python), and
    the anchors it moves are the reference's."""
    core_run, state = _touching_with_a_ball(load_body)
    reference, _ = _touching_with_a_ball(load_body)
    integrator = RK4(step_s=5e-4)
    taus = [np.linspace(-1.0, 1.0, 6), np.linspace(2.0, -0.5, 6)]
    ends, ref = state, state
    for k in range(10):
        t0, t1 = 2e-3 * k, 2e-3 * (k + 1)
        ends = core_run._together(integrator, t0, *ends, taus, t1)
        ref = reference.together_reference(integrator, t0, *ref, taus, t1)
        np.testing.assert_allclose(ends.q, ref.q, rtol=0.0, atol=1e-12)
        np.testing.assert_allclose(ends.v, ref.v, rtol=0.0, atol=1e-9)
    assert np.max(np.abs(ends.v - state.v)) > 1e-2  # the contacts pushed
    memories, expected = (
        [m for m in (*r._memories()[0], *r._memories()[1], *(s.memory for s in r.contacts.sets))
         if m is not None]
        for r in (core_run, reference)
    )  # fmt: skip
    assert sum(len(m.anchors) for m in memories) > 0
    assert all(_memories_equal(a, b, 1e-12) for a, b in zip(memories, expected, strict=True))


def test_the_core_bound_test_and_held_wrenches_are_the_references(load_body):
    """The core's bound test (`RobotsSystem.near`) answers as the reference's
    (`RobotContacts.near`) from touching to apart, at every horizon; each robot's wrench on
    the ball (`RobotsSystem.object_wrenches`) is the reference's, to rounding."""
    robots, state = _touching_with_a_ball(load_body)
    ball = robots.layout.q_slices[0].start + 7  # after robot a in the first system
    state.q[ball : ball + 3] = [-0.145, 0.0, -4.89]  # on a (5 mm deep) and b (18 mm)
    answers = []
    for shift in np.linspace(0.0, 1.5, 16):
        q = state.q.copy()
        q[robots.layout.q_slices[1].start] += shift  # b moves away along x
        for horizon_s in (0.0, 0.01, 0.5):
            reference = robots.contacts.near(
                robots.sides(q, state.v), lambda q=q: robots._kinematics(q, state.v), horizon_s
            )
            assert robots.near(q, state.v, horizon_s) == reference
            answers.append(reference)
        wrenches = robots.object_wrenches(q, state.v)
        expected = robots.object_wrenches_reference(q, state.v)
        np.testing.assert_allclose(wrenches, expected, rtol=0.0, atol=1e-12)
    assert any(answers) and not all(answers)
    on_ball = robots.object_wrenches(*state)
    assert np.linalg.norm(on_ball[0][:3]) > 0.1 and np.linalg.norm(on_ball[1][:3]) > 0.1


def test_the_core_solves_each_robots_joint_limits_as_the_reference():
    """Two BlueROV2 Heavy + Alpha 5 within reach of each other (one core call a period),
    each arm's second joint driven into its lower limit: the core solves each robot's
    limits at the period's end (`System::constrain`) as the reference does
    (`period.constrained`, Pinocchio's ADMM to 1e-8), neither crossing it."""
    scenario = load_scenario(
        ROOT / "scenarios" / "two_robots.toml",
        {"robots[1].initial.position_world_m": [0.0, -0.8, -2.0]},
    )
    plants = [r.plant for r in scenario.robots]
    runs = [Robots([System(p) for p in plants], scenario.names) for _ in range(2)]
    starts = []
    for r in scenario.robots:
        q, v = r.q0.copy(), np.zeros(r.uvms.nv)
        q[8], v[7] = 0.002, -0.5  # 2 mm from its lower limit (0), closing at 0.5 rad/s
        starts.append((q, v))
    taus = [np.r_[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0] for _ in starts]
    ends = []
    for robots, cross in zip(runs, ("_together", "together_reference"), strict=True):
        state = robots.layout.join(starts)
        for system, part in zip(robots.systems, robots.split(*state), strict=True):
            system.start(SystemState(*part))
        robots.start(state)
        assert robots.near(*state, 0.01)
        ends.append(getattr(robots, cross)(scenario.settings.integrator, 0.0, *state, taus, 0.01))
    (q, v), (q_ref, v_ref) = ends
    # the core's active set solves the limits exactly (q at 0), the ADMM to its tolerance
    np.testing.assert_allclose(q, q_ref, rtol=0.0, atol=1e-8)
    np.testing.assert_allclose(v, v_ref, rtol=0.0, atol=1e-6)
    for at, part in zip(runs[0].layout.q_slices, runs[0].layout.v_slices, strict=True):
        assert q[at][8] == pytest.approx(0.0, abs=1e-9)  # it ends at the limit, not past
        assert v[part][7] == pytest.approx(-0.002 / 0.01, abs=1e-6)  # what closes the gap


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled-systems", "python-loop"])
def test_a_first_robots_object_resting_on_the_seabed_logs_its_weight_while_robots_touch(
    load_body, compiled
):
    """Robot a's world holds a seabed (rigid contacts with the fixed world, the default)
    and a ball resting on it; robots a and b touch, so each period is one core call for
    both (`RobotsSystem`). What a's run logs of the ball on the seabed is the core's rigid
    contact of the period: the ball's weight in water, (rho_s - rho) V g, upwards. Systems
    built compiled log it from their core system; those of a run (the Python loop,
    ``compiled=False``) by the reference's path, from the core system that solved it."""
    a, b = _sphere(load_body), _sphere(load_body, mass=6.0, radius=0.15)
    radius, density = 0.05, 2000.0
    seabed = plane("seabed", [0.0, 0.0, -6.0], [0.0, 0.0, 1.0], 0.6, 0.5)
    ball = free_object(
        "ball", "sphere", {"radius_m": radius}, ([1.0, 0.0, -6.0 + radius], [0.0, 0.0, 0.0]),
        density_kg_m3=density, water_density_kg_m3=RHO,
    )  # fmt: skip
    world = World(a, [seabed], ContactLaw(), [ball])
    assert world.fixed_contact == "rigid"
    first = System(Plant(a, world=world, free_surface=False), compiled=compiled)
    second = System(Plant(b, free_surface=False), compiled=compiled)
    robots = Robots([first, second], ["a", "b"])
    q_a, q_b = a.neutral_configuration(), b.neutral_configuration()
    q_a[:3], q_b[:3] = [-0.24, 0.0, -5.0], [0.0, 0.003, -5.0]  # 1 cm into each other
    state = robots.layout.join([first.initial_state(q_a, np.zeros(6)), (q_b, np.zeros(6))])
    for system, part in zip(robots.systems, robots.split(*state), strict=True):
        system.start(SystemState(*part))
    robots.start(state)
    integrator, taus = RK4(step_s=5e-4), [np.zeros(6)] * 2
    q, v = state
    for k in range(5):
        assert robots.near(q, v, 2e-3)  # the robots' period, together
        q, v = robots.advance(integrator, 2e-3 * k, SystemState(q, v), taus, 2e-3 * (k + 1))
    q_first, v_first = robots.split(q, v)[0]
    logged = first.log.signals(q_first, v_first)["free_object_contact"].reshape(-1, 9)
    names = first.moving.moving.object_pair_names
    on_seabed = logged[[k for k, n in enumerate(names) if "seabed" in n]].sum(axis=0)
    weight_N = (density - RHO) * 4.0 / 3.0 * np.pi * radius**3 * 9.81
    # 5.00733 N logged against 5.00809 N: the period's mean force, 10 ms after the start
    np.testing.assert_allclose(on_seabed[:3], [0.0, 0.0, weight_N], rtol=1e-3, atol=1e-6)


def test_the_core_bound_spheres_are_the_references_at_any_reach_and_speed():
    """The first test of the core's bound (`RobotsSystem.root_spheres`, what `near` reads)
    gives each side, the two arms' robots then the carried pipe, the sphere of the reference
    (`robot_reach.reach_sphere`: radius R + 2 s h + clearance, s = |v| + |w| R + 2 R
    sum |qd|) at random states, reaches from 0.2 to 3 m and horizons up to 0.5 s, to
    rounding: the arm joints' rates weigh with the reach on both sides of 1 m."""
    scenario = load_scenario(ROOT / "scenarios" / "cooperative_transport.toml")
    plants = [r.plant for r in scenario.robots]
    plants[1:] = [Plant(p.uvms, world=None, free_surface=False) for p in plants[1:]]
    robots = Robots([System(p) for p in plants], scenario.names)
    core, _ = robots.compiled
    rng = np.random.default_rng(5)
    n_sides = len(robots.contacts.sides)
    assert n_sides == 3  # two robots, one free object
    starts = [
        system.initial_state(r.q0, np.zeros(r.uvms.nv))
        for system, r in zip(robots.systems, scenario.robots, strict=True)
    ]
    for _ in range(40):
        q = robots.layout.join(starts)[0]
        for at in robots.layout.q_slices:  # each system's robot somewhere else
            q[at.start : at.start + 3] += rng.uniform(-2.0, 2.0, size=3)
        v = rng.normal(scale=2.0, size=robots.layout.nv)
        reaches = rng.uniform(0.2, 3.0, size=n_sides)
        horizon_s = float(rng.choice([0.0, 0.002, 0.05, 0.5]))
        core.reach_m = list(reaches)
        centers, radii = core.root_spheres(q, v, horizon_s)
        for k, ((q_k, v_k), reach) in enumerate(zip(robots.sides(q, v), reaches, strict=True)):
            center, radius = reach_sphere(q_k, v_k, reach, horizon_s)
            np.testing.assert_allclose(centers[k], center, rtol=0.0, atol=1e-12)
            assert radii[k] == pytest.approx(radius, rel=1e-12)
    core.reach_m = [np.inf] * n_sides
    assert np.all(np.isinf(core.root_spheres(q, v, 0.01)[1]))
