"""Free objects: a body of the world integrated beside the UVMS, coupled to it only by
contact forces exchanged equal and opposite. Checked against statics, Newton's law with the
added mass, momentum conservation and the energy."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, ROOT, G, body_urdf, hydro_xml
from free_object_helpers import undamped

import uvms_pin as up
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object, solid_mass_properties
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

FLOOR_Z = -10.0


def _pusher(load_body, mass=4.0, radius=0.1):
    """A one-body 'UVMS': a neutrally buoyant sphere without added mass or damping."""
    volume = mass / RHO
    inertia = (0.4 * mass * radius**2,) * 3
    collision = f'<sphere radius="{radius}"/>'
    urdf = body_urdf(mass=mass, inertia=inertia, hydro=hydro_xml(volume), collision=collision)
    return load_body(urdf)


def _run(system, q, v, tau, duration_s, step_s, period_s):
    """(t, the robot's q, v, the objects' states) after each period of ``system``."""
    state = system.initial_state(q, v)
    system.start(state)
    q_sys, v_sys = state.q, state.v
    n = system.layout.q_slices[0].stop, system.layout.v_slices[0].stop
    out = [(0.0, q_sys[: n[0]], v_sys[: n[1]], np.r_[q_sys[n[0] :], v_sys[n[1] :]])]
    for k in range(round(duration_s / period_s)):
        q_sys, v_sys = system.advance(
            RK4(step_s), k * period_s, q_sys, v_sys, tau, (k + 1) * period_s
        )
        out.append(
            ((k + 1) * period_s, q_sys[: n[0]], v_sys[: n[1]], np.r_[q_sys[n[0] :], v_sys[n[1] :]])
        )
    return out


def _momentum_world(uvms, q, v):
    """The linear momentum (body and entrained water) of a one-body UVMS, world axes."""
    mass = up.mass_matrix(uvms, q)
    return pin.Quaternion(q[3:7]).matrix() @ (mass @ v)[:3]


def test_mass_properties_of_the_solids():
    m, c, inertia = solid_mass_properties("box", {"size_m": [1.0, 0.5, 0.2]}, None, 2000.0)
    assert m == pytest.approx(200.0) and np.all(c == 0.0)
    assert np.allclose(np.diag(inertia), 200.0 / 12 * np.array([0.29, 1.04, 1.25]))
    m, _, inertia = solid_mass_properties("sphere", {"radius_m": 0.5}, 10.0, None)
    assert m == 10.0 and np.allclose(inertia, np.eye(3) * 0.4 * 10.0 * 0.25)
    m, _, inertia = solid_mass_properties("cylinder", {"radius_m": 0.1, "length_m": 1.0}, 3.0, None)
    assert np.allclose(np.diag(inertia), [3.0 * 1.03 / 12, 3.0 * 1.03 / 12, 0.015])
    assert solid_mass_properties("sphere", {"radius_m": 0.01}, 0.004, None)[0] == 0.004  # 4 g
    for mass, density in ((0.0, None), (-1.0, None), (None, 0.0), (math.nan, None)):
        with pytest.raises(up.ParameterError, match="a free sphere needs a positive mass"):
            solid_mass_properties("sphere", {"radius_m": 0.5}, mass, density)


def test_a_free_object_has_the_hydrodynamics_of_its_shape():
    obj = free_object(
        "ball", "sphere", {"radius_m": 0.2}, ([0, 0, -5], [0, 0, 0]),
        density_kg_m3=RHO, water_density_kg_m3=RHO,
    )  # fmt: skip
    volume = 4.0 / 3.0 * math.pi * 0.2**3
    (body,) = obj.uvms.hydro_bodies
    assert body.params.volume_m3 == pytest.approx(volume)
    assert obj.mass_kg == pytest.approx(RHO * volume)
    assert np.allclose(np.diag(body.params.added_mass)[:3], 0.5 * RHO * volume)
    assert np.all(body.params.quadratic_damping[:3] > 0.0)  # its form drag
    # neutrally buoyant, centred: no net hydrostatic load at rest
    q = obj.q0
    assert up.forward_dynamics(obj.uvms, q, np.zeros(6), np.zeros(6)) == pytest.approx(
        np.zeros(6), abs=1e-9
    )


def test_a_free_box_dropped_on_the_seafloor_rests_on_its_net_weight(load_body):
    pusher = _pusher(load_body)
    box = free_object(
        "box", "box", {"size_m": [0.6, 0.4, 0.3]}, ([0.0, 0.0, FLOOR_Z + 0.2], [0, 0, 0]),
        density_kg_m3=3.0 * RHO, water_density_kg_m3=RHO,
    )  # fmt: skip
    law = ContactLaw(stiffness_N_m=1e5, dissipation_s_m=0.5)
    floor = plane("seafloor", [0, 0, FLOOR_Z], [0, 0, 1], 0.6, 0.5)
    world = World(pusher, [floor], law, [box], fixed_contact="compliant")  # a soft seabed
    system = System(Plant(pusher, world=world, free_surface=False))
    q = pusher.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]  # far away: only the box touches the floor
    states = _run(system, q, np.zeros(6), np.zeros(6), 20.0, 4e-3, 2e-2)
    q_end, v_end, box_end = states[-1][1], states[-1][2], states[-1][3]
    sets, fixed = system.moving.found(q_end, v_end, [(box_end[:7], box_end[7:])])
    assert all(len(s) == 0 for s in sets)
    forces = fixed[0]
    assert len(forces.touch) == 4  # its four bottom corners
    net = 2.0 * RHO * 0.6 * 0.4 * 0.3 * G  # W - B
    total = forces.force_world_N.sum(axis=0)
    assert total[2] == pytest.approx(net, rel=1e-6)
    assert np.allclose(total[:2], 0.0, atol=1e-6 * net)
    z_box = states[-1][3][2]
    assert FLOOR_Z + 0.15 - z_box == pytest.approx(net / (4 * law.stiffness_N_m), rel=1e-6)
    # the UVMS did not move: nothing touched it
    assert np.allclose(q_end[:3], [20.0, 0.0, -5.0], atol=1e-9)
    # logged: the box's pair with the floor carries the same force
    logged = system.log.signals(np.r_[q_end, box_end[:7]], np.r_[v_end, box_end[7:]])
    assert system.log.record()["world"]["object_pairs"] == ["box|seafloor"]
    np.testing.assert_array_equal(logged["free_objects"], box_end)
    assert logged["free_object_contact"][:3] == pytest.approx(total, rel=1e-12)


def _push_setup(load_body, force_N):
    pusher = _pusher(load_body)
    ball = undamped(
        free_object(
            "ball", "sphere", {"radius_m": 0.2}, ([0.0, 0.0, -5.0], [0, 0, 0]),
            density_kg_m3=RHO, water_density_kg_m3=RHO,
        )
    )  # fmt: skip
    world = World(pusher, [], ContactLaw(stiffness_N_m=2e4, dissipation_s_m=2.0), [ball])
    system = System(Plant(pusher, world=world, free_surface=False))
    q = pusher.neutral_configuration()
    q[:3] = [-0.3, 0.0, -5.0]  # touching the ball's left side
    tau = np.zeros(6)
    tau[0] = force_N
    return pusher, ball, system, q, tau


def test_a_neutral_free_sphere_pushed_by_a_constant_force_accelerates_at_f_over_m_plus_ma(
    load_body,
):
    force = 20.0
    _, ball, system, q, tau = _push_setup(load_body, force)
    states = _run(system, q, np.zeros(6), tau, 3.0, 1e-3, 1e-2)
    m_ball = ball.mass_kg
    m_added = 0.5 * RHO * 4.0 / 3.0 * math.pi * 0.2**3  # a sphere's: half the displaced water
    m_pusher = 4.0
    # the two move together: the ball's speed grows at F / (m_p + m + m_A) (the contact's
    # ringing averages out over the 2 s)
    speed = {round(t, 6): s[7] for t, _, _, s in states}
    measured = (speed[3.0] - speed[1.0]) / 2.0
    assert measured == pytest.approx(force / (m_pusher + m_ball + m_added), rel=0.01)
    # and the ball alone obeys f = (m + m_A) a with the contact force f on it: at a state
    t, q_t, v_t, s = states[150]
    states_now = [(s[:7].copy(), s[7:].copy())]
    accel = system.acceleration(t, np.concatenate([q_t, s[:7]]), np.concatenate([v_t, s[7:]]), tau)
    sets, _ = system.moving.found(q_t, v_t, states_now)
    f_on_ball = -sets[0].force_world_N.sum(axis=0)
    assert np.linalg.norm(f_on_ball) > 1.0
    rotation = pin.Quaternion(s[3:7]).matrix()
    # body acceleration of the ball [v_dot + w x v]: at its small spin, linear part
    a_world = rotation @ accel[6:9]
    assert a_world == pytest.approx(f_on_ball / (m_ball + m_added), rel=1e-6, abs=1e-9)


def test_momentum_is_exchanged_equal_and_opposite_and_energy_never_gained(load_body):
    """The pusher hits the neutral ball off-centre (friction acts too), nothing else
    touches, nothing damps: the total linear momentum stays, the kinetic energy never grows."""
    pusher, ball, system, q, _ = _push_setup(load_body, 0.0)
    q[:3] = [-0.6, 0.08, -5.0]  # 0.3 m apart, 8 cm off the line of centres
    v = np.zeros(6)
    v[0] = 0.5
    states = _run(system, q, v, np.zeros(6), 1.5, 5e-4, 1e-2)
    momentum, energy = [], []
    for _, q_t, v_t, s in states:
        p = _momentum_world(pusher, q_t, v_t) + _momentum_world(ball.uvms, s[:7], s[7:])
        momentum.append(p)
        energy.append(
            up.kinetic_energy(pusher, q_t, v_t) + up.kinetic_energy(ball.uvms, s[:7], s[7:])
        )
    momentum, energy = np.array(momentum), np.array(energy)
    p0 = 4.0 * 0.5
    assert np.max(np.abs(momentum - momentum[0])) <= 1e-6 * p0
    ball_speed = np.linalg.norm(states[-1][3][7:10])
    assert ball_speed > 0.02  # it was hit (4 kg at 0.5 m/s on 51 kg with its added mass)
    assert abs(states[-1][3][8]) > 1e-3  # and off the line: a sideways part
    # never gained: apart again at the end, the energy left is at most the initial
    bodies = system.moving
    touching = [
        len(bodies.found(q_t, v_t, [(s[:7], s[7:])])[0][0]) > 0 for _, q_t, v_t, s in states
    ]
    assert any(touching) and not touching[-1]
    assert energy[-1] <= energy[0] * (1.0 + 1e-9)
    assert energy[-1] < energy[0]  # the Hunt-Crossley damping took some


def test_free_objects_need_a_sampled_loop(load_body):
    pusher, _, system, q, _ = _push_setup(load_body, 0.0)
    from uvms_pin.control.base import ZeroController
    from uvms_pin.sim.closed_loop import simulate_closed_loop
    from uvms_pin.sim.sensors import SensorConfig, SensorSuite
    from uvms_pin.sim.settings import SimulationSettings

    settings = SimulationSettings(0.1, RK4(step_s=1e-3), log_period_s=0.01)
    sensors = SensorSuite(pusher.model, SensorConfig(), 0.1, 0)
    with pytest.raises(up.ParameterError, match="sampled"):
        simulate_closed_loop(system.plant, ZeroController(6), sensors, q, np.zeros(6), settings)


def test_both_backends_integrate_free_objects_alike(load_body):
    """On the core backend the system's period is one compiled call (every body and
    contact), on the Python backend the Python integrator around the reference dynamics:
    the two agree to rounding."""
    finals = []
    for backend in ("core", "python"):
        pusher = _pusher(load_body)
        ball = free_object(
            "ball", "sphere", {"radius_m": 0.2}, ([0.0, 0.0, -5.0], [0, 0, 0.3]),
            mass_kg=40.0, water_density_kg_m3=RHO,
        )  # fmt: skip
        floor = plane("seafloor", [0, 0, -5.25], [0, 0, 1], 0.6, 0.5)
        world = World(pusher, [floor], ContactLaw(), [ball])
        system = System(Plant(pusher, world=world, free_surface=False, backend=backend))
        q = pusher.neutral_configuration()
        q[:3] = [-0.31, 0.02, -5.0]
        v = np.zeros(6)
        v[0] = 0.3
        states = _run(system, q, v, np.zeros(6), 0.3, 1e-3, 1e-2)
        finals.append(np.concatenate([states[-1][1], states[-1][2], states[-1][3]]))
    assert np.allclose(finals[0], finals[1], rtol=1e-9, atol=1e-11)
    assert np.linalg.norm(finals[0][13 + 7 : 13 + 10]) > 1e-3  # the ball moved


def test_a_free_mesh_has_its_volume_mass_and_a_positive_inertia():
    rock = free_object(
        "rock", "mesh", {"path": ROOT / "scenarios" / "meshes" / "rock.obj"},
        ([0, 0, -5], [0, 0, 0]), density_kg_m3=2600.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    (body,) = rock.uvms.hydro_bodies
    assert rock.mass_kg == pytest.approx(2600.0 * body.params.volume_m3, rel=1e-9)
    inertia = rock.uvms.model.inertias[1].inertia
    assert np.all(np.linalg.eigvalsh(inertia) > 0.0)
    assert len(rock.pieces) == 1  # its hull collides
    # without a scale the file's own size; scaled by 2 on every axis: 8 times the volume
    # and mass, 32 times the inertia (m r^2)
    import trimesh

    path = ROOT / "scenarios" / "meshes" / "rock.obj"
    assert body.params.volume_m3 == pytest.approx(abs(trimesh.load(path).volume), rel=1e-9)
    big = free_object(
        "rock", "mesh", {"path": path, "scale": [2.0, 2.0, 2.0]},
        ([0, 0, -5], [0, 0, 0]), density_kg_m3=2600.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    assert big.mass_kg == pytest.approx(8.0 * rock.mass_kg, rel=1e-9)
    assert big.uvms.hydro_bodies[0].params.volume_m3 == pytest.approx(8.0 * body.params.volume_m3)
    np.testing.assert_allclose(big.uvms.model.inertias[1].inertia, 32.0 * inertia, rtol=1e-9)


def test_a_free_objects_record_is_its_start():
    """What the views draw and a rollout keeps of a free object: its start pose (position
    (3,) and rotation), mass, friction and sizes."""
    from uvms_pin.physics.world.free_object import free_object

    box = free_object(
        "box", "box", {"size_m": [0.2, 0.4, 0.6]}, ([1.0, -2.0, -3.0], [0.1, -0.2, 0.3]),
        density_kg_m3=1500.0, water_density_kg_m3=1025.0, friction=(0.7, 0.4),
    )  # fmt: skip
    record = box.record()
    assert record["position_world_m"] == [1.0, -2.0, -3.0]
    np.testing.assert_allclose(
        record["rotation_world"], pin.rpy.rpyToMatrix(0.1, -0.2, 0.3), rtol=0, atol=1e-15
    )
    assert record["mass_kg"] == pytest.approx(1500.0 * 0.2 * 0.4 * 0.6, rel=1e-12)
    assert (record["friction_static"], record["friction_kinetic"]) == (0.7, 0.4)
    assert record["size_m"] == [0.2, 0.4, 0.6] and record["free"] is True
