"""The compiled camera's shading (uvms_pin/perception/compiled_camera.py,
src/uvms_core/camera_shading.cpp and vector_exp.cpp): its exponentials are the same bits on
every processor."""

from __future__ import annotations

import math

import numpy as np

from uvms_pin.physics.compiled.extension import core_module

LOG2E = 1.4426950408889634
LN2_HIGH = 6.93147180369123816490e-01
LN2_LOW = 1.90821492927058770002e-10
ROUND = 6755399441055744.0  # 1.5 2^52
ROUND_BITS = 0x4338000000000000  # its bits


def polynomial_exp(x: np.ndarray) -> np.ndarray:
    """vector_exp.cpp's exp, evaluated by numpy: each product and sum rounded on its own (no
    fused multiply-add), as the baseline processor computes it."""
    shifted = x * LOG2E + ROUND
    k = shifted - ROUND
    r = (x - k * LN2_HIGH) - k * LN2_LOW
    p = np.full_like(x, 1.0 / math.factorial(13))
    for n in range(12, -1, -1):
        p = p * r + 1.0 / math.factorial(n)
    # 2^k: k + 1023 in the exponent's bits (k's integer sits in shifted's low bits)
    bits = (shifted.view(np.int64) - ROUND_BITS + 1023) << 52
    return p * bits.view(np.float64)


def test_the_compiled_exponentials_are_those_of_the_baseline_processor():
    """A pixel whose radiance is exactly exp(-r) (no lights, no veiling light, the sky's
    irradiance E_0 (1 + n_z) / 2 = 1 facing up, the reflectance 1, beta_D = 1, K_d = 0) gives
    the polynomial's value to the bit: the x86-64-v3 clone the module picks on a processor
    with AVX2 rounds as the baseline does (no a * b + c fused, CMakeLists.txt). Compiled with
    fused multiply-adds (GCC's default there), a tenth of these values differed in their last
    bit."""
    core = core_module()
    rng = np.random.default_rng(0)
    r = np.concatenate([rng.uniform(0.0, 40.0, 4000), rng.uniform(0.0, 1e-3, 96)])
    n = len(r)
    rays = np.tile([1.0, 0.0, 0.0], (n, 1))  # level: depth 0, the daylight exp(-beta_D r)
    normals = np.tile([0.0, 0.0, 1.0], (n, 1))  # facing up: (1 + n_z) / 2 = 1
    out = (np.empty(n), np.empty((n, 3)), np.empty(n, dtype=np.int32), np.empty((n, 3)))
    core.shade_camera(
        np.zeros(3), np.eye(3), rays, r, normals, np.ones(n, dtype=np.int32),
        np.arange(n, dtype=np.int64), np.array([[0.0] * 3, [1.0] * 3]), np.zeros(3),
        np.ones(3), np.ones(3), 1.0, np.zeros(3), np.zeros((0, 9)), *out,
    )  # fmt: skip
    radiance = out[3]
    expected = polynomial_exp(-r)
    np.testing.assert_allclose(expected, np.exp(-r), rtol=4e-16)  # the polynomial is exp
    for channel in range(3):
        assert radiance[:, channel].tobytes() == expected.tobytes()
