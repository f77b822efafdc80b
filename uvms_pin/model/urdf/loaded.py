"""A URDF loaded once per process: `loaded_uvms` gives a copy of the model already loaded from
the same file content with the same water density (`UVMS.copy`: its own work buffer, the
static parts shared), so that a study's worker, which loads its base scenario once per run,
parses and checks the file once.

The key is the file's path and bytes: an edited URDF is loaded again. The warnings the first
load gave are given again at every call (a caller that filters them sees what it would see
without the cache). Meshes the file refers to are read with the first load only.
"""

from __future__ import annotations

import functools
import warnings
from pathlib import Path

from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import UVMS

__all__ = ["loaded_uvms"]


def loaded_uvms(urdf_path: str | Path, *, water_density_kg_m3: float) -> UVMS:
    """`load_uvms(urdf_path, water_density_kg_m3=...)`, the file parsed once per process.

    Raises:
        ModelError, ParameterError: as `load_uvms` (a failed load is not kept).
    """
    path = Path(urdf_path)
    try:
        content = path.read_bytes()
    except OSError:  # missing or unreadable: load_uvms says so in its own words
        return load_uvms(path, water_density_kg_m3=water_density_kg_m3)
    first, given = _first_load(str(path), content, float(water_density_kg_m3))
    for w in given:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return first.copy()


@functools.lru_cache(maxsize=8)
def _first_load(
    path: str, content: bytes, water_density_kg_m3: float
) -> tuple[UVMS, tuple[warnings.WarningMessage, ...]]:
    """The UVMS of the file at ``path`` holding ``content`` (the key), and the warnings its
    load gave."""
    with warnings.catch_warnings(record=True) as given:
        warnings.simplefilter("always")
        uvms = load_uvms(path, water_density_kg_m3=water_density_kg_m3)
    return uvms, tuple(given)
