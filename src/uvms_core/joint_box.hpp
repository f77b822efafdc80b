// The implicit step of one body's joints with Coulomb friction and position limits, solved
// exactly (mirror of uvms_pin/physics/constraints/joint_box.py, which gives the problem, its
// optimality conditions and why coordinate descent solves it): over a period h,
//
//   min_v  1/2 (v - v_free)^T M (v - v_free) + h sum_j c_j |v_j|
//   subject to  -phi(r_lo) / h <= v <= phi(r_hi) / h
//
// with M the body's mass matrix (its joints; added mass included), c the joints' Coulomb
// friction [N m or N] and r_lo = q - q_min, r_hi = q_max - q the limits' gaps (infinite: no
// limit), phi a penetration removed by the fraction `correction` per period.
#pragma once

#include <Eigen/Core>

namespace uvms {

struct JointBoxStep {
  Eigen::VectorXd velocity;          // v+ (n,) [rad/s or m/s]
  Eigen::VectorXd friction_impulse;  // along each joint [N m s or N s]
  Eigen::VectorXd limit_impulse;     // the lower limit's positive, the upper's negative
};

// The step of the file's comment (InputError unless h > 0, c >= 0 and M_jj > 0).
JointBoxStep joint_box_step(const Eigen::VectorXd& v_free, const Eigen::MatrixXd& mass,
                            const Eigen::VectorXd& coulomb, const Eigen::VectorXd& gap_low,
                            const Eigen::VectorXd& gap_high, double period_s,
                            double correction = 0.2);

}  // namespace uvms
