// Derivatives of the underwater forward dynamics (mirror of uvms_pin/physics/derivatives/).
//
// a(q, v, tau) solves ID(q, v, a) = tau + tau_ext, ID the RNEA with each joint body's fluid
// wrench w_j(q, v, a) as an external force (w_j holds -M_A,j a_j). Along the tangent:
//   dID/dq = dRNEA/dq |_(w fixed) - sum_j J_j^T dw_j/dq         (likewise d/dv)
//   M = dID/da = M_RB + sum_j J_j^T M_A,j J_j
//   da/dq = -M^-1 dID/dq,  da/dv = -M^-1 dID/dv,  da/dtau = M^-1.
// Pinocchio's computeRNEADerivatives gives the first term and, in its data, what each joint's
// LOCAL velocity and acceleration derivatives are made of (joint_motions(): the formulas of
// Pinocchio's getJointAccelerationDerivatives, LOCAL, as 6x6 products); the fluid terms' own
// Jacobians are each hydro unit's (added_mass.hpp, damping.hpp, restoring.hpp), one function
// per term as in fluid.py. fluid.py writes each term's dw/dq and dw/dv as (6, nv) blocks; here
// each term gives its 6 x 6 sensitivities to the body's acceleration, velocity and pose
// (WrenchSensitivity), summed per joint and chained with the joint's motion derivatives once:
//   dw/dq = W_a da/dq + W_nu dnu/dq + W_delta J,   dw/dv = W_a da/dv + W_nu J,
// the same sums regrouped (five (6, n) products per joint instead of about twenty; the
// Python reference, which the tests compare with to 1e-10, keeps the term-by-term form).
//
// Under a free surface (derivatives_surface.cpp, mirror of physics/derivatives/surface.py)
// the terms above use the wet volumes, centres of buoyancy, added masses and damping
// fractions, held; the surface's own terms (through each cut hull's wetting x_i, its pose
// Jacobian by 4-point differences of Hull::wet) are added to dw/dq and dw/dv.
//
// A Derivatives owns a copy of the Dynamics it differentiates, like Plant, and a Pinocchio
// data of its own for the RNEA derivatives (they overwrite buffers, e.g. data.M and the
// composite inertias, that the dynamics' articulated pass keeps between calls): not
// thread-safe, no allocation per call.
#pragma once

#include <vector>

#include "dynamics.hpp"

namespace uvms {

using Matrix6x = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using Matrix3x = Eigen::Matrix<double, 3, Eigen::Dynamic>;

// The three Jacobians of zeta_dot (nv x nv each), q along the tangent.
struct ForwardDynamicsDerivatives {
  Eigen::MatrixXd da_dq;
  Eigen::MatrixXd da_dv;
  Eigen::MatrixXd da_dtau;
};

// One joint body's motion and its Jacobians, LOCAL frame (mirror of motion.py JointMotion).
struct JointMotion {
  Mat3 rotation;
  Vec3 translation;
  Vec6 velocity;
  Matrix6x jacobian;  // d nu / dv = d a / d qdd
  Matrix6x velocity_dq;
  Matrix6x acceleration_dq;
  Matrix6x acceleration_dv;
  // nonzero columns: those up to the joint's own (its support and joints before it)
  int columns = 0;

  Vec3 point(const Vec3& point_in_joint_m) const {
    return rotation * point_in_joint_m + translation;
  }
  // d p_world / dq of a point fixed in the joint frame: R (J^v - [r]x J^w).
  Matrix3x point_dq(const Vec3& point_in_joint_m) const;
};

using Mat36 = Eigen::Matrix<double, 3, 6>;

// The flow seen in a body frame, U = R_b^T u and A = R_b^T Du/Dt at a point fixed in the
// joint frame, and their Jacobians in the joint frame's own twist delta = [dp; dtheta]
// (R -> R exp([dtheta]x), p -> p + R dp): d/dq = d/d delta J (fluid.py FlowInBody).
struct FlowSeenByBody {
  Vec3 velocity;
  Vec3 acceleration;
  Mat36 velocity_by_pose;
  Mat36 acceleration_by_pose;
};

FlowSeenByBody flow_in_body(const JointMotion& motion, const Mat3& rotation_in_joint,
                            const Vec3& point_in_joint_m, const FlowGradientsAtPoint& flow);

// A joint body's fluid wrench w(a, nu, pose), linearised: dw = W_a da + W_nu dnu + W_delta
// delta, each term adding its own; chained with the joint's motion derivatives once per
// joint (6 x 6 products, not one (6, nv) product per term).
struct WrenchSensitivity {
  Mat6 by_acceleration = Mat6::Zero();
  Mat6 by_velocity = Mat6::Zero();
  Mat6 by_pose = Mat6::Zero();
};

class Derivatives {
 public:
  explicit Derivatives(const Dynamics& dynamics);
  Derivatives(const Derivatives&) = delete;
  Derivatives& operator=(const Derivatives&) = delete;

  const ForwardDynamicsDerivatives& forward_dynamics_derivatives(
      const ConstVec& q, const ConstVec& v, const ConstVec& tau, const FlowField& flow,
      const ConstVec* tau_ext, double time_s = 0.0, bool free_surface = false);

  Dynamics& dynamics() { return dynamics_; }

 private:
  // fext_ = w_j(q, v, a): the fluid wrenches with each body's whole acceleration
  void wrenches_at(const ConstVec& q, const ConstVec& v, const Eigen::VectorXd& a,
                   const FlowField& flow, double time_s);
  void joint_motions();
  void fluid_jacobians(const FlowField& flow, double time_s);
  // each term's sensitivities (added to sensitivity_[joint]), then the chain rule
  void added_mass_sensitivity(int joint, const FlowGradientsAtPoint& flow);
  void restoring_sensitivity(int joint, const FlowGradientsAtPoint& flow, bool waves);
  void damping_sensitivity(const DampedBody& body, const FlowGradientsAtPoint& flow);
  void chain_sensitivity(int joint);
  // derivatives_surface.cpp: the wet-fraction terms of the hulls the surface cuts
  void surface_jacobians(const FlowField& flow, double time_s);
  void surface_joint_terms(int joint, const FlowGradientsAtPoint& at_cob, bool moving_water);

  Dynamics dynamics_;
  Data data_;  // the RNEA derivatives' and the joint motions' (not the dynamics')
  std::vector<int> hydro_joints_;
  std::vector<JointMotion> motion_;  // per joint id (only hydro joints filled)
  std::vector<Matrix6x> dw_dq_, dw_dv_;
  ForceVector fext_;
  std::vector<WrenchSensitivity> sensitivity_;  // per joint id (hydro joints)
  Matrix6x work_;  // M_A J of the mass matrix
  // joint_motions' world products of each joint k's columns, formed once a call (6 x nv):
  // v_p x S_k, v_p x S_k + dS_k and a_p x S_k + v_p x (v_p x S_k)
  Matrix6x world_velocity_dq_, world_acceleration_dv_, world_acceleration_dq_;
  bool free_surface_ = false;
  std::vector<char> cut_;                               // per hull: 0 < f < 1
  std::vector<Eigen::Matrix<double, 12, Eigen::Dynamic>> wetting_dq_;  // dx_i/dq per cut hull
  Eigen::VectorXd acceleration_;
  Eigen::MatrixXd did_dq_, did_dv_, mass_;
  Eigen::LLT<Eigen::MatrixXd> cholesky_;
  Eigen::MatrixXd inverse_factor_;  // L^-1 of the factor, on the way to M^-1
  ForwardDynamicsDerivatives out_;
};

}  // namespace uvms
