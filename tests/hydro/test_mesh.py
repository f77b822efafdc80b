"""Coefficients derived from a collision mesh equal those of the primitive it is.

A box and a cylinder written as meshes, rotated and offset in the mesh file, loaded from a
URDF, give the added mass, damping, volume and centre of buoyancy of the same shape given
as a URDF primitive at that pose; a wedge's centre of buoyancy is its centroid (not the
middle of its bounding box).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
import trimesh
from conftest import body_urdf

from uvms_pin.hydro.damping import damping_wrench

#: the shape's pose in the mesh file (a generic rotation and an offset)
ROTATION = pin.rpy.rpyToMatrix(0.3, -0.5, 0.9)
OFFSET_M = np.array([0.05, -0.02, 0.11])


def _pose(rotation: np.ndarray, offset: np.ndarray) -> np.ndarray:
    transform = np.eye(4)
    transform[:3, :3], transform[:3, 3] = rotation, offset
    return transform


def _numbers(values) -> str:
    return " ".join(repr(float(v)) for v in values)  # every digit: the pose is exact


def _origin(rotation: np.ndarray, offset: np.ndarray) -> str:
    rpy = pin.rpy.matrixToRpy(rotation)
    return f'<origin xyz="{_numbers(offset)}" rpy="{_numbers(rpy)}"/>'


def _write(mesh: trimesh.Trimesh, path) -> str:
    """The mesh as an OBJ file with every digit (an STL would round it to float32: 1e-7)."""
    path.write_text(trimesh.exchange.obj.export_obj(mesh, digits=17))
    return f'<geometry><mesh filename="{path}"/></geometry>'


def _body(load_body, collision: str):
    """The derived hydrodynamic body of a one-link URDF whose <collision> is ``collision``."""
    text = body_urdf().replace("  </link>", f"    <collision>{collision}</collision>\n  </link>")
    (body,) = load_body(text).hydro_bodies
    assert body.params.derived
    return body


def _in_link_frame(body) -> dict[str, np.ndarray]:
    """What the dynamics see of a body, in the link frame (its coefficients are given at
    its own frame, ``placement_in_joint``): volume, centre of buoyancy, added mass and
    linear damping (X^T M X), and the damping wrench at a set of velocities (quadratic
    drag included, evaluated in the body's frame as the dynamics do)."""
    x = body.action_joint_to_body
    p = body.params
    nus = np.random.default_rng(0).normal(size=(20, 6)) * [0.3, 0.3, 0.3, 1.0, 1.0, 1.0]
    return {
        "volume": np.array([p.volume_m3]),
        "centre of buoyancy": body.placement_in_joint.act(p.center_of_buoyancy_m),
        "added mass": x.T @ p.added_mass @ x,
        "linear damping": x.T @ p.linear_damping @ x,
        "damping wrench": np.array(
            [x.T @ damping_wrench(p.linear_damping, p.quadratic_damping, x @ nu) for nu in nus]
        ),
    }


def _mesh_and_primitive(load_body, tmp_path, mesh: trimesh.Trimesh, primitive: str, name: str):
    """(from the mesh file, posed in it; from the primitive at the same pose in the URDF)."""
    mesh.apply_transform(_pose(ROTATION, OFFSET_M))
    from_mesh = _body(load_body, _write(mesh, tmp_path / f"{name}.obj"))
    from_primitive = _body(
        load_body, f"{_origin(ROTATION, OFFSET_M)}<geometry>{primitive}</geometry>"
    )
    return from_mesh, from_primitive


def test_a_box_mesh_rotated_and_offset_is_the_box(load_body, tmp_path):
    """The oriented bounding box of a box is the box (its axes in some order and sign):
    the same body to rounding."""
    sides = (0.3, 0.2, 0.12)  # distinct by more than 15 %: a box, not a cylinder
    box = trimesh.creation.box(extents=sides)
    from_mesh, box_ = _mesh_and_primitive(
        load_body, tmp_path, box, f'<box size="{sides[0]} {sides[1]} {sides[2]}"/>', "box"
    )
    assert "box" in from_mesh.params.origin
    assert from_mesh.params.volume_m3 == pytest.approx(0.3 * 0.2 * 0.12, rel=1e-12)
    mesh_view, box_view = _in_link_frame(from_mesh), _in_link_frame(box_)
    np.testing.assert_allclose(box_view["centre of buoyancy"], OFFSET_M, rtol=0, atol=1e-15)
    for name, expected in box_view.items():
        scale = float(np.max(np.abs(expected)))
        np.testing.assert_allclose(
            mesh_view[name], expected, rtol=0, atol=1e-12 * scale, err_msg=name
        )


@pytest.mark.parametrize("sections", [64, 256])
def test_a_cylinder_mesh_rotated_and_offset_is_the_cylinder_to_its_faceting(
    load_body, tmp_path, sections
):
    """A cylinder of N sections is a prism whose section lies between the circles of radius
    r cos(pi/N) and r: its volume is N/(2 pi) sin(2 pi/N) of the cylinder's, and its
    bounding box's half-width (the radius the derivation uses) lies in [r cos(pi/N), r].
    Every coefficient is the length times a power of the radius of at most 5 (the end
    faces' tumbling drag, r^5) or the volume times a function of r/L of lower order, so each
    agrees with the cylinder's within 1 - cos(pi/N)^5 (~5/2 (pi/N)^2: 0.6 % at N = 64,
    0.04 % at N = 256) of its size; the centre of buoyancy, on the axis at mid-length by
    symmetry, is exact.

    The body sits on the cylinder's axis at its centre, as the URDF cylinder does; only the
    turn of its section axes about that axis is free (the bounding box's, not the URDF's):
    the cross-flow drag, component-wise in those axes, is compared in the body's own frame,
    where both are (d_cross, d_cross, d_axial, d_tumble, d_tumble, d_roll)."""
    radius, length = 0.05, 0.3
    cylinder = trimesh.creation.cylinder(radius=radius, height=length, sections=sections)
    from_mesh, cylinder_ = _mesh_and_primitive(
        load_body,
        tmp_path,
        cylinder,
        f'<cylinder radius="{radius}" length="{length}"/>',
        f"cylinder{sections}",
    )
    assert "cylinder" in from_mesh.params.origin
    prism = 0.5 * sections * math.sin(2.0 * math.pi / sections) * radius**2 * length
    assert from_mesh.params.volume_m3 == pytest.approx(prism, rel=1e-12)
    placed, expected_place = from_mesh.placement_in_joint, cylinder_.placement_in_joint
    np.testing.assert_allclose(placed.translation, OFFSET_M, rtol=0, atol=1e-15)
    axis = placed.rotation[:, 2]
    assert abs(axis @ expected_place.rotation[:, 2]) == pytest.approx(1.0, abs=1e-12)
    mesh_view, cylinder_view = _in_link_frame(from_mesh), _in_link_frame(cylinder_)
    np.testing.assert_allclose(mesh_view["centre of buoyancy"], OFFSET_M, rtol=0, atol=1e-15)
    faceting = 1.0 - math.cos(math.pi / sections) ** 5
    for name in ("volume", "added mass", "linear damping"):
        expected = cylinder_view[name]
        scale = float(np.max(np.abs(expected)))
        np.testing.assert_allclose(
            mesh_view[name], expected, rtol=0, atol=faceting * scale, err_msg=name
        )
    np.testing.assert_allclose(
        from_mesh.params.quadratic_damping, cylinder_.params.quadratic_damping, rtol=faceting
    )
    # the faceting, not a looser match: the difference is of its order
    assert np.max(np.abs(mesh_view["added mass"] - cylinder_view["added mass"])) > 0.1 * (
        faceting * np.max(np.abs(cylinder_view["added mass"]))
    )


def test_a_wedge_is_buoyed_at_its_centroid_not_its_bounding_box_centre(load_body, tmp_path):
    """A right triangular prism (legs a, b, length L): V = a b L / 2, centroid (a/3, b/3,
    L/2) from the right-angle edge; its bounding box's centre is (a/2, b/2, L/2)."""
    a, b, length = 0.2, 0.1, 0.3
    section = np.array([[0.0, 0.0], [a, 0.0], [0.0, b]])
    wedge = trimesh.creation.extrude_triangulation(section, np.array([[0, 1, 2]]), length)
    wedge.apply_transform(_pose(ROTATION, OFFSET_M))
    body = _body(load_body, _write(wedge, tmp_path / "wedge.obj"))
    view = _in_link_frame(body)
    assert view["volume"][0] == pytest.approx(0.5 * a * b * length, rel=1e-12)
    centroid = OFFSET_M + ROTATION @ np.array([a / 3.0, b / 3.0, length / 2.0])
    np.testing.assert_allclose(view["centre of buoyancy"], centroid, rtol=0, atol=1e-15)


@pytest.mark.parametrize("scale", [(-1.0, 1.0, 1.0), (1.0, -2.0, 0.5), (-1.0, -1.0, -1.0)])
def test_a_mesh_mirrored_by_its_scale_is_the_mirrored_mesh(load_body, tmp_path, scale):
    """URDF's ``scale="-1 1 1"`` (a left part made from a right one's file): the wedge
    scaled by a negative factor is the body of a file holding the scaled vertices, its
    centroid (and every coefficient) on the mirrored side."""
    a, b, length = 0.2, 0.1, 0.3
    section = np.array([[0.0, 0.0], [a, 0.0], [0.0, b]])
    wedge = trimesh.creation.extrude_triangulation(section, np.array([[0, 1, 2]]), length)
    wedge.apply_transform(_pose(ROTATION, OFFSET_M))
    given = _write(wedge, tmp_path / "wedge.obj").replace("/>", f' scale="{_numbers(scale)}"/>')
    scaled = _body(load_body, given)
    mirrored = wedge.copy()
    mirrored.apply_transform(np.diag([*scale, 1.0]))  # trimesh turns its faces out again
    expected = _in_link_frame(_body(load_body, _write(mirrored, tmp_path / "mirrored.obj")))
    centroid = OFFSET_M + ROTATION @ np.array([a / 3.0, b / 3.0, length / 2.0])
    np.testing.assert_allclose(
        expected["centre of buoyancy"], np.asarray(scale) * centroid, rtol=0, atol=1e-15
    )
    assert scaled.params.volume_m3 == pytest.approx(
        0.5 * a * b * length * abs(np.prod(scale)), rel=1e-12
    )
    for name, value in _in_link_frame(scaled).items():
        size = float(np.max(np.abs(expected[name])))
        np.testing.assert_allclose(value, expected[name], rtol=0, atol=1e-12 * size, err_msg=name)


def test_the_surface_cuts_a_box_mesh_where_the_box_is(load_body, tmp_path):
    """The hull of a body derived from a mesh sits where the mesh is: a rotated, offset box
    mesh and the box primitive at that pose leave the same wet volume and moment, at random
    heights and tilts of the link (the body frame of the mesh is its bounding box's, so a
    hull left in the mesh frame would be turned and shifted)."""
    from uvms_pin.hydro.hull import SurfaceAt

    sides = (0.3, 0.2, 0.12)
    box = trimesh.creation.box(extents=sides)
    box.apply_transform(_pose(ROTATION, OFFSET_M))

    def hull(collision: str):
        text = body_urdf().replace(
            "  </link>", f"    <collision>{collision}</collision>\n  </link>"
        )
        (only,) = load_body(text).surface_bodies.hulls
        return only

    from_mesh = hull(_write(box, tmp_path / "box.obj"))
    from_box = hull(
        f'{_origin(ROTATION, OFFSET_M)}<geometry><box size="{_numbers(sides)}"/></geometry>'
    )
    rng = np.random.default_rng(3)
    for _ in range(40):
        rotation = pin.rpy.rpyToMatrix(*rng.uniform(-math.pi, math.pi, 3))
        position = np.array([0.0, 0.0, rng.uniform(-0.25, 0.25)])
        cut_mesh = from_mesh.wet(rotation, position, SurfaceAt())
        cut_box = from_box.wet(rotation, position, SurfaceAt())
        assert cut_mesh.volume_m3 == pytest.approx(cut_box.volume_m3, rel=1e-12, abs=1e-15)
        np.testing.assert_allclose(cut_mesh.moment_m4, cut_box.moment_m4, rtol=0, atol=1e-14)


@pytest.mark.parametrize(
    "vertices",
    [
        [[0, 0, 0], [1, 0, 0], [0, 1, 0]],  # one triangle: qhull needs 4 points
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],  # every point in one plane
    ],
    ids=["one-triangle", "flat"],
)
def test_a_mesh_enclosing_no_volume_is_refused_naming_the_file(load_body, tmp_path, vertices):
    """A flat mesh has no convex hull: ParameterError naming the file (qhull's own error was
    raised through), and the link's derived body refuses it as a ModelError naming the link."""
    from uvms_pin.errors import ModelError, ParameterError
    from uvms_pin.hydro.mesh import load_mesh_geometry

    faces = [[0, 1, 2]] if len(vertices) == 3 else [[0, 1, 2], [1, 3, 2]]
    path = tmp_path / "flat.stl"
    trimesh.Trimesh(vertices, faces, process=False).export(path)
    with pytest.raises(ParameterError, match=r"flat\.stl' encloses no volume"):
        load_mesh_geometry(path)
    text = body_urdf(mass=1.0, collision=f'<mesh filename="{path}"/>')
    with pytest.raises(ModelError, match=r"link 'body'.*encloses no volume"):
        load_body(text)


