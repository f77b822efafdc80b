"""Automatic trim: foam and lead ballast so a UVMS floats neutral and level, as pilots do.

A heavy arm makes the vehicle sink (weight > buoyancy) and tip (the centre of gravity G moves
off the vertical of the centre of buoyancy B). Pilots add syntactic foam on top and lead
ballast below. :func:`plan_trim` computes how much and where, for the arm in a given
configuration (e.g. the task's initial one) with the vehicle level:

- the foam is a slab of the hull's footprint (lx x ly) on top of the hull, density
  ``foam_density_kg_m3`` (syntactic foam, 200-450 kg/m^3 for shallow depths), thickness
  t_f = V_f / (lx ly), centroid at z_top + t_f / 2;
- the ballast is a lead slab (11340 kg/m^3) under the hull, centroid at z_bottom - t_b / 2.

With rho the water density, M, V, z_G, z_B the system's mass, volume and centre heights
before trim, the two unknowns V_f (foam volume) and m_b (ballast mass) solve two linear
equations (t_f, t_b change z_f, z_b slightly: a few fixed-point passes):

    neutral:  (rho - rho_f) V_f + (rho / rho_b - 1) m_b = M - rho V
    BG:       rho (V z_B + V_f z_f + m_b z_b / rho_b) - (M z_G + rho_f V_f z_f + m_b z_b)
                = BG (M + rho_f V_f + m_b)

(the second is z_B' - z_G' = BG multiplied by the total weight, which equals the total
buoyancy once neutral). A negative solution means one of the two cannot help (e.g. a light
arm needs no foam): it is set to zero, neutrality is kept and the BG obtained is reported.

Level trim (no pitch or roll moment at rest): the horizontal positions of the foam and the
ballast are the least-norm solution of
L_f x_f - N_b x_b = M x_G - rho V x_B (and the same in y), with L_f = (rho - rho_f) V_f the
foam's net lift and N_b = m_b (1 - rho / rho_b) the ballast's net weight, clipped to the
hull footprint; what the clipping leaves is reported as a residual moment and the static
angle it causes (moment / (W BG)).

`uvms_pin.model.trim_urdf.add_trim_links` writes them into the URDF. Only the volumes and
masses of the foam and ballast are added (their ``<hydrodynamics>`` hold the volume): the
foam slab enlarges the vehicle's envelope, whose added mass and drag grow a little, but a
slab on top of the hull is not a free plate (``box_hydro`` of a thin slab would add a flat
plate's large heave added mass): the change is neglected. Re-derive the hull's
coefficients for the new envelope if the foam is thick.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector, positive
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS

__all__ = ["TrimReport", "TrimSpec", "mass_properties", "plan_trim"]

LEAD_DENSITY_KG_M3 = 11340.0
_FIXED_POINT_PASSES = 8
#: a net lift or weight below this fraction of the system's mass is none (rounding)
_NEGLIGIBLE = 1e-12


@dataclass(frozen=True)
class TrimSpec:
    """What the trim should achieve and with what.

    Attributes:
        bg_m: metacentric height BG = z_B - z_G [m] wanted (> 0: passively stable in roll
            and pitch; the reference LBV150 UVMS has 1.72 cm).
        foam_density_kg_m3: buoyant foam (syntactic foam 200-450; must be < water).
        ballast_density_kg_m3: ballast (lead 11340; must be > water).
        footprint_m: (lx, ly) of the foam and ballast slabs; None = the hull's collision box.
        top_z_m, bottom_z_m: heights of the hull's top and bottom in the vehicle frame;
            None = from the hull's collision box.
        footprint_center_m: (x, y) of the footprint centre; None = the hull box's.
    """

    bg_m: float = 0.02
    foam_density_kg_m3: float = 350.0
    ballast_density_kg_m3: float = LEAD_DENSITY_KG_M3
    footprint_m: tuple[float, float] | None = None
    top_z_m: float | None = None
    bottom_z_m: float | None = None
    footprint_center_m: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        for name in ("bg_m", "foam_density_kg_m3", "ballast_density_kg_m3"):
            positive(name, getattr(self, name))
        # each given one finite: a nan here would place the foam or the ballast at nan
        if self.footprint_m is not None:
            for k, side in enumerate(finite_vector("footprint_m", self.footprint_m, 2)):
                positive(f"footprint_m[{k}]", side)
        if self.footprint_center_m is not None:
            finite_vector("footprint_center_m", self.footprint_center_m, 2)
        for name in ("top_z_m", "bottom_z_m"):
            if getattr(self, name) is not None:
                finite_vector(name, [getattr(self, name)], 1)
        if self.top_z_m is not None and self.bottom_z_m is not None:
            if not self.top_z_m > self.bottom_z_m:
                raise ParameterError(
                    f"top_z_m must be above bottom_z_m, got {self.top_z_m} and {self.bottom_z_m}"
                )


@dataclass
class TrimReport:
    """What the trim added and what it achieves (positions in the vehicle frame [m])."""

    foam_volume_m3: float
    foam_mass_kg: float
    foam_size_m: tuple[float, float, float]
    foam_position_m: np.ndarray
    ballast_mass_kg: float
    ballast_volume_m3: float
    ballast_size_m: tuple[float, float, float]
    ballast_position_m: np.ndarray
    mass_before_kg: float
    mass_after_kg: float
    net_buoyancy_before_N: float
    net_buoyancy_after_N: float
    bg_before_m: float
    bg_target_m: float
    bg_after_m: float
    residual_moment_Nm: np.ndarray  # (roll, pitch) moment left at rest, about x and y
    residual_tilt_rad: np.ndarray  # static (roll, pitch) it causes
    notes: list[str] = field(default_factory=list)

    def as_dict(self) -> dict:
        out = asdict(self)
        for key, value in out.items():
            if isinstance(value, np.ndarray):
                out[key] = value.tolist()
        return out

    def summary(self) -> str:
        lines = [
            f"foam: {self.foam_volume_m3 * 1e3:.2f} L, {self.foam_mass_kg:.3f} kg, slab "
            f"{self.foam_size_m[0]:.3f} x {self.foam_size_m[1]:.3f} x {self.foam_size_m[2]:.3f} m "
            f"at [{', '.join(f'{x:.3f}' for x in self.foam_position_m)}] m",
            f"ballast: {self.ballast_mass_kg:.3f} kg lead ({self.ballast_volume_m3 * 1e3:.3f} L) "
            f"at [{', '.join(f'{x:.3f}' for x in self.ballast_position_m)}] m",
            f"net buoyancy {self.net_buoyancy_before_N:+.3f} N -> {self.net_buoyancy_after_N:+.3f} N, "
            f"mass {self.mass_before_kg:.3f} -> {self.mass_after_kg:.3f} kg, "
            f"BG {self.bg_before_m * 100:.2f} -> {self.bg_after_m * 100:.2f} cm "
            f"(target {self.bg_target_m * 100:.2f} cm)",
        ]
        if np.any(np.abs(self.residual_tilt_rad) > 1e-6):
            lines.append(
                "residual static tilt (roll, pitch): "
                f"{np.degrees(self.residual_tilt_rad[0]):.2f}, "
                f"{np.degrees(self.residual_tilt_rad[1]):.2f} deg"
            )
        lines += self.notes
        return "\n".join(lines)


def mass_properties(uvms: UVMS, q: np.ndarray) -> tuple[float, np.ndarray, float, np.ndarray]:
    """(mass [kg], centre of gravity [m], volume [m^3], centre of buoyancy [m]) of the whole
    system at the arm configuration of ``q``, in the vehicle frame (the vehicle part of q is
    ignored)."""
    model = uvms.model
    q = np.array(q, dtype=float)
    q[:7] = pin.neutral(model)[:7]
    data = model.createData()
    com = np.array(pin.centerOfMass(model, data, q))
    mass = float(data.mass[0])
    volume, moment = 0.0, np.zeros(3)
    for body in uvms.hydro_bodies:
        v = body.params.volume_m3
        if v == 0.0:
            continue
        placement = data.oMi[body.joint_id] * body.placement_in_joint
        volume += v
        moment += v * placement.act(body.params.center_of_buoyancy_m)
    cob = moment / volume if volume > 0.0 else np.zeros(3)
    return mass, com, volume, cob


def plan_trim(
    uvms: UVMS,
    q: np.ndarray,
    spec: TrimSpec = TrimSpec(),
    *,
    hull: tuple[np.ndarray, np.ndarray] | None = None,
) -> TrimReport:
    """Foam and ballast for neutral buoyancy, the wanted BG and a level vehicle.

    Args:
        uvms: the untrimmed system.
        q: configuration whose arm part is used (the vehicle level at the origin).
        spec: targets and materials.
        hull: (centre, size) of the hull box in the vehicle frame, for the defaults of
            ``spec``'s footprint and heights.

    Raises:
        ParameterError: no footprint/heights given and no hull box; foam not lighter or
            ballast not denser than water.
    """
    rho = uvms.water_density_kg_m3
    g = float(np.linalg.norm(uvms.model.gravity.linear))
    rho_f, rho_b = spec.foam_density_kg_m3, spec.ballast_density_kg_m3
    if not rho_f < rho < rho_b:
        raise ParameterError(
            f"foam ({rho_f} kg/m^3) must be lighter and ballast ({rho_b} kg/m^3) denser than "
            f"the water ({rho} kg/m^3)"
        )
    footprint = _footprint(spec, hull)
    before = _MassProperties(*mass_properties(uvms, q))
    foam_v, ballast_m = _foam_and_ballast(before, spec, rho, footprint)
    foam_m = rho_f * foam_v
    ballast_v = ballast_m / rho_b
    z_f, z_b, notes = _heights(before, spec, rho, footprint, foam_v, ballast_m)
    lift = (rho - rho_f) * foam_v
    sink = ballast_m - rho * ballast_v
    foam_xy, ballast_xy, residual = _level(before, rho, footprint, lift, sink)
    foam_pos = np.array([foam_xy[0], foam_xy[1], z_f])
    ballast_pos = np.array([ballast_xy[0], ballast_xy[1], z_b])

    mass, com, volume, cob = before.mass_kg, before.com_m, before.volume_m3, before.cob_m
    mass_after = mass + foam_m + ballast_m
    volume_after = volume + foam_v + ballast_v
    com_after = (mass * com + foam_m * foam_pos + ballast_m * ballast_pos) / mass_after
    cob_after = (volume * cob + foam_v * foam_pos + ballast_v * ballast_pos) / volume_after
    bg_after = float(cob_after[2] - com_after[2])
    if abs(bg_after - spec.bg_m) > 1e-4:
        side = "more" if bg_after > spec.bg_m else "less"
        notes.append(
            f"BG target {spec.bg_m * 100:.2f} cm not reachable with foam and ballast within the "
            f"hull's height: BG = {bg_after * 100:.2f} cm ({side} stable than asked)"
        )
    moment, tilt = _residual_tilt(residual, mass_after * g, bg_after, g)
    if np.any(np.abs(residual) > 1e-9):
        why = (
            "foam/ballast offsets clipped to the hull footprint"
            if lift > 0.0 or sink > 0.0
            else "neutral without foam or ballast, none to level it"
        )
        notes.append(
            f"{why}: the vehicle rests at roll {math.degrees(tilt[0]):.1f} deg, pitch "
            f"{math.degrees(tilt[1]):.1f} deg"
        )
    return TrimReport(
        foam_volume_m3=foam_v,
        foam_mass_kg=foam_m,
        foam_size_m=(float(footprint.lx_m), float(footprint.ly_m), foam_v / footprint.area_m2),
        foam_position_m=foam_pos,
        ballast_mass_kg=ballast_m,
        ballast_volume_m3=ballast_v,
        ballast_size_m=(
            float(footprint.lx_m),
            float(footprint.ly_m),
            ballast_v / footprint.area_m2,
        ),
        ballast_position_m=ballast_pos,
        mass_before_kg=mass,
        mass_after_kg=mass_after,
        net_buoyancy_before_N=(rho * volume - mass) * g,
        net_buoyancy_after_N=(rho * volume_after - mass_after) * g,
        bg_before_m=float(cob[2] - com[2]),
        bg_target_m=spec.bg_m,
        bg_after_m=bg_after,
        residual_moment_Nm=moment,
        residual_tilt_rad=tilt,
        notes=notes,
    )


@dataclass(frozen=True)
class _MassProperties:
    """The system before trim, in the vehicle frame (`mass_properties`)."""

    mass_kg: float
    com_m: np.ndarray
    volume_m3: float
    cob_m: np.ndarray


@dataclass(frozen=True)
class _Footprint:
    """Where the slabs go, in the vehicle frame: their (lx, ly) and its centre (x, y), the
    hull's top (foam on it) and bottom (ballast under it) [m]."""

    lx_m: float
    ly_m: float
    center_x_m: float
    center_y_m: float
    top_z_m: float
    bottom_z_m: float
    area_m2: float


