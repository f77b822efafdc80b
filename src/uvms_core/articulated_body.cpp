// Forward dynamics by the articulated-body algorithm with generalized spatial inertias.
//
// Each body's inertia is I_i + M_A,i (6x6, symmetric positive definite): the added mass is a
// generalized spatial inertia, so Featherstone's recursion carries it exactly, in O(n), with
// the body bias wrench
//   p_i = v_i x* (I_i v_i) - I_i g_i - w_i,
// where g_i is gravity in body axes (gravity acts on the rigid mass only, hence not through
// the root acceleration) and w_i the fluid, contact and disturbance wrenches without the
// -M_A a_i part (fluid_wrenches(..., with_bias_acceleration = false)). The joint's armature
// adds to D = S^T I^A S, as it adds to the diagonal of M. Joint motion subspaces are constant
// in the joint frame for the joint types accepted here.
//
// Per joint, backward (child to parent), with c_i the velocity-product acceleration:
//   U = I^A S,  D = S^T U (+ armature),  u = tau_i - S^T p^A
//   I^a = I^A - U D^-1 U^T,  p^a = p^A + I^a c_i + U D^-1 u       (handed to the parent)
// and forward (root to leaves, root acceleration 0: gravity is in the biases):
//   a' = X_i a_parent + c_i,  qdd_i = D^-1 (u - U^T a'),  a_i = a' + S qdd_i.
// The pass is written out for the two kinds of joint a UVMS is made of: the vehicle's
// free-flyer (S = identity: U = I^A, D factored by a 6x6 Cholesky) and one-DoF joints
// (S a 6-vector: D scalar, I^a a rank-one update); any other constant-subspace joint
// (spherical, translation) takes the generic route with small dynamic matrices.
#include <set>
#include <string>

#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include "dynamics.hpp"
#include "pinocchio_kinematics.hpp"

