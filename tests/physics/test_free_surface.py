"""The free surface in the dynamics: the compiled core against the reference at the surface,
deep bodies exactly as without a surface, bodies above the water under gravity alone."""

from __future__ import annotations

import itertools
import re
import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import assert_rel, mount_on_reference_vehicle

import uvms_pin as up
from uvms_pin.flow import AiryWave, IrregularSea, UniformCurrent
from uvms_pin.model.resources import example_robot_data_dir, shipped_path
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

FLOWS = {
    "still": None,
    "current": UniformCurrent([0.3, -0.1, 0.05]),
    "wave": AiryWave(0.15, 3.0, heading_rad=0.4),
    "sea + current": IrregularSea(0.4, 5.0, n_components=12, seed=3) + UniformCurrent([0.2, 0, 0]),
}


@pytest.fixture(scope="module")
def models(reference_uvms, tmp_path_factory):
    """Boxes, cylinders, spheres (equivalent and collision) and, when installed, meshes."""
    out = {
        "lbv150 + arm": reference_uvms,
        "bluerov2 + alpha5": up.load_uvms(shipped_path("models/uvms_bluerov2_alpha5.urdf")),
    }
    if example_robot_data_dir() is not None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", up.ModelWarning)
            out["panda (meshes)"] = mount_on_reference_vehicle(
                "panda", tmp_path_factory.mktemp("p")
            )
    return out


def _near_the_surface(uvms: up.UVMS, rng: np.random.Generator) -> np.ndarray:
    """A random attitude and arm, the vehicle's origin within 0.3 m of z = 0."""
    q = uvms.neutral_configuration()
    q[:2] = rng.normal(scale=0.5, size=2)
    q[2] = rng.uniform(-0.3, 0.3)
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.normal(scale=0.6, size=3))).coeffs()
    lo = np.maximum(uvms.model.lowerPositionLimit[7:], -np.pi)
    hi = np.minimum(uvms.model.upperPositionLimit[7:], np.pi)
    q[7:] = rng.uniform(lo, hi)
    return q


@pytest.mark.parametrize("flow", FLOWS.values(), ids=FLOWS.keys())
def test_the_core_matches_the_reference_at_the_surface(models, flow):
    """M, h and the forward dynamics with the bodies cut by the surface: 1e-12 relative."""
    rng = np.random.default_rng(21)
    for name, uvms in models.items():
        cut = 0
        for _ in range(6):
            q = _near_the_surface(uvms, rng)
            v = rng.normal(scale=0.5, size=uvms.nv)
            tau = rng.normal(scale=5.0, size=uvms.nv)
            kw = {"flow": flow, "time_s": 1.7, "free_surface": True}
            pin.forwardKinematics(uvms.model, uvms.data, q)
            fractions = Plant(uvms, flow=flow, free_surface=True).wet_fractions(1.7, q)
            cut += int(np.any((fractions > 0.0) & (fractions < 1.0)))
            assert_rel(
                up.mass_matrix(uvms, q, **kw), up.mass_matrix(uvms, q, backend="python", **kw)
            )
            assert_rel(
                up.bias_forces(uvms, q, v, **kw), up.bias_forces(uvms, q, v, backend="python", **kw)
            )
            assert_rel(
                up.forward_dynamics(uvms, q, v, tau, **kw),
                up.forward_dynamics(uvms, q, v, tau, backend="python", **kw),
            )
        assert cut >= 4, name  # the states do cut bodies


def test_the_plants_advance_alike_through_the_surface(reference_uvms):
    """The compiled plant over a control period (RK4) against the reference's, as the
    vehicle crosses z = 0 in a wave."""
    rng = np.random.default_rng(5)
    wave = AiryWave(0.1, 2.5)
    plants = [
        Plant(reference_uvms, flow=wave, free_surface=True, backend=b) for b in ("core", "python")
    ]
    for _ in range(3):
        q = _near_the_surface(reference_uvms, rng)
        v = rng.normal(scale=0.3, size=reference_uvms.nv)
        v[2] = 0.5
        tau = rng.normal(size=reference_uvms.nv)
        for plant in plants:
            plant.attach(q)
        (qc, vc), (qp, vp) = (System(p).advance(RK4(5e-4), 0.3, q, v, tau, 0.302) for p in plants)
        assert_rel(qc, qp)
        assert_rel(vc, vp)


