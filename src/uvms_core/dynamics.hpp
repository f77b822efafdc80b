// Underwater dynamics of a UVMS (mirror of uvms_pin/physics/reference.py):
//
//   M(q) zeta_dot + h(q, zeta) = tau + tau_ext
//   M = M_RB + sum_i J_i^T M_A,i J_i
//   h = C_RB zeta + g_RB - sum_i J_i^T [ -M_A,i (a_i - nu_c_dot,i) - C_A,i(nu_r,i) nu_r,i
//                                         - D_i(nu_r,i) nu_r,i + w_buoy,i ]
//
// Under a free surface (surface.cpp, mirror of uvms_pin/physics/surface.py) the volumes,
// centres of buoyancy and added masses are the wet ones and the damping is scaled by each
// body's wet fraction, when some body is not deep; otherwise nothing changes.
//
// Forward dynamics runs an articulated-body pass (articulated_body.cpp) in which each body's
// inertia is the generalized spatial inertia I_i + M_A,i: the added mass is exact and inside
// M, in O(n), after one kinematics pass. Models with a joint whose motion subspace depends on
// q (none in the shipped ones) use M by CRBA and h by RNEA, then a Cholesky solve.
//
// One object per model: the Pinocchio model (static) plus its work buffers (no allocation
// per call). Not thread-safe, like uvms.data.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>

#include "flow.hpp"
#include "hydro_bodies.hpp"

namespace uvms {

using Model = pinocchio::Model;
using Data = pinocchio::Data;
using ForceVector = pinocchio::container::aligned_vector<pinocchio::Force>;
// read-only vectors, passed without copies (and the types libpinocchio_default instantiates)
using ConstVec = Eigen::Ref<const Eigen::VectorXd>;

class Dynamics {
 public:
  Dynamics(Model model, HydroBodies hydro);
  Dynamics(const Dynamics& other);

  const Model& model() const { return model_; }
  int nq() const { return model_.nq; }
  int nv() const { return model_.nv; }

  // Kinematics at (q, zeta, zeta_dot = 0): placements, body velocities, bias accelerations.
  void kinematics(const ConstVec& q, const ConstVec& v);
  // After kinematics(): the wrench of the water on each joint body (LOCAL), all but M_A zeta_dot
  // (with_bias_acceleration: also -M_A a_bias, as h needs; the articulated pass does not).
  // free_surface: the bodies are cut by the surface of the flow (surface.cpp), and the added
  // masses that accelerations() and the mass matrix use are the wet ones until the next call.
  void fluid_wrenches(double time_s, const FlowField& flow, bool with_bias_acceleration,
                      bool free_surface = false);
  // After kinematics() and the wrenches: zeta_dot for tau (+ tau_ext), by the articulated
  // pass when the model allows it, else h, M and Cholesky.
  const Eigen::VectorXd& accelerations(const ConstVec& q, const ConstVec& v, const ConstVec& tau,
                                       const ConstVec* tau_ext);
  // Whether fluid_wrenches must include -M_A a_bias before accelerations().
  bool needs_bias_acceleration() const { return !articulated_; }
  // After fluid_wrenches(): add a wrench given at a world point in world axes to joint j.
  void add_world_wrench(int joint_id, const Vec3& point_world_m, const Vec6& wrench_world);
  // Add a wrench given in joint j's own frame (e.g. a body wrench on the vehicle).
  void add_local_wrench(int joint_id, const Vec6& wrench_local);
  // h(q, zeta) - sum_i J_i^T fext_i from the wrenches accumulated above.
  const Eigen::VectorXd& bias_from_wrenches(const ConstVec& q, const ConstVec& v);
  // M(q), symmetric, added mass included (every body wet).
  const Eigen::MatrixXd& mass_matrix(const ConstVec& q);
  // M(q) with the added masses scaled by the wet fractions under the flow's surface at time_s.
  const Eigen::MatrixXd& mass_matrix_in(const ConstVec& q, const FlowField& flow, double time_s,
                                        bool free_surface);
  // zeta_dot = M^-1 rhs, by Cholesky (throws SimulationFailure if M is not SPD).
  const Eigen::VectorXd& solve(const ConstVec& q, const ConstVec& rhs);

  // The public operations of uvms_pin.physics.dynamics.
  const Eigen::VectorXd& bias_forces(const ConstVec& q, const ConstVec& v,
                                     const FlowField& flow, double time_s = 0.0,
                                     bool free_surface = false);
  const Eigen::VectorXd& forward_dynamics(const ConstVec& q, const ConstVec& v,
                                          const ConstVec& tau, const FlowField& flow,
                                          const ConstVec* tau_ext, double time_s = 0.0,
                                          bool free_surface = false);

