// The cost terms of an underwater OCP (mirror of uvms_pin/ocp/costs.py): weighted least
// squares l = (1/2) r^T W r of a residual r(x, u), with its Jacobians R_x (over the tangent
// dx = (dq, dv)) and R_u. Frame Jacobians are Pinocchio's LOCAL ones at the node's state
// (after computeJointJacobians and updateFramePlacements in the node's data).
//
//   frame pose         r = log6(T_target^-1 T_f)         R_q = Jlog6 J_f          (6)
//   frame rotation     r = log3(R_target^T R_f)          R_q = Jlog3 J_f^w        (3)
//   frame position     r = p_f - p_target [m]            R_q = R_f J_f^v          (3)
//   effort             r = u (thrust [N], torque [N m])  R_u = I                  (nu)
//   state              r = (q (-) q_ref, v - v_ref)      R_q = dDifference, R_v = I
//   contact force      r = f - f_d [N]                   R_x = [df/dq, df/dv]     (3)
//   joint limits       r = q_j - clip(q_j, lo_j, hi_j)   R_q = 1 outside, else 0  (n)
//
// One struct per term, a variant of them (CostKind); an OcpTerm is a kind with its weights
// (W's diagonal, the term's scale already applied: scale_i W_i of costs.py).
#pragma once

#include <variant>
#include <vector>

#include <pinocchio/spatial/se3.hpp>

#include "derivatives.hpp"

namespace uvms {

struct FramePoseCost {
  int frame_id = 0;
  pinocchio::SE3 target = pinocchio::SE3::Identity();
};

struct FrameRotationCost {
  int frame_id = 0;
  Mat3 rotation = Mat3::Identity();  // world <- target
};

struct FramePositionCost {
  int frame_id = 0;
  Vec3 target_m = Vec3::Zero();
};

struct EffortCost {
  int size = 0;  // nu
};

struct StateDeviationCost {
  Eigen::VectorXd x_ref;  // (nq + nv)
};

struct ContactForceCost {
  Vec3 target_N = Vec3::Zero();  // f_d, world axes
};

struct JointLimitCost {
  std::vector<int> q_index, v_index;  // the one-DoF arm joints'
  Eigen::VectorXd lower, upper;       // their limits less the margin [rad or m]
};

using CostKind = std::variant<FramePoseCost, FrameRotationCost, FramePositionCost, EffortCost,
                              StateDeviationCost, ContactForceCost, JointLimitCost>;

struct OcpTerm {
  CostKind kind;
  Eigen::VectorXd weights;  // scale W's diagonal (nr of the kind)
};

// The rows of a term's residual (nu: the node's inputs, nv: the model's velocities).
int residual_size(const CostKind& kind, int nv);

// The terms' work buffers (no allocation per call): a frame's LOCAL Jacobian (6, nv) and a
// configuration Jacobian (nv, nv).
struct TermWork {
  explicit TermWork(int nv) : frame_jacobian(Matrix6x::Zero(6, nv)), configuration(nv, nv) {}
  Matrix6x frame_jacobian;
  Eigen::MatrixXd configuration;
};

// What the terms read of the node's state besides x and u: the frames' placements and LOCAL
// Jacobians (data after computeJointJacobians and updateFramePlacements) and the contact's
// force and its derivatives (null without a contact).
struct TermState {
  const Model& model;
  Data& data;
  TermWork& work;
  const Vec6* wrench_world = nullptr;
  const Matrix6x* wrench_dq = nullptr;
  const Matrix6x* wrench_dv = nullptr;
};

// r (nr) into out.
void term_residual(const CostKind& kind, const TermState& at, const Eigen::VectorXd& x,
                   const Eigen::VectorXd& u, Eigen::Ref<Eigen::VectorXd> out);
// [R_x R_u] (nr, 2 nv + nu) into out (zeroed here first).
void term_jacobian(const CostKind& kind, const TermState& at, const Eigen::VectorXd& x,
                   const Eigen::VectorXd& u, Eigen::Ref<Eigen::MatrixXd> out);

}  // namespace uvms
