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
#include <set>
#include <string>

#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include "dynamics.hpp"

namespace uvms {

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
  pinocchio::neutral(model_, q);
  pinocchio::forwardKinematics(model_, scratch, ConstVec(q));
  subspace_.assign(nj, Subspace(6, 0));
  u_mat_.assign(nj, Subspace(6, 0));
  u_dinv_.assign(nj, Subspace(6, 0));
  dinv_.assign(nj, Small(0, 0));
  u_vec_.assign(nj, Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>(0));
  inertia_a_.assign(nj, Mat6::Zero());
  bias_a_.assign(nj, Vec6::Zero());
  bias_acc_.assign(nj, Vec6::Zero());
  acc_.assign(nj, Vec6::Zero());
  for (int j = 1; j < nj; ++j) {
    const int n = model_.joints[j].nv();
    subspace_[j] = scratch.joints[j].S().matrix();
    u_mat_[j].resize(6, n);
    u_dinv_[j].resize(6, n);
    dinv_[j].resize(n, n);
    u_vec_[j].resize(n);
  }
}

void Dynamics::articulated_body_pass(const ConstVec& tau) {
  const int nj = model_.njoints;
  // bodies: articulated inertia and bias wrench start as the body's own
  for (int i = 1; i < nj; ++i) {
    const auto& inertia = model_.inertias[i];
    const pinocchio::Motion& velocity = data_.v[i];
    const pinocchio::Motion gravity_local = data_.oMi[i].actInv(model_.gravity);
    inertia_a_[i] = inertia.matrix() + hydro_.added_mass_per_joint[i];
    bias_a_[i] = velocity.cross(inertia * velocity).toVector() -
                 (inertia * gravity_local).toVector() - fext_[i].toVector();
    // velocity-product acceleration of joint i: a_bias,i - X_i a_bias,parent
    bias_acc_[i] = data_.a[i].toVector() -
                   data_.liMi[i].actInv(data_.a[model_.parents[i]]).toVector();
  }
  // backward: articulated inertias and bias wrenches, child to parent
  for (int i = nj - 1; i > 0; --i) {
    const auto& s = subspace_[i];
    const int idx = model_.joints[i].idx_v(), n = model_.joints[i].nv();
    u_mat_[i].noalias() = inertia_a_[i] * s;
    Small d = s.transpose() * u_mat_[i];
    d.diagonal() += model_.armature.segment(idx, n);  // rotor inertia of the drive
    dinv_[i] = d.inverse();
    u_vec_[i] = tau.segment(idx, n) - s.transpose() * bias_a_[i];
    u_dinv_[i].noalias() = u_mat_[i] * dinv_[i];
    const int parent = model_.parents[i];
    if (parent == 0) continue;
    const Mat6 inertia_art = inertia_a_[i] - u_dinv_[i] * u_mat_[i].transpose();
    const Vec6 bias_art = bias_a_[i] + inertia_art * bias_acc_[i] + u_dinv_[i] * u_vec_[i];
    const Mat6 to_parent = data_.liMi[i].toDualActionMatrix();  // forces child -> parent
    inertia_a_[parent].noalias() += to_parent * inertia_art * to_parent.transpose();
    bias_a_[parent].noalias() += to_parent * bias_art;
  }
  // forward: accelerations, root to leaves (root acceleration 0: gravity is in the biases)
  acc_[0].setZero();
  for (int i = 1; i < nj; ++i) {
    const int idx = model_.joints[i].idx_v(), n = model_.joints[i].nv();
    const Vec6 a_parent =
        data_.liMi[i].actInv(pinocchio::Motion(acc_[model_.parents[i]])).toVector() +
        bias_acc_[i];
    acceleration_.segment(idx, n).noalias() =
        dinv_[i] * (u_vec_[i] - u_mat_[i].transpose() * a_parent);
    acc_[i] = a_parent + subspace_[i] * acceleration_.segment(idx, n);
  }
  if (!acceleration_.allFinite()) {
    throw SimulationFailure("articulated-body inertia is not positive definite");
  }
}

}  // namespace uvms
