"""Reference paths p(t) in R^3 with their first two derivatives, for tracking tasks.

Every path answers ``at(t) -> (p [m], p_dot [m/s], p_ddot [m/s^2])`` analytically, so a
controller can feed forward the velocity and acceleration. The periodic curves (circle,
lemniscate, helix) run on a phase theta(t) = omega g(t) that starts at rest: with a ramp
T_r > 0, g'(t) is the minimum-jerk blend s(t / T_r) from 0 to 1 (zero speed and
acceleration at t = 0, full speed from T_r on); with T_r = 0 the curve starts at full speed.

    s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5,   g(t) = T_r (2.5 tau^4 - 3 tau^5 + tau^6)  (t < T_r)
    g(t) = T_r / 2 + (t - T_r)                                                         (t >= T_r)

The curves lie in the plane normal to ``normal`` (a horizontal circle for [0, 0, 1]), with
in-plane axes e1, e2 (`plane_axes`): e1 is the world x axis projected on the plane (the y
axis when x is nearly normal), e2 = normal x e1.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from uvms_pin.checks import finite_vector, nonnegative, positive
from uvms_pin.errors import ParameterError

__all__ = [
    "Circle",
    "Helix",
    "Hold",
    "Lemniscate",
    "MinimumJerk",
    "Path",
    "Waypoints",
    "minimum_jerk",
    "plane_axes",
]

PathPoint = tuple[np.ndarray, np.ndarray, np.ndarray]


class Path(Protocol):
    """A reference path: ``at(t)`` -> (position [m], velocity [m/s], acceleration [m/s^2])."""

    def at(self, time_s: float) -> PathPoint: ...


def minimum_jerk(tau: float) -> tuple[float, float, float]:
    """(s, ds/dtau, d2s/dtau2) of the minimum-jerk blend 10 tau^3 - 15 tau^4 + 6 tau^5,
    clamped to [0, 1] outside (0 before, 1 after, zero derivatives)."""
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0
    t2 = tau * tau
    return (
        t2 * tau * (10.0 - 15.0 * tau + 6.0 * t2),
        30.0 * t2 * (1.0 - 2.0 * tau + t2),
        60.0 * tau * (1.0 - 3.0 * tau + 2.0 * t2),
    )


def plane_axes(normal) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal in-plane axes (e1, e2) of the plane normal to ``normal``."""
    n = finite_vector("normal", normal, 3)
    norm = np.linalg.norm(n)
    if norm < 1e-12:
        raise ParameterError("normal must not be the zero vector")
    n = n / norm
    seed = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = seed - (seed @ n) * n
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(n, e1)


@dataclass(frozen=True)
class Phase:
    """theta(t) = omega g(t) with the ramped start of the module docstring; t < 0 is at rest.

    Args: omega_rad_s: the full angular rate [rad/s]. ramp_s: T_r >= 0 [s].
    """

    omega_rad_s: float
    ramp_s: float = 0.0

    def at(self, time_s: float) -> tuple[float, float, float]:
        """(theta [rad], theta_dot [rad/s], theta_ddot [rad/s^2])."""
        w, ramp = self.omega_rad_s, self.ramp_s
        if time_s <= 0.0:
            return 0.0, 0.0, 0.0
        if ramp <= 0.0 or time_s >= ramp:
            return w * (time_s - 0.5 * ramp), w, 0.0
        tau = time_s / ramp
        s, ds, _ = minimum_jerk(tau)
        g = ramp * tau**4 * (2.5 - 3.0 * tau + tau * tau)
        return w * g, w * s, w * ds / ramp


def _periodic(period_s: float, ramp_s: float) -> Phase:
    return Phase(2.0 * math.pi / positive("period_s", period_s), nonnegative("ramp_s", ramp_s))


class Circle:
    """p = c + r (cos theta - 1) e1 + r sin theta e2 ... shifted so that p(0) = ``start``:
    the circle through ``start`` with its centre at start - r e1, run counter-clockwise
    about ``normal``.

    Args: start: p(0) [m]. radius_m: r. period_s: one turn at full speed. normal: the
    plane's normal. ramp_s: the phase's start ramp T_r.
    """

    def __init__(self, start, radius_m: float, period_s: float, normal=(0, 0, 1), ramp_s=0.0):
        self.start = finite_vector("start", start, 3)
        self.radius_m = positive("radius_m", radius_m)
        self.phase = _periodic(period_s, ramp_s)
        self.e1, self.e2 = plane_axes(normal)
        self.center = self.start - self.radius_m * self.e1

    def at(self, time_s: float) -> PathPoint:
        th, dth, ddth = self.phase.at(time_s)
        c, s, r = math.cos(th), math.sin(th), self.radius_m
        radial = c * self.e1 + s * self.e2  # unit vector from the centre
        tangent = -s * self.e1 + c * self.e2
        return (
            self.center + r * radial,
            r * dth * tangent,
            r * ddth * tangent - r * dth * dth * radial,
        )


