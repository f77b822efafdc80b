"""The derivatives of the plant's acceleration with world contacts
(`uvms_pin.physics.derivatives.world_contact`, through `Plant.acceleration_derivatives`):
the robot's corners on a seafloor plane, flat and tilted, new contacts and anchored ones,
sticking and slipping patches, against 4-point central differences of `Plant.acceleration`
(the reference backend) with the friction's memory held; states where a corner is within
reach of the plane, or a patch near its cone, are not used (the active set is frozen)."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, mount_on_reference_vehicle

from uvms_pin.errors import ParameterError
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.physics.world.world import World
from uvms_pin.sim.plant import Plant

FD_REL = 1e-6
STEP = 1e-6
MARGIN_M = 2e-4  # no corner this close to the plane: the active set holds over the stencil


@pytest.fixture(scope="module", params=["reference", "ur5"])
def uvms(request, reference_uvms, tmp_path_factory):
    if request.param == "reference":
        return reference_uvms
    return mount_on_reference_vehicle("ur5", tmp_path_factory.mktemp("ur5"))


def _corner_heights(world: World, q: np.ndarray, normal: np.ndarray) -> np.ndarray:
    model = world.uvms.model
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    out = []
    for piece in world.pieces:
        if piece.corners_m is None:
            continue
        where = data.oMi[piece.joint_id] * piece.placement_in_joint
        out.append((where.translation + piece.corners_m @ where.rotation.T) @ normal)
    return np.concatenate(out)


def _on_the_floor(uvms, rng, normal):
    """(plant, q, v, tau): the vehicle tilted at random, the plane 6-12 mm above its lowest
    corner along ``normal``, no corner within MARGIN_M of it."""
    for _ in range(200):
        q = uvms.neutral_configuration()
        q[:3] = [0.3, -0.2, -3.0]
        q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.normal(scale=0.15, size=3))).coeffs()
        lo = np.maximum(uvms.model.lowerPositionLimit[7:], -np.pi)
        hi = np.minimum(uvms.model.upperPositionLimit[7:], np.pi)
        q[7:] = rng.uniform(lo, hi)
        probe = World(uvms, [plane("floor", [0, 0, 0], normal, 0.6, 0.5)])
        heights = _corner_heights(probe, q, probe.objects[0].normal_world)
        level = heights.min() + rng.uniform(0.006, 0.012)
        if np.min(np.abs(heights - level)) < MARGIN_M:
            continue
        point = level * probe.objects[0].normal_world
        world = World(uvms, [plane("floor", point, normal, 0.6, 0.5)])
        plant = Plant(uvms, world=world, backend="python")
        v = rng.normal(scale=0.05, size=uvms.nv)
        return plant, q, v, rng.normal(scale=5.0, size=uvms.nv)
    raise AssertionError("no state clear of the plane's kinks")


def _relative_error(got, expected) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


def _assert_matches(plant, q, v, tau, time_s=0.1):
    uvms = plant.uvms
    integrate = lambda x, dx: pin.integrate(uvms.model, x, dx)  # noqa: E731
    accel = plant.acceleration
    expected = (
        central_difference(lambda x: accel(time_s, x, v, tau), q, uvms.nv, STEP, integrate),
        central_difference(lambda x: accel(time_s, q, x, tau), v, uvms.nv, STEP),
        central_difference(lambda x: accel(time_s, q, v, x), tau, uvms.nv, 1e-3),
    )
    got = plant.acceleration_derivatives(time_s, q, v, tau)
    errors = [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]
    assert max(errors) < FD_REL, errors


def _anchor(plant, q, v, offset_m, slipping: bool):
    """Anchor every contact point ``offset_m`` away along the plane (a patch slipping or
    not); returns the contact forces then."""
    forces = plant.world_forces(q, v)
    normal = forces.touch.normal_world[0]
    tangent = np.cross(normal, [1.0, 0.0, 0.0])
    tangent /= np.linalg.norm(tangent)
    for key, point in zip(forces.touch.keys(), forces.touch.point_world_m, strict=True):
        plant.friction.anchors[key] = point + offset_m * tangent
    if slipping:
        patches = forces.touch.piece * len(plant.world.objects) + forces.touch.obj
        plant.friction.slipping.update(int(p) for p in patches)
    return plant.world_forces(q, v)


@pytest.mark.parametrize("normal", [[0, 0, 1], [0.2, -0.1, 1.0]], ids=["flat", "tilted"])
def test_new_contacts_match_finite_differences(uvms, normal):
    """Fresh contacts (anchored where they are: no spring stretch)."""
    rng = np.random.default_rng(61)
    plant, q, v, tau = _on_the_floor(uvms, rng, np.array(normal, dtype=float))
    assert len(plant.world_forces(q, v).touch) >= 2
    _assert_matches(plant, q, v, tau)


def test_sticking_anchored_contacts_match_finite_differences(uvms):
    rng = np.random.default_rng(62)
    plant, q, v, tau = _on_the_floor(uvms, rng, np.array([0.0, 0.0, 1.0]))
    forces = _anchor(plant, q, v, 2e-4, slipping=False)
    assert np.all(forces.sticking)
    _assert_matches(plant, q, v, tau)


def test_slipping_contacts_match_finite_differences(uvms):
    rng = np.random.default_rng(63)
    plant, q, v, tau = _on_the_floor(uvms, rng, np.array([0.0, 0.0, 1.0]))
    forces = _anchor(plant, q, v, 0.05, slipping=True)
    assert not np.any(forces.sticking)
    _assert_matches(plant, q, v, tau)


def test_the_contact_terms_are_needed(reference_uvms):
    """Without the contacts' own derivative (their force held) the Jacobian misses."""
    rng = np.random.default_rng(64)
    plant, q, v, tau = _on_the_floor(reference_uvms, rng, np.array([0.0, 0.0, 1.0]))
    got = plant.acceleration_derivatives(0.1, q, v, tau)
    forces = plant.world_forces(q, v)
    from uvms_pin.physics.dynamics import forward_dynamics_derivatives

    held = forward_dynamics_derivatives(
        reference_uvms,
        q,
        v,
        tau,
        tau_ext=plant.world.generalized_force(q, plant._world_data, forces),
        backend="python",
        free_surface=True,
    )
    assert _relative_error(held[0], got[0]) > 1e-2