def _footprint(spec: TrimSpec, hull: tuple[np.ndarray, np.ndarray] | None) -> _Footprint:
    """``spec``'s footprint and heights, the hull box's where ``spec`` leaves them None."""
    if hull is None and (
        spec.footprint_m is None or spec.top_z_m is None or spec.bottom_z_m is None
    ):
        raise ParameterError(
            "the vehicle has no box collision: give TrimSpec footprint_m, top_z_m and bottom_z_m"
        )
    hull_center = np.zeros(3) if hull is None else np.asarray(hull[0], dtype=float)
    hull_size = np.zeros(3) if hull is None else np.asarray(hull[1], dtype=float)
    lx, ly = spec.footprint_m if spec.footprint_m is not None else hull_size[:2]
    cx, cy = spec.footprint_center_m if spec.footprint_center_m is not None else hull_center[:2]
    top = spec.top_z_m if spec.top_z_m is not None else hull_center[2] + hull_size[2] / 2
    bottom = spec.bottom_z_m if spec.bottom_z_m is not None else hull_center[2] - hull_size[2] / 2
    area = lx * ly
    if not (area > 0.0 and math.isfinite(area)):
        raise ParameterError(f"trim footprint must be positive, got {lx} x {ly} m")
    return _Footprint(lx, ly, cx, cy, top, bottom, area)


