// The task-priority kinematic level: prioritized tasks -> a generalized velocity reference
// (mirror of uvms_pin/control/tracking/task_priority.py; the names below are the Python ones).
//
// Tasks, highest priority first:
//   1. joint limits (set-based): k_l (q_lo + m - q_j) <= q_dot_j <= k_l (q_hi - m - q_j); a
//      joint whose rate the tasks below would take past a bound gets the row q_dot_j = that
//      bound and the tasks are solved again (the active set grows until no rate is out);
//   2. the tracking task, x_dot_r = [p_dot_r + K_p (p_r - p); K_o e_o] (its `rows`);
//   3. vehicle roll and pitch (an end-effector task only): w_x, w_y = k_a e_a, e_a the first
//      two components of log3(R_v^T R_level), R_level the vehicle's yaw alone;
//   4. manipulability (set-based, w(q) = sqrt(det(J_a J_a^T)) < w_min): u += N_K W^1/2
//      [0; k_m grad w] (grad by central differences on the configuration manifold).
// Each task in the null space of the ones above, in the metric W (zeta = W^-1/2 u):
//   u_k = u_{k-1} + (J_k N_{k-1})^+ (x_k - J_k u_{k-1}),  N_k = N_{k-1} - V_k V_k^T
// with the damped inverse A^+ = V diag(s / (s^2 + lambda^2)) U^T by the SVD, singular values
// at or below RANK_CUTOFF s_max left out. Passive velocities are not unknowns: their measured
// values move the tasks (x_k - J_k,P zeta_P) and zeta_r,P = zeta_P.
#pragma once

#include <vector>

#include "law_tracking.hpp"

namespace uvms {

// KinematicGains (validated by the Python dataclass; the level checks the sizes).
struct KinematicGains {
  double position_gain_per_s = 1.0;     // K_p [1/s]
  double orientation_gain_per_s = 1.0;  // K_o [1/s]
  double attitude_gain_per_s = 1.0;     // k_a [1/s] (0: no attitude task)
  double joint_limit_margin_rad = 0.1;  // m [rad]
  double joint_limit_gain_per_s = 2.0;  // k_l [1/s]
  double manipulability_threshold = 0.0;  // w_min (0: no manipulability task)
  double manipulability_gain = 1.0;       // k_m [rad/s per unit of w]
  Eigen::VectorXd velocity_weights;       // W's diagonal (nv), > 0
  double damping = 1e-3;                  // lambda
  std::vector<int> passive_velocities;    // distinct, in 0..5
};

// RANK_CUTOFF: singular values below this fraction of the largest are dropped, not damped.
constexpr double kRankCutoff = 1e-9;

// One task of the recursion: J_k (m_k x n) and x_k (m_k).
struct PriorityTask {
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd rate;
};

// _damped_inverse_and_rows: A^T (A A^T + lambda^2 I)^-1 and an orthonormal basis of A's row
// space (its rows), the directions with s <= RANK_CUTOFF s_max left out.
struct DampedInverse {
  Eigen::MatrixXd inverse;  // n x m
  Eigen::MatrixXd rows;     // r x n
};
DampedInverse damped_inverse_and_rows(const Eigen::MatrixXd& matrix, double damping);

// prioritized_velocity: zeta (n) solving `tasks` in priority order in the metric
// W = diag(weights), plus `secondary` (n, or nullptr) projected into their null space.
Eigen::VectorXd prioritized_velocity(const std::vector<PriorityTask>& tasks,
                                     const Eigen::VectorXd& weights, double damping,
                                     const Eigen::VectorXd* secondary);

// KinematicLevel.reference's outputs.
struct KinematicReference {
  Eigen::VectorXd zeta_r;  // nv [m/s, rad/s body; joint rates]
  Vec3 position_error = Vec3::Zero();     // e_p [m]
  Vec3 orientation_error = Vec3::Zero();  // e_o [rad]
  Eigen::VectorXd active_limits;          // one 0/1 per joint with limits
};

class KinematicLevel {
 public:
  KinematicLevel(pinocchio::Model model, TrackingTaskSettings task, KinematicGains gains);
  int nq() const { return pose_.model().nq; }
  int nv() const { return pose_.model().nv; }
  // The joints with limits (one configuration entry each).
  int n_bounded() const { return static_cast<int>(bounded_q_.size()); }
  // zeta_r at the measured (q, v) for the path's p_r [m] and p_dot_r [m/s] at t.
  const KinematicReference& reference(const Vec3& p_r, const Vec3& v_r, const Eigen::VectorXd& q,
                                      const Eigen::VectorXd& v);
  // w(q) = sqrt(det(J_a J_a^T)), J_a the arm's columns of the frame Jacobian (LWA).
  double manipulability(const Eigen::VectorXd& q);

 private:
  // The recursion over the driven velocities, the passive ones at their measured v.
  Eigen::VectorXd solve(const std::vector<PriorityTask>& tasks, const Eigen::VectorXd& v,
                        const Eigen::VectorXd* secondary) const;
  // zeta_r with every bounded joint's rate inside its bounds, and which are held.
  void solve_within_limits(const std::vector<PriorityTask>& tasks, const Eigen::VectorXd& q,
                           const Eigen::VectorXd& v, const Eigen::VectorXd* secondary);
  PriorityTask attitude_task() const;
  // [0 (6); k_m grad w] while w(q) < w_min: true and into `out`; false otherwise.
  bool manipulability_velocity(const Eigen::VectorXd& q, Eigen::VectorXd& out);

  TrackingPose pose_;
  KinematicGains gains_;
  std::vector<int> bounded_q_, bounded_v_;  // the joints with limits: q and v indices
  Eigen::VectorXd lower_, upper_;
  std::vector<int> passive_, active_;  // velocity indices
  Eigen::VectorXd weights_active_;
  KinematicReference out_;
};

}  // namespace uvms
