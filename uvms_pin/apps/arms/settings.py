"""The options of an arm comparison (`uvms_pin.apps.arms.compare.compare_arms`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from uvms_pin.model.trim import TrimSpec


@dataclass(frozen=True)
class CompareSettings:
    """Options of :func:`~uvms_pin.apps.arms.compare.compare_arms` (picklable: they go to
    worker processes).

    Attributes:
        duration_s: simulated duration [s]; None keeps the scenario's.
        trim: foam and ballast added for the arm at its initial configuration; None: none.
        mount_rpy: every arm's base orientation on the vehicle [rad]; None (default): each
            arm's own (`ArmEntry.mount_rpy_rad`: a table-top arm upside down, the Alpha 5 as
            Reach mounts it).
        ik_starts: starts of the initial-configuration search; seed: its random seed.
        keep_rollouts: write each arm's row, rollout, metrics and figures to OUT/<arm>/.
        overrides: scenario overrides for every arm (``--set``), as (dotted key, value)
            pairs.
    """

    duration_s: float | None = None
    trim: TrimSpec | None = TrimSpec()  # noqa: RUF009 - frozen, immutable default
    mount_rpy: tuple[float, float, float] | None = None
    ik_starts: int = 24
    seed: int = 0
    keep_rollouts: bool = False
    overrides: tuple[tuple[str, Any], ...] = ()

    @property
    def scenario_overrides(self) -> dict[str, Any]:
        """The overrides every arm's scenario is loaded with (``--set``, then --duration)."""
        out = dict(self.overrides)
        if self.duration_s is not None:
            out["scenario.duration_s"] = self.duration_s
        return out
