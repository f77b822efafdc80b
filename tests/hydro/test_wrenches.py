"""Pure-function tests of the hydrodynamic wrenches (added mass, damping, buoyancy, current)
and of HydroParams validation.

Tolerances: identities that hold exactly in real arithmetic are checked to 1e-12 relative to
the size of the terms involved (a few products of O(1) numbers); the finite-difference check
of the current's body-frame derivative uses a central difference of step 1e-5, whose error
is O(h^2 |w|^2 |v_c|) ~ 1e-10.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.added_mass import (
    added_mass_in_parent,
    kirchhoff_jacobian,
    kirchhoff_wrench,
)
from uvms_pin.hydro.current import current_acceleration_body, current_velocity_body
from uvms_pin.hydro.damping import damping_wrench
from uvms_pin.hydro.params import HydroParams
from uvms_pin.hydro.restoring import (
    buoyancy_potential_energy,
    buoyancy_wrench,
    froude_krylov_wrench,
    point_force_jacobians,
)

RHO = 1025.0
GRAVITY = np.array([0.0, 0.0, -9.81])
N_RANDOM = 50


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def _random_psd(rng: np.random.Generator, rank: int = 6) -> np.ndarray:
    a = rng.normal(size=(6, rank))
    return a @ a.T


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    quat = rng.normal(size=4)
    return pin.Quaternion(quat / np.linalg.norm(quat)).toRotationMatrix()


# ---- added mass -------------------------------------------------------------------------


@pytest.mark.parametrize("rank", [6, 3, 1])
def test_kirchhoff_wrench_does_no_work(rank):
    """nu . C_A(nu) nu = 0 for any symmetric PSD M_A (also singular ones)."""
    rng = _rng(rank)
    for _ in range(N_RANDOM):
        added = _random_psd(rng, rank)
        nu = rng.normal(size=6)
        wrench = kirchhoff_wrench(added, nu)
        scale = np.linalg.norm(nu) ** 2 * np.linalg.norm(added @ nu)
        assert abs(nu @ wrench) < 1e-12 * scale
        assert np.linalg.norm(wrench) > 1e-6 * scale or rank < 6  # not trivially zero


def test_kirchhoff_wrench_is_pinocchio_spatial_cross_product():
    """C_A(nu) nu = nu x* (M_A nu), Pinocchio's Motion.cross(Force)."""
    rng = _rng(10)
    for _ in range(N_RANDOM):
        added = _random_psd(rng)
        nu = rng.normal(size=6)
        expected = pin.Motion(nu).cross(pin.Force(added @ nu)).vector
        np.testing.assert_allclose(
            kirchhoff_wrench(added, nu), expected, rtol=0, atol=1e-12 * np.abs(expected).max()
        )


