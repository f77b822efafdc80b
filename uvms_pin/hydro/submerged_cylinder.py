"""The part of a cylinder below a plane (see `uvms_pin.hydro.submerged` for the quantities).

The cylinder (radius R, length L, axis z, centred on its origin) is a stack of discs. In the
disc at height s the plane n . x = d cuts the chord u = t(s) = (d - n_z s) / n_p, with
n_p = |(n_x, n_y)| and u the coordinate along e = (n_x, n_y) / n_p; the disc's submerged
part {u < t} is a circular segment of half-angle theta = atan2(sqrt(R^2 - t^2), -t):

    area       S(t) = R^2 (2 theta - sin 2 theta) / 2   (0 for t <= -R, pi R^2 for t >= R)
    moment     integral u dS = -2/3 (R^2 - t^2)^(3/2)
    chord      c(t) = 2 sqrt(R^2 - t^2)

so V = integral S ds, M = e integral(-2/3 (R^2-t^2)^(3/2)) ds + z integral s S ds, and the
waterplane (the chords, seen along e, shrunk by n_p): A = integral c ds / n_p,
M_A = integral c (t e + s z) ds / n_p. Where the discs are whole (t >= R) the integrals are
exact; across the cut (|t| < R) they are integrated by Gauss-Legendre after the change of
variable s = a + (b - a)(1 - cos(pi w)) / 2, which turns the square-root ends of S into an
analytic integrand (error near machine precision with 32 nodes, tested against the closed
form). A plane parallel to the axis (n_z = 0) is one segment times L; a plane nearly
perpendicular to it (n_p < 1e-12) cuts whole discs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvms_pin.checks import positive
from uvms_pin.hydro.submerged import CentredSolid, WetPart

__all__ = ["Cylinder"]

#: Gauss-Legendre nodes on the cosine map (s = a + (b - a) * MAP_POINTS; ds = (b - a) MAP_WEIGHTS).
QUADRATURE_NODES = 32
_x, _w = np.polynomial.legendre.leggauss(QUADRATURE_NODES)
_w01 = 0.5 * (_x + 1.0)
MAP_POINTS = 0.5 * (1.0 - np.cos(np.pi * _w01))
MAP_WEIGHTS = 0.5 * _w * (0.5 * np.pi * np.sin(np.pi * _w01))
#: Below this |(n_x, n_y)| the plane is taken as perpendicular to the axis.
AXIAL_TOLERANCE = 1e-12


def x_minus_sin(x: float | np.ndarray) -> float | np.ndarray:
    """x - sin(x), without the cancellation of small x (a series below 0.25)."""
    x = np.asarray(x, dtype=float)
    x2 = x * x
    series = (
        x
        * x2
        / 6.0
        * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0 * (1.0 - x2 / 110.0))))
    )
    out = np.where(np.abs(x) < 0.25, series, x - np.sin(x))
    return out if out.ndim else float(out)


@dataclass(frozen=True)
class Cylinder(CentredSolid):
    """A cylinder of radius R and length L along z, centred on its origin [m]."""

    label = "cylinder"

    radius_m: float
    length_m: float

    def __post_init__(self) -> None:
        for name in ("radius_m", "length_m"):
            object.__setattr__(self, name, positive(f"cylinder {name}", getattr(self, name)))

    @property
    def volume_m3(self) -> float:
        return math.pi * self.radius_m**2 * self.length_m

    @property
    def bounding_radius_m(self) -> float:
        return math.hypot(self.radius_m, 0.5 * self.length_m)

    def below(self, normal: np.ndarray, depth_m: float) -> WetPart:
        n_p = math.hypot(normal[0], normal[1])
        if n_p <= AXIAL_TOLERANCE:
            return self._stacked_discs(float(normal[2]), depth_m)
        e = np.array([normal[0] / n_p, normal[1] / n_p, 0.0])
        nz, half, r = float(normal[2]), 0.5 * self.length_m, self.radius_m
        if nz == 0.0:  # the same segment in every disc
            return _slices(np.array([0.0]), np.array([self.length_m]), depth_m, n_p, nz, r, e)
        s_whole = (depth_m - n_p * r) / nz  # t = R
        s_none = (depth_m + n_p * r) / nz  # t = -R
        if nz > 0.0:
            whole, cut = (-half, min(half, s_whole)), (max(-half, s_whole), min(half, s_none))
        else:
            whole, cut = (max(-half, s_whole), half), (max(-half, s_none), min(half, s_whole))
        part = WetPart.empty()
        if whole[1] > whole[0]:
            length = whole[1] - whole[0]
            volume = math.pi * r * r * length
            part = WetPart(
                volume, np.array([0.0, 0.0, volume * 0.5 * (whole[0] + whole[1])]), 0.0, np.zeros(3)
            )
        if cut[1] > cut[0]:
            heights = cut[0] + (cut[1] - cut[0]) * MAP_POINTS
            part = part + _slices(heights, (cut[1] - cut[0]) * MAP_WEIGHTS, depth_m, n_p, nz, r, e)
        return part

    def _stacked_discs(self, nz: float, depth_m: float) -> WetPart:
        """A plane perpendicular to the axis at s = d / n_z: whole discs below it."""
        half, disc = 0.5 * self.length_m, math.pi * self.radius_m**2
        plane = depth_m / nz
        low, high = (-half, min(half, plane)) if nz > 0.0 else (max(-half, plane), half)
        if high <= low:
            return WetPart.empty()
        volume = disc * (high - low)
        moment = np.array([0.0, 0.0, volume * 0.5 * (low + high)])
        if -half < plane < half:
            return WetPart(volume, moment, disc, np.array([0.0, 0.0, disc * plane]))
        return WetPart(volume, moment, 0.0, np.zeros(3))


def _slices(
    heights: np.ndarray,
    weights: np.ndarray,
    depth_m: float,
    n_p: float,
    nz: float,
    r: float,
    e: np.ndarray,
) -> WetPart:
    """The quadrature sum over discs at ``heights`` (weights = ds) of the cut discs."""
    t = np.clip((depth_m - nz * heights) / n_p, -r, r)
    half_chord_sq = (r - t) * (r + t)
    half_chord = np.sqrt(half_chord_sq)
    theta = np.arctan2(half_chord, -t)
    area = 0.5 * r * r * x_minus_sin(2.0 * theta)
    lateral = -(2.0 / 3.0) * half_chord_sq * half_chord
    chord = 2.0 * half_chord
    volume = float(weights @ area)
    moment = e * float(weights @ lateral) + np.array([0.0, 0.0, float(weights @ (heights * area))])
    wet_area = float(weights @ chord) / n_p
    wet_moment = (
        e * float(weights @ (chord * t)) + np.array([0.0, 0.0, float(weights @ (chord * heights))])
    ) / n_p
    return WetPart(volume, moment, wet_area, wet_moment)
