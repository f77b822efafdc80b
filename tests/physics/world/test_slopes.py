"""A sphere, a cylinder and a box released on 10 and 40 degree slopes in the water: the
analytic rolling, sliding or sticking acceleration, and a mechanical energy that never rises.

The body (mass m, volume V, in water of density rho; its hydrodynamic drag left out, its
buoyancy and added mass kept) rests on a slope of angle theta. Along the slope's downhill
direction d its net weight pulls with F = (m - rho V) g sin(theta) and presses with
N = (m - rho V) g cos(theta) (the buoyancy acts at the centroid: no moment).

Rolling without slip (a sphere or a cylinder of radius r, lying across the slope): the
velocity is s_dot u, u = [d; (n x d) / r] (the body's twist per unit speed, n the slope's
normal), and Lagrange's equation with the kinetic energy 1/2 s_dot^2 u^T M u (M the 6 x 6
mass matrix, added mass included) gives

    a = F / (u^T M u) = (m - rho V) g sin(theta) / (m + m_added + (I + I_added) / r^2),

m_added the added mass along d, I and I_added the rigid and added inertia about the rolling
axis (a sphere: m_added = rho V / 2, I = 2/5 m r^2, I_added = 0; u^T M u is taken from the
object's own mass matrix, the sphere's checked against these closed forms). It rolls while
the friction this needs, f = F - (m + m_added) a, is within mu_s N.

Otherwise (a box: it cannot roll) it sticks while tan(theta) <= mu_s (a = 0), and slides
beyond with

    a = (m - rho V) g (sin(theta) - mu_k cos(theta)) / (m + m_added).

Coulomb's mu_s and mu_k are the regime switch: the box (mu_s = 0.6) sticks at 10 degrees
(tan = 0.18) and slides at 40 (tan = 0.84); the sphere and the cylinder need
f / N = 0.25 tan(theta) and 0.26 tan(theta) and roll at both.

The acceleration is the second derivative of a quadratic fitted to the distance travelled
from 0.2 s to 1 s (the first 0.2 s: the stick springs taking their load), within 2 % of the
analytic one; a sticking box creeps less than 1 mm (its stick springs' stretch, the load
over 4 k_t, and its tilt on its compliant corners) and comes to rest (its fitted
acceleration below 0.01 m/s^2). The penalty contact
sinks a body by delta = N / (n k) (3 mm for the sphere at the default k): a sphere rolls
about coal's point, r - delta / 2 from its centre, 0.8 % slower than the rigid r at 10
degrees. The cylinder touches a plane by the 2 x 16 corners of its rims' prism
(`uvms_pin.physics.world.robot_geometry`): it rolls as a 16-gon, each corner landing with an
impact that takes energy, and about corners delta deep: 4.0 % slower than the smooth
cylinder at 10 degrees, 2.3 % at 40. That is the contact's geometry, not its friction (the
cylinder rolled so before the friction's material points); within 5 %, and the 2 % of the
smooth cylinder is expected to fail (strict xfail) until its rims touch as circles.

The mechanical energy E = T + (m - rho V) g z + 1/2 k sum delta_i^2 + 1/2 k_t sum |s_i|^2
(kinetic with the added mass, gravity with the buoyancy, what the normal springs and the
stick springs of the sticking points hold; a slipping point's friction is Coulomb's kinetic
one, its anchor following) never rises by more than 1e-4 of the kinetic energy gained over
the run (1e-4 J at least), read after each control period. It cannot stay within 1e-9 J:
the contact dissipates (Hunt-Crossley's damper, the tangential damper, the kinetic friction)
but a rolling sphere's stick spring is measured at the material point that was at the
contact when the period began, while its force acts at the contact point. Over a period that
point leaves the contact along a cycloid, its tangential drift r (omega dt)^3 / 6, and the
spring gains k_t |s| times it with no work done by the force: a rise of the order of the
stick spring's energy, third order in omega dt. Measured: the sphere gains 1.3e-5 J at 10
degrees and 2.4e-3 J at 40 (49 J of kinetic energy at 1 s, 24 rad/s); the box and the
cylinder never gain. Before the stretch was measured from material points a sphere on an
8-degree slope gained 8.1 J in 1 s and spun at 19.7 rad/s while moving 2 cm.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, G, body_urdf, hydro_xml
from free_object_helpers import undamped

import uvms_pin as up
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

DENSITY = 2600.0  # a rock's
MU = (0.6, 0.5)
PERIOD_S, STEP_S, DURATION_S = 2e-3, 5e-4, 1.0
SHAPES = {
    "sphere": {"radius_m": 0.1},
    "cylinder": {"radius_m": 0.1, "length_m": 0.3},
    "box": {"size_m": [0.2, 0.2, 0.2]},
}
#: the points a resting body touches the slope by (its resting depth: N / (points k))
POINTS = {"sphere": 1, "cylinder": 2, "box": 4}
#: the rise of the mechanical energy allowed, relative to the kinetic energy gained
ENERGY_RISE = 1e-4
#: ... on rigid contacts [J]
RIGID_RISE_J = 1e-9


@dataclasses.dataclass
class Slope:
    """A body on a slope: its system, directions and analytic acceleration."""

    system: System
    obj: object
    down: np.ndarray
    normal: np.ndarray
    expected_m_s2: float
    regime: str
    u: np.ndarray  # the body twist per unit speed down the slope (LOCAL)


def _slope(load_body, kind: str, theta_deg: float, contact: str = "rigid") -> Slope:
    theta = math.radians(theta_deg)
    normal = np.array([-math.sin(theta), 0.0, math.cos(theta)])  # rising towards +x
    down = -np.array([math.cos(theta), 0.0, math.sin(theta)])
    rotation = pin.rpy.rpyToMatrix(0.0, -theta, 0.0)  # its z along the slope's normal
    if kind == "cylinder":  # lying across the slope, its axis along y
        rotation = rotation @ pin.rpy.rpyToMatrix(math.pi / 2, 0.0, 0.0)
    sizes = SHAPES[kind]
    half = sizes.get("radius_m") or sizes["size_m"][2] / 2
    law = ContactLaw()
    foot = np.array([0.0, 0.0, -10.0])

    def made(sunk_m: float):
        pose = (foot + normal * (half - sunk_m), pin.rpy.matrixToRpy(rotation))
        return undamped(
            free_object(
                "body", kind, sizes, pose, density_kg_m3=DENSITY, water_density_kg_m3=RHO,
                friction=MU,
            )
        )  # fmt: skip

    probe = made(0.0)
    m, volume = probe.mass_kg, probe.uvms.hydro_bodies[0].params.volume_m3
    net = (m - RHO * volume) * G
    # rigid: touching; compliant: at its resting depth
    sunk = 0.0 if contact == "rigid" else net * math.cos(theta) / (POINTS[kind] * law.stiffness_N_m)
    obj = made(sunk)
    mass = up.mass_matrix(obj.uvms, obj.q0)  # 6 x 6, LOCAL, added mass included
    rolls = kind != "box"
    spin = np.cross(normal, down) / half if rolls else np.zeros(3)
    u = np.r_[rotation.T @ down, rotation.T @ spin]
    force, load = net * math.sin(theta), net * math.cos(theta)
    translating = u[:3] @ mass[:3, :3] @ u[:3]  # m + m_added
    if rolls and force - translating * force / (u @ mass @ u) <= MU[0] * load:
        expected, regime = force / (u @ mass @ u), "rolls"
    elif math.tan(theta) <= MU[0]:
        expected, regime = 0.0, "sticks"
    else:
        expected = net * (math.sin(theta) - MU[1] * math.cos(theta)) / translating
        regime = "slides"
    pusher = load_body(
        body_urdf(
            mass=4.0,
            inertia=(0.016,) * 3,
            hydro=hydro_xml(4.0 / RHO),
            collision='<sphere radius="0.1"/>',
        )
    )  # fmt: skip  (the robot, far away: only the body moves on the slope)
    world = World(pusher, [plane("slope", foot, normal, *MU)], law, [obj], fixed_contact=contact)
    system = System(Plant(pusher, world=world, free_surface=False))
    return Slope(system, obj, down, normal, expected, regime, u)


def _energy(slope: Slope, q: np.ndarray, v: np.ndarray) -> float:
    """T + (m - rho V) g z + what the contact's springs hold [J]."""
    system, obj = slope.system, slope.obj
    (q_r, v_r), (q_o, v_o) = system.layout.split(q, v)
    law = system.plant.world.law
    weight = -obj.uvms.net_buoyancy_N
    if system.object_contacts is not None:  # rigid: no spring holds anything
        return up.kinetic_energy(obj.uvms, q_o, v_o) + weight * q_o[2]
    _, (forces,) = system.moving.found(q_r, v_r, [(q_o, v_o)])
    springs = 0.5 * law.stiffness_N_m * float(np.sum(forces.touch.depth_m**2))
    # a sticking point's stick spring holds 1/2 k_t |s|^2; a slipping point's friction is
    # Coulomb's kinetic one, not its spring's (the anchor follows it): nothing held
    stretch = np.linalg.norm(forces.stretch_m, axis=1)[forces.sticking]
    springs += 0.5 * law.tangential_stiffness_N_m * float(np.sum(stretch**2))
    return up.kinetic_energy(obj.uvms, q_o, v_o) + weight * q_o[2] + springs


