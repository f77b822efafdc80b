"""A simulation's result: preallocated arrays plus metadata; saves as .npz + JSON."""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from uvms_pin.atomic import atomic_write
from uvms_pin.errors import ParameterError

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

ARRAY_FILE = "rollout.npz"
META_FILE = "rollout.json"


@dataclass
class Rollout:
    """Logged trajectory of one run.

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
        cls, n_samples: int, nq: int, nv: int, metadata: dict[str, Any] | None = None
    ) -> Rollout:
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

    def metrics(self) -> dict[str, float]:
        """Scalar summary (see `uvms_pin.metrics.compute_metrics`)."""
        from uvms_pin.metrics import compute_metrics

        return compute_metrics(self)

    def to_dataframe(self) -> pd.DataFrame:
        """One row per sample, index ``time_s``, columns ``<array>.<component>_<unit>``
        (e.g. ``q.vehicle.x_m``, ``v.arm_joint1_rad_s``, ``tau.vehicle.fx_N``,
        ``wrench_contact_world.fx_N``, ``e_x.fx_N``); ``attrs["units"]`` maps each column
        to its unit. The scheme is in `uvms_pin.rollout_table` and docs/api.md."""
        from uvms_pin.rollout_table import to_dataframe

        return to_dataframe(self)

    def plot(self, kind: str | None = None) -> Figure | dict[str, Figure]:
        """A matplotlib Figure of this rollout: ``kind`` one of `uvms_pin.viz.figures.KINDS`
        ("pose", "velocities", "energy", "force", "first_level", "second_level"); without
        ``kind`` every figure the rollout has data for, as a dict by kind."""
        from uvms_pin.viz.figures import plot_rollout

        return plot_rollout(self, kind)

    # ---- persistence ------------------------------------------------------------------
    def save(self, directory: str | Path) -> Path:
        """Write ``rollout.npz`` and ``rollout.json`` into ``directory`` atomically."""
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        # Fix: serialise the metadata before writing anything; it used to be serialised
        # after rollout.npz was replaced, so unserialisable metadata left a new .npz next
        # to no (or a previous run's) rollout.json.
        text = json.dumps(self.metadata, indent=2, sort_keys=True, default=_json_default)
        arrays = {name: getattr(self, name) for name in self._BASE}
        arrays.update({f"signal__{k}": a for k, a in self.signals.items()})
        atomic_write(out / ARRAY_FILE, lambda f: np.savez_compressed(f, **arrays), binary=True)
        atomic_write(out / META_FILE, lambda f: f.write(text), binary=False)
        return out

    @classmethod
    def load(cls, directory: str | Path) -> Rollout:
        src = Path(directory)
        if not (src / ARRAY_FILE).is_file() or not (src / META_FILE).is_file():
            raise ParameterError(f"{src} holds no rollout ({ARRAY_FILE} and {META_FILE} expected)")
        try:
            with np.load(src / ARRAY_FILE) as data:
                base = {name: data[name] for name in cls._BASE}
                signals = {
                    k[len("signal__") :]: data[k] for k in data.files if k.startswith("signal__")
                }
            metadata = json.loads((src / META_FILE).read_text(encoding="utf-8"))
        except (OSError, ValueError, KeyError, zipfile.BadZipFile) as exc:  # JSON errors too
            raise ParameterError(
                f"{src} holds a damaged rollout ({type(exc).__name__}: {exc}); rerun the scenario"
            ) from exc
        if not isinstance(metadata, dict):
            raise ParameterError(f"{src / META_FILE}: a JSON object expected")
        return cls(**base, signals=signals, metadata=metadata)


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def write_json_atomic(path: Path, payload: dict[str, Any]) -> None:
    """Write a JSON file so that a crash never leaves it half-written."""
    text = json.dumps(payload, indent=2, sort_keys=True, default=_json_default)
    atomic_write(path, lambda f: f.write(text), binary=False)
