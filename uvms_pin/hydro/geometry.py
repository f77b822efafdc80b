"""Hydrodynamic coefficients of collision primitives (sphere, cylinder, box, ellipsoid).

Every function is pure and returns a :class:`~uvms_pin.hydro.params.HydroParams` with
``derived=True``. Coefficients are given at the primitive's centre, in the primitive's frame,
with URDF conventions (box centred on its origin; cylinder centred, axis along z), and in
Pinocchio's spatial order [linear x, y, z; angular x, y, z]. Use :func:`hydro_in_frame` to move
them to a link origin.

Models used (all magnitudes, positive):

- Added mass: potential flow. Exact for the sphere and the ellipsoid (Lamb 1932, sec. 114-115;
  Imlay 1961); strip theory for the transverse motion of a cylinder (Newman 1977, sec. 4.13);
  Lamb's k-factor of the spheroid of the same length and diameter for its axial motion; the
  ellipsoid with the box's aspect ratios and the box's volume for a box.
- Quadratic damping: form drag, 0.5 rho Cd A_projected in translation; the integral of the
  strip drag over the body in rotation (formulas in each function); skin friction where there
  is no form drag (sphere rotation, cylinder roll).
- Linear damping: the quadratic law "linearised" at a reference speed,
  D_lin = D_quad * u_ref (and omega_ref for rotation): below u_ref the linear term dominates,
  which stands for the laminar/viscous regime in which the quadratic law underestimates drag.
  With u_ref = 0.1 m/s this gives the BlueROV2 surge ratio D_lin/D_quad = 13.7/141 = 0.097 m/s
  (von Benzon et al. 2022). Pass 0 to get no linear damping.

Arguments every primitive takes: ``water_density_kg_m3``, rho [kg/m^3] > 0;
``linear_damping_reference_speed_m_s``, u_ref [m/s] >= 0 (default 0.1), and
``linear_damping_reference_rate_rad_s``, omega_ref [rad/s] >= 0 (default 0.5); where skin
friction enters, ``skin_friction_coefficient``, Cf [-] >= 0 (default 0.0047, the ITTC-1957
line at Re = 1e6).

References:
    H. Lamb, Hydrodynamics, 6th ed., Cambridge, 1932, sec. 114-115 (ellipsoid).
    F. H. Imlay, The complete expressions for "added mass" of a rigid body moving in an ideal
        fluid, DTMB report 1528, 1961.
    J. N. Newman, Marine Hydrodynamics, MIT Press, 1977, sec. 4.13 (added mass, strip theory).
    T. I. Fossen, Handbook of Marine Craft Hydrodynamics and Motion Control, Wiley, 2011/2021,
        sec. 6.4 / 8.4 (Lamb's k-factors of a prolate spheroid).
    DNV-RP-C205, Environmental conditions and environmental loads, 2010, App. D (drag
        coefficients) and App. A (added mass of 2-D sections and 3-D bodies).
    S. F. Hoerner, Fluid-Dynamic Drag, 1965 (drag of bluff bodies, skin friction).
"""

from __future__ import annotations

import math

import numpy as np

from uvms_pin.checks import nonnegative, positive
from uvms_pin.errors import ParameterError
from uvms_pin.hydro.elliptic import carlson_rd
from uvms_pin.hydro.params import HydroParams
from uvms_pin.hydro.vector import skew

__all__ = [
    "box_hydro",
    "cylinder_hydro",
    "ellipsoid_added_mass",
    "ellipsoid_shape_integrals",
    "hydro_in_frame",
    "sphere_hydro",
]

#: Defaults shared by all primitives (documented in the module docstring).
_DEFAULT_REFERENCE_SPEED_M_S = 0.1
_DEFAULT_REFERENCE_RATE_RAD_S = 0.5
#: ITTC-1957 friction line at Re = 1e6: 0.075 / (log10(Re) - 2)^2 = 0.0047.
_DEFAULT_SKIN_FRICTION = 0.0047


# --------------------------------------------------------------------------- validation


