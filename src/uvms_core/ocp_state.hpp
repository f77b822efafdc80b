// The state manifold of a UVMS for crocoddyl (mirror of uvms_pin/ocp/state.py):
// x = (q, v), tangent dx = (dq, dv) (2 nv),
//   x (+) dx = (q (+) dq, v + dv),   x1 (-) x0 = (q1 (-) q0, v1 - v0)
// by Pinocchio's integrate / difference (a continuous joint's angle by atan2, as the Python),
// with their exact Jacobians [[dIntegrate or dDifference, 0], [0, +-I]] and the parallel
// transport crocoddyl's solvers use.
//
// Why not crocoddyl's StateMultibody: the libcrocoddyl 3.2.1 wheel was built against a
// Pinocchio whose Model / Data layout differs from pin 4.1's, so nothing of Pinocchio may cross
// into libcrocoddyl; this state (and the action model) computes with the core's Pinocchio and
// gives crocoddyl plain vectors and matrices only.
#pragma once

#include <vector>

#include <crocoddyl/core/state-base.hpp>

#include "dynamics.hpp"

namespace uvms {

class UvmsState : public crocoddyl::StateAbstractTpl<double> {
 public:
  using VectorXs = Eigen::VectorXd;
  using MatrixXs = Eigen::MatrixXd;

  explicit UvmsState(const Model& model);

  VectorXs zero() const override;
  // a state about the neutral one (crocoddyl's interface; seeded: the same every call)
  VectorXs rand() const override;
  void diff(const Eigen::Ref<const VectorXs>& x0, const Eigen::Ref<const VectorXs>& x1,
            Eigen::Ref<VectorXs> dxout) const override;
  void integrate(const Eigen::Ref<const VectorXs>& x, const Eigen::Ref<const VectorXs>& dx,
                 Eigen::Ref<VectorXs> xout) const override;
  void Jdiff(const Eigen::Ref<const VectorXs>& x0, const Eigen::Ref<const VectorXs>& x1,
             Eigen::Ref<MatrixXs> Jfirst, Eigen::Ref<MatrixXs> Jsecond,
             crocoddyl::Jcomponent firstsecond) const override;
  void Jintegrate(const Eigen::Ref<const VectorXs>& x, const Eigen::Ref<const VectorXs>& dx,
                  Eigen::Ref<MatrixXs> Jfirst, Eigen::Ref<MatrixXs> Jsecond,
                  crocoddyl::Jcomponent firstsecond, crocoddyl::AssignmentOp op) const override;
  void JintegrateTransport(const Eigen::Ref<const VectorXs>& x,
                           const Eigen::Ref<const VectorXs>& dx, Eigen::Ref<MatrixXs> Jin,
                           crocoddyl::Jcomponent firstsecond) const override;

  const Model& model() const { return model_; }

  // crocoddyl's scalar casts: a copy for double; no float model (the core is double only)
  std::shared_ptr<crocoddyl::StateBase> cloneAsDouble() const override {
    return std::make_shared<UvmsState>(*this);
  }
  std::shared_ptr<crocoddyl::StateBase> cloneAsFloat() const override {
    throw InputError("the UVMS state has no float version");
  }

 private:
  // J = [[jq, 0], [0, sign I]] set, added or removed (op) into out
  void block(const MatrixXs& jq, double sign, Eigen::Ref<MatrixXs> out,
             crocoddyl::AssignmentOp op) const;

  Model model_;
  std::vector<int> circle_q_, circle_v_;  // continuous joints: their q (cos) and v indices
  mutable MatrixXs jq_;                   // work buffer (nv, nv)
  // the configurations and tangents of a call as the library's instantiations take them (plain
  // vectors: pinocchio_kinematics.hpp), kept so that a node's call allocates nothing
  mutable VectorXs q0_, q1_, dq_, q_out_, v_out_;
  mutable MatrixXs transported_;
};

}  // namespace uvms
