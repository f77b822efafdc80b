"""The ellipsoid kind (`uvms_pin.physics.world.kinds.ellipsoid`): read from a scenario and
checked there, touched as a fixed object (Python and compiled core alike), free (it sinks
and rests on the seabed on its net weight, its buoyancy its own volume's) and drawn by the
replay."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, ROOT, G, body_urdf, hydro_xml

from uvms_pin.apps.viz.meshcat_scene import recording_visualizer
from uvms_pin.apps.viz.replay import scene_for_rollout
from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.hydro.geometry import ellipsoid_added_mass, sphere_hydro
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.physics.world.world import FrictionMemory, World
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.run import simulate
from uvms_pin.sim.system import System

AXES = (0.4, 0.25, 0.15)  # a flat boulder, lying on its shortest axis
FLOOR_Z = -10.0


def _pusher(load_body, radius=0.1, mass=4.0):
    """A neutrally buoyant sphere without added mass or damping: the 'UVMS'."""
    hydro = hydro_xml(mass / RHO)
    collision = f'<sphere radius="{radius}"/>'
    return load_body(body_urdf(mass=mass, inertia=(0.016,) * 3, hydro=hydro, collision=collision))


def test_its_keys_are_read_from_a_scenario_and_checked_there():
    ellipsoid = {"type": "ellipsoid", "name": "boulder", "semi_axes_m": list(AXES)}
    objects = [{**ellipsoid, "position_world_m": [3.0, 0.0, -9.9]}]
    scenario = load_scenario(ROOT / "scenarios" / "seabed_landing.toml", {"world.objects": objects})
    (boulder,) = scenario.plant.world.objects
    assert boulder.kind == "ellipsoid" and boulder.bound_radius_m == 0.4
    assert boulder.record()["semi_axes_m"] == list(AXES)
    bad = [{**ellipsoid, "semi_axes_m": [0.4, -0.25, 0.15], "position_world_m": [3, 0, -9.9]}]
    with pytest.raises(ScenarioError, match=r"objects\[0\]\.semi_axes_m.*must be > 0"):
        load_scenario(ROOT / "scenarios" / "seabed_landing.toml", {"world.objects": bad})
    with pytest.raises(ParameterError, match="semi_axes_m"):
        solid("b", "ellipsoid", {"semi_axes_m": [1.0, 2.0]}, [0, 0, 0], [0, 0, 0], 0.6, 0.5)


@pytest.mark.parametrize(("axis", "semi_axis"), [(0, AXES[0]), (1, AXES[1]), (2, AXES[2])])
def test_a_fixed_ellipsoid_pushes_a_sphere_out_along_its_axis(load_body, axis, semi_axis):
    """A sphere 1 cm into the tip of a semi-axis: k delta out along that axis (at rest), in
    the Python reference and in the compiled core alike."""
    pusher = _pusher(load_body)
    law = ContactLaw(stiffness_N_m=1e4)
    turn = [0.0, 0.0, 0.5]
    boulder = solid("boulder", "ellipsoid", {"semi_axes_m": AXES}, [1, 2, -3], turn, 0.6, 0.5)
    world = World(pusher, [boulder], law)
    rotation = boulder.placement.rotation
    q = pusher.neutral_configuration()
    q[:3] = boulder.placement.translation + rotation[:, axis] * (semi_axis + 0.1 - 0.01)
    data = pusher.model.createData()
    pin.forwardKinematics(pusher.model, data, q, np.zeros(6))
    forces = world.forces(data, FrictionMemory())
    assert len(forces.touch) == 1
    assert forces.touch.depth_m[0] == pytest.approx(0.01, abs=1e-6)
    force = forces.force_world_N[0]
    assert np.linalg.norm(force) == pytest.approx(1e4 * 0.01, rel=1e-4)
    # along the axis within coal's EPA tolerance on a curved surface's normal (~0.3 deg)
    assert force @ rotation[:, axis] / np.linalg.norm(force) > 0.9999
    core = Plant(pusher, world=world, free_surface=False).compiled
    got = core.world_forces(q, np.zeros(6), FrictionMemory())
    assert np.allclose(got["force_world_N"], forces.force_world_N, rtol=1e-12, atol=1e-10)
    assert np.allclose(got["point_world_m"], forces.touch.point_world_m, rtol=0, atol=1e-12)


def test_a_free_ellipsoid_has_its_own_volume_and_added_mass():
    obj = free_object(
        "float", "ellipsoid", {"semi_axes_m": AXES}, ([0, 0, -5], [0, 0, 0]),
        density_kg_m3=0.5 * RHO, water_density_kg_m3=RHO,
    )  # fmt: skip
    (body,) = obj.uvms.hydro_bodies
    volume = 4.0 / 3.0 * math.pi * np.prod(AXES)
    assert body.params.volume_m3 == pytest.approx(volume, rel=1e-14)
    assert obj.mass_kg == pytest.approx(0.5 * RHO * volume, rel=1e-14)
    assert np.diag(body.params.added_mass) == pytest.approx(ellipsoid_added_mass(*AXES, RHO))
    inertia = obj.uvms.model.inertias[1].inertia
    a, b, c = AXES
    expected = obj.mass_kg / 5.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    assert np.diag(inertia) == pytest.approx(expected, rel=1e-12)
    # its drag: the equal-volume sphere's over its projected areas (a sphere's for a sphere)
    r = float(np.prod(AXES)) ** (1.0 / 3.0)
    sphere = sphere_hydro(r, RHO).quadratic_damping
    assert body.params.quadratic_damping[:3] == pytest.approx(
        sphere[:3] * np.array([b * c, a * c, a * b]) / r**2, rel=1e-12
    )
    round_one = free_object(
        "ball", "ellipsoid", {"semi_axes_m": [0.2] * 3}, ([0, 0, -5], [0, 0, 0]),
        mass_kg=10.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    ball = sphere_hydro(0.2, RHO)
    params = round_one.uvms.hydro_bodies[0].params
    assert params.quadratic_damping == pytest.approx(ball.quadratic_damping, rel=1e-12)
    assert params.added_mass == pytest.approx(ball.added_mass, rel=1e-9, abs=1e-9)


def test_a_free_ellipsoid_sinks_and_rests_on_the_seabed_on_its_net_weight(load_body):
    pusher = _pusher(load_body)
    boulder = free_object(
        "boulder", "ellipsoid", {"semi_axes_m": AXES}, ([0.0, 0.0, FLOOR_Z + 0.3], [0, 0, 0]),
        density_kg_m3=2.0 * RHO, water_density_kg_m3=RHO,
    )  # fmt: skip
    law = ContactLaw(stiffness_N_m=1e5, dissipation_s_m=0.5)
    floor = plane("seabed", [0, 0, FLOOR_Z], [0, 0, 1], 0.6, 0.5)
    system = System(
        Plant(
            pusher,
            world=World(pusher, [floor], law, [boulder], fixed_contact="compliant"),
            free_surface=False,
        )
    )
    q = pusher.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]  # far away: only the boulder touches the seabed
    start = system.initial_state(q, np.zeros(6))
    system.start(start)
    q_sys, v_sys, tau, period = start.q, start.v, np.zeros(6), 2e-2
    for k in range(1000):  # 20 s
        q_sys, v_sys = system.advance(RK4(4e-3), k * period, q_sys, v_sys, tau, (k + 1) * period)
    (q, v), (q_b, v_b) = system.layout.split(q_sys, v_sys)
    state = np.concatenate([q_b, v_b])
    _, fixed = system.moving.found(q, v, [(q_b, v_b)])
    forces = fixed[0]
    assert len(forces.touch) == 1  # a smooth shape: coal's one deepest point
    volume = 4.0 / 3.0 * math.pi * np.prod(AXES)
    net = (2.0 * RHO - RHO) * volume * G  # W - B: its buoyancy is its own volume's
    total = forces.force_world_N.sum(axis=0)
    assert total[2] == pytest.approx(net, rel=1e-6)
    assert np.allclose(total[:2], 0.0, atol=1e-6 * net)
    # lying on its shortest axis, its lowest point net / k into the seabed
    assert FLOOR_Z + AXES[2] - state[2] == pytest.approx(net / law.stiffness_N_m, rel=1e-5)
    assert np.allclose(np.abs(pin.Quaternion(state[3:7]).matrix()[:, 2]), [0, 0, 1], atol=1e-6)


def test_the_replay_draws_a_fixed_and_a_free_ellipsoid():
    objects = [
        {"type": "plane", "name": "seabed", "point_world_m": [0.0, 0.0, -10.0]},
        {"type": "ellipsoid", "name": "boulder", "semi_axes_m": list(AXES),
         "position_world_m": [3.0, 0.0, -9.9]},
        {"type": "ellipsoid", "name": "float", "semi_axes_m": [0.1, 0.1, 0.2],
         "position_world_m": [-3.0, 0.0, -9.0], "density_kg_m3": 500.0},
    ]  # fmt: skip
    scenario = load_scenario(
        ROOT / "scenarios" / "push_object.toml",
        {"world.objects": objects, "scenario.duration_s": 0.1},
    )
    rollout = simulate(scenario, progress=False)
    assert rollout.signals["free_objects"][-1, 2] > -9.0  # the float rises
    scene = scene_for_rollout(rollout)
    vis, window = recording_visualizer()
    scene.build(vis)
    for path in (b"uvms_pin/world/objects/boulder", b"uvms_pin/world/free/float/shape"):
        drawn = [c for c in window.commands if path in c and b"set_object" in c]
        # meshcat's ellipsoid: a unit sphere its radii scale (the kind's Drawing)
        assert len(drawn) == 1 and b"SphereGeometry" in drawn[0]