def _linear_from_quadratic(quadratic: np.ndarray, reference: tuple[float, float]) -> np.ndarray:
    """Diagonal linear damping D_lin = D_quad * [u_ref]*3 + [omega_ref]*3 (see module doc),
    ``reference`` = (u_ref [m/s], omega_ref [rad/s]), each checked finite and >= 0."""
    u = nonnegative("linear_damping_reference_speed_m_s", reference[0])
    w = nonnegative("linear_damping_reference_rate_rad_s", reference[1])
    return np.diag(quadratic * np.array([u, u, u, w, w, w]))


def _at_centre(
    volume_m3: float,
    added_mass: np.ndarray,
    quadratic_damping: np.ndarray,
    reference: tuple[float, float],
    origin: str,
) -> HydroParams:
    """A primitive's coefficients at its centre (its centre of buoyancy, by symmetry), the
    linear damping from the quadratic one at the ``reference`` speed and rate (the
    primitive's two ``linear_damping_reference_*`` arguments), marked derived."""
    return HydroParams(
        volume_m3=volume_m3,
        center_of_buoyancy_m=np.zeros(3),
        added_mass=added_mass,
        linear_damping=_linear_from_quadratic(quadratic_damping, reference),
        quadratic_damping=quadratic_damping,
        derived=True,
        origin=origin,
    )


# --------------------------------------------------------------------------- ellipsoid


def ellipsoid_shape_integrals(a_m: float, b_m: float, c_m: float) -> tuple[float, float, float]:
    """Lamb's shape integrals (alpha0, beta0, gamma0) of the ellipsoid with semi-axes a, b, c.

    alpha0 = a b c * int_0^inf dl / ((a^2 + l) Delta(l)),
    Delta(l) = sqrt((a^2 + l)(b^2 + l)(c^2 + l)), and beta0, gamma0 likewise with b^2, c^2 in
    the first factor (Lamb 1932, sec. 114). They are dimensionless, depend only on the aspect
    ratios and satisfy alpha0 + beta0 + gamma0 = 2 (each is 2/3 for a sphere). The integral
    is Carlson's symmetric elliptic integral (`uvms_pin.hydro.elliptic`):
    alpha0 = 2/3 a b c R_D(b^2, c^2, a^2), and cyclically; the axes are scaled by the largest
    one first.

    Args:
        a_m, b_m, c_m: semi-axes along x, y, z [m], finite and > 0.

    Returns:
        (alpha0, beta0, gamma0).
    """
    a = positive("a_m", a_m)
    b = positive("b_m", b_m)
    c = positive("c_m", c_m)
    scale = max(a, b, c)
    a2, b2, c2 = (a / scale) ** 2, (b / scale) ** 2, (c / scale) ** 2
    abc = math.sqrt(a2 * b2 * c2)
    return (
        2.0 / 3.0 * abc * carlson_rd(b2, c2, a2),
        2.0 / 3.0 * abc * carlson_rd(c2, a2, b2),
        2.0 / 3.0 * abc * carlson_rd(a2, b2, c2),
    )


def _rotational_added_inertia(
    mass_displaced: float, s1: float, s2: float, k1: float, k2: float
) -> float:
    """Added moment of inertia of an ellipsoid about the axis normal to semi-axes s1, s2.

    I = (1/5) m_f (s1^2 - s2^2)^2 (k2 - k1) / (2 (s1^2 - s2^2) + (s1^2 + s2^2)(k1 - k2))
    (Lamb 1932, sec. 115; Imlay 1961), with k1, k2 the shape integrals of the axes s1, s2 and
    m_f = rho V. It vanishes for s1 = s2 (a body of revolution turning about its axis).
    """
    d = s1 * s1 - s2 * s2
    if abs(d) <= 1e-12 * max(s1, s2) ** 2:
        return 0.0
    num = d * d * (k2 - k1)
    den = 2.0 * d + (s1 * s1 + s2 * s2) * (k1 - k2)
    return max(0.0, 0.2 * mass_displaced * num / den)