def test_kirchhoff_wrench_of_a_sphere_vanishes():
    """A sphere translating (w = 0) with isotropic added mass: p1 = m v is parallel to v, so
    v x p1 = 0 and the whole wrench vanishes exactly (d'Alembert's paradox)."""
    added = np.diag([2.0, 2.0, 2.0, 0.0, 0.0, 0.0])
    nu = np.array([0.3, -1.2, 0.7, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(kirchhoff_wrench(added, nu), np.zeros(6))


def test_kirchhoff_wrench_munk_moment():
    """A body with X_u != Y_v moving obliquely in the x-y plane feels the Munk moment
    N = (Y_v - X_u) u v ... with Pinocchio signs: C_A nu moment_z = v x p1 = u v (Y_v - X_u)."""
    xu, yv = 2.0, 7.0
    added = np.diag([xu, yv, 1.0, 0.1, 0.1, 0.1])
    u, v = 0.6, -0.4
    wrench = kirchhoff_wrench(added, np.array([u, v, 0, 0, 0, 0]))
    np.testing.assert_allclose(wrench, [0, 0, 0, 0, 0, u * v * (yv - xu)], atol=1e-15)


def test_added_mass_in_parent_preserves_kinetic_energy():
    """1/2 nu_c^T M_A nu_c = 1/2 nu_p^T (X^T M_A X) nu_p with nu_c = X nu_p, for random
    placements; and the result is symmetric PSD (1e-12 relative)."""
    rng = _rng(11)
    for _ in range(N_RANDOM):
        added = _random_psd(rng)
        placement = pin.SE3(_random_rotation(rng), rng.normal(size=3))
        x = placement.inverse().action
        moved = added_mass_in_parent(added, x)
        nu_parent = rng.normal(size=6)
        nu_child = placement.actInv(pin.Motion(nu_parent)).vector
        energy_child = 0.5 * nu_child @ added @ nu_child
        energy_parent = 0.5 * nu_parent @ moved @ nu_parent
        assert energy_parent == pytest.approx(energy_child, rel=1e-12)
        np.testing.assert_allclose(moved, moved.T, atol=1e-12 * np.abs(moved).max())
        assert np.linalg.eigvalsh(moved).min() > -1e-12 * np.abs(moved).max()


def test_added_mass_in_parent_keeps_kirchhoff_covariant():
    """The Kirchhoff wrench moved from child to parent (X^T w) equals the one computed with
    the moved added mass: frame covariance, what lets rigidly joined bodies add up."""
    rng = _rng(12)
    for _ in range(N_RANDOM):
        added = _random_psd(rng)
        placement = pin.SE3(_random_rotation(rng), rng.normal(size=3))
        x = placement.inverse().action
        nu_parent = rng.normal(size=6)
        in_child = x.T @ kirchhoff_wrench(added, x @ nu_parent)
        in_parent = kirchhoff_wrench(added_mass_in_parent(added, x), nu_parent)
        np.testing.assert_allclose(in_parent, in_child, atol=1e-11 * np.abs(in_child).max())


def test_kirchhoff_jacobian_is_the_derivative_of_the_wrench_for_one_body_and_a_stack():
    """d(C_A(nu) nu)/d nu by central differences. The wrench is quadratic in nu, so the
    central difference (w(nu + h e_k) - w(nu - h e_k)) / 2h is exact up to rounding (h = 1e-3,
    1e-10 relative). A stack of bodies (k, 6, 6), (k, 6) gives each body's Jacobian."""
    rng = _rng(11)
    k, h = 4, 1e-3
    added = np.array([_random_psd(rng) for _ in range(k)])
    nu = rng.normal(size=(k, 6))
    stacked = kirchhoff_jacobian(added, nu)
    assert stacked.shape == (k, 6, 6)
    for b in range(k):
        fd = np.column_stack(
            [
                (
                    kirchhoff_wrench(added[b], nu[b] + h * e)
                    - kirchhoff_wrench(added[b], nu[b] - h * e)
                )
                / (2 * h)
                for e in np.eye(6)
            ]
        )
        scale = np.abs(fd).max()
        np.testing.assert_allclose(kirchhoff_jacobian(added[b], nu[b]), fd, atol=1e-10 * scale)
        np.testing.assert_allclose(stacked[b], fd, atol=1e-10 * scale)


# ---- damping ----------------------------------------------------------------------------


def test_damping_power_is_never_positive():
    """nu_r . w_D <= 0 for PSD (also non-symmetric with PSD symmetric part) D_lin, D_quad >= 0."""
    rng = _rng(20)
    for _ in range(N_RANDOM):
        skew = rng.normal(size=(6, 6))
        linear = _random_psd(rng, 3) + (skew - skew.T)  # a skew part does no work
        quadratic = rng.uniform(0, 5, 6)
        nu = rng.normal(size=6)
        power = nu @ damping_wrench(linear, quadratic, nu)
        expected = -(nu @ linear @ nu) - quadratic @ (np.abs(nu) * nu * nu)
        assert power <= 1e-12 * abs(expected)
        assert power == pytest.approx(expected, rel=1e-12)


def test_damping_is_odd_and_splits_linear_plus_quadratic():
    rng = _rng(21)
    linear = _random_psd(rng)
    quadratic = rng.uniform(0, 5, 6)
    for _ in range(N_RANDOM):
        nu = rng.normal(size=6)
        w = damping_wrench(linear, quadratic, nu)
        np.testing.assert_array_equal(damping_wrench(linear, quadratic, -nu), -w)
        np.testing.assert_allclose(
            w,
            damping_wrench(linear, np.zeros(6), nu)
            + damping_wrench(np.zeros((6, 6)), quadratic, nu),
            atol=1e-13 * np.abs(w).max(),
        )
    # quadratic law: doubling the speed quadruples the (purely quadratic) wrench, exactly
    nu = rng.normal(size=6)
    np.testing.assert_allclose(
        damping_wrench(np.zeros((6, 6)), quadratic, 2 * nu),
        4 * damping_wrench(np.zeros((6, 6)), quadratic, nu),
        rtol=1e-15,
    )
    np.testing.assert_array_equal(damping_wrench(linear, quadratic, np.zeros(6)), np.zeros(6))


# ---- buoyancy ---------------------------------------------------------------------------


def test_buoyancy_is_rho_v_g_up_in_the_world_for_any_attitude():
    """R f_b = (0, 0, rho V g) and the moment is r_b x f_b (1e-12 relative)."""
    rng = _rng(30)
    volume = 0.011
    lift = RHO * volume * 9.81
    for _ in range(N_RANDOM):
        rotation = _random_rotation(rng)
        cob = rng.normal(size=3) * 0.1
        wrench = buoyancy_wrench(volume, cob, rotation, RHO, GRAVITY)
        np.testing.assert_allclose(rotation @ wrench[:3], [0, 0, lift], atol=1e-12 * lift)
        np.testing.assert_allclose(wrench[3:], np.cross(cob, wrench[:3]), atol=1e-12 * lift)


def test_buoyancy_moment_is_minus_gradient_of_potential():
    """Rotating the body by a small body-frame angle e_k h changes U_b by -moment_k h
    (virtual work); central difference h = 1e-6, error O(h^2) ~ 1e-12 relative."""
    rng = _rng(31)
    volume, h = 0.01, 1e-6
    for _ in range(10):
        rotation = _random_rotation(rng)
        position = rng.normal(size=3)
        cob = rng.normal(size=3) * 0.1
        moment = buoyancy_wrench(volume, cob, rotation, RHO, GRAVITY)[3:]
        for k in range(3):
            delta = np.zeros(3)
            delta[k] = h

            def energy(rot, position=position, cob=cob):
                return buoyancy_potential_energy(volume, position + rot @ cob, RHO, GRAVITY)

            d_energy = (
                energy(rotation @ pin.exp3(delta)) - energy(rotation @ pin.exp3(-delta))
            ) / (2 * h)
            assert d_energy == pytest.approx(-moment[k], abs=1e-6 * RHO * volume * 9.81 * 0.1)


def test_froude_krylov_is_rho_v_times_flow_acceleration_at_the_centre_of_buoyancy():
    """The pressure of an accelerating flow pushes the displaced volume with rho V Du/Dt
    (world) at the centre of buoyancy: R f = rho V a and the moment is r_b x f, for one body
    and for a stack; with a = -g it is the buoyancy wrench (both are rho V (Du/Dt - g))."""
    rng = _rng(32)
    volume = 0.02
    rotations = np.array([_random_rotation(rng) for _ in range(5)])
    cobs = rng.normal(size=(5, 3)) * 0.1
    accelerations = rng.normal(size=(5, 3))
    stacked = froude_krylov_wrench(np.full(5, volume), cobs, rotations, RHO, accelerations)
    for b in range(5):
        wrench = froude_krylov_wrench(volume, cobs[b], rotations[b], RHO, accelerations[b])
        scale = RHO * volume * np.linalg.norm(accelerations[b])
        np.testing.assert_allclose(
            rotations[b] @ wrench[:3], RHO * volume * accelerations[b], atol=1e-12 * scale
        )
        np.testing.assert_allclose(wrench[3:], np.cross(cobs[b], wrench[:3]), atol=1e-12 * scale)
        np.testing.assert_allclose(stacked[b], wrench, atol=1e-12 * scale)
    np.testing.assert_allclose(
        froude_krylov_wrench(volume, cobs[0], rotations[0], RHO, -GRAVITY),
        buoyancy_wrench(volume, cobs[0], rotations[0], RHO, GRAVITY),
        atol=1e-12 * RHO * volume * 9.81,
    )


def test_point_force_jacobians_are_derivatives_for_one_body_and_a_stack():
    """w(R, F) = [R^T F; r x R^T F]: d/d theta under R -> R exp([theta]x) by central
    differences (h = 1e-6, error O(h^2) ~ 1e-12) and d/dF (w is linear in F: exact), for
    one body and for each body of a stack (k, 3), (k, 3, 3)."""
    rng = _rng(33)
    k, h = 4, 1e-6
    rotations = np.array([_random_rotation(rng) for _ in range(k)])
    points = rng.normal(size=(k, 3))
    forces = rng.normal(size=(k, 3)) * 10.0

    def wrench(rotation, point, force):
        f = rotation.T @ force
        return np.r_[f, np.cross(point, f)]

    forces_body = np.einsum("kji,kj->ki", rotations, forces)
    by_rotation_stack, by_force_stack = point_force_jacobians(forces_body, points, rotations)
    for b in range(k):
        rotation, point, force = rotations[b], points[b], forces[b]
        fd_rotation = np.column_stack(
            [
                (
                    wrench(rotation @ pin.exp3(h * e), point, force)
                    - wrench(rotation @ pin.exp3(-h * e), point, force)
                )
                / (2 * h)
                for e in np.eye(3)
            ]
        )
        fd_force = np.column_stack(
            [wrench(rotation, point, force + e) - wrench(rotation, point, force) for e in np.eye(3)]
        )
        by_rotation, by_force = point_force_jacobians(rotation.T @ force, point, rotation)
        scale = np.linalg.norm(force) * (1 + np.linalg.norm(point))
        for got_rotation, got_force in (
            (by_rotation, by_force),
            (by_rotation_stack[b], by_force_stack[b]),
        ):
            np.testing.assert_allclose(got_rotation, fd_rotation, atol=1e-8 * scale)
            np.testing.assert_allclose(
                got_force, fd_force, atol=1e-12 * (1 + np.linalg.norm(point))
            )


# ---- current ----------------------------------------------------------------------------


def test_current_velocity_body_is_rotated_world_current():
    rng = _rng(40)
    current = np.array([0.3, -0.2, 0.1])
    for _ in range(10):
        rotation = _random_rotation(rng)
        nu_c = current_velocity_body(rotation, current)
        np.testing.assert_allclose(rotation @ nu_c[:3], current, atol=1e-15)
        np.testing.assert_array_equal(nu_c[3:], np.zeros(3))  # irrotational


def test_current_acceleration_is_time_derivative_along_a_rotation():
    """R(t) = R0 exp(t [w]x) (body angular velocity w): d/dt [R^T v_c; 0] by central
    differences (h = 1e-5) equals current_acceleration_body(w, R0^T v_c) to 1e-9."""
    rng = _rng(41)
    current = np.array([0.5, -0.3, 0.2])
    h = 1e-5
    for _ in range(N_RANDOM):
        rotation = _random_rotation(rng)
        omega = rng.normal(size=3)

        def nu_c(t, rotation=rotation, omega=omega):
            return current_velocity_body(rotation @ pin.exp3(t * omega), current)

        fd = (nu_c(h) - nu_c(-h)) / (2 * h)
        got = current_acceleration_body(omega, nu_c(0.0)[:3])
        np.testing.assert_allclose(got, fd, atol=1e-9)
    # and with no rotation the current is constant in the body too
    np.testing.assert_array_equal(current_acceleration_body(np.zeros(3), current), np.zeros(6))


# ---- HydroParams validation ------------------------------------------------------------

_GOOD = {
    "volume_m3": 0.01,
    "center_of_buoyancy_m": np.zeros(3),
    "added_mass": np.eye(6),
    "linear_damping": np.eye(6),
    "quadratic_damping": np.ones(6),
}
_NOT_SYMMETRIC = np.eye(6)
_NOT_SYMMETRIC[0, 1] = 0.1
_NOT_PSD = np.diag([1.0, 1, 1, 1, 1, -0.5])
_ACTIVE_DAMPING = np.eye(6)
_ACTIVE_DAMPING[0, 0] = -1.0

BAD_PARAMS = {
    "negative volume": ({"volume_m3": -0.1}, "volume must be >= 0"),
    "nan volume": ({"volume_m3": np.nan}, "volume contains a non-finite"),
    "cob size": ({"center_of_buoyancy_m": np.zeros(2)}, "center_of_buoyancy must have 3"),
    "added mass shape": ({"added_mass": np.eye(5)}, "added_mass must be 6x6"),
    "added mass not symmetric": ({"added_mass": _NOT_SYMMETRIC}, "added_mass must be symmetric"),
    "added mass not PSD": ({"added_mass": _NOT_PSD}, "added_mass must be positive semi-definite"),
    "added mass inf": ({"added_mass": np.full((6, 6), np.inf)}, "added_mass contains a non-finite"),
    "linear damping active": (
        {"linear_damping": _ACTIVE_DAMPING},
        "linear_damping must be positive",
    ),
    "linear damping shape": ({"linear_damping": np.ones(4)}, "linear_damping must be 6x6"),
    "quadratic negative": (
        {"quadratic_damping": np.array([1, 1, 1, 1, 1, -1.0])},
        "quadratic_damping must be >= 0",
    ),
    "quadratic shape": ({"quadratic_damping": np.ones(7)}, "quadratic_damping must have 6"),
}


@pytest.mark.parametrize("case", list(BAD_PARAMS), ids=list(BAD_PARAMS))
def test_hydro_params_validation(case):
    change, message = BAD_PARAMS[case]
    with pytest.raises(ParameterError, match=message):
        HydroParams(**{**_GOOD, **change})


def test_hydro_params_accepts_diagonals_and_symmetrises():
    p = HydroParams(0.01, [0, 0, 0.01], np.arange(1.0, 7.0), np.arange(1.0, 7.0), np.ones(6))
    np.testing.assert_array_equal(p.added_mass, np.diag(np.arange(1.0, 7.0)))
    np.testing.assert_array_equal(p.linear_damping, np.diag(np.arange(1.0, 7.0)))
    assert p.center_of_buoyancy_m.shape == (3,)
    # a round-off asymmetry (below 1e-9 of the scale) is accepted and removed
    nearly = np.eye(6)
    nearly[0, 1] = 1e-13
    q = HydroParams(0.01, np.zeros(3), nearly, np.zeros(6), np.zeros(6))
    np.testing.assert_array_equal(q.added_mass, q.added_mass.T)


def test_hydro_params_equality_compares_values():
    """Dataclass equality must not raise on array fields (it used to: 'truth value of an
    array is ambiguous'); ``origin`` is a note and is not compared."""
    a = HydroParams(**_GOOD, origin="URDF")
    b = HydroParams(**_GOOD, origin="somewhere else")
    assert a == b
    assert a != HydroParams(**{**_GOOD, "volume_m3": 0.02})
    assert a != HydroParams(**{**_GOOD, "added_mass": 2 * np.eye(6)})
    assert a != HydroParams(**_GOOD, derived=True)
    assert HydroParams.dry() == HydroParams.dry()
