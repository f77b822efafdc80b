"""A simulation's result: preallocated arrays plus metadata; saves as .npz + JSON."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.results import perception as frames
from uvms_pin.results.atomic import atomic_paths, json_text
from uvms_pin.results.outdir import check_writable, given_path
from uvms_pin.results.perception import (
    CameraRecord,
    SonarRecord,
    camera_record,
    load_perception,
    save_perception,
    sonar_record,
)
from uvms_pin.results.rollout_data import RolloutData

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

ARRAY_FILE = "rollout.npz"
META_FILE = "rollout.json"


class Rollout(RolloutData):
    """Logged trajectory of one run, with its views (metrics, pandas table, figures) and
    its files (``rollout.npz`` + ``rollout.json``, saved and loaded).

    Arrays have one row per logged sample (``len(time_s)``); ``signals`` holds extra
    per-sample arrays (controller errors and funnels, ...) by name. ``metadata`` is
    JSON-serialisable: seed, scenario parameters, package versions, status, wall time;
    ``status`` reads how the run ended as a `RunStatus`.
    """

    def metrics(self) -> dict[str, float]:
        """Scalar summary (see `uvms_pin.results.metrics.compute_metrics`)."""
        from uvms_pin.results.metrics import compute_metrics

        return compute_metrics(self)

    def to_dataframe(self) -> pd.DataFrame:
        """One row per sample, index ``time_s``, columns ``<array>.<component>_<unit>``
        (e.g. ``q.vehicle.x_m``, ``v.arm_joint1_rad_s``, ``tau.vehicle.fx_N``,
        ``wrench_contact_world.fx_N``, ``e_x.fx_N``); ``attrs["units"]`` maps each column
        to its unit. The scheme is in `uvms_pin.results.table` and docs/api.md."""
        from uvms_pin.results.table import to_dataframe

        return to_dataframe(self)

    def plot(self, kind: str | None = None) -> Figure | dict[str, Figure]:
        """A matplotlib Figure of this rollout: ``kind`` one of `uvms_pin.results.figures.kinds.KINDS`
        ("pose", "velocities", "energy", "force", "first_level", "second_level", "tracking");
        without
        ``kind`` every figure the rollout has data for, as a dict by kind."""
        from uvms_pin.results.figures.kinds import plot_rollout

        return plot_rollout(self, kind)

    def camera(self, name: str) -> CameraRecord:
        """The images of the camera ``name`` (``[[sensors.camera]]``): ``time_s`` (T,),
        ``depth_m`` (T, H, W), ``rgb`` (T, H, W, 3) uint8, ``label`` (T, H, W)."""
        return camera_record(self.perception, self.metadata, name)

    def sonar(self, name: str) -> SonarRecord:
        """The images of the sonar ``name`` (``[[sensors.sonar]]``): ``time_s`` (T,),
        ``intensity`` (T, bins, beams), ``range_m`` (bins,), ``bearing_rad`` (beams,)."""
        return sonar_record(self.perception, self.metadata, name)

    def to_mcap(self, path: str | Path, *, urdf: str | Path | None = None) -> Path:
        """Write this rollout as a ROS 2 bag: one MCAP file, CDR-encoded ROS 2 messages
        (``/tf``, ``/joint_states``, ``/odometry/truth``, ...; docs/ros.md), written aside
        and renamed into place. ``urdf``: the model, if it moved since the run. Needs the
        ``ros`` extra (``pip install "uvms-pin[ros]"``)."""
        from uvms_pin.apps.export.ros_bag import write_mcap

        return write_mcap(self, given_path("path", path), urdf=urdf)

    # ---- persistence ------------------------------------------------------------------
    def save(self, directory: str | Path) -> Path:
        """Write ``rollout.npz`` and ``rollout.json`` into ``directory`` atomically (and the
        cameras' and sonars' images, when it has some, into ``perception.npz``)."""
        out = check_writable(given_path("directory", directory), "save")
        out.mkdir(parents=True, exist_ok=True)
        # Fix: serialise the metadata before writing anything; it used to be serialised
        # after rollout.npz was replaced, so unserialisable metadata left a new .npz next
        # to no (or a previous run's) rollout.json.
        text = json_text(self.metadata, standard=False)  # read back exactly by load
        arrays = {name: getattr(self, name) for name in self._BASE}
        arrays.update({f"signal__{k}": a for k, a in self.signals.items()})
        # both written to temporary files first, then renamed: a full disk (or Ctrl-C) while
        # writing either leaves the previous pair, never a new array file beside old metadata
        with atomic_paths(out / ARRAY_FILE, out / META_FILE) as (arrays_tmp, meta_tmp):
            with open(arrays_tmp, "wb") as f:
                np.savez_compressed(f, **arrays)
            meta_tmp.write_text(text, encoding="utf-8")
        if self.perception:
            with atomic_paths(out / frames.FILE) as (frames_tmp,):
                save_perception(frames_tmp, self.perception)
        elif (out / frames.FILE).is_file():  # a previous run's images: not this one's
            (out / frames.FILE).unlink()
        return out

    @classmethod
    def load(cls, directory: str | Path) -> Rollout:
        src = given_path("directory", directory)
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
        perception = load_perception(src / frames.FILE) if "perception" in metadata else {}
        return cls(**base, signals=signals, metadata=metadata, perception=perception)
