"""Wave spectra: Pierson-Moskowitz and JONSWAP, one-sided, in angular frequency.

    S_PM(w) = 5/16 Hs^2 wp^4 w^-5 exp(-5/4 (wp / w)^4)                    [m^2 s / rad]
    S_J(w)  = N(gamma) S_PM(w) gamma^r,  r = exp(-(w - wp)^2 / (2 sigma^2 wp^2)),
              sigma = 0.07 (w <= wp), 0.09 (w > wp)

with wp = 2 pi / Tp. The zeroth moment m0 = int S dw of S_PM is Hs^2 / 16 exactly; N(gamma)
is computed (not the usual 1 - 0.287 ln gamma fit) so that S_J has m0 = Hs^2 / 16 too, i.e.
Hs = 4 sqrt(m0) is exactly the significant height asked for.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from uvms_pin.errors import ParameterError


def _check(significant_height_m: float, peak_period_s: float, gamma: float) -> None:
    if not (significant_height_m >= 0.0 and math.isfinite(significant_height_m)):
        raise ParameterError(f"significant_height_m must be >= 0, got {significant_height_m}")
    if not (peak_period_s > 0.0 and math.isfinite(peak_period_s)):
        raise ParameterError(f"peak_period_s must be positive, got {peak_period_s}")
    if not (1.0 <= gamma <= 20.0):
        raise ParameterError(f"peak_enhancement (gamma) must be in [1, 20], got {gamma}")


def pierson_moskowitz_spectrum(
    omega_rad_s: np.ndarray, significant_height_m: float, peak_period_s: float
) -> np.ndarray:
    """S_PM(w) [m^2 s/rad] of a fully developed sea of significant height Hs and peak Tp."""
    _check(significant_height_m, peak_period_s, 1.0)
    w = np.asarray(omega_rad_s, dtype=float)
    wp = 2.0 * math.pi / peak_period_s
    out = np.zeros_like(w)
    pos = w > 0.0
    out[pos] = (
        5.0
        / 16.0
        * significant_height_m**2
        * wp**4
        * w[pos] ** -5
        * np.exp(-1.25 * (wp / w[pos]) ** 4)
    )
    return out


def _peak_shape(w_over_wp: np.ndarray, gamma: float) -> np.ndarray:
    sigma = np.where(w_over_wp <= 1.0, 0.07, 0.09)
    return gamma ** np.exp(-((w_over_wp - 1.0) ** 2) / (2.0 * sigma**2))


@functools.lru_cache(maxsize=64)
def _jonswap_normalisation(gamma: float) -> float:
    """N(gamma) with int S_PM gamma^r dw = int S_PM dw (in units wp = 1, Hs = 4)."""

    def pm(x: float) -> float:
        return 5.0 * x**-5 * math.exp(-1.25 * x**-4)

    def shaped(x: float) -> float:
        return pm(x) * float(_peak_shape(np.array(x), gamma))

    # scipy.integrate is imported where it is used: it takes a quarter second to import,
    # which every start-up would pay otherwise
    from scipy.integrate import quad

    m0_pm = quad(pm, 0.05, 50.0, points=[1.0], limit=200)[0]
    m0_j = quad(shaped, 0.05, 50.0, points=[1.0], limit=200)[0]
    return m0_pm / m0_j


def jonswap_spectrum(
    omega_rad_s: np.ndarray,
    significant_height_m: float,
    peak_period_s: float,
    peak_enhancement: float = 3.3,
) -> np.ndarray:
    """S_J(w) [m^2 s/rad]; peak_enhancement gamma = 1 gives Pierson-Moskowitz."""
    _check(significant_height_m, peak_period_s, peak_enhancement)
    w = np.asarray(omega_rad_s, dtype=float)
    wp = 2.0 * math.pi / peak_period_s
    base = pierson_moskowitz_spectrum(w, significant_height_m, peak_period_s)
    if peak_enhancement == 1.0:
        return base
    return (
        _jonswap_normalisation(float(peak_enhancement))
        * base
        * _peak_shape(w / wp, peak_enhancement)
    )
