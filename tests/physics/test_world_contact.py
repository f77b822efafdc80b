"""Contact with the world: bodies resting, sticking, sliding and bouncing on the seafloor,
checked against statics, Coulomb's law, a one-dimensional impact and the energy, on both
backends (the compiled contacts and the Python reference)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, G, body_urdf, hydro_xml
from scipy.integrate import solve_ivp

import uvms_pin as up
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.physics.world.touch import Touch
from uvms_pin.physics.world.world import ContactForces, World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

A, B, C = 1.0, 0.5, 0.5  # box [m]
DENSITY = 3.0  # the box is three times as dense as the water
FLOOR_Z = -10.0
ADDED = (60.0, 90.0, 110.0, 5.0, 6.0, 7.0)  # diagonal added mass of the box [kg, kg m^2]


@pytest.fixture(params=["core", "python"])
def backend(request) -> str:
    return request.param


#: The long runs (tens of seconds simulated, 4 to 11 s of the Python reference's time each):
#: compiled only. The Python reference is held to the compiled contacts pointwise and over
#: runs that stick, slide and rebound (box on a slope, sphere and cylinder on a box, box on a
#: mesh: tests/physics/test_world_compiled.py), and the short cases here run on both.
LONG_RUN_BACKEND = pytest.mark.parametrize("backend", ["core"])


def _box(load_body, damping=(0.0,) * 6):
    m = DENSITY * RHO * A * B * C
    inertia = (m * (B * B + C * C) / 12, m * (A * A + C * C) / 12, m * (A * A + B * B) / 12)
    hydro = hydro_xml(A * B * C, added=ADDED, lin=damping)
    return load_body(
        body_urdf(mass=m, inertia=inertia, hydro=hydro, collision=f'<box size="{A} {B} {C}"/>')
    )


def _net_weight_N() -> float:
    return (DENSITY - 1.0) * RHO * A * B * C * G


def _run(plant: Plant, q, v, duration_s, step_s=1e-3, period_s=1e-2):
    plant.attach(q)
    tau = np.zeros(plant.uvms.nv)
    out = [(0.0, q, v)]
    for k in range(round(duration_s / period_s)):
        q, v = System(plant).advance(RK4(step_s), k * period_s, q, v, tau, (k + 1) * period_s)
        out.append(((k + 1) * period_s, q, v))
    return out


def _on_slope(uvms, theta: float, lift_m: float = 0.0):
    """q with the box's bottom face on a slope of angle theta about y (rising towards +x),
    the box's x up the slope."""
    normal = np.array([-math.sin(theta), 0.0, math.cos(theta)])
    q = uvms.neutral_configuration()
    q[:3] = np.array([0.0, 0.0, FLOOR_Z]) + (0.5 * C + lift_m) * normal
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.0, -theta, 0.0)).coeffs()
    return q, normal


def _bottom(q: np.ndarray) -> np.ndarray:
    """The centre of the box's bottom face in the world [m]."""
    return q[:3] + pin.Quaternion(q[3:7]).matrix() @ np.array([0.0, 0.0, -0.5 * C])


def _slope_world(uvms, theta, mu_s, mu_k, law: ContactLaw):
    _, normal = _on_slope(uvms, theta)
    return World(uvms, [plane("seafloor", [0.0, 0.0, FLOOR_Z], normal, mu_s, mu_k)], law)


@LONG_RUN_BACKEND
def test_a_box_rests_on_the_seafloor_with_its_net_weight_and_does_not_sink(load_body, backend):
    uvms = _box(load_body, damping=(200.0,) * 6)
    law = ContactLaw(stiffness_N_m=1e5, dissipation_s_m=0.5)
    world = World(uvms, [plane("seafloor", [0, 0, FLOOR_Z], [0, 0, 1], 0.6, 0.5)], law)
    plant = Plant(uvms, world=world, free_surface=False, backend=backend)
    q, _ = _on_slope(uvms, 0.0, lift_m=0.02)
    states = _run(plant, q, np.zeros(uvms.nv), 60.0, step_s=1e-2, period_s=5e-2)
    _, q_end, v_end = states[-1]
    forces = plant.world_forces(q_end, v_end)
    total = forces.force_world_N.sum(axis=0)
    assert len(forces.touch) == 4  # the four bottom corners
    assert total[2] == pytest.approx(_net_weight_N(), rel=1e-6)
    assert np.allclose(total[:2], 0.0, atol=1e-6 * _net_weight_N())
    # no sinking: at rest at the static depth (W - B) / (4 k) from 30 s to 60 s
    depth = FLOOR_Z + 0.5 * C - q_end[2]
    assert depth == pytest.approx(_net_weight_N() / (4 * law.stiffness_N_m), rel=1e-6)
    z_half = next(s[1][2] for s in states if s[0] >= 30.0)
    assert abs(q_end[2] - z_half) < 1e-7


