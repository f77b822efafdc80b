// exp over an array, vectorized (vector_exp.hpp).
#include "vector_exp.hpp"

#include <cstdint>
#include <cstring>

namespace uvms::perception {

UVMS_VECTOR_CLONES
void exp_in_place(double* x, Eigen::Index n) {
  constexpr double kLog2e = 1.4426950408889634;
  constexpr double kLn2High = 6.93147180369123816490e-01;  // ln 2's first 32 bits
  constexpr double kLn2Low = 1.90821492927058770002e-10;   // and the rest
  // 1.5 2^52: v + it rounds v to an integer (to even on a tie) held in its low bits
  constexpr double kRound = 6755399441055744.0;
  constexpr std::int64_t kRoundBits = 0x4338000000000000LL;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double v = x[i];
    const double shifted = v * kLog2e + kRound;
    const double k = shifted - kRound;
    const double r = (v - k * kLn2High) - k * kLn2Low;
    double p = 1.0 / 6227020800.0;  // 1 / 13!
    p = p * r + 1.0 / 479001600.0;
    p = p * r + 1.0 / 39916800.0;
    p = p * r + 1.0 / 3628800.0;
    p = p * r + 1.0 / 362880.0;
    p = p * r + 1.0 / 40320.0;
    p = p * r + 1.0 / 5040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    p = p * r + 1.0;
    p = p * r + 1.0;
    // 2^k: k + 1023 in the exponent's bits (k's integer sits in shifted's low bits)
    std::int64_t bits;
    std::memcpy(&bits, &shifted, sizeof bits);
    bits = (bits - kRoundBits + 1023) << 52;
    double scale;
    std::memcpy(&scale, &bits, sizeof scale);
    x[i] = p * scale;
  }
}

}  // namespace uvms::perception