@pytest.mark.parametrize("flow", FLOWS.values(), ids=FLOWS.keys())
def test_deep_bodies_are_exactly_as_without_a_surface(models, flow):
    """Every body below the deepest trough: the same numbers, bit for bit, in both
    backends (the surface costs one bound check per body there)."""
    rng = np.random.default_rng(8)
    for uvms in models.values():
        q = _near_the_surface(uvms, rng)
        q[2] = -8.0
        v = rng.normal(scale=0.5, size=uvms.nv)
        tau = rng.normal(size=uvms.nv)
        for backend in ("core", "python"):
            kw = {"flow": flow, "time_s": 0.4, "backend": backend}
            if flow is None:
                kw.pop("flow")
            np.testing.assert_array_equal(
                up.forward_dynamics(uvms, q, v, tau, free_surface=True, **kw),
                up.forward_dynamics(uvms, q, v, tau, **kw),
            )
            np.testing.assert_array_equal(
                up.bias_forces(uvms, q, v, free_surface=True, **kw),
                up.bias_forces(uvms, q, v, **kw),
            )
            np.testing.assert_array_equal(
                up.mass_matrix(uvms, q, free_surface=True, backend=backend),
                up.mass_matrix(uvms, q, backend=backend),
            )


def test_bodies_under_the_local_surface_are_exactly_as_without_one(reference_uvms):
    """In a sea whose crests could reach them (sum |A| above the hull's top) but whose
    surface over each body is above it now: bit for bit the numbers without a surface."""
    sea = IrregularSea(0.5, 5.0, seed=1)
    uvms = reference_uvms
    q = uvms.neutral_configuration()
    q[2] = -1.0
    v = np.random.default_rng(2).normal(scale=0.3, size=uvms.nv)
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q)
    bodies = uvms.surface_bodies
    centers = np.array(
        [
            data.oMi[int(j)].act(c)
            for j, c in zip(bodies.joint_ids, bodies.bound_center_in_joint_m, strict=True)
        ]
    )
    assert np.max(centers[:, 2] + bodies.bound_radius_m) > -sea.elevation_bound_m
    checked = 0
    for t in np.linspace(0.0, 20.0, 41):
        if np.any(sea.surface_elevation(t, centers[:, :2]) < centers[:, 2] + bodies.bound_radius_m):
            continue
        for backend in ("core", "python"):
            kw = {"flow": sea, "time_s": t, "backend": backend}
            np.testing.assert_array_equal(
                up.bias_forces(uvms, q, v, free_surface=True, **kw),
                up.bias_forces(uvms, q, v, **kw),
            )
        checked += 1
    assert checked > 10


def test_above_the_water_a_body_feels_gravity_only(models):
    """High above the waves: the rigid-body dynamics, no buoyancy, added mass or drag."""
    rng = np.random.default_rng(3)
    for uvms in models.values():
        q = _near_the_surface(uvms, rng)
        q[2] = 6.0
        v = rng.normal(scale=0.5, size=uvms.nv)
        tau = rng.normal(size=uvms.nv)
        rigid = pin.aba(uvms.model, uvms.model.createData(), q, v, tau)
        for backend in ("core", "python"):
            fd = up.forward_dynamics(
                uvms, q, v, tau, flow=FLOWS["wave"], free_surface=True, backend=backend
            )
            np.testing.assert_allclose(fd, rigid, rtol=1e-9, atol=1e-9)
            mass = up.mass_matrix(uvms, q, free_surface=True, backend=backend)
            upper = np.triu(pin.crba(uvms.model, uvms.model.createData(), q))
            np.testing.assert_allclose(mass, upper + np.triu(upper, 1).T, atol=1e-9)
        energy = up.potential_energy(uvms, q, free_surface=True)
        assert energy == pytest.approx(
            pin.computePotentialEnergy(uvms.model, uvms.model.createData(), q), rel=1e-12
        )


def _hull_pieces(rotations_and_offsets) -> list:
    """One hull piece of each kind of shape at each (rotation, offset), and the core's."""
    from uvms_pin.hydro.hull import HullPiece
    from uvms_pin.hydro.submerged import Ellipsoid, Polyhedron, Sphere
    from uvms_pin.hydro.submerged_cylinder import Cylinder
    from uvms_pin.physics.compiled.extension import core_module
    from uvms_pin.physics.compiled.hull import piece_to_core

    shapes = [Sphere(0.3), Ellipsoid((0.4, 0.2, 0.1)), Cylinder(0.15, 0.8),
              Polyhedron.box((0.5, 0.3, 0.2))]  # fmt: skip
    pieces = []
    for shape in shapes:
        for rotation, offset in rotations_and_offsets():
            piece = HullPiece(shape, rotation, offset)
            pieces.append((piece, piece_to_core(piece, core_module())))
    return pieces