@LONG_RUN_BACKEND
@pytest.mark.parametrize("theta_deg", [10.0, 25.0])
def test_a_block_on_a_slope_gentler_than_its_friction_stays_put(load_body, theta_deg, backend):
    uvms = _box(load_body, damping=(500.0,) * 6)  # the water's drag damps its rocking
    theta = math.radians(theta_deg)
    mu_s, mu_k = 0.6, 0.4
    assert math.tan(theta) < mu_s
    # a heavy block (1.9 t with its added mass): its stick springs need their damping, here
    # about critical (a spring ringing past mu_s f_n would break away: the step of the load
    # would then be felt, not the static friction)
    law = ContactLaw(1e5, 5.0, tangential_stiffness_N_m=1e5, tangential_damping_N_s_m=3e4)
    plant = Plant(uvms, world=_slope_world(uvms, theta, mu_s, mu_k, law), backend=backend)
    # placed at rest on the slope at the depth that carries it, sticking where it is
    depth = _net_weight_N() * math.cos(theta) / (4 * law.stiffness_N_m)
    q, _ = _on_slope(uvms, theta, lift_m=-depth)
    states = _run(plant, q, np.zeros(uvms.nv), 10.0, step_s=5e-3, period_s=1e-2)
    downslope = np.array([-math.cos(theta), 0.0, -math.sin(theta)])
    along = np.array([(_bottom(s[1]) - _bottom(q)) @ downslope for s in states])
    # stuck: it moves only while its corners land and the stick springs stretch to carry its
    # weight along the slope, (W - B) sin(theta) / (4 k_t) ~ mm, then not at all (no creep)
    stretch = _net_weight_N() * math.sin(theta) / (4 * law.tangential_stiffness_N_m)
    assert np.max(np.abs(along)) < 3.0 * stretch  # the pitch of its rocking adds
    late = along[3 * len(along) // 4 :]  # the last 2.5 s
    assert np.ptp(late) < 1e-7
    assert abs(late[-1] - late[0]) < 1e-8
    assert np.linalg.norm(states[-1][2]) < 1e-5
    forces = plant.world_forces(states[-1][1], states[-1][2])
    assert np.all(forces.sticking)
    friction = forces.force_world_N - forces.normal_N[:, None] * forces.touch.normal_world
    ratio = np.linalg.norm(friction.sum(axis=0)) / forces.normal_N.sum()
    assert ratio == pytest.approx(math.tan(theta), rel=1e-4)  # it holds the slope's load


@pytest.mark.parametrize("theta_deg", [35.0, 45.0])
def test_a_block_on_a_steep_slope_slides_at_the_coulomb_acceleration(load_body, theta_deg, backend):
    uvms = _box(load_body)
    theta = math.radians(theta_deg)
    mu_s, mu_k = 0.6, 0.4
    assert math.tan(theta) > mu_s
    world = _slope_world(uvms, theta, mu_s, mu_k, ContactLaw(1e5, 0.5))
    plant = Plant(uvms, world=world, backend=backend)
    q, _ = _on_slope(uvms, theta)
    states = _run(plant, q, np.zeros(uvms.nv), 2.0, step_s=2e-3, period_s=1e-2)
    downslope = np.array([-math.cos(theta), 0.0, -math.sin(theta)])
    m = DENSITY * RHO * A * B * C
    expected = _net_weight_N() * (math.sin(theta) - mu_k * math.cos(theta)) / (m + ADDED[0])
    # the speed along the slope (body x) between 0.5 s and 2 s
    speed = {t: float(pin.Quaternion(q[3:7]).matrix() @ v[:3] @ downslope) for t, q, v in states}
    measured = (speed[2.0] - speed[0.5]) / 1.5
    assert measured == pytest.approx(expected, rel=0.02)


def _sphere(load_body, radius, relative_density, added):
    volume = 4.0 / 3.0 * math.pi * radius**3
    m = relative_density * RHO * volume
    inertia = (0.4 * m * radius**2,) * 3
    hydro = hydro_xml(volume, added=(added, added, added, 0, 0, 0))
    urdf = body_urdf(mass=m, inertia=inertia, hydro=hydro, collision=f'<sphere radius="{radius}"/>')
    return load_body(urdf), m, volume


def _impact_oracle(mass_kg, net_weight_N, law, speed_in):
    """The rebound speed of the 1-D impact m x'' = -W' + f_n(delta, delta_dot)."""

    def rhs(_t, y):
        depth, rate = y  # depth and its rate (into the floor)
        force = law.stiffness_N_m * depth * max(0.0, 1.0 + law.dissipation_s_m * rate)
        return [rate, (net_weight_N - force) / mass_kg]

    def out(_t, y):
        return y[0]

    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, (0, 5), [0.0, speed_in], events=out, rtol=1e-11, atol=1e-13)
    return -sol.y_events[0][0][1]


