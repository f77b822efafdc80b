"""The submerged part of each shape against closed forms, independent quadratures and
Monte-Carlo, at many heights and tilts; its waterplane against the derivatives of V."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import quad

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.submerged import Ellipsoid, Polyhedron, Sphere
from uvms_pin.hydro.submerged_cylinder import Cylinder, x_minus_sin

RNG = np.random.default_rng(20260121)


def _normals(count: int) -> list[np.ndarray]:
    """Random unit normals, the axes, and nearly axial ones (the hard cases)."""
    out = [n / np.linalg.norm(n) for n in RNG.normal(size=(count, 3))]
    out += [np.array(a, dtype=float) for a in np.eye(3)] + [-np.eye(3)[2]]
    for eps in (1e-13, 1e-9, 1e-5):
        out.append(np.array([eps, 0.0, math.sqrt(1.0 - eps * eps)]))
        out.append(np.array([math.sqrt(1.0 - eps * eps), 0.0, -eps]))
    return out


def _depths(reach: float, count: int = 9) -> np.ndarray:
    return np.concatenate([np.linspace(-1.1 * reach, 1.1 * reach, count), [-reach, reach, 0.0]])


# ---- closed forms and independent quadratures -----------------------------------------------


def test_sphere_cap_against_slices_at_every_height_and_tilt():
    """V and M of a sphere below a plane against the integral of its disc slices along n."""
    r = 0.37
    sphere = Sphere(r)
    for normal in _normals(20):
        for d in _depths(r):
            top = min(max(d, -r), r)
            volume = quad(lambda s: math.pi * (r * r - s * s), -r, top, epsabs=0, epsrel=1e-13)[0]
            moment = quad(
                lambda s: s * math.pi * (r * r - s * s), -r, top, epsabs=1e-15, epsrel=1e-12
            )[0]
            part = sphere.below(normal, d)
            assert part.volume_m3 == pytest.approx(volume, rel=1e-12, abs=1e-12 * sphere.volume_m3)
            np.testing.assert_allclose(part.moment_m4, moment * normal, atol=1e-12 * r**4)


def test_box_against_the_corner_formula_at_every_height_and_tilt():
    """V of a box below a plane against the inclusion-exclusion of its corners:
    V = sum_v (-1)^k(v) max(d - n.v, 0)^3 / (6 n_x n_y n_z) (k: the coordinates at the upper
    end), for normals without zero components; level boxes give V = a b (d + c/2)."""
    size = np.array([0.8, 0.5, 0.3])
    box = Polyhedron.box(size)
    half = size / 2
    for normal in _normals(40):
        if np.min(np.abs(normal)) < 1e-3:
            continue
        for d in _depths(float(np.abs(normal) @ half)):
            total = 0.0
            for corner in itertools.product((0, 1), repeat=3):
                # corners of the box in the frame where n has positive components
                v = -half + np.array(corner) * size
                total += (-1) ** sum(corner) * max(d - (np.abs(normal) @ v), 0.0) ** 3
            volume = total / (6.0 * np.prod(np.abs(normal)))
            # the box is symmetric: the volume under n is the one under |n|
            part = box.below(normal, d)
            assert part.volume_m3 == pytest.approx(volume, abs=1e-12 * np.prod(size))
    for d in np.linspace(-0.2, 0.2, 9):
        part = box.below(np.array([0.0, 0.0, 1.0]), d)
        expected = size[0] * size[1] * (min(max(d, -half[2]), half[2]) + half[2])
        assert part.volume_m3 == pytest.approx(expected, abs=1e-15)
        if abs(d) < half[2]:
            assert part.waterplane_area_m2 == pytest.approx(size[0] * size[1], rel=1e-13)
            np.testing.assert_allclose(part.centroid_m, [0, 0, 0.5 * (d - half[2])], atol=1e-15)


def _cylinder_slices(r: float, length: float, normal: np.ndarray, d: float) -> tuple[float, float]:
    """V and M_z of a cylinder below a plane by adaptive quadrature of its disc segments
    (acos form, split at the ends of the cut)."""
    n_p, nz = math.hypot(normal[0], normal[1]), normal[2]

    def segment(s: float) -> float:
        t = (d - nz * s) / n_p
        if t >= r:
            return math.pi * r * r
        if t <= -r:
            return 0.0
        return r * r * (math.pi - math.acos(t / r)) + t * math.sqrt(r * r - t * t)

    points = [-length / 2, length / 2]
    if nz != 0.0:
        points += [s for s in ((d - n_p * r) / nz, (d + n_p * r) / nz) if abs(s) < length / 2]
    points = sorted(points)
    volume = moment = 0.0
    for a, b in itertools.pairwise(points):
        volume += quad(segment, a, b, epsabs=1e-16, epsrel=1e-12, limit=200)[0]
        moment += quad(lambda s: s * segment(s), a, b, epsabs=1e-14, epsrel=1e-12, limit=200)[0]
    return volume, moment


def test_cylinder_against_its_segment_integral_at_every_height_and_tilt():
    r, length = 0.21, 1.3
    cylinder = Cylinder(r, length)
    for normal in _normals(25):
        if math.hypot(normal[0], normal[1]) < 1e-6:
            continue  # the adaptive reference cannot resolve a cut this thin; see below
        for d in _depths(cylinder.bounding_radius_m, 7):
            volume, moment = _cylinder_slices(r, length, normal, d)
            part = cylinder.below(normal, d)
            assert part.volume_m3 == pytest.approx(volume, abs=1e-10 * cylinder.volume_m3)
            assert part.moment_m4[2] == pytest.approx(moment, abs=1e-10 * cylinder.volume_m3 * r)


def test_a_cylinder_standing_or_lying_gives_the_closed_forms():
    r, length = 0.2, 1.0
    cylinder = Cylinder(r, length)
    up = np.array([0.0, 0.0, 1.0])
    for d in np.linspace(-0.6, 0.6, 13):  # standing: whole discs
        wet = min(max(d + 0.5, 0.0), 1.0)
        assert cylinder.below(up, d).volume_m3 == pytest.approx(math.pi * r * r * wet, abs=1e-15)
        tilted = cylinder.below(np.array([1e-9, 0.0, math.sqrt(1 - 1e-18)]), d)
        assert tilted.volume_m3 == pytest.approx(math.pi * r * r * wet, abs=1e-9)
    side = np.array([0.0, 1.0, 0.0])
    for d in np.linspace(-0.25, 0.25, 11):  # lying: one segment times L
        t = min(max(d, -r), r)
        segment = r * r * (math.pi - math.acos(t / r)) + t * math.sqrt(r * r - t * t)
        part = cylinder.below(side, d)
        assert part.volume_m3 == pytest.approx(segment * length, rel=1e-13, abs=1e-16)
        assert part.waterplane_area_m2 == pytest.approx(2 * math.sqrt(r * r - t * t) * length)


def test_the_small_angle_series_of_x_minus_sin():
    x = np.array([1e-8, 1e-3, 0.1, 0.2499, 0.25, 1.0, 3.0])
    exact = [
        float(sum((-1) ** k * v ** (2 * k + 3) / math.factorial(2 * k + 3) for k in range(12)))
        for v in x
    ]
    np.testing.assert_allclose(x_minus_sin(x), exact, rtol=1e-13)


def _ellipse_slices(axes, normal, d) -> float:
    """V of an ellipsoid below a plane by slices along its z axis: each slice is an ellipse
    cut by a line, a circular segment stretched by the slice's semi-axes."""
    a, b, c = axes

    def slice_area(z: float) -> float:
        k = math.sqrt(max(1.0 - (z / c) ** 2, 0.0))
        sa, sb = a * k, b * k
        reach = math.hypot(normal[0] * sa, normal[1] * sb)
        if reach == 0.0:
            return math.pi * sa * sb if normal[2] * z < d else 0.0
        t = max(min((d - normal[2] * z) / reach, 1.0), -1.0)
        return sa * sb * (math.pi - math.acos(t) + t * math.sqrt(1.0 - t * t))

    return quad(slice_area, -c, c, epsabs=0, epsrel=1e-13, limit=400)[0]