def ellipsoid_added_mass(a_m: float, b_m: float, c_m: float, rho_kg_m3: float) -> np.ndarray:
    """Diagonal of the potential-flow added mass of an ellipsoid, at its centre, in its axes.

    With V = 4/3 pi a b c and (alpha0, beta0, gamma0) from :func:`ellipsoid_shape_integrals`
    (Lamb 1932, sec. 114-115; Imlay 1961; Fossen 2011, sec. 6.4 for the spheroid case):

        X_u = alpha0 / (2 - alpha0) rho V,  Y_v = beta0 / (2 - beta0) rho V,
        Z_w = gamma0 / (2 - gamma0) rho V,
        K_p = 1/5 rho V (b^2 - c^2)^2 (gamma0 - beta0)
              / (2 (b^2 - c^2) + (b^2 + c^2)(beta0 - gamma0)),
        and M_q, N_r by the cyclic permutation (a, b, c) -> (b, c, a) -> (c, a, b).

    The general (tri-axial) ellipsoid is handled; the sphere gives 0.5 rho V and zero
    rotational terms exactly; the matrix is diagonal because the three planes of symmetry
    decouple all motions.

    Args:
        a_m, b_m, c_m: semi-axes along x, y, z [m].
        rho_kg_m3: fluid density [kg/m^3].

    Returns:
        (6,) [kg, kg, kg, kg m^2, kg m^2, kg m^2].
    """
    a = positive("a_m", a_m)
    b = positive("b_m", b_m)
    c = positive("c_m", c_m)
    rho = positive("rho_kg_m3", rho_kg_m3)
    alpha0, beta0, gamma0 = ellipsoid_shape_integrals(a, b, c)
    mf = rho * 4.0 / 3.0 * math.pi * a * b * c
    return np.array(
        [
            alpha0 / (2.0 - alpha0) * mf,
            beta0 / (2.0 - beta0) * mf,
            gamma0 / (2.0 - gamma0) * mf,
            _rotational_added_inertia(mf, b, c, beta0, gamma0),
            _rotational_added_inertia(mf, c, a, gamma0, alpha0),
            _rotational_added_inertia(mf, a, b, alpha0, beta0),
        ]
    )


# --------------------------------------------------------------------------- primitives


def sphere_hydro(
    radius_m: float,
    water_density_kg_m3: float,
    *,
    drag_coefficient: float = 0.47,
    skin_friction_coefficient: float = _DEFAULT_SKIN_FRICTION,
    linear_damping_reference_speed_m_s: float = _DEFAULT_REFERENCE_SPEED_M_S,
    linear_damping_reference_rate_rad_s: float = _DEFAULT_REFERENCE_RATE_RAD_S,
) -> HydroParams:
    """Hydrodynamic coefficients of a sphere of radius r, at its centre.

    - Volume V = 4/3 pi r^3, centre of buoyancy at the centre.
    - Added mass (exact potential flow, Lamb 1932 sec. 92; Newman 1977 sec. 4.13):
      0.5 rho V on the translational diagonal, 0 in rotation.
    - Quadratic damping: translation 0.5 rho Cd pi r^2 (Cd = 0.47, subcritical sphere,
      Hoerner 1965; DNV-RP-C205 App. D); rotation by skin friction only, integrating the wall
      shear 0.5 rho Cf (omega r sin(theta))^2 times its arm r sin(theta) over the surface:
      D_rot = 3 pi^2 / 8 rho Cf r^5.
    - Linear damping: D_quad * reference speed / rate (module docstring).

    Args:
        radius_m: r [m] > 0.
        drag_coefficient: Cd of the sphere [-].
        the others: see the module docstring.
    """
    r = positive("radius_m", radius_m)
    rho = positive("water_density_kg_m3", water_density_kg_m3)
    cd = nonnegative("drag_coefficient", drag_coefficient)
    cf = nonnegative("skin_friction_coefficient", skin_friction_coefficient)
    reference = (linear_damping_reference_speed_m_s, linear_damping_reference_rate_rad_s)
    volume = 4.0 / 3.0 * math.pi * r**3
    ma = 0.5 * rho * volume
    added = np.diag([ma, ma, ma, 0.0, 0.0, 0.0])
    d_lin = 0.5 * rho * cd * math.pi * r * r
    d_rot = 3.0 * math.pi**2 / 8.0 * rho * cf * r**5
    quadratic = np.array([d_lin, d_lin, d_lin, d_rot, d_rot, d_rot])
    origin = f"sphere r={r:g} m: potential-flow added mass, Cd={cd:g}"
    return _at_centre(volume, added, quadratic, reference, origin)


