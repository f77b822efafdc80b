"""What a run's cameras and sonars recorded, beside its rollout (not in its arrays).

A rollout holds them in ``perception``: sensor name -> its arrays (``time_s`` (T,) and what
each firing gave, stacked: a camera's ``depth_m`` (T, H, W) float32, ``rgb`` (T, H, W, 3)
uint8 and ``label`` (T, H, W) int16; a sonar's ``intensity`` (T, bins, beams) with its
``range_m`` (bins,) and ``bearing_rad`` (beams,), a multibeam's (and an altimeter's)
``beam_range_m`` and ``beam_intensity`` (T, beams) too); its metadata's ``perception`` says each
sensor's kind and, for a camera, its labels' names (label k is ``label_names[k - 1]``, 0:
nothing met). Saved compressed as ``perception.npz`` beside ``rollout.npz``.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.errors import ParameterError

__all__ = [
    "FILE",
    "CameraRecord",
    "SonarRecord",
    "camera_record",
    "load_perception",
    "save_perception",
    "sonar_record",
]

FILE = "perception.npz"
_SEP = "__"


@dataclass(frozen=True)
class CameraRecord:
    """A camera's images: ``time_s`` (T,), ``depth_m`` (T, H, W) [m] (NaN: nothing met),
    ``rgb`` (T, H, W, 3) uint8, ``label`` (T, H, W) and ``label_names``."""

    time_s: np.ndarray
    depth_m: np.ndarray
    rgb: np.ndarray
    label: np.ndarray
    label_names: tuple[str, ...]


@dataclass(frozen=True)
class SonarRecord:
    """A sonar's images: ``time_s`` (T,), ``intensity`` (T, bins, beams), ``range_m``
    (bins,) [m] and ``bearing_rad`` (beams,) [rad]; a multibeam's detections (an
    altimeter's reading, one beam) ``beam_range_m`` (T, beams) [m] (NaN: none) and
    ``beam_intensity`` (T, beams) (None for an imaging sonar)."""

    time_s: np.ndarray
    intensity: np.ndarray
    range_m: np.ndarray
    bearing_rad: np.ndarray
    beam_range_m: np.ndarray | None = None
    beam_intensity: np.ndarray | None = None


def _arrays(perception: dict, metadata: dict, name: str, kind: str) -> dict[str, np.ndarray]:
    described = metadata.get("perception", {}).get(name)
    if described is None or described.get("kind") != kind:
        known = [n for n, d in metadata.get("perception", {}).items() if d.get("kind") == kind]
        raise ParameterError(
            f"this rollout has no {kind} '{name}' (its {kind}s: {', '.join(known) or 'none'})"
        )
    if name not in perception:  # the run had it: its images were not saved or not found
        raise ParameterError(
            f"this rollout's {kind} '{name}' has no images: they are kept in {FILE} beside "
            "rollout.npz, which was not found when it was loaded (copy it with the rollout)"
        )
    return perception[name]


def camera_record(perception: dict, metadata: dict, name: str) -> CameraRecord:
    arrays = _arrays(perception, metadata, name, "camera")
    names = tuple(metadata["perception"][name].get("label_names", ()))
    return CameraRecord(arrays["time_s"], arrays["depth_m"], arrays["rgb"], arrays["label"], names)


def sonar_record(perception: dict, metadata: dict, name: str) -> SonarRecord:
    arrays = _arrays(perception, metadata, name, "sonar")
    return SonarRecord(
        arrays["time_s"],
        arrays["intensity"],
        arrays["range_m"],
        arrays["bearing_rad"],
        arrays.get("beam_range_m"),
        arrays.get("beam_intensity"),
    )


#: zlib's fastest level: images compress 3.5 times faster than at its default (6), into a file
#: about a tenth larger (measured on scenarios/seabed_survey.toml's 151 frames: 0.74 s and
#: 24.4 MB against 2.6 s and 22.4 MB)
COMPRESS_LEVEL = 1


def save_perception(path: Path, perception: dict[str, dict[str, np.ndarray]]) -> None:
    """Every sensor's arrays into one compressed ``.npz`` at ``path`` (what ``np.load``
    reads: one ``.npy`` per array in a deflated zip)."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=COMPRESS_LEVEL) as zf:
        for name, arrays in perception.items():
            for key, array in arrays.items():
                with zf.open(f"{name}{_SEP}{key}.npy", "w", force_zip64=True) as f:
                    np.lib.format.write_array(f, np.asanyarray(array), allow_pickle=False)


def load_perception(path: Path) -> dict[str, dict[str, np.ndarray]]:
    """What `save_perception` wrote (empty when there is no file)."""
    if not path.is_file():
        return {}
    out: dict[str, Any] = {}
    try:
        with np.load(path) as data:
            for key in data.files:
                name, _, array = key.rpartition(_SEP)
                out.setdefault(name, {})[array] = data[key]
    except (OSError, ValueError, zipfile.BadZipFile) as exc:
        raise ParameterError(f"{path} is damaged ({type(exc).__name__}: {exc})") from exc
    return out
