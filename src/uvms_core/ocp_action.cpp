// The UVMS in water as a crocoddyl differential action model (ocp_action.hpp).
#include "ocp_action.hpp"

#include <exception>

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms {

OcpWorkspace::OcpWorkspace(const Dynamics& dyn, std::optional<int> frame)
    : dynamics(dyn),
      derivatives(dyn),
      contact_frame(frame),
      contact(NoContact{}),
      data(dyn.model()),
      jacobian_lwa(Matrix6x::Zero(6, dyn.nv())),
      q(Eigen::VectorXd::Zero(dyn.nq())),
      v(Eigen::VectorXd::Zero(dyn.nv())),
      tau(Eigen::VectorXd::Zero(dyn.nv())),
      tau_ext(Eigen::VectorXd::Zero(dyn.nv())),
      term_work(dyn.nv()) {
  if (frame) contact_derivatives.emplace(dyn.model(), static_cast<pinocchio::FrameIndex>(*frame));
}

namespace {

int rows_of(const std::vector<OcpTerm>& terms, int nv) {
  int rows = 0;
  for (const auto& term : terms) rows += residual_size(term.kind, nv);
  return rows;
}

}  // namespace

UnderwaterActionModel::UnderwaterActionModel(std::shared_ptr<UvmsState> state,
                                             std::shared_ptr<OcpWorkspace> work,
                                             std::vector<OcpTerm> terms,
                                             Eigen::MatrixXd input_matrix, FlowField flow,
                                             double time_s, const Eigen::VectorXd& lower,
                                             const Eigen::VectorXd& upper)
    : Base(state, static_cast<std::size_t>(input_matrix.cols()),
           static_cast<std::size_t>(rows_of(terms, state->model().nv))),
      work_(std::move(work)),
      terms_(std::move(terms)),
      input_matrix_(std::move(input_matrix)),
      flow_(std::move(flow)),
      time_s_(time_s) {
  const int nv = state->model().nv;
  weights_.resize(static_cast<Eigen::Index>(nr_));
  int row = 0;
  for (const auto& term : terms_) {
    const int size = residual_size(term.kind, nv);
    if (term.weights.size() != size) {
      throw InputError("ocp cost term: " + std::to_string(size) + " weights needed, got " +
                       std::to_string(term.weights.size()));
    }
    if (std::holds_alternative<ContactForceCost>(term.kind) && !work_->contact_frame) {
      throw InputError("ocp: a contact-force cost needs a contact in the node's dynamics");
    }
    weights_.segment(row, size) = term.weights;
    row += size;
  }
  stacked_ = Eigen::MatrixXd::Zero(nr_, 2 * nv + nu_);
  weighted_ = stacked_;
  if (lower.size() > 0) {
    set_u_lb(lower);
    set_u_ub(upper);
  }
}

std::shared_ptr<UnderwaterActionModel::DataBase> UnderwaterActionModel::createData() {
  return std::allocate_shared<DataBase>(Eigen::aligned_allocator<DataBase>(), static_cast<Base*>(this));
}

void UnderwaterActionModel::contact_and_frames(const Eigen::VectorXd& q,
                                               const Eigen::VectorXd& v) {
  OcpWorkspace& w = *work_;
  const Model& model = w.dynamics.model();
  pinlib::forward_kinematics(model, w.data, q, v);
  pinocchio::updateFramePlacements(model, w.data);
  if (!w.contact_frame) return;
  // the end-effector's contact (task_contact.py _contact_in): lambda at (p, p_dot), and
  // tau_ext = -J^T lambda by the frame's Jacobian (the joints' at the placements above)
  pinlib::compute_joint_jacobians(model, w.data);
  const auto frame = static_cast<pinocchio::FrameIndex>(*w.contact_frame);
  const Vec3 position = w.data.oMf[frame].translation();
  const Vec3 velocity =
      pinocchio::getFrameVelocity(model, w.data, frame, pinocchio::LOCAL_WORLD_ALIGNED).linear();
  w.jacobian_lwa.setZero();
  pinlib::get_frame_jacobian(model, w.data, frame, pinocchio::LOCAL_WORLD_ALIGNED,
                              w.jacobian_lwa);
  wrench_ = contact_wrench_world(w.contact, position, velocity);
  w.tau_ext.noalias() = -w.jacobian_lwa.transpose() * wrench_;
}

void UnderwaterActionModel::residuals(DataBase& data, const Eigen::VectorXd& x,
                                      const Eigen::VectorXd& u, const TermState& at) {
  const int nv = state_->get_nv();
  int row = 0;
  for (const auto& term : terms_) {
    const int size = residual_size(term.kind, nv);
    term_residual(term.kind, at, x, u, data.r.segment(row, size));
    row += size;
  }
  data.cost = 0.5 * data.r.dot(weights_.cwiseProduct(data.r));
}

void UnderwaterActionModel::calc_or_throw(DataBase& data, const Eigen::VectorXd& x,
                                          const Eigen::VectorXd& u) {
  OcpWorkspace& w = *work_;
  const int nq = state_->get_nq(), nv = state_->get_nv();
  const Eigen::VectorXd& q = w.q = x.head(nq);
  const Eigen::VectorXd& v = w.v = x.tail(nv);
  contact_and_frames(q, v);
  w.tau.noalias() = input_matrix_ * u;
  const ConstVec ext(w.tau_ext);
  data.xout = w.dynamics.forward_dynamics(q, v, w.tau, flow_, w.contact_frame ? &ext : nullptr,
                                          time_s_);
  if (!data.xout.allFinite()) throw SimulationFailure("zeta_dot is not finite");
  const TermState at{w.dynamics.model(), w.data, w.term_work, &wrench_, nullptr, nullptr};
  residuals(data, x, u, at);
}

void UnderwaterActionModel::calc_diff_or_throw(DataBase& data, const Eigen::VectorXd& x,
                                               const Eigen::VectorXd& u) {
  OcpWorkspace& w = *work_;
  const int nq = state_->get_nq(), nv = state_->get_nv();
  const Eigen::VectorXd& q = w.q = x.head(nq);
  const Eigen::VectorXd& v = w.v = x.tail(nv);
  // the costs' frames and LOCAL Jacobians at q; the contact's own kinematics are its data's
  const Model& model = w.dynamics.model();
  pinlib::compute_joint_jacobians(model, w.data, q);
  pinocchio::updateFramePlacements(model, w.data);
  w.tau.noalias() = input_matrix_ * u;
  const Matrix6x* wrench_dq = nullptr;
  const Matrix6x* wrench_dv = nullptr;
  const ConstVec* ext = nullptr;
  std::optional<ConstVec> tau_ext;
  if (w.contact_derivatives) {
    w.contact_derivatives->contact_derivatives(model, w.contact, q, v);
    wrench_ = w.contact_derivatives->wrench_world();
    tau_ext.emplace(w.contact_derivatives->generalized_force());
    ext = &*tau_ext;
    wrench_dq = &w.contact_derivatives->wrench_dq();
    wrench_dv = &w.contact_derivatives->wrench_dv();
  }
  const ForwardDynamicsDerivatives& d =
      w.derivatives.forward_dynamics_derivatives(q, v, w.tau, flow_, ext, time_s_);
  data.Fx.leftCols(nv) = d.da_dq;
  data.Fx.rightCols(nv) = d.da_dv;
  if (w.contact_derivatives) {
    data.Fx.leftCols(nv).noalias() += d.da_dtau * w.contact_derivatives->tau_dq();
    data.Fx.rightCols(nv).noalias() += d.da_dtau * w.contact_derivatives->tau_dv();
  }
  data.Fu.noalias() = d.da_dtau * input_matrix_;
  // Gauss-Newton: the terms' rows stacked, R = [R_x R_u], l_x = R_x^T W r, l_xx = R_x^T W R_x
  const TermState at{w.dynamics.model(), w.data, w.term_work, &wrench_, wrench_dq, wrench_dv};
  residuals(data, x, u, at);
  int row = 0;
  for (const auto& term : terms_) {
    const int size = residual_size(term.kind, nv);
    term_jacobian(term.kind, at, x, u, stacked_.middleRows(row, size));
    row += size;
  }
  weighted_ = weights_.asDiagonal() * stacked_;
  const int ndx = 2 * nv;
  data.Lx.noalias() = weighted_.leftCols(ndx).transpose() * data.r;
  data.Lu.noalias() = weighted_.rightCols(nu_).transpose() * data.r;
  data.Lxx.noalias() = stacked_.leftCols(ndx).transpose() * weighted_.leftCols(ndx);
  data.Luu.noalias() = stacked_.rightCols(nu_).transpose() * weighted_.rightCols(nu_);
  data.Lxu.noalias() = stacked_.leftCols(ndx).transpose() * weighted_.rightCols(nu_);
}

void UnderwaterActionModel::hold(DataBase& data, const std::string& where,
                                 const std::string& message, bool diff) {
  if (work_->held.empty()) work_->held = "ocp node " + where + ": " + message;
  if (diff) {
    data.Fx.setZero();
    data.Fu.setZero();
    data.Lx.setZero();
    data.Lu.setZero();
    data.Lxx.setZero();
    data.Luu.setZero();
    data.Lxu.setZero();
  } else {
    data.xout.setZero();
    data.r.setZero();
    data.cost = kRejectedCost;
  }
}

void UnderwaterActionModel::calc(const std::shared_ptr<DataBase>& data,
                                 const Eigen::Ref<const Eigen::VectorXd>& x,
                                 const Eigen::Ref<const Eigen::VectorXd>& u) {
  try {
    calc_or_throw(*data, x, u);
  } catch (const std::exception& e) {  // it cannot cross crocoddyl's loop (held, see header)
    hold(*data, "calc", e.what(), false);
  }
}

void UnderwaterActionModel::calcDiff(const std::shared_ptr<DataBase>& data,
                                     const Eigen::Ref<const Eigen::VectorXd>& x,
                                     const Eigen::Ref<const Eigen::VectorXd>& u) {
  try {
    calc_diff_or_throw(*data, x, u);
  } catch (const std::exception& e) {
    hold(*data, "calcDiff", e.what(), true);
  }
}

}  // namespace uvms
