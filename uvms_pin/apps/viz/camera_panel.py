"""A run's first camera beside its replay: its images as JPEG data, shown at the replay's
time (the last image taken at or before it)."""

from __future__ import annotations

import base64
import io
from typing import Any

import numpy as np

from uvms_pin.results.rollout import Rollout

__all__ = ["CAMERA_SCRIPT", "camera_panel"]

#: at most this many images in a page (evenly decimated beyond)
MAX_IMAGES = 200

#: the page's part: show the image of the replay's time (``UVMS_CAMERA`` and ``currentTime``
#: given by the page)
CAMERA_SCRIPT = """
const cameraImage = document.getElementById("uvms-camera");
let cameraShown = -1;
function showCamera(t) {
  if (!UVMS_CAMERA) return;
  let k = 0;
  while (k + 1 < UVMS_CAMERA.times.length && UVMS_CAMERA.times[k + 1] <= t + 1e-9) k++;
  if (k !== cameraShown) { cameraImage.src = UVMS_CAMERA.images[k]; cameraShown = k; }
}
"""


def _jpeg(rgb: np.ndarray) -> str:
    from PIL import Image  # matplotlib's own image library

    out = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb)).save(out, format="JPEG", quality=85)
    return "data:image/jpeg;base64," + base64.b64encode(out.getvalue()).decode("ascii")


def camera_panel(rollout: Rollout, t0: float) -> dict[str, Any] | None:
    """The first camera's images (times from ``t0`` [s]) as the page shows them, None
    without a camera."""
    cameras = [
        name
        for name, described in rollout.metadata.get("perception", {}).items()
        if described.get("kind") == "camera" and name in rollout.perception
    ]
    if not cameras:
        return None
    record = rollout.camera(cameras[0])
    rows = np.arange(len(record.time_s))
    if len(rows) > MAX_IMAGES:
        rows = np.unique(np.linspace(0, len(rows) - 1, MAX_IMAGES).round().astype(int))
    return {
        "name": cameras[0],
        "times": (record.time_s[rows] - t0).tolist(),
        "images": [_jpeg(record.rgb[k]) for k in rows],
    }
