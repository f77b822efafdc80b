"""What only a blown-up integration gives: a non-finite state or an absurd speed, and the
numerical errors that mean the same."""

from __future__ import annotations

import math

import numpy as np

#: A speed this large [m/s or rad/s] only comes out of a blown-up integration.
DIVERGED_SPEED = 1e4

#: What numerical code raises on a blown-up state (a singular chart Jacobian or mass
#: matrix, an overflow): reported as a SimulationError with the partial rollout kept.
NUMERICAL_FAILURES = (np.linalg.LinAlgError, FloatingPointError, OverflowError, ZeroDivisionError)


def diverged(q: np.ndarray, v: np.ndarray) -> bool:
    """True for a state only a blown-up integration gives: non-finite, or a speed above
    `DIVERGED_SPEED`."""
    # one reduction each (a sum is NaN or inf if any entry is, the extremes bound |v|); the
    # exact test only when they do not settle it (e.g. a sum beyond 1e308)
    low, high = float(v.min()), float(v.max())
    if math.isfinite(float(q.sum())) and -DIVERGED_SPEED <= low and high <= DIVERGED_SPEED:
        return False
    return not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))) or bool(
        np.max(np.abs(v)) > DIVERGED_SPEED
    )
