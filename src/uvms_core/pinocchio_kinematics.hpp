// Pinocchio's kinematics as the core calls them (the configuration space, the joints' and
// frames' placements and Jacobians): through the instantiations the `pin` wheel's
// libpinocchio_default already holds (PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION declares them
// `extern template`), never instantiated again in a unit of the core. The dynamics (RNEA, CRBA,
// their derivatives) are in pinocchio_dynamics.hpp. The PPC's computeFrameJacobian, which
// frames.hxx defines `inline` (GCC instantiates it wherever frames.hpp is included), is called
// from a unit of its own: pinocchio_frame_jacobian.hpp.
//
// Why: an algorithm called with argument types other than the library's (a VectorXd where it
// instantiated Ref<const VectorXd>, a block where it instantiated VectorXd) is compiled again
// from the headers, with its visitor over every joint type of the collection: about 30 s of
// compiler CPU for one `aba` call (measured: a unit with one call took 37.6 s with VectorXd
// arguments, 3.7 s with Ref ones). Each wrapper passes exactly the types of one
// `extern template` declaration of pinocchio/src/algorithm/*.hxx; the computation is the
// library's, the same code the Python bindings (`pin.integrate`, `pin.aba`) run.
//
// Two families of declared types: forwardKinematics and the joints' Jacobians take
// Ref<const VectorXd>, which binds a vector, a Ref or a contiguous segment without a copy; the
// configuration space (integrate, difference, their Jacobians, neutral, isNormalized) and the
// frames' Jacobians take plain VectorXd / MatrixXd / Matrix6xd: an argument of another type is
// copied into one first (an nq-sized copy, small beside the joint visitor it calls).
#pragma once

#include <Eigen/Core>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>

#include "types.hpp"

namespace uvms::pinlib {

using Model = pinocchio::Model;
using Data = pinocchio::Data;
using VectorRef = Eigen::Ref<const Eigen::VectorXd>;
using Matrix6x = pinocchio::Data::Matrix6x;
using Matrix6xRef = Eigen::Ref<Matrix6x>;

// ---- Ref<const VectorXd> arguments -------------------------------------------------------

inline void forward_kinematics(const Model& model, Data& data, const VectorRef& q) {
  pinocchio::forwardKinematics(model, data, q);
}

inline void forward_kinematics(const Model& model, Data& data, const VectorRef& q,
                               const VectorRef& v) {
  pinocchio::forwardKinematics(model, data, q, v);
}

inline void forward_kinematics(const Model& model, Data& data, const VectorRef& q,
                               const VectorRef& v, const VectorRef& a) {
  pinocchio::forwardKinematics(model, data, q, v, a);
}

inline void compute_joint_jacobians(const Model& model, Data& data, const VectorRef& q) {
  pinocchio::computeJointJacobians(model, data, q);
}

// the joints' Jacobians of the placements data already holds (after forward_kinematics)
inline void compute_joint_jacobians(const Model& model, Data& data) {
  pinocchio::computeJointJacobians(model, data);
}

inline void get_joint_jacobian(const Model& model, const Data& data, pinocchio::JointIndex joint,
                               pinocchio::ReferenceFrame frame, Matrix6xRef jacobian) {
  pinocchio::getJointJacobian(model, data, joint, frame, jacobian);
}

// ---- plain VectorXd / MatrixXd / Matrix6xd arguments --------------------------------------

inline void frames_forward_kinematics(const Model& model, Data& data, const Eigen::VectorXd& q) {
  pinocchio::framesForwardKinematics(model, data, q);
}

inline void get_frame_jacobian(const Model& model, Data& data, pinocchio::FrameIndex frame,
                               pinocchio::ReferenceFrame reference, Matrix6x& jacobian) {
  pinocchio::getFrameJacobian(model, data, frame, reference, jacobian);
}

// q_out = q (+) v
inline void integrate(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                      Eigen::VectorXd& q_out) {
  pinocchio::integrate(model, q, v, q_out);
}

inline Eigen::VectorXd integrated(const Model& model, const Eigen::VectorXd& q,
                                  const Eigen::VectorXd& v) {
  Eigen::VectorXd q_out(model.nq);
  pinocchio::integrate(model, q, v, q_out);
  return q_out;
}

// v_out = q1 (-) q0, the tangent vector that takes q0 to q1
inline void difference(const Model& model, const Eigen::VectorXd& q0, const Eigen::VectorXd& q1,
                       Eigen::VectorXd& v_out) {
  pinocchio::difference(model, q0, q1, v_out);
}

inline Eigen::VectorXd differenced(const Model& model, const Eigen::VectorXd& q0,
                                   const Eigen::VectorXd& q1) {
  Eigen::VectorXd v_out(model.nv);
  pinocchio::difference(model, q0, q1, v_out);
  return v_out;
}

inline void d_integrate(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                        Eigen::MatrixXd& jacobian, pinocchio::ArgumentPosition argument) {
  pinocchio::dIntegrate(model, q, v, jacobian, argument);
}

inline void d_difference(const Model& model, const Eigen::VectorXd& q0, const Eigen::VectorXd& q1,
                         Eigen::MatrixXd& jacobian, pinocchio::ArgumentPosition argument) {
  pinocchio::dDifference(model, q0, q1, jacobian, argument);
}

// J <- the transport of J by dIntegrate (in place), pinocchio::dIntegrateTransport's 4-argument
// form
inline void d_integrate_transport(const Model& model, const Eigen::VectorXd& q,
                                  const Eigen::VectorXd& v, Eigen::MatrixXd& jacobian,
                                  pinocchio::ArgumentPosition argument) {
  pinocchio::dIntegrateTransport(model, q, v, jacobian, argument);
}

inline void neutral(const Model& model, Eigen::VectorXd& q_out) {
  pinocchio::neutral(model, q_out);
}

inline Eigen::VectorXd neutral(const Model& model) { return pinocchio::neutral(model); }

inline bool is_normalized(const Model& model, const Eigen::VectorXd& q, double tolerance) {
  return pinocchio::isNormalized(model, q, tolerance);
}

// The largest |norm - 1| of a configuration's unit parts (a quaternion, a (cos, sin) pair)
// the bindings take: uvms_pin.physics.configuration.NORM_TOLERANCE (a test holds them equal)
constexpr double kNormTolerance = 1e-9;

// The bindings' check of a q they are given: on the configuration manifold (its unit parts'
// norms within `tolerance` of 1), else InputError in the words the Python side recognises
// (uvms_pin.physics.configuration.OFF_MANIFOLD) to name the joint. A quaternion of norm 0
// or 2 would give a rotation that is none, and M, h of it, silently.
inline void require_on_manifold(const Model& model, const Eigen::VectorXd& q,
                                double tolerance = kNormTolerance) {
  if (!is_normalized(model, q, tolerance)) {
    throw InputError("q is not on the configuration manifold");
  }
}

}  // namespace uvms::pinlib
