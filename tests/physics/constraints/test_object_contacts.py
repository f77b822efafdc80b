"""Free objects on the fixed world as rigid contacts (`uvms_pin.physics.constraints.
object_contacts`, `uvms_pin.physics.world.gaps`): the candidate points, a box resting on its
net weight, the compiled period against the Python reference, and the scenario's key."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, body_urdf, hydro_xml
from free_object_helpers import undamped

from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.object_contacts import ObjectWorldContacts
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.gaps import candidates
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

PERIOD_S = 2e-3
#: compiled (projected Gauss-Seidel to 1e-10 m/s) against the reference (Pinocchio's ADMM
#: to 1e-8 m/s): a second of sliding, rolling and an impact agree to this (3e-6 measured)
AGREEMENT = 1e-5


def _pusher(load_body):
    return load_body(
        body_urdf(
            mass=4.0, inertia=(0.016,) * 3, hydro=hydro_xml(4.0 / RHO),
            collision='<sphere radius="0.1"/>',
        )
    )  # fmt: skip


def _object(kind: str, sizes: dict, position, rpy=(0.0, 0.0, 0.0), velocity=None):
    return undamped(
        free_object(
            kind, kind, sizes, (np.asarray(position, float), np.asarray(rpy, float)),
            density_kg_m3=2000.0, water_density_kg_m3=RHO, friction=(0.6, 0.5),
            velocity_body=velocity,
        )
    )  # fmt: skip


def _run(system: System, periods: int, compiled: bool):
    """(the states after each period, the system) from the scenario's start."""
    system.compiled_allowed = compiled
    robot = system.plant.uvms
    q = robot.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]
    state = system.initial_state(q, np.zeros(robot.nv))
    system.start(state)
    q_s, v_s = state.q, state.v
    out = []
    for k in range(periods):
        t0 = k * PERIOD_S
        q_s, v_s = system.advance(RK4(5e-4), t0, q_s, v_s, np.zeros(robot.nv), t0 + PERIOD_S)
        out.append(np.concatenate([q_s, v_s]))
    return np.array(out)


def _scene(load_body, contact: str = "rigid") -> System:
    """A box sliding down a 40-degree slope (its corners on a plane) and a sphere thrown
    along the seafloor at a fixed box (coal's points on a plane and on a solid), sliding,
    then rolling, then stopped by the box."""
    floor = plane("seafloor", [0.0, 0.0, -10.0], [0.0, 0.0, 1.0], 0.6, 0.5)
    tilt = math.radians(40.0)
    slope = plane("slope", [3.0, 0.0, -10.0], [-math.sin(tilt), 0.0, math.cos(tilt)], 0.6, 0.5)
    rock = solid("rock", "box", {"size_m": [0.3, 0.3, 0.3]}, [0.0, 0.6, -9.85], [0.0] * 3, 0.6, 0.5)
    on_slope = np.array([3.5, 0.0, -10.0 + 0.5 * math.tan(tilt)])
    normal = np.array([-math.sin(tilt), 0.0, math.cos(tilt)])
    box = _object("box", {"size_m": [0.2, 0.3, 0.1]}, on_slope + 0.05 * normal, (0.0, -tilt, 0.0))
    ball = _object("sphere", {"radius_m": 0.1}, [0.0, 0.0, -9.9], velocity=[0, 1.5, 0, 0, 0, 0])
    world = World(
        _pusher(load_body), [floor, slope, rock], ContactLaw(), [box, ball],
        fixed_contact=contact,
    )  # fmt: skip
    return System(Plant(world.uvms, world=world, free_surface=False))


def test_a_cylinder_on_a_plane_touches_by_its_rims_lowest_points_and_a_sphere_by_coals(
    load_body,
):
    floor = plane("seafloor", [0.0, 0.0, -10.0], [0.0, 0.0, 1.0], 0.6, 0.5)
    lying = _object("cylinder", {"radius_m": 0.1, "length_m": 0.4}, [0, 0, -9.88], (1.2, 0, 0))
    ball = _object("sphere", {"radius_m": 0.1}, [0.0, 0.0, -9.95])
    world = World(_pusher(load_body), [floor], ContactLaw(), [lying, ball])
    system = System(Plant(world.uvms, world=world, free_surface=False))
    for obj, own in zip(world.free, system.moving.moving.object_worlds, strict=True):
        data = obj.uvms.model.createData()
        pin.forwardKinematics(obj.uvms.model, data, obj.q0)
        found = candidates(data, own.pieces, own.objects, own.bounds, 0.0)
        rotation = pin.Quaternion(obj.q0[3:]).matrix()
        if obj.kind == "cylinder":  # the two rims' lowest points, 0.1 / cos(tilt) low
            assert [c.corner for c in found] == [-2, -3]
            axis = rotation[:, 2]
            for c in found:
                center = obj.q0[:3] + axis * (axis @ (c.point_world_m - obj.q0[:3]))
                assert abs(axis @ (c.point_world_m - obj.q0[:3])) == pytest.approx(0.2)
                assert np.linalg.norm(c.point_world_m - center) == pytest.approx(0.1)
                assert c.gap_m == pytest.approx(c.point_world_m[2] + 10.0, abs=1e-12)
            assert min(c.gap_m for c in found) < 0.0  # one rim inside: 0.12 m + reach
        else:  # coal's signed distance: the centre's height less the radius, inside
            (c,) = found
            assert c.corner == -1  # coal's one point of the pair, not a corner
            assert c.gap_m == pytest.approx(-0.05, abs=1e-9)
            np.testing.assert_allclose(c.point_world_m, obj.q0[:3] - [0, 0, 0.1], atol=1e-9)