def cylinder_hydro(
    radius_m: float,
    length_m: float,
    water_density_kg_m3: float,
    *,
    drag_coefficient_cross: float = 1.1,
    drag_coefficient_axial: float = 0.9,
    skin_friction_coefficient: float = _DEFAULT_SKIN_FRICTION,
    linear_damping_reference_speed_m_s: float = _DEFAULT_REFERENCE_SPEED_M_S,
    linear_damping_reference_rate_rad_s: float = _DEFAULT_REFERENCE_RATE_RAD_S,
) -> HydroParams:
    """Hydrodynamic coefficients of a solid circular cylinder (axis z, centred), at its centre.

    With r the radius, L the length, V = pi r^2 L:

    Added mass:
      - transverse (x, y), strip theory with the 2-D circle coefficient Ca = 1
        (Newman 1977, sec. 4.13; DNV-RP-C205 Table A-1): X_u = Y_v = rho pi r^2 L;
      - rotation about a transverse axis, the same strips at arm s, integrated over
        s in [-L/2, L/2]: K_p = M_q = rho pi r^2 L^3 / 12;
      - axial (z): Lamb's k-factor of the spheroid with the same length and diameter
        (semi-axes L/2, r, r): Z_w = k1 rho V, k1 = gamma0 / (2 - gamma0)
        (Lamb 1932, sec. 114; Fossen 2011). It tends to the end-disk value as L -> 0 up to the
        cylinder/spheroid volume ratio and to 0 for a slender body;
      - roll (about the axis): 0 (a body of revolution spinning about its axis moves no fluid in
        potential flow).
      Strip theory ignores the end effects of a finite cylinder, which lower the transverse
      coefficient (DNV-RP-C205 Table A-2: Ca ~ 0.78 at L/D = 2.5, 0.9 at L/D = 5): the
      transverse values are upper estimates for short links.

    Quadratic damping (form drag, component-wise):
      - transverse: 0.5 rho Cd_cross (2 r L); axial: 0.5 rho Cd_axial (pi r^2);
      - rotation about a transverse axis (x or y): the strip at arm s moves at omega s, so
        M = int_{-L/2}^{L/2} 0.5 rho Cd_cross (2 r) |omega s| omega s s ds
          = rho Cd_cross r L^4 / 32 * |omega| omega,
        plus the end faces moving axially at omega x (disk strips of chord 2 sqrt(r^2 - x^2)):
        rho Cd_axial int_{-r}^{r} |x|^3 sqrt(r^2 - x^2) dx = 4/15 rho Cd_axial r^5;
      - roll, skin friction on the side (shear 0.5 rho Cf (omega r)^2 on 2 pi r L, arm r) and on
        both end disks: pi rho Cf r^4 (L + 2 r / 5).
      Defaults Cd_cross = 1.1 (subcritical circular cylinder, DNV-RP-C205 App. D), Cd_axial =
      0.9 (blunt cylinder end-on, Hoerner 1965 ch. 3, L/D of 1-5).

    Linear damping: D_quad * reference speed / rate (module docstring).

    Args:
        radius_m: r [m] > 0.
        length_m: L [m] > 0.
        drag_coefficient_cross, drag_coefficient_axial: Cd [-] >= 0.
        the others: see the module docstring.
    """
    r = positive("radius_m", radius_m)
    length = positive("length_m", length_m)
    rho = positive("water_density_kg_m3", water_density_kg_m3)
    cd_x = nonnegative("drag_coefficient_cross", drag_coefficient_cross)
    cd_a = nonnegative("drag_coefficient_axial", drag_coefficient_axial)
    cf = nonnegative("skin_friction_coefficient", skin_friction_coefficient)
    reference = (linear_damping_reference_speed_m_s, linear_damping_reference_rate_rad_s)

    volume = math.pi * r * r * length
    m_strip = rho * volume  # Ca = 1 times the displaced mass
    _, _, gamma0 = ellipsoid_shape_integrals(r, r, 0.5 * length)
    k_axial = gamma0 / (2.0 - gamma0)
    i_transverse = m_strip * length * length / 12.0
    added = np.diag([m_strip, m_strip, k_axial * m_strip, i_transverse, i_transverse, 0.0])

    d_cross = 0.5 * rho * cd_x * 2.0 * r * length
    d_axial = 0.5 * rho * cd_a * math.pi * r * r
    d_tumble = rho * cd_x * r * length**4 / 32.0 + 4.0 / 15.0 * rho * cd_a * r**5
    d_roll = math.pi * rho * cf * r**4 * (length + 0.4 * r)
    quadratic = np.array([d_cross, d_cross, d_axial, d_tumble, d_tumble, d_roll])
    origin = (
        f"cylinder r={r:g} m L={length:g} m: strip-theory added mass (Ca=1), "
        f"axial k1={k_axial:.3f}, Cd={cd_x:g}/{cd_a:g}"
    )
    return _at_centre(volume, added, quadratic, reference, origin)


