"""A regular linear (Airy) wave."""

from __future__ import annotations

import math

import numpy as np

from uvms_pin.checks import Plausible, number
from uvms_pin.errors import ParameterError
from uvms_pin.flow.components import (
    STANDARD_GRAVITY_M_S2,
    WaveComponents,
    WaveField,
    wavenumber,
)

__all__ = ["AiryWave", "wavenumber"]


def _finite(value: float, name: str, *, positive: bool = False) -> float:
    value = number(name, value)
    if not math.isfinite(value) or (positive and value <= 0.0):
        raise ParameterError(
            f"{name} must be {'positive and ' if positive else ''}finite, got {value}"
        )
    return value


#: A gravity wave's period [s]: below ~0.1 s waves are capillary ripples (surface tension,
#: not gravity, restores them), beyond an hour they are tides
WAVE_PERIOD = Plausible(
    "s",
    usual=(1.0, 30.0),
    possible=(0.1, 3600.0),
    usual_text="sea waves (swell: up to ~25 s)",
    impossible_text="Airy theory is of gravity waves: shorter ones are capillary ripples, "
    "longer ones tides",
    hints=("a period in milliseconds?", ""),
)
#: Waves steeper than this break (Michell's limit of height over wavelength)
MAX_STEEPNESS = 1.0 / 7.0


class AiryWave(WaveField):
    """eta = A cos(k e.p - w t + phi): linear wave theory in finite or infinite depth.

    Args:
        amplitude_m: A (half the wave height) [m].
        period_s: T = 2 pi / w [s].
        heading_rad: direction the wave travels, world, from +x towards +y [rad].
        water_depth_m: d [m] (the sea floor at z = -d); inf for deep water.
        phase_rad: phi [rad].
        gravity_m_s2: g in the dispersion relation [m/s^2].
    """

    def __init__(
        self,
        amplitude_m: float,
        period_s: float,
        heading_rad: float = 0.0,
        water_depth_m: float = math.inf,
        phase_rad: float = 0.0,
        gravity_m_s2: float = STANDARD_GRAVITY_M_S2,
    ):
        amplitude = _finite(amplitude_m, "amplitude_m")
        if amplitude < 0.0:
            raise ParameterError(f"amplitude_m must be >= 0, got {amplitude}")
        period = _finite(period_s, "period_s", positive=True)
        heading = _finite(heading_rad, "heading_rad")
        phase = _finite(phase_rad, "phase_rad")
        depth = number("water_depth_m", water_depth_m)
        if not depth > 0.0:
            raise ParameterError(f"water_depth_m must be positive (or inf), got {water_depth_m}")
        refusal = WAVE_PERIOD.refusal(period)  # (a scenario warns of unusual ones)
        if refusal is not None:
            raise ParameterError(f"period_s = {refusal}")
        omega = 2.0 * math.pi / period
        k = wavenumber(omega, depth, gravity_m_s2)
        if 2.0 * amplitude * k / (2.0 * math.pi) > MAX_STEEPNESS:
            raise ParameterError(
                f"a wave of height 2 amplitude_m = {2.0 * amplitude:g} m over its wavelength "
                f"{2.0 * math.pi / k:.4g} m (period {period:g} s) is steeper than 1/7: it "
                "breaks, and Airy theory holds for gentle waves"
            )
        self.amplitude_m, self.period_s, self.heading_rad = amplitude, period, heading
        self.water_depth_m, self.phase_rad = depth, phase
        self.components = WaveComponents(
            np.array([amplitude]),
            np.array([omega]),
            np.array([k]),
            np.array([heading]),
            np.array([phase]),
            depth,
        )

    @property
    def wavenumber_rad_m(self) -> float:
        return float(self.components.wavenumber_rad_m[0])

    @property
    def wavelength_m(self) -> float:
        return 2.0 * math.pi / self.wavenumber_rad_m

    def __repr__(self) -> str:
        return (
            f"AiryWave(amplitude_m={self.amplitude_m}, period_s={self.period_s}, "
            f"heading_rad={self.heading_rad}, water_depth_m={self.water_depth_m})"
        )
