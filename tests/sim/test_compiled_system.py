"""The compiled system of bodies (src/uvms_core/system.hpp, built in
uvms_pin/sim/compiled/system.py) against the Python reference (uvms_pin/sim/system/ and
uvms_pin/physics/world/moving.py, pairs.py): the moving contacts' forces, the friction
memories they leave, the right-hand side, the period step and a push_object rollout; and a
system the core cannot do still runs in Python, its reason recorded."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, body_urdf, hydro_xml
from free_object_helpers import undamped

import uvms_pin as up
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.moving import contacts_of_core
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.world import World
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.integrators import RK4, Adaptive
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System
from uvms_pin.sim.system.period import integrated_step

ROOT = Path(__file__).resolve().parents[2]
FLOOR_Z = -10.0
TOL = 1e-12


def _scene(load_body, backend: str = "core", compiled: bool = True) -> tuple[System, np.ndarray]:
    """A sphere 'UVMS' pressing on a box that rests on the floor, a ball against the box's
    other side (on the floor too): robot-object, object-object and object-floor contacts,
    every body moving. (The system, its state at t = 0 after `start`.)"""
    volume = 4.0 / RHO
    urdf = body_urdf(
        mass=4.0, inertia=(0.016,) * 3, hydro=hydro_xml(volume, added=(2.0,) * 6, lin=(1.0,) * 6),
        collision='<sphere radius="0.1"/>',
    )  # fmt: skip
    pusher = load_body(urdf)
    box = free_object(
        "box", "box", {"size_m": [0.6, 0.4, 0.3]}, ([0.0, 0.0, FLOOR_Z + 0.149], [0, 0, 0.1]),
        density_kg_m3=2.0 * RHO, water_density_kg_m3=RHO,
    )  # fmt: skip
    ball = free_object(
        "ball", "sphere", {"radius_m": 0.2}, ([0.49, 0.03, FLOOR_Z + 0.199], [0.2, 0, 0]),
        density_kg_m3=1.5 * RHO, water_density_kg_m3=RHO, velocity_body=[-0.1, 0, 0, 0, 0.3, 0],
    )  # fmt: skip
    floor = plane("seafloor", [0, 0, FLOOR_Z], [0, 0, 1], 0.6, 0.5)
    law = ContactLaw(stiffness_N_m=3e4, dissipation_s_m=1.0)
    world = World(pusher, [floor], law, [box, ball], fixed_contact="compliant")
    system = System(
        Plant(pusher, world=world, free_surface=False, backend=backend), compiled=compiled
    )
    q = pusher.neutral_configuration()
    q[:3] = [-0.39, 0.02, FLOOR_Z + 0.16]
    v = np.array([0.2, 0.05, -0.02, 0.1, -0.2, 0.3])
    state = system.initial_state(q, v)
    system.start(state)
    return system, state


def _advance(system, state, n, period_s=2e-3, tau=None):
    q, v = state.q, state.v
    tau = np.array([5.0, 0, 0, 0, 0, 0]) if tau is None else tau
    for k in range(n):
        q, v = system.advance(RK4(5e-4), k * period_s, q, v, tau, (k + 1) * period_s)
    return q, v


def _memories(system) -> list:
    return copy.deepcopy(system.friction_memories())


def _assert_contacts_equal(python, core):
    assert len(python) == len(core)
    fields = ("force_world_N", "normal_N", "stretch_m", "material_m")
    touch_fields = ("point_world_m", "normal_world", "depth_m", "velocity_world_m_s")
    for a, b in zip(python, core, strict=True):
        if a is None:
            assert b is None
            continue
        for name in ("piece", "obj", "corner"):
            np.testing.assert_array_equal(getattr(a.touch, name), getattr(b.touch, name))
        for name in touch_fields:
            x, y = getattr(a.touch, name), getattr(b.touch, name)
            np.testing.assert_allclose(
                y, x, rtol=TOL, atol=TOL * max(1.0, np.abs(x).max(initial=0))
            )
        for name in fields:
            x, y = getattr(a, name), getattr(b, name)
            np.testing.assert_allclose(
                y, x, rtol=TOL, atol=TOL * max(1.0, np.abs(x).max(initial=0))
            )
        np.testing.assert_array_equal(a.sticking, b.sticking)
        if hasattr(a, "pair"):
            np.testing.assert_array_equal(a.pair, b.pair)


def _assert_memories_equal(python, core):
    for a, b in zip(python, core, strict=True):
        if a is None:
            continue
        assert a.slipping == b.slipping
        for name in ("anchors", "material"):
            x, y = getattr(a, name), getattr(b, name)
            assert x.keys() == y.keys()
            for key in x:
                np.testing.assert_allclose(y[key], x[key], rtol=TOL, atol=TOL)


def test_the_moving_contacts_and_their_memories_are_the_references(load_body):
    system, state = _scene(load_body)
    assert not isinstance(system.compiled, Fallback) and system.compiled is not None
    q, v = _advance(system, state, 13)  # anchors set; the robot-box pair slips, others stick
    memories = system.friction_memories()
    assert any(m is not None and m.anchors for m in memories[1:])
    assert any(m is not None and m.slipping for m in memories[1:])
    (q_r, v_r), *objects = system.layout.split(q, v)
    python = system.moving.found(q_r, v_r, objects)
    core = contacts_of_core(system.compiled.contacts(q, v, memories))
    sets, fixed = python
    assert [len(s) for s in sets] == [1, 0, 1]  # robot-box, robot-ball (apart), box-ball
    assert [len(f.touch) for f in fixed] == [4, 1]  # the box's corners, the ball
    _assert_contacts_equal(sets, core[0])
    _assert_contacts_equal(fixed, core[1])
    # the anchors move alike at the period's end
    before = _memories(system)
    system.compiled.settle(q, v, system.friction_memories())
    from_core = _memories(system)
    for held, memory in zip(before, system.friction_memories(), strict=True):
        if memory is not None:
            memory.anchors, memory.slipping, memory.material = (
                held.anchors, held.slipping, held.material,
            )  # fmt: skip
    system.settle(q, v)
    _assert_memories_equal(_memories(system), from_core)


def test_the_right_hand_side_is_the_references(load_body):
    """The generalized forces of every contact (J^T f on each body) enter the accelerations
    alike: the core adds each force as a wrench at its point, the reference as J^T f."""
    system, state = _scene(load_body)
    q, v = _advance(system, state, 13)
    tau = np.array([5.0, -1.0, 2.0, 0.1, 0.0, -0.2])
    python = system.acceleration(0.04, q, v, tau)
    core = system.compiled.acceleration(0.04, q, v, tau, system.friction_memories())
    scale = np.abs(python).max()
    assert scale > 1.0  # the contacts push
    np.testing.assert_allclose(core, python, rtol=1e-11, atol=1e-11 * scale)


def test_a_period_is_the_python_integrators_to_rounding(load_body):
    """One period by the compiled system and by the Python integrator (its anchors moved
    at its end), from the same state and memories."""
    system, state = _scene(load_body)
    q, v = _advance(system, state, 10)
    held = _memories(system)
    tau = np.array([5.0, 0, 0, 0, 0, 0])
    core = system.advance(RK4(5e-4), 0.02, q, v, tau, 0.022)
    from_core = _memories(system)
    for memory, kept in zip(system.friction_memories(), held, strict=True):
        if memory is not None:
            memory.anchors, memory.slipping, memory.material = (
                kept.anchors, kept.slipping, kept.material,
            )  # fmt: skip
    python = integrated_step(system, RK4(5e-4))(0.02, q, v, tau, 0.022)
    for x, y in zip(python, core, strict=True):
        np.testing.assert_allclose(y, x, rtol=1e-11, atol=1e-13)
    _assert_memories_equal(_memories(system), from_core)


def _momentum_world(uvms, q, v):
    """The linear momentum (body and entrained water) of a floating body, world axes."""
    return pin.Quaternion(q[3:7]).matrix() @ (up.mass_matrix(uvms, q) @ v)[:3]


def test_two_free_objects_collide_passively_in_the_core(load_body):
    """Two neutral, undamped spheres collide off-centre (the robot far away), the compiled
    system stepping them: the contact exchanges equal and opposite forces (the total
    momentum stays, 1e-9) and never gives energy (the kinetic energy never exceeds the
    initial; the Hunt-Crossley damping and the friction take some)."""
    pusher = load_body(body_urdf(mass=4.0, hydro=hydro_xml(4.0 / RHO)))

    def ball(name, x, y, v0):
        made = free_object(
            name, "sphere", {"radius_m": 0.2}, ([x, y, -5.0], [0, 0, 0]), density_kg_m3=RHO,
            water_density_kg_m3=RHO, velocity_body=v0,
        )  # fmt: skip
        return undamped(made)

    a = ball("a", 0.0, 0.0, [0.6, 0, 0, 0, 0, 0.5])
    b = ball("b", 0.5, 0.1, [0, 0, 0, 0, 0, 0])
    world = World(pusher, [], ContactLaw(stiffness_N_m=2e4, dissipation_s_m=1.0), [a, b])
    system = System(Plant(pusher, world=world, free_surface=False))
    q = pusher.neutral_configuration()
    q[:3] = [30.0, 0.0, -5.0]
    state = system.initial_state(q, np.zeros(6))
    system.start(state)
    assert "one compiled call" in system.log.record(RK4(5e-4))["world"]["integration"]
    q_s, v_s = state.q, state.v
    momentum, energy, touched = [], [], False
    for k in range(400):
        parts = system.layout.split(q_s, v_s)[1:]
        momentum.append(
            sum(_momentum_world(o.uvms, *s) for o, s in zip((a, b), parts, strict=True))
        )
        energy.append(
            sum(up.kinetic_energy(o.uvms, *s) for o, s in zip((a, b), parts, strict=True))
        )
        q_s, v_s = system.advance(RK4(5e-4), k * 2e-3, q_s, v_s, np.zeros(6), (k + 1) * 2e-3)
        sets, _ = contacts_of_core(system.compiled.contacts(q_s, v_s, system.friction_memories()))
        touched |= len(sets[-1]) > 0  # the pair a|b
    momentum, energy = np.array(momentum), np.array(energy)
    assert touched
    assert np.abs(momentum - momentum[0]).max() <= 1e-9 * np.linalg.norm(momentum[0])
    assert energy.max() <= energy[0] * (1.0 + 1e-12)
    assert energy[-1] < 0.999 * energy[0]  # some dissipated
    parts = system.layout.split(q_s, v_s)[1:]
    assert np.linalg.norm(parts[1][1][:3]) > 0.1  # b was hit


def test_a_world_the_core_cannot_do_runs_in_python_with_its_reason(load_body):
    for backend, compiled, integrator, reason in (
        ("python", True, RK4(5e-4), "the Python backend"),
        ("core", False, RK4(5e-4), "the Python integration was asked for"),
        ("core", True, Adaptive(), "the integrator Adaptive"),
    ):
        system, state = _scene(load_body, backend, compiled)
        record = system.log.record(integrator)["world"]
        assert "Python integrator" in record["integration"] and reason in record["integration"]
        q, _ = _advance(system, state, 2)  # the integrated step, as before
        assert np.all(np.isfinite(q))
    system, _ = _scene(load_body)
    assert "one compiled call" in system.log.record(RK4(5e-4))["world"]["integration"]


def test_push_object_compiled_follows_the_python_integration():
    """The shipped scenario, its controller in the loop, compiled and in Python. The push is
    brought forward (the arm's posture in 2 s, the surge from 1 s: the jaws meet the box
    after about 2.26 s, not 5.5 s) and the run ends 0.54 s later, as the scenario's own first
    6 s did: the Python reference's rest of the box on the seabed adds nothing after its
    first second. The box rests on the seabed by rigid contacts, solved to the reference
    ADMM's tolerance (1e-8 m/s) and by the core's Gauss-Seidel: the runs agree to 1e-8 until
    the jaws push the box; then the box breaks away, and where it sticks or slides (a switch
    of its friction between mu_s and mu_k at 1e-6 m/s) the two solves' rounding takes
    different sides for a period: 5e-5 on the robot's q, 6e-4 on the box's state, 0.005 N on
    its contact forces (85 N on the jaws) at 2.8 s (measured; asked: RIGID_AGREEMENT). With
    the compliant law (the seabed a spring) the runs agree to AGREEMENT."""
    push_early = {"controller.push_start_s": 1.0, "controller.ramp_s": 2.0}
    scenario = load_scenario(
        ROOT / "scenarios" / "push_object.toml", {"scenario.duration_s": 2.8, **push_early}
    )
    compiled = up.simulate(scenario, progress=False)
    python = up.simulate(scenario, progress=False, compiled_loop=False)
    assert "one compiled call" in compiled.metadata["world"]["world"]["integration"]
    assert "Python integrator" in python.metadata["world"]["world"]["integration"]
    seabed = np.abs(compiled.signals["free_object_contact"]).max(axis=1) > 0
    assert seabed.mean() > 0.9  # the box rests on the seabed
    on_box = compiled.signals["world_contact"].reshape(len(compiled.time_s), -1, 9)
    pairs = compiled.metadata["world_contact_pairs"]
    jaws = [k for k, name in enumerate(pairs) if name.endswith("|box")]
    pushed = np.abs(on_box[:, jaws, :3]).max(axis=(1, 2)) > 1.0
    assert pushed.any() and compiled.time_s[pushed][0] > 2.2  # the UVMS pushed the box
    travel = compiled.signals["free_objects"][-1, :2] - compiled.signals["free_objects"][0, :2]
    assert travel[0] > 0.02  # ahead of the vehicle, by centimetres
    before = compiled.time_s < 2.2  # before the jaws reach the box
    np.testing.assert_allclose(compiled.q[before], python.q[before], rtol=0, atol=1e-8)
    np.testing.assert_allclose(compiled.q, python.q, rtol=0, atol=RIGID_AGREEMENT)
    np.testing.assert_allclose(
        compiled.signals["free_objects"], python.signals["free_objects"],
        rtol=0, atol=10 * RIGID_AGREEMENT,
    )  # fmt: skip
    np.testing.assert_allclose(
        compiled.signals["free_object_contact"], python.signals["free_object_contact"],
        rtol=0, atol=0.05,
    )  # fmt: skip


#: [m, rad]: push_object compiled against the Python reference on rigid contacts (above)
RIGID_AGREEMENT = 1e-4


AGREEMENT = 1e-10  # [m, rad, m/s, rad/s]; the forces [N] to 1e3 times that (k = 2e4 N/m)


def _push_object_system(overrides: dict | None = None) -> tuple[System, object]:
    scenario = load_scenario(ROOT / "scenarios" / "push_object.toml", overrides or {})
    return System(scenario.plant), scenario


def _one_period_each_way(system: System, q, v, tau):
    """(the compiled period, the Python reference's) from (q, v) at the same memories."""
    held = _memories(system)
    core = system.advance(RK4(5e-4), 0.0, q, v, tau, 0.002)
    for memory, kept in zip(system.friction_memories(), held, strict=True):
        if memory is not None:
            memory.anchors, memory.slipping, memory.material = (
                kept.anchors, kept.slipping, kept.material,
            )  # fmt: skip
    return core, integrated_step(system, RK4(5e-4))(0.0, q, v, tau, 0.002)


def test_a_joint_limit_is_solved_in_the_compiled_period_as_in_the_reference():
    """push_object's joint limits are constraints: an arm joint driven into its lower limit
    is stopped there by the compiled period as by the reference's solve (its ADMM to 1e-8),
    the box's configuration advanced as q0 (+) h v+ with the rest."""
    # the box on the compliant law: its rigid contacts are solved to the reference's ADMM
    # tolerance (test_object_contacts), the joint limits here to 1e-9
    system, scenario = _push_object_system({"world.fixed_contact": "compliant"})
    assert system.plant.joint_limits is not None
    q0 = scenario.q0.copy()
    q0[8] = 2e-4  # the shoulder 0.2 mrad above its lower limit (0), moving into it
    v0 = np.zeros(scenario.uvms.nv)
    # at 1 rad/s: the arm lowered so touches the world, whose push over the period (on the
    # shoulder and its drive's armature) stops a joint at 0.5 rad/s before its limit does
    v0[7] = -1.0
    state = system.initial_state(q0, v0)
    system.start(state)
    core, python = _one_period_each_way(system, state.q, state.v, np.zeros(scenario.uvms.nv))
    nq = scenario.uvms.nq
    # held at the limit: its velocity the one that closes the gap in the period, not -0.5
    assert abs(core[0][8]) <= 1e-9 and core[1][7] == pytest.approx(-2e-4 / 0.002, rel=1e-6)
    np.testing.assert_allclose(core[0], python[0], rtol=0, atol=1e-9)
    # the reference's ADMM stops at 1e-8 on the constraint velocities: through M^-1 the
    # other joints' velocities differ by ~1e-7 (an elbow at 2.9 rad/s: 4e-8 relative)
    np.testing.assert_allclose(core[1], python[1], rtol=1e-6, atol=1e-9)
    box = system.layout.q_slices[1]
    assert nq == box.start
    np.testing.assert_allclose(core[0][box], python[0][box], rtol=0, atol=1e-12)


def test_self_collision_beside_a_free_object_is_compiled_alike():
    """With ``self_collision`` the arm's pairs with its vehicle join the compiled system's
    sets: a few periods agree with the reference's."""
    system, scenario = _push_object_system(
        {"world.contact.self_collision": True, "world.fixed_contact": "compliant"}
    )
    assert any(s.a == -1 and s.b == -1 for s in system.moving.moving.sets)
    assert "one compiled call" in system.log.record(RK4(5e-4))["world"]["integration"]
    state = system.initial_state(scenario.q0, scenario.v0)
    system.start(state)
    tau = np.zeros(scenario.uvms.nv)
    tau[6:] = [0.5, -2.0, 1.0, 0.1]
    q, v = state.q, state.v
    for _ in range(5):
        core, python = _one_period_each_way(system, q, v, tau)
        np.testing.assert_allclose(core[0], python[0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(core[1], python[1], rtol=0, atol=1e-10)
        q, v = core
