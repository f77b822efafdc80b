"""An irregular, short- or long-crested sea: a seeded sum of Airy components drawn from a
JONSWAP (or Pierson-Moskowitz) spectrum.

Frequencies: ``n_components`` equal bins over [w_min, w_max] (default 0.5 to 3.5 wp), each
frequency drawn uniformly inside its bin (so the record does not repeat with period
2 pi / dw); amplitude A_j = sqrt(2 S(w_j) dw); phases uniform in [0, 2 pi). Headings: all
equal to ``heading_rad`` (long-crested), or, with ``spreading_exponent`` s, drawn from the
cos-2s spreading function D(b) ~ cos^{2s}((b - heading) / 2) (one direction per frequency,
which avoids phase-locked standing patterns). Every draw comes from ``seed``.
"""

from __future__ import annotations

import math

import numpy as np

from uvms_pin.checks import finite_vector, number, seed_value
from uvms_pin.errors import ParameterError
from uvms_pin.flow.airy import WAVE_PERIOD
from uvms_pin.flow.components import (
    STANDARD_GRAVITY_M_S2,
    WaveComponents,
    WaveField,
    wavenumber,
)
from uvms_pin.flow.spectrum import jonswap_spectrum


def _spread_headings(
    rng: np.random.Generator, mean_rad: float, exponent: float | None, count: int
) -> np.ndarray:
    if exponent is None:
        return np.full(count, mean_rad)
    if not (exponent > 0.0 and math.isfinite(exponent)):
        raise ParameterError(f"spreading_exponent must be positive, got {exponent}")
    grid = np.linspace(-math.pi, math.pi, 4001)
    density = np.cos(grid / 2.0) ** (2.0 * exponent)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(grid))])
    cdf /= cdf[-1]
    return mean_rad + np.interp(rng.uniform(size=count), cdf, grid)


#: More components than any sea needs (tens to hundreds resolve a JONSWAP spectrum); each
#: is summed at every body at every integrator stage, so the bound keeps a run's time (and
#: the time between two checks for Ctrl-C) in proportion.
MAX_COMPONENTS = 2000


class IrregularSea(WaveField):
    """A seeded realisation of a JONSWAP sea (gamma = 1: Pierson-Moskowitz).

    Args:
        significant_height_m: Hs = 4 sqrt(m0) [m].
        peak_period_s: Tp [s].
        peak_enhancement: JONSWAP gamma (3.3 North Sea; 1 = Pierson-Moskowitz).
        heading_rad: mean direction of travel (world, from +x towards +y) [rad].
        spreading_exponent: s of cos-2s spreading; None = long-crested.
        n_components: number of frequency components.
        seed: seed of the frequencies, phases and headings.
        water_depth_m: d [m]; inf for deep water.
        frequency_range: (w_min, w_max) as multiples of the peak frequency.
    """

    def __init__(
        self,
        significant_height_m: float,
        peak_period_s: float,
        peak_enhancement: float = 3.3,
        heading_rad: float = 0.0,
        spreading_exponent: float | None = None,
        n_components: int = 100,
        seed: int = 0,
        water_depth_m: float = math.inf,
        frequency_range: tuple[float, float] = (0.5, 3.5),
        gravity_m_s2: float = STANDARD_GRAVITY_M_S2,
    ):
        if (
            isinstance(n_components, bool)
            or not isinstance(n_components, int)
            or not 1 <= n_components <= MAX_COMPONENTS
        ):
            raise ParameterError(
                f"n_components must be an integer in 1..{MAX_COMPONENTS}, got {n_components!r}"
                " (each component is summed at every body at every integrator stage)"
            )
        significant_height_m = number("significant_height_m", significant_height_m)
        peak_period_s = number("peak_period_s", peak_period_s)
        peak_enhancement = number("peak_enhancement", peak_enhancement)
        heading_rad = number("heading_rad", heading_rad)
        water_depth_m = number("water_depth_m", water_depth_m)
        if spreading_exponent is not None:
            spreading_exponent = number("spreading_exponent", spreading_exponent)
        refusal = WAVE_PERIOD.refusal(peak_period_s)  # a scenario warns of unusual
        if refusal is not None:
            raise ParameterError(f"peak_period_s = {refusal}")
        low, high = finite_vector("frequency_range", frequency_range, 2)
        if not (0.0 < low < 1.0 < high and math.isfinite(high)):
            raise ParameterError(
                f"frequency_range must be (low, high) multiples of the peak frequency with "
                f"0 < low < 1 < high, got {frequency_range}"
            )
        if not float(water_depth_m) > 0.0:
            raise ParameterError(f"water_depth_m must be positive (or inf), got {water_depth_m}")
        if not math.isfinite(heading_rad):
            raise ParameterError(f"heading_rad must be finite, got {heading_rad}")
        self.significant_height_m = float(significant_height_m)
        self.peak_period_s = float(peak_period_s)
        self.peak_enhancement = float(peak_enhancement)
        self.seed = seed_value("seed", seed)
        self.water_depth_m = float(water_depth_m)
        rng = np.random.default_rng(self.seed)
        wp = 2.0 * math.pi / self.peak_period_s
        edges = np.linspace(low * wp, high * wp, n_components + 1)
        d_omega = edges[1] - edges[0]
        omega = edges[:-1] + rng.uniform(size=n_components) * d_omega
        spectrum = jonswap_spectrum(
            omega, self.significant_height_m, self.peak_period_s, self.peak_enhancement
        )
        amplitude = np.sqrt(2.0 * spectrum * d_omega)
        phase = rng.uniform(0.0, 2.0 * math.pi, size=n_components)
        heading = _spread_headings(rng, float(heading_rad), spreading_exponent, n_components)
        k = np.array([wavenumber(w, self.water_depth_m, gravity_m_s2) for w in omega])
        self.components = WaveComponents(amplitude, omega, k, heading, phase, self.water_depth_m)

    @property
    def components_significant_height_m(self) -> float:
        """4 sqrt(sum A_j^2 / 2): the significant height the drawn components carry."""
        return 4.0 * math.sqrt(0.5 * float(np.sum(self.components.amplitude_m**2)))

    def __repr__(self) -> str:
        return (
            f"IrregularSea(Hs={self.significant_height_m} m, Tp={self.peak_period_s} s, "
            f"gamma={self.peak_enhancement}, seed={self.seed})"
        )