def _foam_and_ballast(
    before: _MassProperties, spec: TrimSpec, rho: float, footprint: _Footprint
) -> tuple[float, float]:
    """(V_f [m^3], m_b [kg]) solving the neutral and BG equations (module docstring); the
    slab heights move the centroids, hence the fixed-point passes. A negative solution:
    the one material that keeps the system neutral alone."""
    mass, com, volume, cob = before.mass_kg, before.com_m, before.volume_m3, before.cob_m
    rho_f, rho_b, bg = spec.foam_density_kg_m3, spec.ballast_density_kg_m3, spec.bg_m
    foam_v, ballast_m = 0.0, 0.0
    for _ in range(_FIXED_POINT_PASSES):
        z_f = footprint.top_z_m + 0.5 * foam_v / footprint.area_m2
        z_b = footprint.bottom_z_m - 0.5 * (ballast_m / rho_b) / footprint.area_m2
        a = np.array(
            [
                [rho - rho_f, rho / rho_b - 1.0],
                [(rho - rho_f) * z_f - bg * rho_f, (rho / rho_b - 1.0) * z_b - bg],
            ]
        )
        b = np.array([mass - rho * volume, bg * mass - rho * volume * cob[2] + mass * com[2]])
        foam_v, ballast_m = np.linalg.solve(a, b)
        if foam_v < 0.0 or ballast_m < 0.0:
            if mass - rho * volume >= 0.0:  # sinks: foam only
                foam_v, ballast_m = (mass - rho * volume) / (rho - rho_f), 0.0
            else:  # floats: ballast only
                foam_v, ballast_m = 0.0, (mass - rho * volume) / (rho / rho_b - 1.0)
    # a system neutral already (a model trimmed for this water) solves to amounts of the
    # order of its mass's rounding (1e-18 m^3 of foam): none, not a slab to place
    negligible_kg = _NEGLIGIBLE * mass
    if foam_v * (rho - rho_f) < negligible_kg:
        foam_v = 0.0
    if ballast_m * (1.0 - rho / rho_b) < negligible_kg:
        ballast_m = 0.0
    return float(foam_v), float(ballast_m)