def _binary_stl_headed_solid(mesh: trimesh.Trimesh) -> bytes:
    """``mesh`` as a binary STL whose 80-byte header starts with ``solid``, as some CAD
    tools write it."""
    data = bytearray(trimesh.exchange.stl.export_stl(mesh))
    data[:80] = b"solid exported by a CAD tool".ljust(80, b" ")
    return bytes(data)


@pytest.mark.parametrize(
    "name, export",
    [
        ("sphere.stl", lambda m: trimesh.exchange.stl.export_stl(m)),
        ("solid.stl", _binary_stl_headed_solid),
        ("ascii.stl", lambda m: trimesh.exchange.stl.export_stl_ascii(m).encode()),
        ("sphere.obj", lambda m: trimesh.exchange.obj.export_obj(m).encode()),
        ("sphere.ply", lambda m: trimesh.exchange.ply.export_ply(m, encoding="binary")),
        ("sphere.glb", lambda m: trimesh.exchange.gltf.export_glb(trimesh.Scene(m))),
    ],
)
def test_the_memory_weighed_before_a_mesh_is_read_bounds_what_reading_it_takes(
    tmp_path, name, export
):
    """`mesh_bytes` (what the check before a mesh is read weighs) is at least the peak of
    the memory allocated while reading and reducing it (tracemalloc: Python's and numpy's
    allocations), for a 5,120-triangle sphere in the compact formats (binary STL, PLY and
    GLB: about 19 to 50 bytes a triangle) and the text ones; about 1,400 bytes a triangle,
    whatever the format."""
    import tracemalloc

    from uvms_pin.hydro.mesh import load_mesh_geometry, mesh_bytes

    path = tmp_path / name
    path.write_bytes(export(trimesh.creation.icosphere(subdivisions=4)))
    load_mesh_geometry(path, (2.0, 2.0, 2.0))  # the readers' imports (cached apart)
    tracemalloc.start()
    try:
        geometry = load_mesh_geometry(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert geometry.watertight and len(geometry.triangles) == 5120
    assert peak > 1000 * 5120  # what the bound is weighed against: the triangles' memory
    assert mesh_bytes(path) >= peak, f"{mesh_bytes(path)} bytes weighed, {peak} taken"