def box_hydro(
    size_m,
    water_density_kg_m3: float,
    *,
    drag_coefficient: float = 1.05,
    linear_damping_reference_speed_m_s: float = _DEFAULT_REFERENCE_SPEED_M_S,
    linear_damping_reference_rate_rad_s: float = _DEFAULT_REFERENCE_RATE_RAD_S,
) -> HydroParams:
    """Hydrodynamic coefficients of a rectangular box of sides (lx, ly, lz), at its centre.

    Added mass: the general (tri-axial) ellipsoid with the box's aspect ratios and the box's
    volume, i.e. semi-axes s_i = (l_i / 2) (6 / pi)^(1/3), through
    :func:`ellipsoid_added_mass` (Lamb 1932, sec. 114-115). A cube gives 0.5 rho V; the
    3-D body table of DNV-RP-C205 (Table A-2) gives about 0.68 rho V for a cube, so this is a
    lower estimate for compact boxes and closer for elongated ones; 2-D rectangles are not
    used here because they ignore the end effects that dominate ROV-sized, stubby hulls.

    Quadratic damping (form drag, component-wise):
      - translation along x: 0.5 rho Cd ly lz (likewise y, z with the projected face);
      - rotation about x: the two profiles normal to y and to z are split in strips moving
        at omega z and omega y, each strip a bluff plate of the same Cd:
        M_x = rho Cd lx (ly^4 + lz^4) / 64 * |omega| omega; likewise
        M_y = rho Cd ly (lz^4 + lx^4) / 64, M_z = rho Cd lz (lx^4 + ly^4) / 64.
      Default Cd = 1.05, the cube face-on (Hoerner 1965; DNV-RP-C205 App. D gives 1.0-1.1 for
      a cube, up to 2 for long rectangular sections).

    Linear damping: D_quad * reference speed / rate (module docstring).

    Args:
        size_m: (lx, ly, lz) full side lengths [m], each > 0.
        drag_coefficient: Cd [-] >= 0.
        the others: see the module docstring.
    """
    sides = np.asarray(size_m, dtype=object).reshape(-1)
    if sides.shape != (3,):
        raise ParameterError(f"size_m must be 3 numbers, got {size_m!r}")
    lx, ly, lz = (positive(f"size_m[{i}]", s) for i, s in enumerate(sides))
    rho = positive("water_density_kg_m3", water_density_kg_m3)
    cd = nonnegative("drag_coefficient", drag_coefficient)
    reference = (linear_damping_reference_speed_m_s, linear_damping_reference_rate_rad_s)

    volume = lx * ly * lz
    k = 0.5 * (6.0 / math.pi) ** (1.0 / 3.0)  # equal-volume semi-axis factor
    added = np.diag(ellipsoid_added_mass(k * lx, k * ly, k * lz, rho))

    half = 0.5 * rho * cd
    quadratic = np.array(
        [
            half * ly * lz,
            half * lz * lx,
            half * lx * ly,
            rho * cd * lx * (ly**4 + lz**4) / 64.0,
            rho * cd * ly * (lz**4 + lx**4) / 64.0,
            rho * cd * lz * (lx**4 + ly**4) / 64.0,
        ]
    )
    origin = f"box {lx:g}x{ly:g}x{lz:g} m: equal-volume ellipsoid added mass (Lamb), Cd={cd:g}"
    return _at_centre(volume, added, quadratic, reference, origin)


