"""Small vector helpers for the hot path (np.cross costs ~10 us per call on 3-vectors)."""

from __future__ import annotations

import numpy as np


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b over the last axis (length 3); leading axes broadcast."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def mat_vec(matrices: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """M v over the last axes: (..., m, n) x (..., n) -> (..., m)."""
    return np.matmul(matrices, vectors[..., None])[..., 0]


def mat_t_vec(matrices: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """M^T v over the last axes: (..., n, m) x (..., n) -> (..., m)."""
    return np.matmul(vectors[..., None, :], matrices)[..., 0, :]


def skew(vectors: np.ndarray) -> np.ndarray:
    """[a]x (..., 3, 3) with [a]x b = a x b, for a (..., 3)."""
    a0, a1, a2 = vectors[..., 0], vectors[..., 1], vectors[..., 2]
    zero = np.zeros_like(a0)
    rows = [[zero, -a2, a1], [a2, zero, -a0], [-a1, a0, zero]]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)