def test_a_solid_object_s_contact_is_refused(reference_uvms):
    rng = np.random.default_rng(65)
    plant, q, v, tau = _on_the_floor(reference_uvms, rng, np.array([0.0, 0.0, 1.0]))
    level = plant.world.objects[0].placement.translation[2]
    rock = solid(
        "rock", "box", {"size_m": [4.0, 4.0, 1.0]}, [0.3, -0.2, level - 0.5], [0, 0, 0], 0.6, 0.5
    )
    world = World(reference_uvms, [rock])
    boxed = Plant(reference_uvms, world=world, backend="python")
    assert len(boxed.world_forces(q, v).touch)
    with pytest.raises(ParameterError, match="coal's deepest point"):
        boxed.acceleration_derivatives(0.1, q, v, tau)


def test_the_core_backend_gives_the_reference(reference_uvms):
    """The plant on the core: the whole compiled (src/uvms_core/plant_derivatives.cpp), the
    same (tests/physics/derivatives/test_world_contact_core.py: every case)."""
    rng = np.random.default_rng(66)
    plant, q, v, tau = _on_the_floor(reference_uvms, rng, np.array([0.0, 0.0, 1.0]))
    _anchor(plant, q, v, 2e-4, slipping=False)
    python = plant.acceleration_derivatives(0.1, q, v, tau)
    compiled = Plant(reference_uvms, world=plant.world, backend="core")
    compiled.friction = plant.friction
    core = compiled.acceleration_derivatives(0.1, q, v, tau)
    for a, b in zip(core, python, strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * np.abs(b).max())


def _lowest_points(world: World, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(every corner's height, every sphere's lowest height) along z (world)."""
    model = world.uvms.model
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    spheres = []
    for piece in world.pieces:
        if isinstance(piece.shape, coal.Sphere):
            where = data.oMi[piece.joint_id] * piece.placement_in_joint
            spheres.append(where.translation[2] - piece.shape.radius)
    return _corner_heights(world, q, np.array([0.0, 0.0, 1.0])), np.array(spheres)


@pytest.mark.parametrize("anchored", [False, True, "rolled"], ids=["new", "anchored", "rolled"])
def test_a_sphere_on_the_floor_matches_finite_differences(anchored):
    """The BlueROV2 + Alpha 5 (its links are spheres): a link resting on the seafloor, its
    contact point sliding on the sphere as the state moves; "rolled": its stretch measured
    from a material point a few mm off the contact point (where the period began), the
    compiled derivatives the same."""
    import warnings

    import uvms_pin as up
    from uvms_pin.model.resources import shipped_path

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        uvms = up.load_uvms(shipped_path("models/uvms_bluerov2_alpha5.urdf"))
    rng = np.random.default_rng(67)
    probe = World(uvms, [plane("floor", [0, 0, -50.0], [0, 0, 1], 0.6, 0.5)])
    for _ in range(500):
        q = uvms.neutral_configuration()
        q[:3] = [0.3, -0.2, -3.0]
        q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.normal(scale=0.3, size=3))).coeffs()
        lo = np.maximum(uvms.model.lowerPositionLimit[7:], -np.pi)
        hi = np.minimum(uvms.model.upperPositionLimit[7:], np.pi)
        q[7:] = rng.uniform(lo, hi)
        corners, spheres = _lowest_points(probe, q)
        level = spheres.min() + rng.uniform(0.004, 0.01)
        everything = np.r_[corners, spheres]
        if corners.min() > spheres.min() and np.min(np.abs(everything - level)) > MARGIN_M:
            break
    else:
        raise AssertionError("no state with a sphere on the floor clear of the kinks")
    world = World(uvms, [plane("floor", [0, 0, level], [0, 0, 1], 0.6, 0.5)])
    plant = Plant(uvms, world=world, backend="python")
    v, tau = rng.normal(scale=0.05, size=uvms.nv), rng.normal(scale=5.0, size=uvms.nv)
    forces = plant.world_forces(q, v)
    assert np.any(forces.touch.corner < 0)  # a sphere's point
    if anchored:
        _anchor(plant, q, v, 1e-4, slipping=False)
    if anchored == "rolled":
        data = uvms.model.createData()
        pin.forwardKinematics(uvms.model, data, q, v)
        for key, point in zip(forces.touch.keys(), forces.touch.point_world_m, strict=True):
            if key[2] < 0:
                joint = world.pieces[key[0]].joint_id
                local = data.oMi[joint].actInv(point)
                plant.friction.material[key] = local + np.array([1e-3, -2e-3, 5e-4])
        assert plant.world_forces(q, v).sticking.all()
    _assert_matches(plant, q, v, tau)
    if anchored == "rolled":
        python = plant.acceleration_derivatives(0.1, q, v, tau)
        compiled = Plant(uvms, world=world, backend="core")
        compiled.friction = plant.friction
        core = compiled.acceleration_derivatives(0.1, q, v, tau)
        for a, b in zip(core, python, strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * np.abs(b).max())