def _heights(
    before: _MassProperties,
    spec: TrimSpec,
    rho: float,
    footprint: _Footprint,
    foam_v: float,
    ballast_m: float,
) -> tuple[float, float, list[str]]:
    """(z_f, z_b [m], notes): the slabs' centroids on top of and under the hull; with one
    material only, its height is the free parameter left to reach the BG target (clipped
    to the hull's height)."""
    mass, com, volume, cob = before.mass_kg, before.com_m, before.volume_m3, before.cob_m
    rho_f, bg = spec.foam_density_kg_m3, spec.bg_m
    top, bottom, area = footprint.top_z_m, footprint.bottom_z_m, footprint.area_m2
    foam_m = rho_f * foam_v
    ballast_v = ballast_m / spec.ballast_density_kg_m3
    z_f = top + 0.5 * foam_v / area
    z_b = bottom - 0.5 * ballast_v / area
    notes: list[str] = []
    weight_bg = bg * (mass + foam_m + ballast_m) - rho * volume * cob[2] + mass * com[2]
    if foam_v > 0.0 and ballast_m == 0.0:
        t = foam_v / area
        wanted = weight_bg / ((rho - rho_f) * foam_v)
        z_f = float(np.clip(wanted, bottom + t / 2, top + t / 2))
        if z_f < top:
            notes.append(
                f"foam centroid lowered to z = {z_f:.3f} m (inside the frame) for the BG target"
            )
    elif ballast_m > 0.0 and foam_v == 0.0:
        t = ballast_v / area
        wanted = weight_bg / (rho * ballast_v - ballast_m)
        z_b = float(np.clip(wanted, bottom - t / 2, top - t / 2))
        if z_b > bottom:
            notes.append(f"ballast raised to z = {z_b:.3f} m (inside the frame) for the BG target")
    return z_f, z_b, notes