  Data& data() { return data_; }

 private:
  friend class Derivatives;  // derivatives.hpp: reads the model, hydro and work buffers
  void prepare();
  // M(q) with the added masses of the current wet state.
  const Eigen::MatrixXd& assemble_mass_matrix(const ConstVec& q);
  // surface.cpp: the wet state after kinematics() (wet_active_ false: every body deep, the
  // constant per-joint arrays apply), and the wrenches of the changing added mass.
  void check_surface_bodies() const;
  void update_wet_state(double time_s, const FlowField& flow, bool free_surface);
  void add_wet_fraction_wrenches();
  const Mat6& added_mass(int j) const {
    return wet_active_ ? wet_added_mass_[j] : hydro_.added_mass_per_joint[j];
  }
  double volume(int j) const {
    return wet_active_ ? wet_volume_[j] : hydro_.volume_per_joint_m3[j];
  }
  const Vec3& center_of_buoyancy(int j) const {
    return wet_active_ ? wet_cob_[j] : hydro_.center_of_buoyancy_per_joint_m[j];
  }
  double damping_fraction(const DampedBody& body) const {
    return wet_active_ && body.hull_index >= 0 ? fraction_[body.hull_index] : 1.0;
  }
  // articulated_body.cpp
  void prepare_articulated();
  void articulated_body_pass(const ConstVec& tau);
  void articulated_bodies();  // each body's own inertia and bias wrench
  void articulated_backward(int joint, const ConstVec& tau, Mat6& inertia_art, Vec6& bias_art);
  void articulated_forward(int joint, const Vec6& parent_acceleration);

  Model model_;
  Data data_;
  HydroBodies hydro_;
  std::vector<int> joints_with_added_mass_;
  std::vector<int> joints_with_volume_;
  std::vector<int> support_width_;  // columns 0..w-1 hold joint j's support (a chain); -1: tree
  ForceVector fext_;
  Eigen::VectorXd zero_, h_, rhs_, acceleration_;
  Eigen::MatrixXd mass_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> jacobian_, added_times_jacobian_;
  Eigen::LLT<Eigen::MatrixXd> cholesky_;

  // the free surface (surface.cpp): per joint, the wet volume, centre of buoyancy and added
  // mass (valid while wet_active_), and per hull its wet fraction, gradient and rate
  bool wet_active_ = false;
  std::vector<double> wet_volume_;
  aligned_vector<Vec3> wet_cob_;
  aligned_vector<Mat6> wet_added_mass_;
  std::vector<char> wet_touched_;  // joints with a hull not deep
  std::vector<char> deep_, dry_;
  std::vector<SurfaceAt> surface_;  // over each hull the bound check leaves undecided
  std::vector<int> cut_;           // hulls the surface cuts
  std::vector<double> fraction_, fraction_rate_, hull_volume_;
  aligned_vector<Vec6> fraction_gradient_;
  aligned_vector<Vec3> hull_moment_;
  aligned_vector<Vec6> relative_velocity_;  // nu_r per joint, for the wet-fraction wrenches

  // articulated-body pass (articulated_body.cpp). Each joint's motion subspace S is constant
  // in its frame; the pass is specialised by its kind: a free-flyer (S = I, 6x6 LLT), a
  // one-DoF joint (S a 6-vector: scalar D, rank-one update) or any other (n <= 6, generic).
  enum class JointKind { kFree, kOneDof, kGeneric };
  using Subspace = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
  bool articulated_ = false;
  std::vector<JointKind> kind_;
  aligned_vector<Mat6> body_inertia_;  // I_i + M_A,i in joint i's frame (constant)
  aligned_vector<Mat6> inertia_a_;     // articulated inertia I^A_i
  aligned_vector<Vec6> bias_a_, bias_acc_, acc_;
  // one-DoF joints: S, U = I^A S, 1 / D, u = tau - S^T p^A
  aligned_vector<Vec6> axis_, u_axis_;
  std::vector<double> d_inv_, u_scalar_;
  // free-flyers: D = I^A (+ armature) factored, u = tau - p^A
  std::vector<Eigen::LLT<Mat6>, Eigen::aligned_allocator<Eigen::LLT<Mat6>>> d_free_;
  aligned_vector<Vec6> u_free_;
  // other joints
  std::vector<Subspace, Eigen::aligned_allocator<Subspace>> subspace_, u_mat_, u_dinv_;
  std::vector<Small, Eigen::aligned_allocator<Small>> dinv_;
  std::vector<SmallVec, Eigen::aligned_allocator<SmallVec>> u_vec_;
};

// Model from the text archive of Python's pin.Model.saveToString() (model_io.cpp).
Model model_from_text(const std::string& text);

}  // namespace uvms
