"""Carlson's symmetric elliptic integral of the second kind, R_D, for the ellipsoid's shape
integrals (`uvms_pin.hydro.geometry.ellipsoid_shape_integrals`).

    R_D(x, y, z) = 3/2 int_0^inf dt / ((t + z) sqrt((t + x)(t + y)(t + z)))

for x, y >= 0 (at most one of them 0) and z > 0, by Carlson's duplication algorithm (B. C.
Carlson, "Numerical computation of real or complex elliptic integrals", Numerical
Algorithms 10, 1995, algorithm of sec. 2 and eq. 2.19): each step replaces (x, y, z) by
((x + l) / 4, (y + l) / 4, (z + l) / 4), l = sqrt(x y) + sqrt(y z) + sqrt(z x), and adds
3 / (sqrt(z) (z + l)) times 4^-k to a sum; once the three arguments are within a relative
``1.5e-3`` of their weighted mean A = (x + y + 3 z) / 5, a fifth-order series in their
deviations finishes (its remainder is below 3 (1.5e-3)^6 = 3e-17 relative). About ten steps,
pure Python: the ellipsoid's integrals no longer import scipy.integrate (0.5 s of a start-up
that loads a model with cylinders), and are exact to rounding rather than to quadrature's
1e-12.
"""

from __future__ import annotations

import math

from uvms_pin.errors import ParameterError

__all__ = ["carlson_rd"]

#: the arguments' spread below which the series finishes, relative to their mean: its
#: remainder, about 3 tol^6 relative, is below double precision's rounding
_TOLERANCE = 1.5e-3


def carlson_rd(x: float, y: float, z: float) -> float:
    """R_D(x, y, z) for finite x, y >= 0 (not both 0) and z > 0; else `ParameterError`."""
    finite = math.isfinite(x) and math.isfinite(y) and math.isfinite(z)
    if not (finite and x >= 0.0 and y >= 0.0 and z > 0.0 and x + y > 0.0):
        raise ParameterError(
            f"R_D needs finite x, y >= 0 (not both 0) and z > 0, got {x}, {y}, {z}"
        )
    total, weight = 0.0, 1.0
    while True:
        mean = (x + y + 3.0 * z) / 5.0
        dx, dy, dz = (mean - x) / mean, (mean - y) / mean, (mean - z) / mean
        if max(abs(dx), abs(dy), abs(dz)) < _TOLERANCE:
            break
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * (sy + sz) + sy * sz
        total += weight / (sz * (z + lam))
        weight *= 0.25
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
    # the series in the elementary symmetric functions of the deviations (dx + dy + 3 dz = 0)
    ea = dx * dy
    eb = dz * dz
    e2 = ea - 6.0 * eb
    e3 = (3.0 * ea - 8.0 * eb) * dz
    e4 = 3.0 * (ea - eb) * eb
    e5 = ea * eb * dz
    series = (
        1.0
        - 3.0 / 14.0 * e2
        + 1.0 / 6.0 * e3
        + 9.0 / 88.0 * e2 * e2
        - 3.0 / 22.0 * e4
        - 9.0 / 52.0 * e2 * e3
        + 3.0 / 26.0 * e5
    )
    return 3.0 * total + weight * series / (mean * math.sqrt(mean))