def _level(
    before: _MassProperties, rho: float, footprint: _Footprint, lift: float, sink: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(foam (x, y), ballast (x, y) [m], residual [kg m]): the least-norm horizontal offsets
    that leave no pitch or roll moment, L_f x_f - N_b x_b = M x_G - rho V x_B (``lift``
    L_f, ``sink`` N_b as masses), clipped to the footprint; the residual is the moment
    (as mass * m, about y for x, about x for y) the clipping leaves."""
    mass, com, volume, cob = before.mass_kg, before.com_m, before.volume_m3, before.cob_m
    cx, cy = footprint.center_x_m, footprint.center_y_m
    foam_xy = np.array([cx, cy], dtype=float)
    ballast_xy = np.array([cx, cy], dtype=float)
    residual = np.zeros(2)
    half = np.array([footprint.lx_m, footprint.ly_m]) / 2
    center = np.array([cx, cy])
    for k in range(2):
        # about the footprint centre: L (x_f - c) - N (x_b - c) = D - (L - N) c
        demand = mass * com[k] - rho * volume * cob[k] - (lift - sink) * center[k]
        norm = lift * lift + sink * sink
        if norm > 0.0:
            df, db = demand * lift / norm, -demand * sink / norm
            df, db = float(np.clip(df, -half[k], half[k])), float(np.clip(db, -half[k], half[k]))
        else:
            df = db = 0.0
        foam_xy[k] = center[k] + df
        ballast_xy[k] = center[k] + db
        residual[k] = demand - (lift * df - sink * db)
    return foam_xy, ballast_xy, residual


def _residual_tilt(
    residual_kg_m: np.ndarray, weight_N: float, bg_m: float, g: float
) -> tuple[np.ndarray, np.ndarray]:
    """(roll, pitch) moment [N m] the clipped offsets leave, and the static tilt [rad] it
    causes against the righting stiffness W BG."""
    # excess weight at +x pitches the nose down (+ about y), at +y rolls to the left side
    # down (- about x): r x (0, 0, -W)
    moment_roll = -residual_kg_m[1] * g
    moment_pitch = residual_kg_m[0] * g
    stiffness = weight_N * max(bg_m, 1e-9)
    tilt = np.array(
        [
            math.asin(max(-1.0, min(1.0, moment_roll / stiffness))),
            math.asin(max(-1.0, min(1.0, moment_pitch / stiffness))),
        ]
    )
    return np.array([moment_roll, moment_pitch]), tilt