def test_ellipsoid_against_its_slices_at_every_height_and_tilt():
    axes = (0.5, 0.3, 0.2)
    ellipsoid = Ellipsoid(axes)
    assert ellipsoid.volume_m3 == pytest.approx(4 / 3 * math.pi * 0.03)
    for normal in _normals(15):
        for d in _depths(0.5, 7):
            part = ellipsoid.below(normal, d)
            assert part.volume_m3 == pytest.approx(
                _ellipse_slices(axes, normal, d), abs=1e-10 * ellipsoid.volume_m3
            )
    normal = _normals(1)[0]
    same = Ellipsoid((0.3, 0.3, 0.3)).below(normal, 0.1)
    ball = Sphere(0.3).below(normal, 0.1)
    assert same.volume_m3 == pytest.approx(ball.volume_m3, rel=1e-14)
    np.testing.assert_allclose(same.moment_m4, ball.moment_m4, atol=1e-16)


def _octahedron() -> Polyhedron:
    """|x| + |y| + |z| <= 1 as 8 outward triangles."""
    vertices = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    faces = []
    for sx, sy, sz in itertools.product((1, -1), repeat=3):
        i, j, k = (0 if sx > 0 else 1), (2 if sy > 0 else 3), (4 if sz > 0 else 5)
        faces.append((i, j, k) if sx * sy * sz > 0 else (i, k, j))
    return Polyhedron(vertices, np.array(faces))


