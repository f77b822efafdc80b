// Disturbances: body wrenches on the vehicle (mirror of uvms_pin/physics/disturbance.py).
#pragma once

#include <cmath>
#include <optional>

#include "types.hpp"

namespace uvms {

// delta(t) = amplitude sin(2 pi t / period + phase)  [N; N m], vehicle body frame.
struct SinusoidalDisturbance {
  Vec6 amplitude;
  double period_s;
  double phase_rad;

  Vec6 at(double time_s) const {
    return amplitude * std::sin(2.0 * M_PI * time_s / period_s + phase_rad);
  }
};

using Disturbance = std::optional<SinusoidalDisturbance>;

}  // namespace uvms
