"""A run's first camera and first imaging sonar beside its replay: their images as JPEG
data, each shown at the replay's time (the last image taken at or before it).

The sonar's image is its intensity in dB (50 dB below the run's brightest echo, copper, as
perception.png draws it): range up from the nearest bin, port on the left.
"""

from __future__ import annotations

import base64
import io
from typing import Any

import numpy as np

from uvms_pin.results.figures.perception import decibels, snapshot_rows
from uvms_pin.results.rollout import Rollout

__all__ = ["PANELS_SCRIPT", "image_panels"]

#: at most this many images in a page per panel (evenly decimated beyond)
MAX_IMAGES = 200

#: the page's part: show each panel's image of the replay's time (``UVMS_PANELS`` given by
#: the page, an ``<img>`` of each panel's ``id``)
PANELS_SCRIPT = """
const panelImages = UVMS_PANELS.map((panel) => document.getElementById(panel.id));
const panelShown = UVMS_PANELS.map(() => -1);
function showPanels(t) {
  UVMS_PANELS.forEach((panel, i) => {
    let k = 0;
    while (k + 1 < panel.times.length && panel.times[k + 1] <= t + 1e-9) k++;
    if (k !== panelShown[i]) { panelImages[i].src = panel.images[k]; panelShown[i] = k; }
  });
}
"""


def _jpeg(rgb: np.ndarray) -> str:
    from PIL import Image  # matplotlib's own image library

    out = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb)).save(out, format="JPEG", quality=85)
    return "data:image/jpeg;base64," + base64.b64encode(out.getvalue()).decode("ascii")


def _first(rollout: Rollout, kind: str, wanted=lambda name: True) -> str | None:
    for name, described in rollout.metadata.get("perception", {}).items():
        if described.get("kind") == kind and name in rollout.perception and wanted(name):
            return name
    return None


def sonar_rgb(intensity: np.ndarray, low_db: float, high_db: float) -> np.ndarray:
    """A sonar image (bins, beams) as 8-bit colour (bins, beams, 3): its dB on the copper
    scale from ``low_db`` to ``high_db``, the nearest bin at the bottom, port (the last
    beam, the largest bearing) on the left."""
    from matplotlib import colormaps

    db = decibels(intensity)[0]
    level = np.clip((db - low_db) / max(high_db - low_db, 1e-12), 0.0, 1.0)
    rgb = colormaps["copper"](level[::-1, ::-1])[..., :3]
    return np.round(255.0 * rgb).astype(np.uint8)


def image_panels(rollout: Rollout, t0: float) -> list[dict[str, Any]]:
    """The first camera's and the first imaging sonar's images (times from ``t0`` [s]) as
    the page shows them: ``id`` (its ``<img>``), ``label``, ``times``, ``images``."""
    out = []
    camera = _first(rollout, "camera")
    if camera is not None:
        record = rollout.camera(camera)
        rows = snapshot_rows(len(record.time_s), MAX_IMAGES)
        out.append({
            "id": "uvms-camera",
            "label": f"camera {camera}",
            "times": (record.time_s[rows] - t0).tolist(),
            "images": [_jpeg(record.rgb[k]) for k in rows],
        })  # fmt: skip

    def imaging(name: str) -> bool:  # not a multibeam's profile, not an altimeter's beam
        arrays = rollout.perception[name]
        return "beam_range_m" not in arrays and arrays["intensity"].shape[2] > 1

    sonar = _first(rollout, "sonar", imaging)
    if sonar is not None:
        record = rollout.sonar(sonar)
        rows = snapshot_rows(len(record.time_s), MAX_IMAGES)
        _, low, high = decibels(record.intensity)
        out.append({
            "id": "uvms-sonar",
            "label": f"sonar {sonar}",
            "times": (record.time_s[rows] - t0).tolist(),
            "images": [_jpeg(sonar_rgb(record.intensity[k], low, high)) for k in rows],
        })  # fmt: skip
    return out
