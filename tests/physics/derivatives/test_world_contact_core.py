"""The compiled world-contact derivatives (src/uvms_core/derivatives_world_contact.cpp, through
`Plant.acceleration_derivatives` on the core: src/uvms_core/plant_derivatives.cpp) against their
Python reference (`uvms_pin.physics.derivatives.world_contact`, the same plant on
``backend="python"``) to 1e-10 relative: the reference vehicle and a mounted UR5 with corners
on a seafloor and a wall at once, fresh contacts, anchored sticking ones and slipping
patches; a BlueROV2 + Alpha 5 sphere link on the seafloor; the compiled derivatives against
central differences of the compiled `Plant.acceleration`; a planted sign error in the
reference is seen; a solid object's contact refused by both."""

from __future__ import annotations

import warnings

import coal
import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, mount_on_reference_vehicle

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.flow import UniformCurrent
from uvms_pin.physics.derivatives import world_contact
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.physics.world.world import World
from uvms_pin.sim.plant import Plant

CORE_REL = 1e-10  # the compiled derivatives against the reference's
FD_REL = 1e-6  # against central differences of the plant's acceleration
MARGIN_M = 2e-4  # no contact point this close to a plane (the active set holds)
FLOOR, WALL = np.array([0.0, 0.0, 1.0]), np.array([0.9, -0.3, 0.1])


@pytest.fixture(scope="module", params=["reference", "ur5"])
def uvms(request, reference_uvms, tmp_path_factory):
    if request.param == "reference":
        return reference_uvms
    return mount_on_reference_vehicle("ur5", tmp_path_factory.mktemp("ur5"))


@pytest.fixture(scope="module")
def sphere_uvms():
    from uvms_pin.model.resources import shipped_path

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        return up.load_uvms(shipped_path("models/uvms_bluerov2_alpha5.urdf"))


def _lowest(world: World, q: np.ndarray, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(every corner's height, every sphere's lowest point's height) along ``normal``."""
    data = world.uvms.model.createData()
    pin.forwardKinematics(world.uvms.model, data, q)
    corners, spheres = [], []
    for piece in world.pieces:
        where = data.oMi[piece.joint_id] * piece.placement_in_joint
        if piece.corners_m is not None:
            corners.append((where.translation + piece.corners_m @ where.rotation.T) @ normal)
        elif isinstance(piece.shape, coal.Sphere):
            spheres.append([where.translation @ normal - piece.shape.radius])
    stack = lambda parts: np.concatenate(parts) if parts else np.zeros(0)  # noqa: E731
    return stack(corners), stack(spheres)


def _random_q(uvms, rng, tilt=0.15):
    q = uvms.neutral_configuration()
    q[:3] = [0.3, -0.2, -3.0]
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.normal(scale=tilt, size=3))).coeffs()
    lo = np.maximum(uvms.model.lowerPositionLimit[7:], -np.pi)
    hi = np.minimum(uvms.model.upperPositionLimit[7:], np.pi)
    q[7:] = rng.uniform(lo, hi)
    return q


def _touching_planes(uvms, rng, normals, spheres_first=False):
    """(world, q): one plane per normal, each 4-12 mm above the lowest corner (or sphere)
    along its normal, no point within MARGIN_M of any plane."""
    probe = World(uvms, [plane("probe", [0, 0, -50.0], [0, 0, 1], 0.6, 0.5)])
    for _ in range(500):
        q = _random_q(uvms, rng, 0.3 if spheres_first else 0.15)
        objects, clear = [], True
        for k, normal in enumerate(normals):
            unit = normal / np.linalg.norm(normal)
            corners, spheres = _lowest(probe, q, unit)
            deepest = spheres.min() if spheres_first else corners.min()
            if spheres_first and corners.min() <= deepest:
                clear = False
                break
            level = deepest + rng.uniform(0.004, 0.012)
            if np.min(np.abs(np.r_[corners, spheres] - level)) < MARGIN_M:
                clear = False
                break
            objects.append(plane(f"plane{k}", level * unit, unit, 0.6, 0.5))
        if clear:
            return World(uvms, objects), q
    raise AssertionError("no state clear of the planes' kinks")


def _pair(world, **kw) -> tuple[Plant, Plant]:
    """The plant on the reference and on the core, sharing the friction's memory."""
    python = Plant(world.uvms, world=world, backend="python", **kw)
    core = Plant(world.uvms, world=world, backend="core", **kw)
    core.friction = python.friction
    return python, core


def _anchor(plant, q, v, offset_m, slipping: bool):
    """Anchor every contact point ``offset_m`` away along its plane, its patch slipping or
    not; returns the contact forces then."""
    forces = plant.world_forces(q, v)
    for key, point, normal in zip(
        forces.touch.keys(), forces.touch.point_world_m, forces.touch.normal_world, strict=True
    ):
        tangent = np.cross(normal, [0.3, 1.0, 0.2])
        plant.friction.anchors[key] = point + offset_m * tangent / np.linalg.norm(tangent)
    if slipping:
        patches = forces.touch.piece * len(plant.world.objects) + forces.touch.obj
        plant.friction.slipping.update(int(p) for p in patches)
    return plant.world_forces(q, v)


def _relative_error(got, expected) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


def _errors(python, core, q, v, tau, time_s=0.1) -> list[float]:
    expected = python.acceleration_derivatives(time_s, q, v, tau)
    got = core.acceleration_derivatives(time_s, q, v, tau)
    return [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]