# the Python reference once (5 s a run; the compiled runs agree with it to 1e-12,
# tests/physics/test_world_compiled.py)
@pytest.mark.parametrize(
    ("dissipation", "backend"),
    [(0.0, "core"), (0.3, "core"), (1.0, "core"), (0.3, "python")],
)
def test_a_dropped_sphere_rebounds_as_the_contact_damping_says(load_body, dissipation, backend):
    radius, added = 0.2, 20.0
    uvms, m, volume = _sphere(load_body, radius, 2.0, added)
    law = ContactLaw(stiffness_N_m=2e5, dissipation_s_m=dissipation)
    world = World(uvms, [plane("seafloor", [0, 0, FLOOR_Z], [0, 0, 1], 0.6, 0.5)], law)
    plant = Plant(uvms, world=world, free_surface=False, backend=backend)
    q = uvms.neutral_configuration()
    q[2] = FLOOR_Z + radius + 0.05
    v = np.zeros(uvms.nv)
    # the first impact: it lands after 0.16 s and leaves before 0.24 s
    states = _run(plant, q, v, 0.3, step_s=1e-4, period_s=1e-3)
    heave = np.array([s[2][2] for s in states])
    height = np.array([s[1][2] for s in states]) - (FLOOR_Z + radius)  # > 0: apart
    first = int(np.flatnonzero(height < 0.0)[0])
    last = first + int(np.flatnonzero(height[first:] >= 0.0)[0]) - 1  # the first impact
    net = (m - RHO * volume) * G
    # the samples straddle the contact's edges: in free flight (no drag here) the speed at
    # the edge follows from the sample's by the net weight's constant deceleration
    g_net = net / (m + added)
    speed_in = math.sqrt(heave[first - 1] ** 2 + 2 * g_net * height[first - 1])
    speed_out = math.sqrt(heave[last + 1] ** 2 + 2 * g_net * height[last + 1])
    expected = _impact_oracle(m + added, net, law, speed_in)
    assert speed_out == pytest.approx(expected, rel=2e-3, abs=2e-3 * speed_in)
    assert speed_out <= speed_in * (1.0 + 1e-6)
    energy = np.array(
        [
            up.kinetic_energy(uvms, s[1], s[2])
            + up.potential_energy(uvms, s[1])
            + 0.5 * law.stiffness_N_m * max(0.0, FLOOR_Z + radius - s[1][2]) ** 2
            for s in states
        ]
    )
    scale = 0.5 * (m + added) * speed_in**2  # the energy of the impact
    # never gained in contact (beyond RK4's error); kept whole without dissipation
    assert np.max(np.diff(energy)) <= 1e-6 * scale
    if dissipation == 0.0:
        assert speed_out == pytest.approx(speed_in, rel=1e-4)
        assert np.ptp(energy) <= 1e-5 * scale
    else:
        assert energy[-1] < energy[0] - 0.05 * scale


@LONG_RUN_BACKEND
def test_a_sphere_rests_on_a_box_object_through_coal(load_body, backend):
    radius = 0.2
    uvms, m, volume = _sphere(load_body, radius, 2.0, 20.0)

    box = solid("block", "box", {"size_m": [1.0, 1.0, 0.4]}, [0, 0, FLOOR_Z], [0, 0, 0], 0.6, 0.5)
    world = World(uvms, [box], ContactLaw(stiffness_N_m=1e5, dissipation_s_m=2.0))
    plant = Plant(uvms, world=world, free_surface=False, backend=backend)
    q = uvms.neutral_configuration()
    q[2] = FLOOR_Z + 0.2 + radius + 0.005
    states = _run(plant, q, np.zeros(uvms.nv), 5.0)
    _, q_end, v_end = states[-1]
    forces = plant.world_forces(q_end, v_end)
    assert len(forces.touch) == 1 and forces.touch.corner[0] == -1  # coal's point
    assert forces.force_world_N.sum(axis=0) == pytest.approx(
        [0.0, 0.0, (m - RHO * volume) * G], abs=1e-6 * m * G
    )


