"""Numbers as text, the one way uvms-pin writes them: in files it reads back, in messages
and in tables."""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np


def numbers_text(
    values: Iterable[float] | np.ndarray, digits: int | None = None, sep: str = " "
) -> str:
    """``values`` joined by ``sep``; each exact (``digits=None``: the shortest text that reads
    back as the same float, for URDF and MJCF attributes) or with ``digits`` significant
    digits (``:.{digits}g``, for messages)."""
    array = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
    if digits is None:
        return sep.join(repr(float(x)) for x in array)
    return sep.join(f"{x:.{digits}g}" for x in array)


def cell_text(value: Any, digits: int = 4, nan_text: str = "") -> str:
    """A table cell: a float with ``digits`` significant digits (NaN: ``nan_text``),
    anything else as ``str``."""
    if isinstance(value, float | np.floating):
        return nan_text if math.isnan(value) else f"{value:.{digits}g}"
    return str(value)
