// The end-effector's compliant contact as a generalized force of the state, and its
// derivatives along the tangent (mirror of uvms_pin/physics/derivatives/task_contact.py).
//
// The environment's model (contact.hpp) gives lambda = [f; n] (N; N m), the wrench the
// end-effector exerts ON it at the end-effector frame's origin p, world-aligned axes, as a
// function of p and of its world velocity p_dot. The robot receives
//
//   tau_ext(q, v) = -J(q)^T lambda(p(q), p_dot(q, v))          (J: LOCAL_WORLD_ALIGNED, 6 x nv)
//
// Along the tangent (q (+) dq, v + dv), with J_p = J[:3] (dp = J_p dq, p_dot = J_p v):
//
//   d lambda/dq = L_p J_p + L_pdot d(p_dot)/dq,     d lambda/dv = L_pdot J_p
//   d tau_ext/dq = -d(J^T lambda)/dq |_(lambda fixed) - J^T d lambda/dq
//   d tau_ext/dv = -J^T d lambda/dv
//
// (L_p = d lambda/dp, L_pdot = d lambda/dp_dot (6 x 3): wrench_jacobians, one function per
// contact model.) p_dot = R nu_v with nu the frame's LOCAL velocity, R world <- frame:
//
//   d(p_dot)/dq = R (d nu_v/dq - [nu_v]x J_w^local)
//
// (d nu/dq: Pinocchio's getFrameVelocityDerivatives in LOCAL.) With lambda fixed,
// J^T lambda = J_W^T F, J_W the WORLD Jacobian and F = [f; n + p x f] the wrench about the
// world origin; a column J_k of J_W moves with q only through the joints before it,
// d J_k/dq_m = J_m x J_k (m precedes-or-equals k: supports_mask), so
//
//   d(J_W^T F)/dq [k, m] = -J_k . (J_m x* F)   (projection_dq)
//   and F moves with p:   d(J_W^T F)/dq += J_W^T [0; -[f]x J_p]
//
// LinearSpring: L_p = diag(K), L_pdot = 0. CompliantPlane: inside and pushing, L_p = k n n^T,
// L_pdot = c n n^T; outside or pulling 0 (at the kink, the side where the contact is lost).
// NoContact: all zero.
//
// Unlike the Python functions (which return fresh arrays) TaskContactDerivatives keeps its
// Pinocchio data, its work buffers and its results (read by reference): no allocation per
// call (not thread-safe).
#pragma once

#include "contact.hpp"
#include "derivatives.hpp"

namespace uvms {

using Mat63 = Eigen::Matrix<double, 6, 3>;

// (d lambda/dp, d lambda/dp_dot) (6, 3) of a contact model at (p, p_dot).
struct WrenchJacobians {
  Mat63 by_position = Mat63::Zero();  // [N/m]
  Mat63 by_velocity = Mat63::Zero();  // [N s/m]
};

// f = K (p - p_0): (diag(K), 0).
WrenchJacobians spring_jacobians(const LinearSpring& spring, const Vec3& position_world_m,
                                 const Vec3& velocity_world_m_s);
// f = -n max(0, k d + c d_dot), d = (p_s - p) . n: (k n n^T, c n n^T) while the surface
// pushes, zero otherwise.
WrenchJacobians plane_jacobians(const CompliantPlane& plane, const Vec3& position_world_m,
                                const Vec3& velocity_world_m_s);
// The contact model's (NoContact: zero).
WrenchJacobians wrench_jacobians(const Contact& contact, const Vec3& position_world_m,
                                 const Vec3& velocity_world_m_s);

// (nv, nv) of 0 and 1: [k, m] = 1 when velocity m's joint is velocity k's joint or one of its
// ancestors (where d J_k/dq_m = J_m x J_k can be non-zero).
Eigen::MatrixXd supports_mask(const Model& model);

// Adds d(J_W^T F)/dq (nv, nv) to out, F = [f; n] (6) a fixed wrench about the world origin
// (world axes): [k, m] = -J_k . (J_m x* F) where mask [k, m] (supports_mask); minus_dual: a
// (6, nv) work buffer, out: (nv, nv), product: (nv, nv) work buffer.
void projection_dq(const Matrix6x& jacobian_world, const Vec6& wrench_world_origin,
                   const Eigen::MatrixXd& mask, Matrix6x& minus_dual, Eigen::MatrixXd& product,
                   Eigen::MatrixXd& out);

// One object per (model, frame): contact_derivatives() at a state (the ContactWrench and
// ContactJacobians of the Python file as its accessors).
class TaskContactDerivatives {
 public:
  TaskContactDerivatives(const Model& model, pinocchio::FrameIndex frame_id);

  // The contact's tau_ext at (q, v) and its derivatives, q along the tangent, into the
  // accessors below (``contact`` at the frame; NoContact: zeros).
  void contact_derivatives(const Model& model, const Contact& contact, const ConstVec& q,
                           const ConstVec& v);

  // of the last contact_derivatives call: tau_ext = -J^T lambda (nv) [N, N m], lambda (6),
  // d lambda/dq and d lambda/dv (6, nv), d tau_ext/dq and d tau_ext/dv (nv, nv)
  const Eigen::VectorXd& generalized_force() const { return tau_ext_; }
  const Vec6& wrench_world() const { return wrench_; }
  const Matrix6x& wrench_dq() const { return wrench_dq_; }
  const Matrix6x& wrench_dv() const { return wrench_dv_; }
  const Eigen::MatrixXd& tau_dq() const { return tau_dq_; }
  const Eigen::MatrixXd& tau_dv() const { return tau_dv_; }

 private:
  pinocchio::FrameIndex frame_id_;
  Data data_;
  Eigen::MatrixXd mask_;  // supports_mask of the model
  Eigen::VectorXd zero_, tau_ext_;
  Vec6 wrench_ = Vec6::Zero();
  Matrix6x local_dq_, local_jacobian_, jacobian_lwa_, jacobian_world_, minus_dual_;
  Matrix6x wrench_dq_, wrench_dv_;
  Matrix3x velocity_dq_, arm_dq_;
  Eigen::MatrixXd tau_dq_, tau_dv_, product_;
};

}  // namespace uvms
