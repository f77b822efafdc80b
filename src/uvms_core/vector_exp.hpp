// exp over an array, vectorized: the exponentials of a camera's pixels (camera_shading.cpp).
//
// exp(x) = 2^k exp(r), k = round(x / ln 2), r = x - k ln 2 in [-ln 2 / 2, ln 2 / 2] (ln 2 in
// two parts, Cody and Waite, so that r is exact to rounding), exp(r) by its Taylor polynomial
// of degree 13 (remainder below |r|^14 / 14! < 5e-18), 2^k put in the exponent's bits: within
// an ulp or two of std::exp (tests/perception/test_compiled_caster.py). The loop has no branch,
// so the compiler vectorizes it; on x86-64 it is compiled three times, for the baseline
// (SSE2), for x86-64-v3 (AVX2, FMA: four doubles a vector) and for x86-64-v4 (AVX-512: eight),
// the processor's picked when the module loads (GCC's target_clones): the build's flags stay
// the baseline's. The units that use the clones are compiled with -ffp-contract=off
// (CMakeLists.txt): without it GCC fuses p * r + c into one FMA in the x86-64-v3 and v4
// clones, and an exponential (hence an image) would differ in its last bits between
// processors with and without AVX2.
#pragma once

#include <Eigen/Core>

// A function compiled three times on x86-64 Linux (GCC): for the baseline, x86-64-v3 (AVX2,
// FMA) and x86-64-v4 (AVX-512), the processor's picked when the module loads; elsewhere once,
// for the baseline. The v4 clone took a 320 x 240 image's shading from 4.2 to 3.7 ms on this
// project's machine (AVX-512), the same bits (tests/perception/test_compiled_camera.py).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define UVMS_VECTOR_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define UVMS_VECTOR_CLONES
#endif

namespace uvms::perception {

// The smallest and largest exponents taken: exp(-708) = 3.3e-308, the smallest normal double
// being 2.2e-308; the caller clamps (the camera's exponents are <= 0, exp(-708) standing
// for the 0 or subnormal std::exp gives below it).
constexpr double kExpLowest = -708.0;
constexpr double kExpHighest = 708.0;

// x[i] <- exp(x[i]) for i < n, each x[i] in [kExpLowest, kExpHighest].
void exp_in_place(double* x, Eigen::Index n);

}  // namespace uvms::perception
