"""How a run is integrated and logged, checked before anything runs: periods that divide each
other (nothing is silently rounded) and a log that fits in memory."""

from __future__ import annotations

import math
from dataclasses import dataclass

from uvms_pin.checks import check_memory, number_fields, seed_value
from uvms_pin.errors import ParameterError
from uvms_pin.sim.integrators import Integrator


@dataclass(frozen=True)
class SimulationSettings:
    """How to integrate and log.

    Attributes:
        duration_s: simulated time T [s].
        integrator: a fixed-step or adaptive `Integrator`.
        log_period_s: logging interval [s]; a multiple of the control period if sampled.
        control_period_s: controller period [s] (zero-order hold) or None = continuous.
        seed: master seed of every random draw in the run (recorded in the rollout).
        rebase_period_s: continuous mode only: length of one adaptive-integrator pass
            (the local chart of the free-flyer is re-based at its start).
    """

    duration_s: float
    integrator: Integrator
    log_period_s: float = 0.01
    control_period_s: float | None = None
    seed: int = 0
    rebase_period_s: float = 0.5

    def __post_init__(self) -> None:
        number_fields(self)
        if not isinstance(self.integrator, Integrator):
            raise ParameterError(
                f"integrator must be an Integrator (RK4(), SemiImplicitEuler(), Adaptive()), "
                f"got {self.integrator!r}"
            )
        seed_value("seed", self.seed)
        if not (self.duration_s > 0.0 and math.isfinite(self.duration_s)):
            raise ParameterError(f"duration_s must be positive, got {self.duration_s}")
        if not (self.log_period_s > 0.0 and math.isfinite(self.log_period_s)):
            raise ParameterError(f"log_period_s must be positive, got {self.log_period_s}")
        # Nothing is silently rounded or capped: the run is exactly the one recorded.
        _require_multiple(
            self.duration_s,
            self.log_period_s,
            "duration_s (scenario.duration_s)",
            "log_period_s (output.log_period_s)",
        )
        if self.control_period_s is not None:
            if not (self.control_period_s > 0.0 and math.isfinite(self.control_period_s)):
                raise ParameterError(
                    f"control_period_s must be positive, got {self.control_period_s}"
                )
            _require_multiple(
                self.log_period_s,
                self.control_period_s,
                "log_period_s (output.log_period_s)",
                "control_period_s (control.period_s)",
            )
        step_s = getattr(self.integrator, "step_s", None)
        if step_s is not None:
            # a fixed-step integrator takes equal substeps of each control (or output)
            # interval: a step that does not divide it would be shortened without a trace
            interval, name = (
                (self.control_period_s, "control_period_s (control.period_s)")
                if self.control_period_s is not None
                else (self.log_period_s, "log_period_s (output.log_period_s)")
            )
            _require_multiple(interval, step_s, name, "step_s (integrator.step_s)")

    def log_bytes(self, nq: int, nv: int, n_hulls: int = 0) -> int:
        """Memory the rollout of this run takes [bytes] (float64 arrays, every sample;
        ``n_hulls``: the wet fractions logged under a free surface)."""
        return self.n_log * 8 * (_log_width(nq, nv) + n_hulls)

    @property
    def n_log(self) -> int:
        return round(self.duration_s / self.log_period_s) + 1

    @property
    def ticks_per_log(self) -> int:
        if self.control_period_s is None:
            return 1
        return round(self.log_period_s / self.control_period_s)


def is_multiple(whole: float, part: float) -> bool:
    """Whether whole = n part for an integer n >= 1 (relative slack 1e-6)."""
    ratio = whole / part
    return ratio >= 1.0 - 1e-9 and abs(ratio - round(ratio)) <= 1e-6 * max(1.0, ratio)


def _require_multiple(whole: float, part: float, whole_name: str, part_name: str) -> None:
    """ParameterError unless whole = n part for an integer n >= 1 (`is_multiple`)."""
    if not is_multiple(whole, part):
        raise ParameterError(
            f"{whole_name} = {whole:g} s must be an integer multiple (>= 1) of "
            f"{part_name} = {part:g} s: the run would not be the one recorded"
        )


def _log_width(nq: int, nv: int) -> int:
    """Float64 values logged per sample: the base arrays (`Rollout.allocate`) and the
    controller's signals, bounded by 10 (6 + nv) (the PPC logs 3 x 3 + 5 x 6 + 7 nv: its
    references, errors, funnels and commanded tau)."""
    base = 1 + nq + 2 * nv + 3 * 6 + 2
    return base + 10 * (6 + nv)


def check_log_fits(settings: SimulationSettings, nq: int, nv: int, n_hulls: int = 0) -> None:
    """ParameterError, before anything is allocated, if the rollout would take more than half
    of the available memory (the other half: figures, the saved copy, the rest of the run)."""
    check_memory(
        settings.log_bytes(nq, nv, n_hulls),
        f"the log of this run ({settings.n_log} samples: duration_s {settings.duration_s:g} s "
        f"/ log_period_s {settings.log_period_s:g} s)",
        "shorten scenario.duration_s or lengthen output.log_period_s",
    )