def _released(slope: Slope):
    """(times (n,), distance down the slope (n,), energy (n + 1,), the last state)."""
    system = slope.system
    robot = system.plant.uvms
    q = robot.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]
    state = system.initial_state(q, np.zeros(robot.nv))
    system.start(state)
    q_sys, v_sys = state.q, state.v
    start = q_sys[robot.nq : robot.nq + 3].copy()
    times, distance, energy = [], [], [_energy(slope, q_sys, v_sys)]
    tau = np.zeros(robot.nv)
    for k in range(round(DURATION_S / PERIOD_S)):
        t0, t1 = k * PERIOD_S, (k + 1) * PERIOD_S
        q_sys, v_sys = system.advance(RK4(STEP_S), t0, q_sys, v_sys, tau, t1)
        times.append(t1)
        distance.append((q_sys[robot.nq : robot.nq + 3] - start) @ slope.down)
        energy.append(_energy(slope, q_sys, v_sys))
    return np.array(times), np.array(distance), np.array(energy), (q_sys, v_sys)


def _rise(energy: np.ndarray) -> float:
    """The largest rise of the energy over any earlier value: max_{s < t} E(t) - E(s)."""
    return float(np.max(energy - np.minimum.accumulate(energy)))


def test_the_sphere_s_effective_mass_is_the_closed_form(load_body):
    slope = _slope(load_body, "sphere", 10.0)
    m = slope.obj.mass_kg
    volume = 4.0 / 3.0 * math.pi * 0.1**3
    mass = up.mass_matrix(slope.obj.uvms, slope.obj.q0)
    closed = m + 0.5 * RHO * volume + 0.4 * m  # m + m_added + I / r^2
    assert slope.u @ mass @ slope.u == pytest.approx(closed, rel=1e-12)