@pytest.mark.parametrize("compiled", [False, True], ids=["python", "compiled"])
def test_a_box_on_rigid_contacts_rests_on_its_net_weight_without_sinking(load_body, compiled):
    """At rest on its four corners, on the Python reference and in the compiled system: it
    neither sinks nor lifts, its contacts' mean forces (the solved impulses over the period,
    world axes) add up to its net weight, straight up, each along its corner's normal."""
    floor = plane("seafloor", [0.0, 0.0, -10.0], [0.0, 0.0, 1.0], 0.6, 0.5)
    box = _object("box", {"size_m": [0.2, 0.3, 0.1]}, [0.0, 0.0, -9.95])
    world = World(_pusher(load_body), [floor], ContactLaw(), [box])
    system = System(Plant(world.uvms, world=world, free_surface=False))
    states = _run(system, 250, compiled=compiled)
    robot = system.plant.uvms
    z = states[:, robot.nq + 2]
    assert np.max(np.abs(z + 9.95)) < 1e-9  # neither sinks nor lifts
    q, v = states[-1][:14], states[-1][14:]  # the robot's and the box's (7 + 7, 6 + 6)
    (forces,) = system.moving.found(q[:7], v[:6], [(q[7:], v[6:])])[1]
    weight = -box.uvms.net_buoyancy_N
    assert len(forces.touch) == 4
    assert forces.normal_N.sum() == pytest.approx(weight, rel=1e-6)
    total = forces.force_world_N.sum(axis=0)
    np.testing.assert_allclose(total, [0.0, 0.0, weight], rtol=1e-6, atol=1e-6 * weight)
    np.testing.assert_allclose(forces.force_world_N[:, 2], forces.normal_N, rtol=1e-9)
    assert np.all(forces.sticking)


@pytest.mark.parametrize("periods", [500])
def test_the_compiled_period_is_the_python_reference_to_the_solvers_tolerance(load_body, periods):
    python = _run(_scene(load_body), periods, compiled=False)
    compiled_system = _scene(load_body)
    compiled = _run(compiled_system, periods, compiled=True)
    assert compiled_system.compiled is not None
    np.testing.assert_allclose(compiled, python, rtol=0.0, atol=AGREEMENT)
    moved = np.abs(python[-1] - python[0])
    assert moved.max() > 0.1  # the scene moves: the agreement is not that of rest


def test_the_world_says_how_free_objects_touch_it(load_body):
    floor = plane("seafloor", [0.0, 0.0, -10.0], [0.0, 0.0, 1.0], 0.6, 0.5)
    box = _object("box", {"size_m": [0.2, 0.3, 0.1]}, [0.0, 0.0, -9.95])
    pusher = _pusher(load_body)
    rigid = System(
        Plant(pusher, world=World(pusher, [floor], ContactLaw(), [box]), free_surface=False)
    )
    assert rigid.object_contacts is not None
    assert rigid.log.record()["world"]["fixed_contact"] == "rigid"
    soft = World(pusher, [floor], ContactLaw(), [box], fixed_contact="compliant")
    assert System(Plant(pusher, world=soft, free_surface=False)).object_contacts is None
    with pytest.raises(ParameterError, match="fixed_contact must be one of rigid"):
        World(pusher, [floor], ContactLaw(), [box], fixed_contact="soft")


def test_a_contact_a_spin_brings_within_the_period_is_solved(load_body):
    """A contact is solved when its gap can close within the period at the object's speed,
    its spin included (the normal rate J_n v at the point, omega x r in it): a bar 3 m long
    4 mm above the seafloor, level, turning about x at 2 rad/s: its end at y = -1.5 m comes
    down at 3 m/s, 6 mm in a 2 ms period, so its corners there are solved now (its centre
    does not move: counting the linear speed alone, with the 1 mm margin, they would be
    left until they were in). At rest, nothing is solved; the margin must be a length."""
    floor = plane("seafloor", [0.0, 0.0, -10.0], [0.0, 0.0, 1.0], 0.6, 0.5)
    spin = [0.0, 0.0, 0.0, 2.0, 0.0, 0.0]  # about x: the end at y = -1.5 m goes down
    rows = {}
    for name, velocity in (("spinning", spin), ("at rest", None)):
        bar = _object("box", {"size_m": [0.2, 3.0, 0.1]}, [0.0, 0.0, -9.946], velocity=velocity)
        world = World(_pusher(load_body), [floor], ContactLaw(), [bar])
        system = System(Plant(world.uvms, world=world, free_surface=False))
        robot = system.plant.uvms
        q = robot.neutral_configuration()
        q[:3] = [20.0, 0.0, -5.0]
        state = system.initial_state(q, np.zeros(robot.nv))
        model, data = system.model, system.model.createData()
        pin.computeJointJacobians(model, data, state.q)
        found = system.object_contacts.rows(model, data, state.q, np.abs(state.v), PERIOD_S)
        rows[name] = found
    assert rows["at rest"].size == 0
    spinning = rows["spinning"]
    assert spinning.size >= 6  # at least the two corners going down
    corners = np.array([c.point.point_world_m for c in spinning.where])
    assert np.all(np.abs(corners[:, 1]) == pytest.approx(1.5))
    assert np.all(corners[:, 2] == pytest.approx(-9.996))  # 4 mm up
    with pytest.raises(ParameterError, match="margin must be >= 0"):
        ObjectWorldContacts([None], [1], [None], margin=-1e-3)
