"""Physics tests of uvms_pin.hydro.geometry: analytic limits, symmetry, scaling, bad inputs.

Tolerances are stated per test. "Exact" results (sphere, closed forms) are checked to 1e-12
relative; results through the numerical shape integrals to 1e-9 (quad at epsrel 1e-12);
limits (thin disk, slender spheroid) to the size of the first neglected term.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import quad
from scipy.special import elliprd

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.geometry import (
    box_hydro,
    cylinder_hydro,
    ellipsoid_added_mass,
    ellipsoid_shape_integrals,
    hydro_in_frame,
    sphere_hydro,
)

RHO = 1025.0


def _assert_sym_psd(m: np.ndarray) -> None:
    scale = max(1.0, float(np.abs(m).max()))
    np.testing.assert_allclose(m, m.T, rtol=0.0, atol=1e-12 * scale)
    assert np.linalg.eigvalsh(0.5 * (m + m.T)).min() >= -1e-12 * scale


# ----------------------------------------------------------------------------- sphere


@pytest.mark.parametrize("radius", [0.01, 0.1, 1.3])
def test_sphere_added_mass_is_half_displaced_mass_exactly(radius):
    h = sphere_hydro(radius, RHO)
    volume = 4.0 / 3.0 * math.pi * radius**3
    assert h.volume_m3 == pytest.approx(volume, rel=1e-14)
    expected = np.diag([0.5 * RHO * volume] * 3 + [0.0] * 3)
    np.testing.assert_allclose(h.added_mass, expected, rtol=1e-14, atol=0.0)
    np.testing.assert_array_equal(h.center_of_buoyancy_m, np.zeros(3))
    assert h.derived


def test_sphere_drag_is_half_rho_cd_area():
    h = sphere_hydro(0.2, RHO, drag_coefficient=0.5)
    np.testing.assert_allclose(
        h.quadratic_damping[:3], 0.5 * RHO * 0.5 * math.pi * 0.04, rtol=1e-14
    )


def test_sphere_spin_drag_is_the_skin_friction_moment_over_its_surface():
    """Spinning at w about an axis, the surface at polar angle theta moves at w r sin(theta):
    the shear 0.5 rho Cf (w r sin(theta))^2 at the arm r sin(theta), summed over the surface
    (r^2 sin(theta) dtheta dphi) by quadrature, is D_rot w^2 about every axis."""
    radius, cf, omega = 0.3, 0.004, 1.7
    h = sphere_hydro(radius, RHO, skin_friction_coefficient=cf)
    theta = np.linspace(0.0, math.pi, 20001)
    ring = 0.5 * RHO * cf * (omega * radius * np.sin(theta)) ** 2 * radius * np.sin(theta)
    ring *= 2.0 * math.pi * radius**2 * np.sin(theta)  # the band's area per dtheta
    moment = float(np.sum(0.5 * (ring[1:] + ring[:-1]) * np.diff(theta)))
    np.testing.assert_allclose(h.quadratic_damping[3:] * omega**2, moment, rtol=1e-7)


# ----------------------------------------------------------------------------- ellipsoid


@pytest.mark.parametrize("axes", [(1, 1, 1), (3, 1, 1), (1, 0.5, 0.2), (0.2, 1, 0.4), (1, 1, 1e-3)])
def test_shape_integrals_sum_to_two_and_match_carlson_form(axes):
    # alpha0 = 2/3 abc R_D(b^2, c^2, a^2) (Carlson's symmetric elliptic integral), an
    # independent implementation (scipy.special.elliprd) of the closed form the module uses.
    a, b, c = axes
    alpha0, beta0, gamma0 = ellipsoid_shape_integrals(a, b, c)
    assert alpha0 + beta0 + gamma0 == pytest.approx(2.0, abs=1e-14)
    ref = [
        2.0 / 3.0 * a * b * c * elliprd(b * b, c * c, a * a),
        2.0 / 3.0 * a * b * c * elliprd(c * c, a * a, b * b),
        2.0 / 3.0 * a * b * c * elliprd(a * a, b * b, c * c),
    ]
    np.testing.assert_allclose([alpha0, beta0, gamma0], ref, rtol=1e-14, atol=1e-16)


def test_ellipsoid_reduces_to_sphere():
    r = 0.3
    diag = ellipsoid_added_mass(r, r, r, RHO)
    sphere = np.diag(sphere_hydro(r, RHO).added_mass)
    np.testing.assert_allclose(diag, sphere, rtol=1e-9, atol=0.0)


def test_ellipsoid_matches_lamb_prolate_spheroid_closed_form():
    # Lamb's k-factors of a prolate spheroid a > b = c (Fossen 2011, sec. 6.4), rel. 1e-9.
    a, b = 0.6, 0.15
    e = math.sqrt(1.0 - (b / a) ** 2)
    log = math.log((1.0 + e) / (1.0 - e))
    alpha0 = 2.0 * (1.0 - e * e) / e**3 * (0.5 * log - e)
    beta0 = 1.0 / e**2 - (1.0 - e * e) / (2.0 * e**3) * log
    mf = RHO * 4.0 / 3.0 * math.pi * a * b * b
    k_prime_num = 0.2 * mf * (b * b - a * a) ** 2 * (alpha0 - beta0)
    k_prime_den = 2.0 * (b * b - a * a) + (b * b + a * a) * (beta0 - alpha0)
    expected = [
        alpha0 / (2.0 - alpha0) * mf,
        beta0 / (2.0 - beta0) * mf,
        beta0 / (2.0 - beta0) * mf,
        0.0,
        k_prime_num / k_prime_den,  # Fossen's M_q = N_r are -(this): derivatives
        k_prime_num / k_prime_den,
    ]
    np.testing.assert_allclose(ellipsoid_added_mass(a, b, b, RHO), expected, rtol=1e-9, atol=0.0)


def test_thin_disk_limit():
    # Circular disk of radius a (Lamb sec. 108; Newman Table 4.3): broadside added mass
    # 8/3 rho a^3, rotation about a diameter 16/45 rho a^5. Thickness 1e-4 a: rel. 1e-3.
    a = 0.5
    diag = ellipsoid_added_mass(a, a, 1e-4 * a, RHO)
    assert diag[2] == pytest.approx(8.0 / 3.0 * RHO * a**3, rel=1e-3)
    assert diag[3] == pytest.approx(16.0 / 45.0 * RHO * a**5, rel=1e-3)
    assert diag[4] == pytest.approx(16.0 / 45.0 * RHO * a**5, rel=1e-3)
    assert diag[5] == 0.0


@pytest.mark.parametrize(("aspect", "rel_tol"), [(10.0, 0.05), (30.0, 1e-2), (100.0, 1.5e-3)])
def test_slender_spheroid_transverse_added_mass_tends_to_strip_theory(aspect, rel_tol):
    # Strip theory: int rho pi b(x)^2 dx over the spheroid = rho pi b^2 (4/3) a = rho V.
    # The 3-D correction is about -2 (b/a)^2 (ln(2a/b) - 1): -4.0 % at a/b = 10, -0.69 % at 30,
    # -0.086 % at 100; the tolerances are 5 %, 1 % and 0.15 %.
    b = 0.02
    a = aspect * b
    strip = RHO * math.pi * b * b * 4.0 / 3.0 * a
    diag = ellipsoid_added_mass(a, b, b, RHO)
    assert diag[1] == pytest.approx(strip, rel=rel_tol)
    assert diag[2] == pytest.approx(strip, rel=rel_tol)
    assert diag[1] < strip  # approached from below
    # and the axial one vanishes relative to it
    assert diag[0] / diag[1] < 2.0 * (b / a) ** 2 * math.log(2.0 * aspect)


def test_ellipsoid_rotational_terms_symmetric_under_axis_permutation():
    a, b, c = 0.5, 0.3, 0.1
    d_abc = ellipsoid_added_mass(a, b, c, RHO)
    d_bca = ellipsoid_added_mass(b, c, a, RHO)
    np.testing.assert_allclose(d_bca, d_abc[[1, 2, 0, 4, 5, 3]], rtol=1e-9)


# ----------------------------------------------------------------------------- cylinder


def test_cylinder_strip_theory_values():
    r, length = 0.025, 0.18
    h = cylinder_hydro(r, length, RHO)
    m_strip = RHO * math.pi * r * r * length
    assert h.volume_m3 == pytest.approx(math.pi * r * r * length, rel=1e-14)
    m = h.added_mass
    assert m[0, 0] == pytest.approx(m_strip, rel=1e-14)
    assert m[1, 1] == pytest.approx(m_strip, rel=1e-14)
    assert m[3, 3] == pytest.approx(m_strip * length**2 / 12.0, rel=1e-14)
    assert m[4, 4] == pytest.approx(m_strip * length**2 / 12.0, rel=1e-14)
    assert m[5, 5] == 0.0  # roll about the axis moves no fluid
    # axial: Lamb k1 of the spheroid with semi-axes (r, r, L/2), between 0 and 0.5 for L > 2r
    alpha0, _, _ = ellipsoid_shape_integrals(length / 2.0, r, r)
    assert m[2, 2] == pytest.approx(alpha0 / (2.0 - alpha0) * m_strip, rel=1e-9)
    assert 0.0 < m[2, 2] < 0.5 * m_strip


def test_cylinder_drag_matches_strip_integrals():
    # Closed forms against direct numerical integration of the strip drag, rel. 1e-9.
    r, length, cdx, cda = 0.03, 0.4, 1.2, 0.8
    h = cylinder_hydro(r, length, RHO, drag_coefficient_cross=cdx, drag_coefficient_axial=cda)
    q = h.quadratic_damping
    assert q[0] == pytest.approx(0.5 * RHO * cdx * 2 * r * length, rel=1e-14)
    assert q[2] == pytest.approx(0.5 * RHO * cda * math.pi * r * r, rel=1e-14)
    side, _ = quad(lambda s: 0.5 * RHO * cdx * 2 * r * abs(s) ** 3, -length / 2, length / 2)
    ends, _ = quad(lambda x: 0.5 * RHO * cda * 2 * math.sqrt(r * r - x * x) * abs(x) ** 3, -r, r)
    assert q[3] == pytest.approx(side + ends, rel=1e-9)
    assert q[4] == pytest.approx(side + ends, rel=1e-9)
    # roll: the skin friction 0.5 rho Cf (w s)^2 at the arm s, on the side (s = r, area
    # 2 pi r L) and the two end discs (rings 2 pi s ds), per w^2
    cf = 0.004
    roll = cylinder_hydro(r, length, RHO, skin_friction_coefficient=cf).quadratic_damping[5]
    wall = 0.5 * RHO * cf * r**2 * r * 2.0 * math.pi * r * length
    disc, _ = quad(lambda s: 0.5 * RHO * cf * s**2 * s * 2.0 * math.pi * s, 0.0, r)
    assert roll == pytest.approx(wall + 2.0 * disc, rel=1e-9)


# ----------------------------------------------------------------------------- box


def test_box_volume_and_cube_is_a_sphere():
    h = box_hydro([0.2, 0.2, 0.2], RHO)
    assert h.volume_m3 == pytest.approx(0.008, rel=1e-14)
    # a cube's equal-volume ellipsoid is the sphere of the same volume: 0.5 rho V, rel. 1e-9
    np.testing.assert_allclose(np.diag(h.added_mass)[:3], 0.5 * RHO * 0.008, rtol=1e-9)
    np.testing.assert_allclose(np.diag(h.added_mass)[3:], 0.0, atol=1e-12)


def test_box_drag_uses_projected_areas():
    lx, ly, lz = 0.53, 0.245, 0.254
    h = box_hydro([lx, ly, lz], RHO, drag_coefficient=1.0)
    np.testing.assert_allclose(
        h.quadratic_damping[:3], 0.5 * RHO * np.array([ly * lz, lz * lx, lx * ly]), rtol=1e-14
    )
    assert h.quadratic_damping[3] == pytest.approx(RHO * lx * (ly**4 + lz**4) / 64, rel=1e-14)


def test_box_permutation_permutes_coefficients():
    h = box_hydro([0.5, 0.3, 0.1], RHO)
    g = box_hydro([0.3, 0.1, 0.5], RHO)
    perm = [1, 2, 0, 4, 5, 3]
    np.testing.assert_allclose(np.diag(g.added_mass), np.diag(h.added_mass)[perm], rtol=1e-9)
    np.testing.assert_allclose(g.quadratic_damping, h.quadratic_damping[perm], rtol=1e-12)


# ----------------------------------------------------------------------------- all primitives


def _primitives(scale: float = 1.0, rho: float = RHO):
    return [
        sphere_hydro(0.1 * scale, rho),
        cylinder_hydro(0.02 * scale, 0.15 * scale, rho),
        cylinder_hydro(0.1 * scale, 0.05 * scale, rho),  # disk-like
        box_hydro(np.array([0.53, 0.245, 0.254]) * scale, rho),
        box_hydro(np.array([0.1, 0.4, 0.02]) * scale, rho),
    ]


def test_all_matrices_symmetric_psd_and_damping_non_negative():
    for h in _primitives():
        _assert_sym_psd(h.added_mass)
        _assert_sym_psd(h.linear_damping)
        assert np.all(h.quadratic_damping >= 0.0)
        assert h.volume_m3 > 0.0


def test_scaling_laws():
    # Geometric similarity with factor s: added mass ~ s^3 (translation), ~ s^5 (rotation);
    # form drag ~ s^2 (translation), ~ s^5 (rotation). Rel. 1e-9 (shape integrals).
    s = 2.7
    for small, big in zip(_primitives(1.0), _primitives(s), strict=True):
        assert big.volume_m3 == pytest.approx(s**3 * small.volume_m3, rel=1e-12)
        powers = np.array([3, 3, 3, 5, 5, 5])
        np.testing.assert_allclose(
            np.diag(big.added_mass), s**powers * np.diag(small.added_mass), rtol=1e-9, atol=1e-15
        )
        powers_drag = np.array([2, 2, 2, 5, 5, 5])
        np.testing.assert_allclose(
            big.quadratic_damping, s**powers_drag * small.quadratic_damping, rtol=1e-12
        )


def test_coefficients_proportional_to_density():
    for fresh, sea in zip(_primitives(rho=1000.0), _primitives(rho=1025.0), strict=True):
        np.testing.assert_allclose(sea.added_mass, 1.025 * fresh.added_mass, rtol=1e-9, atol=0)
        np.testing.assert_allclose(
            sea.quadratic_damping, 1.025 * fresh.quadratic_damping, rtol=1e-12
        )
        assert sea.volume_m3 == fresh.volume_m3


def test_linear_damping_is_quadratic_times_reference_speed():
    h = cylinder_hydro(
        0.02,
        0.1,
        RHO,
        linear_damping_reference_speed_m_s=0.2,
        linear_damping_reference_rate_rad_s=0.7,
    )
    ref = h.quadratic_damping * np.array([0.2, 0.2, 0.2, 0.7, 0.7, 0.7])
    np.testing.assert_allclose(h.linear_damping, np.diag(ref), rtol=1e-14)
    none = box_hydro(
        [1, 1, 1],
        RHO,
        linear_damping_reference_speed_m_s=0.0,
        linear_damping_reference_rate_rad_s=0.0,
    )
    np.testing.assert_array_equal(none.linear_damping, np.zeros((6, 6)))


# ----------------------------------------------------------------------------- change of frame


def test_offset_sphere_added_mass_is_a_point_mass_spatial_inertia():
    # A sphere's added mass is m_a diag(1,1,1,0,0,0): at an offset p it must equal
    # Pinocchio's spatial inertia of a point mass m_a at p (exact, 1e-12).
    h = sphere_hydro(0.1, RHO)
    p = np.array([0.3, -0.1, 0.2])
    moved = hydro_in_frame(h, np.eye(3), p)
    expected = pin.Inertia(h.added_mass[0, 0], p, np.zeros((3, 3))).matrix()
    np.testing.assert_allclose(moved.added_mass, expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(moved.center_of_buoyancy_m, p)


def test_frame_change_preserves_energy_and_round_trips():
    rng = np.random.default_rng(1)
    h = box_hydro([0.5, 0.3, 0.1], RHO)
    placement = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.7, 1.1), np.array([0.2, 0.05, -0.1]))
    moved = hydro_in_frame(h, placement.rotation, placement.translation)
    _assert_sym_psd(moved.added_mass)
    _assert_sym_psd(moved.linear_damping)
    x = placement.toActionMatrixInverse()  # motion in F -> motion in B
    for _ in range(5):
        nu_f = rng.normal(size=6)
        nu_b = x @ nu_f
        e_f = nu_f @ moved.added_mass @ nu_f
        e_b = nu_b @ h.added_mass @ nu_b
        assert e_f == pytest.approx(e_b, rel=1e-12)
    back = hydro_in_frame(moved, placement.inverse().rotation, placement.inverse().translation)
    np.testing.assert_allclose(back.added_mass, h.added_mass, rtol=0, atol=1e-12)
    np.testing.assert_allclose(back.linear_damping, h.linear_damping, rtol=0, atol=1e-12)
    np.testing.assert_allclose(back.center_of_buoyancy_m, h.center_of_buoyancy_m, atol=1e-15)


def test_cylinder_laid_along_x_and_hinged_at_its_end():
    # Cylinder axis z -> link x (rotation about y by +pi/2), centre at (L/2, 0, 0).
    r, length = 0.025, 0.18
    c = cylinder_hydro(r, length, RHO)
    rot = pin.rpy.rpyToMatrix(0.0, math.pi / 2, 0.0)
    moved = hydro_in_frame(c, rot, [length / 2, 0.0, 0.0])
    m = moved.added_mass
    m_strip = RHO * math.pi * r * r * length
    assert m[0, 0] == pytest.approx(c.added_mass[2, 2], rel=1e-12)  # axial now along x
    assert m[3, 3] == pytest.approx(0.0, abs=1e-15)  # roll about the link axis
    # rotation about the joint's y axis: the strip integral from 0 to L, rho pi r^2 L^3 / 3
    assert m[4, 4] == pytest.approx(m_strip * length**2 / 3.0, rel=1e-12)
    assert m[2, 4] == pytest.approx(-m_strip * length / 2.0, rel=1e-12)
    assert m[1, 5] == pytest.approx(m_strip * length / 2.0, rel=1e-12)
    # quadratic damping about the hinge: centre value + lumped drag of the centre, documented
    q = moved.quadratic_damping
    assert q[4] == pytest.approx(
        c.quadratic_damping[3] + c.quadratic_damping[0] * (length / 2) ** 3
    )
    assert q[0] == pytest.approx(c.quadratic_damping[2], rel=1e-12)


# ----------------------------------------------------------------------------- bad inputs


@pytest.mark.parametrize("bad", [0.0, -0.1, float("nan"), float("inf"), "abc", None])
def test_bad_sizes_raise_parameter_error_naming_the_argument(bad):
    with pytest.raises(ParameterError, match="radius_m"):
        sphere_hydro(bad, RHO)
    with pytest.raises(ParameterError, match="length_m"):
        cylinder_hydro(0.1, bad, RHO)
    with pytest.raises(ParameterError, match="water_density_kg_m3"):
        box_hydro([1, 1, 1], bad)
    with pytest.raises(ParameterError, match=r"size_m\[1\]"):
        box_hydro([1, bad, 1], RHO)
    with pytest.raises(ParameterError, match="c_m"):
        ellipsoid_added_mass(1, 1, bad, RHO)


def test_bad_keywords_and_shapes_raise_parameter_error():
    with pytest.raises(ParameterError, match="size_m"):
        box_hydro([1, 1], RHO)
    with pytest.raises(ParameterError, match="drag_coefficient_cross"):
        cylinder_hydro(0.1, 0.2, RHO, drag_coefficient_cross=-1.0)
    with pytest.raises(ParameterError, match="linear_damping_reference_speed_m_s"):
        sphere_hydro(0.1, RHO, linear_damping_reference_speed_m_s=-0.1)
    with pytest.raises(ParameterError, match="rotation"):
        hydro_in_frame(sphere_hydro(0.1, RHO), np.diag([1.0, 1.0, -1.0]), np.zeros(3))
    with pytest.raises(ParameterError, match="translation_m"):
        hydro_in_frame(sphere_hydro(0.1, RHO), np.eye(3), [0.0, np.nan, 0.0])