def test_a_mesh_clips_exactly_whatever_its_triangulation():
    """A box made of many small triangles clips to the same numbers as the 12-triangle box;
    the octahedron below z = d gives int 2 (1 - |z|)^2 dz."""
    size = np.array([0.6, 0.4, 0.25])
    grid = np.linspace(-0.5, 0.5, 5)
    vertices, faces = [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            base = len(vertices)
            u, v = [k for k in range(3) if k != axis]
            for p, q in itertools.product(grid, grid):
                point = np.zeros(3)
                point[axis], point[u], point[v] = 0.5 * sign, p, q
                vertices.append(point * size)
            for i, j in itertools.product(range(4), range(4)):
                a, b, c, e = (
                    base + i * 5 + j,
                    base + (i + 1) * 5 + j,
                    base + (i + 1) * 5 + j + 1,
                    base + i * 5 + j + 1,
                )
                outward = np.cross(np.eye(3)[u], np.eye(3)[v]) @ np.eye(3)[axis] * sign > 0
                faces += [(a, b, c), (a, c, e)] if outward else [(a, c, b), (a, e, c)]
    fine = Polyhedron(np.array(vertices), np.array(faces))
    box = Polyhedron.box(size)
    assert fine.volume_m3 == pytest.approx(box.volume_m3, rel=1e-14)
    for normal in _normals(10):
        for d in _depths(0.4, 7):
            a, b = fine.below(normal, d), box.below(normal, d)
            assert a.volume_m3 == pytest.approx(b.volume_m3, abs=1e-14)
            np.testing.assert_allclose(a.moment_m4, b.moment_m4, atol=1e-14)
            assert a.waterplane_area_m2 == pytest.approx(b.waterplane_area_m2, abs=1e-13)
    octahedron = _octahedron()
    for d in np.linspace(-1.0, 1.0, 9):
        expected = quad(lambda z: 2 * (1 - abs(z)) ** 2, -1, d, points=[0.0] if d > 0 else None)[0]
        assert octahedron.below(np.array([0.0, 0.0, 1.0]), d).volume_m3 == pytest.approx(
            expected, abs=1e-14
        )


# ---- Monte-Carlo: every shape, volume and centroid --------------------------------------------


@pytest.mark.parametrize(
    ("shape", "inside"),
    [
        (Sphere(0.4), lambda p: np.sum(p * p, axis=1) <= 0.16),
        (Ellipsoid((0.5, 0.3, 0.2)), lambda p: np.sum((p / [0.5, 0.3, 0.2]) ** 2, axis=1) <= 1),
        (Polyhedron.box((0.6, 0.4, 0.3)), lambda p: np.all(np.abs(p) <= [0.3, 0.2, 0.15], axis=1)),
        (
            Cylinder(0.2, 0.9),
            lambda p: (np.hypot(p[:, 0], p[:, 1]) <= 0.2) & (np.abs(p[:, 2]) <= 0.45),
        ),
        (_octahedron(), lambda p: np.sum(np.abs(p), axis=1) <= 1.0),
    ],
    ids=["sphere", "ellipsoid", "box", "cylinder", "octahedron"],
)
def test_every_shape_against_monte_carlo(shape, inside):
    """Volume and centroid of the submerged part within 4 standard errors of 400 000 points."""
    reach = shape.bounding_radius_m
    points = RNG.uniform(-reach, reach, size=(400_000, 3))
    box_volume = (2 * reach) ** 3
    points = points[inside(points)]
    for normal in _normals(4)[:4]:
        for d in (-0.5 * reach, 0.0, 0.4 * reach):
            below = points[points @ normal < d]
            fraction = len(below) / 400_000
            sigma = box_volume * math.sqrt(fraction * (1 - fraction) / 400_000)
            part = shape.below(normal, d)
            assert abs(part.volume_m3 - fraction * box_volume) < 4 * sigma + 1e-12
            spread = below.std(axis=0) / math.sqrt(len(below))
            assert np.all(np.abs(part.centroid_m - below.mean(axis=0)) < 4 * spread + 1e-9)


# ---- the waterplane: how V changes with the plane -------------------------------------------


@pytest.mark.parametrize(
    "shape",
    [Sphere(0.4), Ellipsoid((0.5, 0.3, 0.2)), Polyhedron.box((0.6, 0.4, 0.3)), Cylinder(0.2, 0.9)],
    ids=["sphere", "ellipsoid", "box", "cylinder"],
)
def test_the_waterplane_is_the_derivative_of_the_volume(shape):
    """dV/dd = A and dV = -M_A . dn (a tilt of the plane about the shape's origin), by
    central differences at random heights and tilts."""
    h = 1e-6
    for normal in _normals(30):
        d = RNG.uniform(-0.9, 0.9) * shape.bounding_radius_m
        part = shape.below(normal, d)
        slope = (shape.below(normal, d + h).volume_m3 - shape.below(normal, d - h).volume_m3) / (
            2 * h
        )
        assert slope == pytest.approx(part.waterplane_area_m2, abs=1e-8)
        w = np.cross(normal, RNG.normal(size=3))
        w /= np.linalg.norm(w)
        turned = [normal * math.cos(e) + w * math.sin(e) for e in (h, -h)]
        tilt = (shape.below(turned[0], d).volume_m3 - shape.below(turned[1], d).volume_m3) / (2 * h)
        assert tilt == pytest.approx(-part.waterplane_moment_m3 @ w, abs=1e-8)


def test_bad_shapes_are_refused():
    with pytest.raises(ParameterError, match="radius"):
        Sphere(-1.0)
    with pytest.raises(ParameterError, match="length_m"):
        Cylinder(0.1, math.nan)
    with pytest.raises(ParameterError, match="semi-axis"):
        Ellipsoid((1.0, 0.0, 1.0))
    box = Polyhedron.box((1, 1, 1))
    with pytest.raises(ParameterError, match="positive volume"):
        Polyhedron(box.vertices_m, box.triangles[:, ::-1])  # inward
    with pytest.raises(ParameterError, match="names a vertex"):
        Polyhedron(box.vertices_m, box.triangles + 5)
