// Fixed-size spatial types shared by the core's units (Pinocchio order: [linear; angular]).
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <string>

namespace uvms {

// The version of the interface the Python seam (uvms_pin/physics/compiled/) is written
// against: the only place it is defined (Python reads _core.API_VERSION).
constexpr int kApiVersion = 14;

using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// [t]x, the matrix of t x (.).
inline Mat3 skew(const Vec3& t) {
  Mat3 out;
  out << 0.0, -t.z(), t.y(), t.z(), 0.0, -t.x(), -t.y(), t.x(), 0.0;
  return out;
}

// Bad input from the caller (shape, non-finite value): ParameterError on the Python side.
struct InputError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// The simulation cannot continue (e.g. M not positive definite): SimulationError in Python.
struct SimulationFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace uvms