def _cut_alike(piece, compiled, normal: np.ndarray, depth: float):
    """The core's (V, M, A, M_A) of ``piece`` below n . x = d held to the reference's, to
    1e-12 of the piece's volume; the reference's part, and the core's waterplane area."""
    scale = piece.shape.volume_m3
    part = piece.below(normal, depth)
    volume, moment, area, wet_moment = compiled.below(normal, depth)
    assert volume == pytest.approx(part.volume_m3, abs=1e-12 * scale)
    np.testing.assert_allclose(moment, part.moment_m4, atol=1e-12 * scale)
    assert area == pytest.approx(part.waterplane_area_m2, abs=1e-12 * scale)
    np.testing.assert_allclose(wet_moment, part.waterplane_moment_m3, atol=1e-12 * scale)
    return part, area


def test_every_shape_is_cut_alike_in_the_core():
    """Each piece's (V, M, A, M_A) under random planes: the core's hull.hpp against
    uvms_pin.hydro, 1e-12 of the piece's scale, for every kind of shape."""
    rng = np.random.default_rng(11)
    placed = lambda: [(pin.exp3(rng.normal(size=3)), rng.normal(scale=0.2, size=3))]  # noqa: E731
    for piece, compiled in _hull_pieces(placed):
        for _ in range(60):
            normal = rng.normal(size=3)
            _cut_alike(piece, compiled, normal / np.linalg.norm(normal), rng.uniform(-0.8, 0.8))


def test_every_shape_upright_or_lying_is_cut_alike_in_the_core():
    """The orientations random planes never draw, and the commonest in a run (a level vehicle
    in still water): each shape's axes along or across the plane's normal exactly (the
    cylinder's own branches: whole discs, or slices at one height), at heights from wholly
    dry through cut to wholly wet, as `test_every_shape_is_cut_alike_in_the_core`. A whole
    wet or dry piece has no waterplane."""
    offset = np.array([0.05, -0.02, 0.0])
    turns = lambda: [(np.eye(3), offset), (pin.rpy.rpyToMatrix(np.pi / 2, 0, 0), offset)]  # noqa: E731
    normals = [np.array(n, dtype=float) for n in ([0, 0, 1], [0, 0, -1], [1, 0, 0], [0, -1, 0])]
    depths = np.linspace(-1.1, 1.1, 23) + 0.013  # no height on a face
    wholes = 0
    for piece, compiled in _hull_pieces(turns):  # upright, lying
        for normal, depth in itertools.product(normals, depths):
            part, area = _cut_alike(piece, compiled, normal, depth)
            if part.volume_m3 in (0.0, pytest.approx(piece.shape.volume_m3, rel=1e-12)):
                wholes += 1
                assert area == 0.0
    assert wholes > 100  # the wholly wet and dry heights were reached


def _arm_link4_variant(tmp_path, damping: bool) -> up.UVMS:
    """The reference UVMS with arm_link4 stripped of its volume and collision geometry (a
    body with damping alone), its damping kept or zeroed."""
    text = shipped_path("models/uvms_lbv150.urdf").read_text()
    start = text.index('<link name="arm_link4">')
    end = text.index("</link>", start)
    link = re.sub(r"\s*<collision>.*?</collision>", "", text[start:end], flags=re.S)
    link = re.sub(r'<volume value="[^"]*"/>', '<volume value="0"/>', link)
    if not damping:
        link = re.sub(r"\s*<(linear|quadratic)_damping [^>]*/>", "", link)
    path = tmp_path / f"arm_link4_{'damped' if damping else 'undamped'}.urdf"
    path.write_text(text[:start] + link + text[end:])
    return up.load_uvms(path)


def test_a_body_with_damping_alone_is_always_wet(tmp_path):
    """A body with neither volume nor geometry has no hull for the surface to cut: its drag
    acts in full wherever it is (docs/physics.md). Its share of h, the damped model's minus
    the undamped one's, is the same high above the water, cut by it, and deep without a
    surface, in both backends."""
    damped, undamped = _arm_link4_variant(tmp_path, True), _arm_link4_variant(tmp_path, False)
    assert -1 in damped.surface_bodies.hull_of_damped  # the stripped body has no hull
    rng = np.random.default_rng(5)
    q = _near_the_surface(damped, rng)
    v = rng.normal(scale=0.6, size=damped.nv)
    for backend in ("core", "python"):

        def drag(z, surface, backend=backend):
            at = q.copy()
            at[2] = z
            return up.bias_forces(damped, at, v, free_surface=surface, backend=backend) - (
                up.bias_forces(undamped, at, v, free_surface=surface, backend=backend)
            )

        deep = drag(-8.0, False)
        assert np.abs(deep[6:]).max() > 1e-3  # the arm's joints feel the link's drag
        np.testing.assert_allclose(drag(6.0, True), deep, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(drag(q[2], True), deep, rtol=1e-12, atol=1e-12)