class Helix(Circle):
    """The `Circle` rising along ``normal`` by ``rise_per_turn_m`` per turn:
    p = circle(t) + (rise / 2 pi) theta n."""

    def __init__(self, start, radius_m, period_s, rise_per_turn_m, normal=(0, 0, 1), ramp_s=0.0):
        super().__init__(start, radius_m, period_s, normal, ramp_s)
        if not math.isfinite(rise_per_turn_m):
            raise ParameterError(f"rise_per_turn_m must be finite, got {rise_per_turn_m}")
        self.normal = np.cross(self.e1, self.e2)
        self.rise_per_rad_m = rise_per_turn_m / (2.0 * math.pi)

    def at(self, time_s: float) -> PathPoint:
        p, v, a = super().at(time_s)
        th, dth, ddth = self.phase.at(time_s)
        k = self.rise_per_rad_m * self.normal
        return p + th * k, v + dth * k, a + ddth * k


class Lemniscate:
    """The figure eight of Gerono through ``start``: p = start + a sin theta e1 +
    (a / 2) sin 2 theta e2, one loop of the eight per half period.

    Args: start: p(0) [m] (the crossing point). half_width_m: a. period_s: the whole eight
    at full speed. normal, ramp_s: as `Circle`.
    """

    def __init__(self, start, half_width_m, period_s, normal=(0, 0, 1), ramp_s=0.0):
        self.start = finite_vector("start", start, 3)
        self.a = positive("half_width_m", half_width_m)
        self.phase = _periodic(period_s, ramp_s)
        self.e1, self.e2 = plane_axes(normal)

    def at(self, time_s: float) -> PathPoint:
        th, dth, ddth = self.phase.at(time_s)
        a, s1, c1 = self.a, math.sin(th), math.cos(th)
        s2, c2 = math.sin(2 * th), math.cos(2 * th)
        x, dx, ddx = a * s1, a * c1, -a * s1  # d/dtheta, d2/dtheta2
        y, dy, ddy = 0.5 * a * s2, a * c2, -2.0 * a * s2
        # chain rule: p_dot = p' theta_dot; p_ddot = p'' theta_dot^2 + p' theta_ddot
        return (
            self.start + x * self.e1 + y * self.e2,
            dth * (dx * self.e1 + dy * self.e2),
            (ddx * dth**2 + dx * ddth) * self.e1 + (ddy * dth**2 + dy * ddth) * self.e2,
        )


class MinimumJerk:
    """Point to point: p = p0 + s((t - t0) / D) (p1 - p0), at rest at both ends (zero
    velocity and acceleration), p0 before t0 and p1 after t0 + D."""

    def __init__(self, start, goal, duration_s: float, start_s: float = 0.0):
        self.p0 = finite_vector("start", start, 3)
        self.p1 = finite_vector("goal", goal, 3)
        self.duration_s = positive("duration_s", duration_s)
        if not math.isfinite(start_s):
            raise ParameterError(f"start_s must be finite, got {start_s}")
        self.start_s = float(start_s)

    def at(self, time_s: float) -> PathPoint:
        d = self.duration_s
        s, ds, dds = minimum_jerk((time_s - self.start_s) / d)
        delta = self.p1 - self.p0
        return self.p0 + s * delta, (ds / d) * delta, (dds / (d * d)) * delta


class Waypoints:
    """Minimum-jerk segments through waypoints reached at given times, at rest at each one:
    p(t) = ``points[0]`` until ``times_s[0]``, the last point after the last time."""

    def __init__(self, points: Sequence, times_s: Sequence[float]):
        pts = np.asarray(points, dtype=float)
        times = np.asarray(times_s, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 2:
            raise ParameterError(
                f"waypoints must be >= 2 points of 3 numbers, got shape {pts.shape}"
            )
        if (
            times.shape != (len(pts),)
            or not np.all(np.isfinite(times))
            or not np.all(np.isfinite(pts))
        ):
            raise ParameterError(
                f"waypoints need one finite time per point: {len(pts)} points, times {times.tolist()}"
            )
        if np.any(np.diff(times) <= 0):
            raise ParameterError(f"waypoint times must increase strictly, got {times.tolist()}")
        self.segments = [
            MinimumJerk(pts[k], pts[k + 1], times[k + 1] - times[k], times[k])
            for k in range(len(pts) - 1)
        ]
        self.times_s = times

    def at(self, time_s: float) -> PathPoint:
        k = int(np.searchsorted(self.times_s, time_s, side="right")) - 1
        return self.segments[min(max(k, 0), len(self.segments) - 1)].at(time_s)


class Hold:
    """A fixed point (station keeping)."""

    def __init__(self, point):
        self.point = finite_vector("point", point, 3)
        self._zero = np.zeros(3)

    def at(self, time_s: float) -> PathPoint:
        return self.point, self._zero, self._zero