@pytest.mark.parametrize("state", ["new", "sticking", "slipping"])
def test_corners_on_a_floor_and_a_wall_match_the_reference(uvms, state):
    rng = np.random.default_rng({"new": 71, "sticking": 72, "slipping": 73}[state])
    for _ in range(3):
        world, q = _touching_planes(uvms, rng, [FLOOR, WALL])
        python, core = _pair(world, flow=UniformCurrent([0.2, -0.1, 0.0]))
        v = rng.normal(scale=0.05, size=uvms.nv)
        tau = rng.normal(scale=5.0, size=uvms.nv)
        forces = python.world_forces(q, v)
        assert set(forces.touch.obj) == {0, 1}  # the floor and the wall
        if state != "new":
            forces = _anchor(
                python, q, v, 2e-4 if state == "sticking" else 0.05, state == "slipping"
            )
            assert np.all(forces.sticking) == (state == "sticking")
            assert np.any(forces.sticking) == (state == "sticking")
        errors = _errors(python, core, q, v, tau)
        assert max(errors) < CORE_REL, errors


@pytest.mark.parametrize("anchored", [False, True], ids=["new", "anchored"])
def test_a_sphere_on_the_floor_matches_the_reference(sphere_uvms, anchored):
    rng = np.random.default_rng(74 + anchored)
    world, q = _touching_planes(sphere_uvms, rng, [FLOOR], spheres_first=True)
    python, core = _pair(world)
    v = rng.normal(scale=0.05, size=sphere_uvms.nv)
    tau = rng.normal(scale=5.0, size=sphere_uvms.nv)
    assert np.any(python.world_forces(q, v).touch.corner < 0)  # a sphere's point
    if anchored:
        _anchor(python, q, v, 1e-4, slipping=False)
    errors = _errors(python, core, q, v, tau)
    assert max(errors) < CORE_REL, errors


def test_a_sliding_sphere_matches_the_reference(sphere_uvms):
    rng = np.random.default_rng(76)
    world, q = _touching_planes(sphere_uvms, rng, [FLOOR], spheres_first=True)
    python, core = _pair(world)
    v = rng.normal(scale=0.05, size=sphere_uvms.nv)
    tau = rng.normal(scale=5.0, size=sphere_uvms.nv)
    assert not np.any(_anchor(python, q, v, 0.05, slipping=True).sticking)
    errors = _errors(python, core, q, v, tau)
    assert max(errors) < CORE_REL, errors


def _finite_differences(plant, q, v, tau, time_s=0.1):
    model = plant.uvms.model
    accel = plant.acceleration
    integrate = lambda x, dx: pin.integrate(model, x, dx)  # noqa: E731
    return (
        central_difference(lambda x: accel(time_s, x, v, tau), q, model.nv, 1e-6, integrate),
        central_difference(lambda x: accel(time_s, q, x, tau), v, model.nv, 1e-6),
        central_difference(lambda x: accel(time_s, q, v, x), tau, model.nv, 1e-3),
    )


@pytest.mark.parametrize("state", ["sticking", "slipping"])
def test_the_compiled_derivatives_match_finite_differences(reference_uvms, state):
    """The core plant's derivatives against central differences of its own (compiled)
    acceleration, the friction's memory held."""
    rng = np.random.default_rng(77)
    world, q = _touching_planes(reference_uvms, rng, [FLOOR, WALL])
    _, core = _pair(world, flow=UniformCurrent([0.2, -0.1, 0.0]))
    v = rng.normal(scale=0.05, size=reference_uvms.nv)
    tau = rng.normal(scale=5.0, size=reference_uvms.nv)
    _anchor(core, q, v, 2e-4 if state == "sticking" else 0.05, state == "slipping")
    got = core.acceleration_derivatives(0.1, q, v, tau)
    expected = _finite_differences(core, q, v, tau)
    errors = [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]
    assert max(errors) < FD_REL, errors


def test_a_planted_sign_error_in_the_reference_is_seen(reference_uvms, monkeypatch):
    """The comparison is sensitive: the slip's scaling derivative with its trial force's
    sign flipped, or the contact force turning into its joint's axes with the wrong sign,
    puts the reference far outside CORE_REL of the compiled derivatives."""
    rng = np.random.default_rng(78)
    world, q = _touching_planes(reference_uvms, rng, [FLOOR, WALL])
    python, core = _pair(world)
    v = rng.normal(scale=0.05, size=reference_uvms.nv)
    tau = rng.normal(scale=5.0, size=reference_uvms.nv)
    _anchor(python, q, v, 0.05, slipping=True)
    assert max(_errors(python, core, q, v, tau)) < CORE_REL
    unscaled = world_contact._unscaled_trial
    monkeypatch.setattr(world_contact, "_unscaled_trial", lambda *a: -unscaled(*a))
    assert max(_errors(python, core, q, v, tau)) > 1e3 * CORE_REL
    monkeypatch.undo()
    force_dq = world_contact.point_force_dq
    flipped = lambda f, df, r, m: force_dq(-f, df, r, m)  # the turning term's sign  # noqa: E731
    monkeypatch.setattr(world_contact, "point_force_dq", flipped)
    assert _errors(python, core, q, v, tau)[0] > 1e3 * CORE_REL


def test_a_solid_object_s_contact_is_refused_by_both(reference_uvms):
    rng = np.random.default_rng(79)
    world, q = _touching_planes(reference_uvms, rng, [FLOOR])
    level = world.objects[0].placement.translation[2]
    rock = solid(
        "rock", "box", {"size_m": [4.0, 4.0, 1.0]}, [0.3, -0.2, level - 0.5], [0, 0, 0], 0.6, 0.5
    )
    python, core = _pair(World(reference_uvms, [rock]))
    zero = np.zeros(reference_uvms.nv)
    assert len(core.world_forces(q, zero).touch)
    for plant in (python, core):
        with pytest.raises(ParameterError, match="coal's deepest point"):
            plant.acceleration_derivatives(0.1, q, zero, zero)