def _as_the_analytic_case(slope: Slope, kind: str, theta_deg: float, within: float):
    """Runs ``slope`` and checks its regime; returns (its energy (n + 1,), its kinetic
    energy at the end [J])."""
    expected_regime = {"sphere": "rolls", "cylinder": "rolls"}.get(
        kind, "sticks" if theta_deg == 10.0 else "slides"
    )
    assert slope.regime == expected_regime
    times, distance, energy, (q_end, v_end) = _released(slope)
    _, (q, v) = slope.system.layout.split(q_end, v_end)  # the body's
    if slope.regime == "sticks":
        assert abs(distance[-1]) < 1e-3
        assert np.linalg.norm(v[:3]) < 1e-3  # at rest (rocking on its corners at 1 mrad/s)
        assert abs(_acceleration(times, distance)) < 0.01  # no creep building up
    else:
        assert _acceleration(times, distance) == pytest.approx(slope.expected_m_s2, rel=within)
    if slope.regime == "rolls":  # no slip: the spin is the speed over the radius
        speed = np.linalg.norm(v[:3])
        assert np.linalg.norm(v[3:]) == pytest.approx(speed / 0.1, rel=0.02)
    return energy, up.kinetic_energy(slope.obj.uvms, q, v)


@pytest.mark.parametrize("theta_deg", [10.0, 40.0])
@pytest.mark.parametrize("kind", ["sphere", "cylinder", "box"])
def test_on_rigid_contacts_it_rolls_slides_or_sticks_within_2_percent_and_never_gains_energy(
    load_body, kind, theta_deg
):
    slope = _slope(load_body, kind, theta_deg)
    energy, _ = _as_the_analytic_case(slope, kind, theta_deg, 0.02)
    assert _rise(energy) <= RIGID_RISE_J


@pytest.mark.parametrize("theta_deg", [10.0, 40.0])
@pytest.mark.parametrize(("kind", "within"), [("sphere", 0.02), ("cylinder", 0.05), ("box", 0.02)])
def test_on_compliant_contacts_it_rolls_slides_or_sticks_as_the_analytic_case(
    load_body, kind, within, theta_deg
):
    slope = _slope(load_body, kind, theta_deg, "compliant")
    energy, kinetic = _as_the_analytic_case(slope, kind, theta_deg, within)
    assert _rise(energy) <= ENERGY_RISE * max(kinetic, 1.0)


@pytest.mark.xfail(
    strict=True,
    reason="the compliant law touches a plane by a cylinder's rims' 16-gon prism: 2-4 % slow",
)
@pytest.mark.parametrize("theta_deg", [10.0, 40.0])
def test_on_compliant_contacts_a_cylinder_rolls_as_the_smooth_one_within_2_percent(
    load_body, theta_deg
):
    slope = _slope(load_body, "cylinder", theta_deg, "compliant")
    times, distance, _, _ = _released(slope)
    assert _acceleration(times, distance) == pytest.approx(slope.expected_m_s2, rel=0.02)


def _acceleration(times: np.ndarray, distance: np.ndarray) -> float:
    """The second derivative of the quadratic fitted from 0.2 s on [m/s^2]."""
    late = times >= 0.2
    return 2.0 * float(np.polyfit(times[late], distance[late], 2)[0])