def test_the_plant_is_unchanged_when_nothing_is_near(reference_uvms):
    uvms = reference_uvms
    far = [
        plane("seafloor", [0, 0, -50.0], [0.1, 0, 1], 0.6, 0.5),
        solid("rock", "sphere", {"radius_m": 1.0}, [30.0, 0, -5], [0, 0, 0], 0.6, 0.5),
        solid(
            "pipe", "cylinder", {"radius_m": 0.3, "length_m": 5.0}, [0, 20, -5], [1, 0, 0], 0.6, 0.5
        ),
    ]
    rng = np.random.default_rng(3)
    for backend in ("core", "python"):
        bare = Plant(uvms, free_surface=False, backend=backend)
        with_world = Plant(uvms, free_surface=False, backend=backend, world=World(uvms, far))
        for _ in range(5):
            q = uvms.neutral_configuration()
            q[:3] = rng.uniform(-1, 1, 3)
            v = rng.normal(size=uvms.nv)
            tau = rng.normal(size=uvms.nv)
            a0 = bare.acceleration(0.0, q, v, tau)
            a1 = with_world.acceleration(0.0, q, v, tau)
            assert np.allclose(a1, a0, rtol=1e-12, atol=1e-12 * np.abs(a0).max())
        assert len(with_world.world_forces(q, v).touch) == 0


def test_each_body_and_object_pair_logs_its_own_wrench(reference_uvms):
    """`World.pair_wrenches`: one row per (body, object), body-major (body * n_objects +
    object): the sum of its points' forces, their normal-force-weighted centre and the
    forces' moment about it (the points' mean when they carry no normal force); a pair
    without a point is zeros. Points of the vehicle's hull on the seafloor (two) and of the
    arm's last link on a rock and on the seafloor."""
    floor = plane("seafloor", [0.0, 0.0, -10.0], [0.0, 0.0, 1.0], 0.6, 0.5)
    rock = solid("rock", "box", {"size_m": [0.3] * 3}, [1.0, 0.0, -9.85], [0.0] * 3, 0.6, 0.5)
    world = World(reference_uvms, [floor, rock], ContactLaw())
    bodies = [p.body for p in world.pieces]
    hull, tip = bodies.index(min(bodies)), bodies.index(max(bodies))
    assert bodies[hull] != bodies[tip]
    piece, obj = np.array([hull, hull, tip, tip]), np.array([0, 0, 1, 0])
    point = np.array([[0.0, 0, -10], [0.2, 0, -10], [1.0, 0, -9.7], [0.5, 0.5, -10]])
    force = np.array([[1.0, 0, 10], [0.0, 2, 30], [-5.0, 0, 0], [0.0, 0, 7]])
    normal_N = np.array([10.0, 30.0, 5.0, 7.0])
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    touch = Touch(piece, obj, np.full(4, -1), point, normals, np.zeros(4), np.zeros((4, 3)))
    out = world.pair_wrenches(ContactForces(touch, force, normal_N, np.ones(4, dtype=bool)))
    assert out.shape == (2 * len(world.body_names), 9)
    row = {(bodies[hull], 0): [0, 1], (bodies[tip], 1): [2], (bodies[tip], 0): [3]}
    for (body, k), mine in row.items():
        center = normal_N[mine] @ point[mine] / normal_N[mine].sum()
        moment = np.cross(point[mine] - center, force[mine]).sum(axis=0)
        expected = np.concatenate([force[mine].sum(axis=0), center, moment])
        np.testing.assert_allclose(out[2 * body + k], expected, rtol=0, atol=1e-12)
    written = [2 * body + k for body, k in row]
    assert not np.any(np.delete(out, written, axis=0))
    # points that carry no normal force (separating fast: the law's max(0, .)): the mean
    idle = world.pair_wrenches(ContactForces(touch, force, np.zeros(4), np.ones(4, dtype=bool)))
    np.testing.assert_allclose(idle[2 * bodies[hull], 3:6], point[:2].mean(axis=0), atol=1e-15)
