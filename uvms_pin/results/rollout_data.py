"""A run's logged trajectory: preallocated arrays, per-sample signals, metadata, status."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from uvms_pin.results.status import RunStatus

_Data = TypeVar("_Data", bound="RolloutData")


@dataclass
class RolloutData:
    """Logged trajectory of one run: what metrics, tables and figures read.

    Arrays have one row per logged sample (``len(time_s)``); ``signals`` holds extra
    per-sample arrays (controller errors and funnels, ...) by name. ``metadata`` is
    JSON-serialisable: seed, scenario parameters, package versions, status, wall time.
    """

    time_s: np.ndarray
    q: np.ndarray
    v: np.ndarray
    tau: np.ndarray
    wrench_contact_world: np.ndarray
    wrench_measured_world: np.ndarray
    wrench_disturbance_body: np.ndarray
    kinetic_energy_J: np.ndarray
    potential_energy_J: np.ndarray
    signals: dict[str, np.ndarray] = field(default_factory=dict)
    metadata: dict[str, Any] = field(default_factory=dict)
    #: the cameras' and sonars' records by sensor name (`uvms_pin.results.perception`)
    perception: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)

    _BASE = (
        "time_s",
        "q",
        "v",
        "tau",
        "wrench_contact_world",
        "wrench_measured_world",
        "wrench_disturbance_body",
        "kinetic_energy_J",
        "potential_energy_J",
    )

    @classmethod
    def allocate(
        cls: type[_Data], n_samples: int, nq: int, nv: int, metadata: dict[str, Any] | None = None
    ) -> _Data:
        """Preallocate every base array for ``n_samples`` rows (NaN until written)."""
        nan = np.nan
        return cls(
            time_s=np.full(n_samples, nan),
            q=np.full((n_samples, nq), nan),
            v=np.full((n_samples, nv), nan),
            tau=np.full((n_samples, nv), nan),
            wrench_contact_world=np.full((n_samples, 6), nan),
            wrench_measured_world=np.full((n_samples, 6), nan),
            wrench_disturbance_body=np.full((n_samples, 6), nan),
            kinetic_energy_J=np.full(n_samples, nan),
            potential_energy_J=np.full(n_samples, nan),
            metadata=dict(metadata or {}),
        )

    def signal(self, name: str, width: int) -> np.ndarray:
        """The (n_samples, width) array for an extra signal, allocated on first use."""
        arr = self.signals.get(name)
        if arr is None:
            arr = np.full((len(self.time_s), width), np.nan)
            self.signals[name] = arr
        return arr

    def truncate(self, n_samples: int) -> None:
        """Keep the first ``n_samples`` rows (after an early stop)."""
        for name in self._BASE:
            setattr(self, name, getattr(self, name)[:n_samples])
        self.signals = {k: a[:n_samples] for k, a in self.signals.items()}

    @property
    def total_energy_J(self) -> np.ndarray:
        return self.kinetic_energy_J + self.potential_energy_J

    def __len__(self) -> int:
        return len(self.time_s)

    @property
    def status(self) -> RunStatus:
        """How the run ended (kept in ``metadata``: ``status``, ``error``, ``violation``)."""
        last = float(self.time_s[-1]) if len(self.time_s) else 0.0
        return RunStatus.from_metadata(self.metadata, last)

    def set_status(self, status: RunStatus) -> None:
        """Record how the run ended (a previous violation is forgotten)."""
        self.metadata.pop("violation", None)
        self.metadata.pop("stop_time_s", None)
        self.metadata.update(status.to_metadata())