# --------------------------------------------------------------------------- change of frame


def _drop_roundoff(m: np.ndarray) -> np.ndarray:
    """Zero the entries below 1e-12 of the largest one (products with cos(pi/2) ~ 6e-17)."""
    scale = float(np.max(np.abs(m))) if m.size else 0.0
    out = m.copy()
    out[np.abs(out) <= 1e-12 * scale] = 0.0
    return out


def hydro_in_frame(params: HydroParams, rotation, translation_m) -> HydroParams:
    """Express a body's coefficients at another frame F (e.g. the link origin).

    The body frame B (where ``params`` hold, e.g. a primitive's centre) sits in F at
    F_R_B = ``rotation`` and F_p_B = ``translation_m``. The motion transform from F to B is

        X = [[R^T, -R^T [p]x], [0, R^T]],   nu_B = X nu_F

    (Pinocchio's ``SE3(R, p).toActionMatrixInverse()``), and the kinetic energy / dissipation
    are invariant, so

        M_A,F = X^T M_A,B X,   D_lin,F = X^T D_lin,B X      (exact; off-diagonal coupling),
        r_b,F = p + R r_b,B,   V unchanged.

    Quadratic damping is not a linear map and is kept as a diagonal estimate at F's origin:
    the translational entries are the rotated diagonal (D_F,i = sum_j R_ij^2 D_B,j, exact for
    axis permutations), and for a unit rotation about F's axis k the centre of B moves at
    u = e_k x p, adding the moment of the lumped translational drag about F's origin:

        D_F,rot,k = sum_j R_ij^2 D_B,rot,j  +  sum_j D_F,lin,j |u_j|^3.

    For a slender rod of length L hinged at one end this gives rho Cd r L^4 (1/32 + 1/8), 5/8 of
    the strip-theory value rho Cd r L^4 / 4: a lower estimate, within the drag-coefficient
    uncertainty of short cylinders.

    Args:
        params: coefficients in frame B.
        rotation: F_R_B (3x3 rotation matrix).
        translation_m: F_p_B (3,) [m].

    Returns:
        HydroParams in frame F (``derived`` and ``origin`` carried over).
    """
    rot = np.asarray(rotation, dtype=float)
    p = np.asarray(translation_m, dtype=float).reshape(-1)
    if rot.shape != (3, 3) or not np.all(np.isfinite(rot)):
        raise ParameterError(f"rotation must be a finite 3x3 matrix, got shape {rot.shape}")
    if not np.allclose(rot.T @ rot, np.eye(3), atol=1e-9) or np.linalg.det(rot) < 0.0:
        raise ParameterError("rotation must be a proper rotation matrix (R^T R = I, det = +1)")
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ParameterError(f"translation_m must be 3 finite numbers, got {translation_m!r}")

    x = np.zeros((6, 6))
    x[:3, :3] = rot.T
    x[:3, 3:] = -rot.T @ skew(np.asarray(p, dtype=float))
    x[3:, 3:] = rot.T
    added = _drop_roundoff(x.T @ params.added_mass @ x)
    linear = _drop_roundoff(x.T @ params.linear_damping @ x)

    r2 = rot * rot
    dq_lin = r2 @ params.quadratic_damping[:3]
    dq_rot = r2 @ params.quadratic_damping[3:]
    for k in range(3):
        u = np.cross(np.eye(3)[k], p)
        dq_rot[k] += float(np.sum(dq_lin * np.abs(u) ** 3))

    return HydroParams(
        volume_m3=params.volume_m3,
        center_of_buoyancy_m=p + rot @ params.center_of_buoyancy_m,
        added_mass=added,
        linear_damping=linear,
        quadratic_damping=np.concatenate([dq_lin, dq_rot]),
        derived=params.derived,
        origin=params.origin,
    )
