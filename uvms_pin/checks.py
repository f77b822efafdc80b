"""Checks of arguments that raise `ParameterError` naming the argument and what is wrong."""

from __future__ import annotations

import numpy as np

from uvms_pin.errors import ParameterError


def finite_vector(name: str, value, size: int) -> np.ndarray:
    """``value`` as a float array of shape (size,) with finite entries, or ParameterError."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be {size} numbers, got {value!r}") from exc
    if array.shape != (size,):
        raise ParameterError(f"{name} must have shape ({size},), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ParameterError(f"{name} contains a non-finite value: {array}")
    return array