namespace uvms {

namespace {

// parent += X* child X*^T for the child-to-parent force transform X* = [R 0; [t]x R  R] of
// the placement (R, t) of the child in the parent, on 3x3 blocks (child symmetric):
//   [A B; B^T C] -> [Ar, Br - Ar P; P Ar + Br^T, Cr + P Br + (P Br)^T - P Ar P],
// with Ar = R A R^T (likewise Br, Cr) and P = [t]x.
void add_transformed_inertia(const pinocchio::SE3& placement, const Mat6& child,
                             Mat6& parent) {
  const Mat3& r = placement.rotation();
  const Mat3 p = skew(placement.translation());
  const Mat3 ar = r * child.topLeftCorner<3, 3>() * r.transpose();
  const Mat3 br = r * child.topRightCorner<3, 3>() * r.transpose();
  const Mat3 cr = r * child.bottomRightCorner<3, 3>() * r.transpose();
  const Mat3 p_ar = p * ar;
  const Mat3 p_br = p * br;
  const Mat3 lower_left = p_ar + br.transpose();
  parent.topLeftCorner<3, 3>() += ar;
  parent.bottomLeftCorner<3, 3>() += lower_left;
  parent.topRightCorner<3, 3>() += lower_left.transpose();
  parent.bottomRightCorner<3, 3>() += cr + p_br + p_br.transpose() - p_ar * p;
}

// parent += X* child (the force transform of the same placement).
void add_transformed_wrench(const pinocchio::SE3& placement, const Vec6& child, Vec6& parent) {
  const Vec3 force = placement.rotation() * child.head<3>();
  parent.head<3>() += force;
  parent.tail<3>() += placement.rotation() * child.tail<3>() + placement.translation().cross(force);
}

}  // namespace

void Dynamics::prepare_articulated() {
  static const std::set<std::string> constant_subspace = {
      "JointModelFreeFlyer",    "JointModelRX",         "JointModelRY",
      "JointModelRZ",           "JointModelRUBX",       "JointModelRUBY",
      "JointModelRUBZ",         "JointModelPX",         "JointModelPY",
      "JointModelPZ",           "JointModelSpherical",  "JointModelTranslation",
      "JointModelRevoluteUnaligned", "JointModelRevoluteUnboundedUnaligned",
      "JointModelPrismaticUnaligned"};
  const int nj = model_.njoints;
  articulated_ = true;
  for (int j = 1; j < nj; ++j) {
    if (constant_subspace.count(model_.joints[j].shortname()) == 0) articulated_ = false;
  }
  if (!articulated_) return;
  Data scratch(model_);
  Eigen::VectorXd q(model_.nq);
  pinlib::neutral(model_, q);
  pinlib::forward_kinematics(model_, scratch, ConstVec(q));
  kind_.assign(nj, JointKind::kGeneric);
  body_inertia_.assign(nj, Mat6::Zero());
  inertia_a_.assign(nj, Mat6::Zero());
  bias_a_.assign(nj, Vec6::Zero());
  bias_acc_.assign(nj, Vec6::Zero());
  acc_.assign(nj, Vec6::Zero());
  axis_.assign(nj, Vec6::Zero());
  u_axis_.assign(nj, Vec6::Zero());
  d_inv_.assign(nj, 0.0);
  u_scalar_.assign(nj, 0.0);
  d_free_.assign(nj, Eigen::LLT<Mat6>());
  u_free_.assign(nj, Vec6::Zero());
  subspace_.assign(nj, Subspace(6, 0));
  u_mat_.assign(nj, Subspace(6, 0));
  u_dinv_.assign(nj, Subspace(6, 0));
  dinv_.assign(nj, Small(0, 0));
  u_vec_.assign(nj, SmallVec(0));
  for (int j = 1; j < nj; ++j) {
    const int n = model_.joints[j].nv();
    body_inertia_[j] = model_.inertias[j].matrix() + hydro_.added_mass_per_joint[j];
    const Subspace s = scratch.joints[j].S().matrix();
    if (model_.joints[j].shortname() == "JointModelFreeFlyer") {
      kind_[j] = JointKind::kFree;
    } else if (n == 1) {
      kind_[j] = JointKind::kOneDof;
      axis_[j] = s.col(0);
    } else {
      subspace_[j] = s;
      u_mat_[j].resize(6, n);
      u_dinv_[j].resize(6, n);
      dinv_[j].resize(n, n);
      u_vec_[j].resize(n);
    }
  }
}

void Dynamics::articulated_bodies() {
  for (int i = 1; i < model_.njoints; ++i) {
    const auto& inertia = model_.inertias[i];
    const pinocchio::Motion& velocity = data_.v[i];
    const pinocchio::Motion gravity_local = data_.oMi[i].actInv(model_.gravity);
    // under a free surface, the body's wet added mass
    inertia_a_[i] = wet_active_ && wet_touched_[i]
                        ? Mat6(model_.inertias[i].matrix() + wet_added_mass_[i])
                        : body_inertia_[i];
    bias_a_[i] = velocity.cross(inertia * velocity).toVector() -
                 (inertia * gravity_local).toVector() - fext_[i].toVector();
    // velocity-product acceleration of joint i: a_bias,i - X_i a_bias,parent
    bias_acc_[i] = data_.a[i].toVector() -
                   data_.liMi[i].actInv(data_.a[model_.parents[i]]).toVector();
  }
}

void Dynamics::articulated_backward(int i, const ConstVec& tau, Mat6& inertia_art,
                                    Vec6& bias_art) {
  const int idx = model_.joints[i].idx_v(), n = model_.joints[i].nv();
  const Mat6& inertia = inertia_a_[i];
  switch (kind_[i]) {
    case JointKind::kOneDof: {
      const Vec6& s = axis_[i];
      u_axis_[i].noalias() = inertia * s;
      const double d = s.dot(u_axis_[i]) + model_.armature[idx];  // rotor inertia of the drive
      d_inv_[i] = 1.0 / d;
      u_scalar_[i] = tau[idx] - s.dot(bias_a_[i]);
      inertia_art = inertia;
      inertia_art.noalias() -= (d_inv_[i] * u_axis_[i]) * u_axis_[i].transpose();
      bias_art = bias_a_[i] + inertia_art * bias_acc_[i] + (d_inv_[i] * u_scalar_[i]) * u_axis_[i];
      return;
    }
    case JointKind::kFree: {
      Mat6 d = inertia;
      d.diagonal() += model_.armature.segment<6>(idx);
      d_free_[i].compute(d);
      if (d_free_[i].info() != Eigen::Success) {
        throw SimulationFailure("articulated-body inertia is not positive definite");
      }
      u_free_[i] = tau.segment<6>(idx) - bias_a_[i];
      if (model_.parents[i] == 0) return;  // nothing to hand on
      inertia_art = inertia;
      inertia_art.noalias() -= inertia * d_free_[i].solve(inertia);
      bias_art = bias_a_[i] + inertia_art * bias_acc_[i] + inertia * d_free_[i].solve(u_free_[i]);
      return;
    }
    case JointKind::kGeneric: {
      const auto& s = subspace_[i];
      u_mat_[i].noalias() = inertia * s;
      Small d = s.transpose() * u_mat_[i];
      d.diagonal() += model_.armature.segment(idx, n);
      dinv_[i] = d.inverse();
      u_vec_[i] = tau.segment(idx, n) - s.transpose() * bias_a_[i];
      u_dinv_[i].noalias() = u_mat_[i] * dinv_[i];
      inertia_art = inertia - u_dinv_[i] * u_mat_[i].transpose();
      bias_art = bias_a_[i] + inertia_art * bias_acc_[i] + u_dinv_[i] * u_vec_[i];
      return;
    }
  }
}

void Dynamics::articulated_forward(int i, const Vec6& a_parent) {
  const int idx = model_.joints[i].idx_v(), n = model_.joints[i].nv();
  switch (kind_[i]) {
    case JointKind::kOneDof: {
      const double qdd = d_inv_[i] * (u_scalar_[i] - u_axis_[i].dot(a_parent));
      acceleration_[idx] = qdd;
      acc_[i] = a_parent + qdd * axis_[i];
      return;
    }
    case JointKind::kFree: {
      const Vec6 qdd = d_free_[i].solve(u_free_[i] - inertia_a_[i] * a_parent);
      acceleration_.segment<6>(idx) = qdd;
      acc_[i] = a_parent + qdd;
      return;
    }
    case JointKind::kGeneric: {
      acceleration_.segment(idx, n).noalias() =
          dinv_[i] * (u_vec_[i] - u_mat_[i].transpose() * a_parent);
      acc_[i] = a_parent + subspace_[i] * acceleration_.segment(idx, n);
      return;
    }
  }
}

void Dynamics::articulated_body_pass(const ConstVec& tau) {
  const int nj = model_.njoints;
  articulated_bodies();
  Mat6 inertia_art;
  Vec6 bias_art;
  for (int i = nj - 1; i > 0; --i) {
    articulated_backward(i, tau, inertia_art, bias_art);
    const int parent = model_.parents[i];
    if (parent == 0) continue;
    add_transformed_inertia(data_.liMi[i], inertia_art, inertia_a_[parent]);
    add_transformed_wrench(data_.liMi[i], bias_art, bias_a_[parent]);
  }
  acc_[0].setZero();
  for (int i = 1; i < nj; ++i) {
    const Vec6 a_parent =
        data_.liMi[i].actInv(pinocchio::Motion(acc_[model_.parents[i]])).toVector() +
        bias_acc_[i];
    articulated_forward(i, a_parent);
  }
  if (acceleration_.allFinite()) return;
  // bias forces that left the floating-point range (the squares of speeds of 1e200, in the
  // damping and the Coriolis terms) make the acceleration non-finite with every inertia
  // sound: returned as it is, for the caller to name (the public call names the fastest
  // speed, a loop the divergence); otherwise an inertia could not be factored
  for (int i = 1; i < nj; ++i) {
    if (!bias_a_[i].allFinite()) return;
  }
  throw SimulationFailure("articulated-body inertia is not positive definite");
}

}  // namespace uvms
