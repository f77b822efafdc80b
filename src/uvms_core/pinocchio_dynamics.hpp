// Pinocchio's dynamics as the core calls them (RNEA, CRBA, the kinematics' and RNEA's
// derivatives): through the library's own instantiations, as pinocchio_kinematics.hpp says.
// They take Ref<const VectorXd> inputs and Ref<MatrixXd> / Ref<Matrix6xd> outputs (the frames'
// velocity derivatives plain Matrix6xd), the types of their `extern template` declarations.
#pragma once

#include <vector>

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames-derivatives.hpp>
#include <pinocchio/algorithm/kinematics-derivatives.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms::pinlib {

using MatrixRef = Eigen::Ref<Eigen::MatrixXd>;

// tau = RNEA(q, v, a) with the external forces fext (in each joint's frame), into data.tau
inline const Eigen::VectorXd& rnea(const Model& model, Data& data, const VectorRef& q,
                                   const VectorRef& v, const VectorRef& a,
                                   const std::vector<pinocchio::Force>& fext) {
  return pinocchio::rnea(model, data, q, v, a, fext);
}

inline const Eigen::MatrixXd& crba(const Model& model, Data& data, const VectorRef& q,
                                   pinocchio::Convention convention) {
  return pinocchio::crba(model, data, q, convention);
}

inline void compute_forward_kinematics_derivatives(const Model& model, Data& data,
                                                   const VectorRef& q, const VectorRef& v,
                                                   const VectorRef& a) {
  pinocchio::computeForwardKinematicsDerivatives(model, data, q, v, a);
}

inline void get_joint_velocity_derivatives(const Model& model, const Data& data,
                                           pinocchio::JointIndex joint,
                                           pinocchio::ReferenceFrame frame,
                                           Matrix6xRef velocity_dq, Matrix6xRef velocity_dv) {
  pinocchio::getJointVelocityDerivatives(model, data, joint, frame, velocity_dq, velocity_dv);
}

// d tau / d(q, v, a) of RNEA, the external forces fext held fixed
inline void compute_rnea_derivatives(const Model& model, Data& data, const VectorRef& q,
                                     const VectorRef& v, const VectorRef& a,
                                     const std::vector<pinocchio::Force>& fext,
                                     MatrixRef rnea_dq, MatrixRef rnea_dv, MatrixRef rnea_da) {
  pinocchio::computeRNEADerivatives(model, data, q, v, a, fext, rnea_dq, rnea_dv, rnea_da);
}

inline void compute_generalized_gravity_derivatives(const Model& model, Data& data,
                                                    const VectorRef& q, MatrixRef gravity_dq) {
  pinocchio::computeGeneralizedGravityDerivatives(model, data, q, gravity_dq);
}

// (the frame's velocity derivatives: plain Matrix6xd, as declared)
inline void get_frame_velocity_derivatives(const Model& model, Data& data,
                                           pinocchio::FrameIndex frame,
                                           pinocchio::ReferenceFrame reference,
                                           Matrix6x& velocity_dq, Matrix6x& velocity_dv) {
  pinocchio::getFrameVelocityDerivatives(model, data, frame, reference, velocity_dq, velocity_dv);
}

}  // namespace uvms::pinlib
