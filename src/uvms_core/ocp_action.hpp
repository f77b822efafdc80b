// The UVMS in water as a crocoddyl differential action model (mirror of
// uvms_pin/ocp/model.py, UnderwaterActionModel).
//
// State x = (q, v) (ocp_state.hpp), control u, tau = B_u u. calc: xout = a(q, v, B_u u) of the
// core's forward dynamics (dynamics.hpp) in the node's flow at its time, with the
// end-effector's compliant contact tau_ext(q, v) = -J^T lambda when the problem has one, and
// the cost l = (1/2) sum_i r_i^T W_i r_i (ocp_costs.hpp). calcDiff:
//
//     Fx = [da/dq, da/dv] + M^-1 [d tau_ext/dq, d tau_ext/dv],   Fu = M^-1 B_u
//
// (derivatives.hpp, derivatives_task_contact.hpp; da/dtau = M^-1) and the Gauss-Newton cost
// derivatives l_x = R_x^T W r, l_xx = R_x^T W R_x (likewise u, xu).
//
// The nodes of one problem share one OcpWorkspace (the dynamics, their derivatives, the
// contact's and a Pinocchio data): crocoddyl calls them one after the other (the planner
// sets its problem to one thread: the wheel's libcrocoddyl is built with OpenMP, and nodes
// run on several threads would need a workspace per thread), each call computes from its
// own (x, u) and writes only its node's data. What a node raises (a singular M, a non-finite acceleration) cannot cross
// crocoddyl's loop: the node's cost is set to kRejectedCost, its other outputs to zero, and
// the first message is held in the workspace for the planner to raise after the solve (as
// uvms_pin.ocp.held_errors).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <crocoddyl/core/diff-action-base.hpp>

#include "contact.hpp"
#include "derivatives_task_contact.hpp"
#include "ocp_costs.hpp"
#include "ocp_state.hpp"

namespace uvms {

// The cost of a node that raised: finite, so that no step through it is accepted.
constexpr double kRejectedCost = 1e30;

struct OcpWorkspace {
  OcpWorkspace(const Dynamics& dynamics, std::optional<int> contact_frame);

  Dynamics dynamics;
  Derivatives derivatives;
  std::optional<TaskContactDerivatives> contact_derivatives;  // with a contact only
  std::optional<int> contact_frame;
  Contact contact;  // the environment, placed by the planner (set_contact)
  Data data;        // the costs' kinematics
  Matrix6x jacobian_lwa;
  Eigen::VectorXd q, v, tau, tau_ext;  // a node's state split, its generalized forces
  TermWork term_work;                  // the cost terms' Jacobian buffers
  std::string held;  // the first failure of a node since the last take()
};

class UnderwaterActionModel : public crocoddyl::DifferentialActionModelAbstractTpl<double> {
 public:
  using Base = crocoddyl::DifferentialActionModelAbstractTpl<double>;
  using DataBase = crocoddyl::DifferentialActionDataAbstractTpl<double>;

  // input_matrix: B_u (nv, nu); flow and time_s: the node's water; bounds: (lower, upper) or
  // none (empty vectors).
  UnderwaterActionModel(std::shared_ptr<UvmsState> state, std::shared_ptr<OcpWorkspace> work,
                        std::vector<OcpTerm> terms, Eigen::MatrixXd input_matrix,
                        FlowField flow, double time_s, const Eigen::VectorXd& lower,
                        const Eigen::VectorXd& upper);

  void calc(const std::shared_ptr<DataBase>& data, const Eigen::Ref<const Eigen::VectorXd>& x,
            const Eigen::Ref<const Eigen::VectorXd>& u) override;
  void calcDiff(const std::shared_ptr<DataBase>& data,
                const Eigen::Ref<const Eigen::VectorXd>& x,
                const Eigen::Ref<const Eigen::VectorXd>& u) override;
  std::shared_ptr<DataBase> createData() override;

  std::vector<OcpTerm>& terms() { return terms_; }

  // crocoddyl's scalar casts: a copy for double (the same workspace); no float model
  std::shared_ptr<crocoddyl::DifferentialActionModelBase> cloneAsDouble() const override {
    return std::make_shared<UnderwaterActionModel>(*this);
  }
  std::shared_ptr<crocoddyl::DifferentialActionModelBase> cloneAsFloat() const override {
    throw InputError("the UVMS action model has no float version");
  }

 private:
  void calc_or_throw(DataBase& data, const Eigen::VectorXd& x, const Eigen::VectorXd& u);
  void calc_diff_or_throw(DataBase& data, const Eigen::VectorXd& x, const Eigen::VectorXd& u);
  // the contact's wrench and tau_ext at (q, v), and the costs' kinematics (frames at q)
  void contact_and_frames(const Eigen::VectorXd& q, const Eigen::VectorXd& v);
  void residuals(DataBase& data, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                 const TermState& at);
  void hold(DataBase& data, const std::string& where, const std::string& message, bool diff);

  std::shared_ptr<OcpWorkspace> work_;
  std::vector<OcpTerm> terms_;
  Eigen::MatrixXd input_matrix_;
  FlowField flow_;
  double time_s_;
  Eigen::VectorXd weights_;  // of every residual row, in the terms' order
  Eigen::MatrixXd stacked_, weighted_;  // [R_x R_u] of the terms, W times it
  Vec6 wrench_ = Vec6::Zero();
};

}  // namespace uvms
