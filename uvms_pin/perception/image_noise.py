"""Seeded standard-normal noise for images, drawn by inverse transform of 16-bit uniforms.

A camera adds a Gaussian read noise to each channel of each pixel: 230,400 draws for a
320 x 240 colour image. numpy's ``standard_normal`` (ziggurat, float32) takes about 2.8 ms
for them on this project's machine, as long as casting the image; a uniform 16-bit code
per draw (``Generator.integers``, 0.35 ms) looked up in a table of the normal quantiles
z_k = Phi^-1((k + 1/2) / 65536), k = 0 .. 65535, takes 0.6 ms in all.

The draws are a standard normal discretised into 65,536 equiprobable levels: each level's
probability is exact, the levels' spacing is below 1e-4 near 0 and about 0.2 at the last
one, |z| <= 4.32 (a normal exceeds it with probability 1.5e-5), and the table is scaled to
unit variance (before: 0.99998). For an 8-bit image with noise of a few counts this is
below the rounding to counts; it is not a generator for statistics in the tails.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from uvms_pin.errors import ParameterError

__all__ = ["LEVELS", "normal_codes", "normal_levels", "standard_normal_f32"]

LEVELS = 1 << 16


@cache
def normal_levels() -> np.ndarray:
    """(65536,) float32: z_k = Phi^-1((k + 1/2) / 65536), scaled to unit variance
    (read-only, computed once)."""
    # scipy.special is imported where it is used: it takes a quarter second to import,
    # which every start-up would pay otherwise
    from scipy.special import ndtri

    z = ndtri((np.arange(LEVELS) + 0.5) / LEVELS)
    z /= np.sqrt(np.mean(z * z))
    table = z.astype(np.float32)
    table.flags.writeable = False
    return table


def normal_codes(rng: np.random.Generator, size: int) -> np.ndarray:
    """``size`` uniform 16-bit codes (uint16) from ``rng``: the draws k whose values are
    `normal_levels`()[k] (the compiled camera looks them up itself).

    They are ``rng.integers(0, 65536, size, dtype=np.uint16)``: numpy splits each 64-bit
    output of PCG64 into 32-bit halves, low first, and each of those into 16-bit halves, low
    first (keeping an unused 32-bit half for the next call). For a size that is a multiple of
    4 and no half kept, that is the raw 64-bit outputs read as 16-bit integers, taken so
    (0.16 ms for a 320 x 240 image's 230,400 codes instead of 0.27 ms): the same codes, the
    generator left in the same state (tests/perception/test_image_noise.py)."""
    bits = rng.bit_generator
    if size % 4 == 0 and type(bits) is np.random.PCG64 and not bits.state["has_uint32"]:
        return bits.random_raw(size // 4).view(np.uint16)
    return rng.integers(0, LEVELS, size=size, dtype=np.uint16)


def standard_normal_f32(
    rng: np.random.Generator, shape: tuple[int, ...], out: np.ndarray | None = None
) -> np.ndarray:
    """Standard-normal draws of ``shape`` (float32) from ``rng``: one uniform 16-bit code
    per draw, looked up in `normal_levels`; written into ``out`` (float32, ``shape``,
    C-contiguous) when given."""
    size = int(np.prod(shape))
    if out is None:
        out = np.empty(shape, dtype=np.float32)
    elif out.shape != tuple(shape) or out.dtype != np.float32 or not out.flags.c_contiguous:
        raise ParameterError(f"out must be a C-contiguous float32 array of shape {tuple(shape)}")
    np.take(normal_levels(), normal_codes(rng, size), out=out.reshape(size))
    return out
