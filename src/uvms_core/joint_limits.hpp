// The arm joints' position limits as unilateral constraints solved implicitly once a control
// period (mirror of uvms_pin/physics/constraints/joint_limits.py, the rows, and of
// uvms_pin/physics/constraints/step.py, the velocity step, for joint limits alone).
//
// The smooth dynamics bring the velocity to v_free at the period's end; the limits add the
// impulses lambda >= 0 through their rows (lower: gap r = q_j - q_min, J = +e_j; upper:
// r = q_max - q_j, J = -e_j), at the configuration q0 of the period's start:
//   v+ = v_free + M^-1 J^T lambda,  sigma = J v+ + phi(r) / h >= 0,  lambda . sigma = 0,
// phi(r) = r for r >= 0, correction * r for r < 0 (a penetration removed by that fraction per
// period). M is the mass matrix with the added mass. As J selects single coordinates, this is
// the box-constrained quadratic program
//   v+ = argmin 1/2 (v - v_free)^T M (v - v_free)  s.t.  -phi_l / h <= v_j <= phi_u / h
// over the selected rows, whose multipliers are the impulses. The Python reference hands the
// rows to Pinocchio's ADMM (tolerance 1e-8 on sigma); this solves the program exactly, by a
// primal active set (finite for a positive definite M), so the two agree to the ADMM's
// tolerance.
//
// Rows: those that can close within the period, gap <= h |v_j| + margin, with |v| the
// velocity's magnitudes (at least the smooth step's own), widened with the solved velocity and solved again until the selection
// no longer grows (at most 4 rounds, then once more), as the Python reference does.
#pragma once

#include <optional>
#include <vector>

#include "types.hpp"

namespace uvms {

// The rounds of widening the selection of active rows before the last solve, in every implicit
// constraint step of the core (physics/constraints/step.py's _MAX_ROUNDS)
constexpr int kWideningRounds = 4;

struct JointLimitConstraintsModel {
  std::vector<int> q_index;   // each limited joint's coordinate in q (one coordinate each)
  std::vector<int> v_index;   // and in v
  Eigen::VectorXd lower_rad;  // its finite limits [rad or m]
  Eigen::VectorXd upper_rad;
  double margin = 1.0e-3;     // a row is solved when its gap <= h |v_j| + margin [rad or m]
  double correction = 0.2;    // beta, the fraction of a penetration removed per period

  void check(Eigen::Index nq, Eigen::Index nv) const;

  // Whether some row is within reach of the period h [s] from q0 when each coordinate moves
  // at `speed` [rad/s, m/s] (else constrain() with that least speed selects nothing).
  bool within_reach(const Eigen::Ref<const Eigen::VectorXd>& q0, const Eigen::VectorXd& speed,
                    double h) const;

  // v (in: v_free, out: v+) over the period h [s] from the configuration q0, mass the mass
  // matrix M(q0) (nv x nv, added mass included). The rows are selected with the speed
  // max(|v|, least_speed) per coordinate: least_speed the smooth step's own (its start
  // velocity and its mean over the period, whose end may cross a limit its end velocity
  // would not reach). Returns whether any row was selected (then the configuration advances
  // as q0 (+) h v+, else the smooth step's own stands).
  bool constrain(const Eigen::MatrixXd& mass, const Eigen::Ref<const Eigen::VectorXd>& q0,
                 Eigen::VectorXd& v, double h, const Eigen::VectorXd& least_speed) const;
};

using JointLimitConstraints = std::optional<JointLimitConstraintsModel>;

}  // namespace uvms
