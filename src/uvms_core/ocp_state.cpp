// The state manifold of a UVMS for crocoddyl (ocp_state.hpp).
#include "ocp_state.hpp"

#include <cmath>
#include <random>

#include "pinocchio_kinematics.hpp"


namespace uvms {

UvmsState::UvmsState(const Model& model)
    : crocoddyl::StateAbstractTpl<double>(model.nq + model.nv, 2 * model.nv),
      model_(model),
      jq_(Eigen::MatrixXd::Zero(model.nv, model.nv)),
      q_out_(model.nq),
      v_out_(model.nv) {
  for (int j = 1; j < model.njoints; ++j) {
    if (model.nqs[j] == 2 && model.nvs[j] == 1) {
      circle_q_.push_back(model.idx_qs[j]);
      circle_v_.push_back(model.idx_vs[j]);
    }
  }
}

Eigen::VectorXd UvmsState::zero() const {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(nx_);
  x.head(model_.nq) = pinlib::neutral(model_);
  return x;
}

Eigen::VectorXd UvmsState::rand() const {
  std::mt19937 engine(0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> normal;
  Eigen::VectorXd tangent(model_.nv);
  for (int k = 0; k < model_.nv; ++k) tangent[k] = uniform(engine);
  Eigen::VectorXd x(nx_);
  x.head(model_.nq) = pinlib::integrated(model_, pinlib::neutral(model_), tangent);
  for (int k = 0; k < model_.nv; ++k) x[model_.nq + k] = normal(engine);
  return x;
}

void UvmsState::diff(const Eigen::Ref<const Eigen::VectorXd>& x0,
                     const Eigen::Ref<const Eigen::VectorXd>& x1,
                     Eigen::Ref<Eigen::VectorXd> dxout) const {
  const int nq = model_.nq, nv = model_.nv;
  q0_ = x0.head(nq);
  q1_ = x1.head(nq);
  pinlib::difference(model_, q0_, q1_, v_out_);
  dxout.head(nv) = v_out_;
  // continuous joints by atan2 (state.py: Pinocchio 4.1's SO(2) log rounds tiny steps to 0)
  for (std::size_t k = 0; k < circle_q_.size(); ++k) {
    const int i = circle_q_[k];
    const double c0 = x0[i], s0 = x0[i + 1], c1 = x1[i], s1 = x1[i + 1];
    dxout[circle_v_[k]] = std::atan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1);
  }
  dxout.tail(nv) = x1.tail(nv) - x0.tail(nv);
}

void UvmsState::integrate(const Eigen::Ref<const Eigen::VectorXd>& x,
                          const Eigen::Ref<const Eigen::VectorXd>& dx,
                          Eigen::Ref<Eigen::VectorXd> xout) const {
  const int nq = model_.nq, nv = model_.nv;
  q0_ = x.head(nq);
  dq_ = dx.head(nv);
  pinlib::integrate(model_, q0_, dq_, q_out_);
  xout.head(nq) = q_out_;
  xout.tail(nv) = x.tail(nv) + dx.tail(nv);
}

void UvmsState::block(const Eigen::MatrixXd& jq, double sign, Eigen::Ref<Eigen::MatrixXd> out,
                      crocoddyl::AssignmentOp op) const {
  const int nv = model_.nv;
  const double s = op == crocoddyl::rmfrom ? -1.0 : 1.0;
  if (op == crocoddyl::setto) out.setZero();
  out.topLeftCorner(nv, nv) += s * jq;
  out.bottomRightCorner(nv, nv).diagonal().array() += s * sign;
}

void UvmsState::Jdiff(const Eigen::Ref<const Eigen::VectorXd>& x0,
                      const Eigen::Ref<const Eigen::VectorXd>& x1,
                      Eigen::Ref<Eigen::MatrixXd> Jfirst, Eigen::Ref<Eigen::MatrixXd> Jsecond,
                      crocoddyl::Jcomponent firstsecond) const {
  const int nq = model_.nq;
  q0_ = x0.head(nq);
  q1_ = x1.head(nq);
  if (firstsecond == crocoddyl::first || firstsecond == crocoddyl::both) {
    pinlib::d_difference(model_, q0_, q1_, jq_, pinocchio::ARG0);
    block(jq_, -1.0, Jfirst, crocoddyl::setto);
  }
  if (firstsecond == crocoddyl::second || firstsecond == crocoddyl::both) {
    pinlib::d_difference(model_, q0_, q1_, jq_, pinocchio::ARG1);
    block(jq_, 1.0, Jsecond, crocoddyl::setto);
  }
}

void UvmsState::Jintegrate(const Eigen::Ref<const Eigen::VectorXd>& x,
                           const Eigen::Ref<const Eigen::VectorXd>& dx,
                           Eigen::Ref<Eigen::MatrixXd> Jfirst,
                           Eigen::Ref<Eigen::MatrixXd> Jsecond,
                           crocoddyl::Jcomponent firstsecond, crocoddyl::AssignmentOp op) const {
  const int nq = model_.nq, nv = model_.nv;
  q0_ = x.head(nq);
  dq_ = dx.head(nv);
  if (firstsecond == crocoddyl::first || firstsecond == crocoddyl::both) {
    pinlib::d_integrate(model_, q0_, dq_, jq_, pinocchio::ARG0);
    block(jq_, 1.0, Jfirst, op);
  }
  if (firstsecond == crocoddyl::second || firstsecond == crocoddyl::both) {
    pinlib::d_integrate(model_, q0_, dq_, jq_, pinocchio::ARG1);
    block(jq_, 1.0, Jsecond, op);
  }
}

void UvmsState::JintegrateTransport(const Eigen::Ref<const Eigen::VectorXd>& x,
                                    const Eigen::Ref<const Eigen::VectorXd>& dx,
                                    Eigen::Ref<Eigen::MatrixXd> Jin,
                                    crocoddyl::Jcomponent firstsecond) const {
  const int nq = model_.nq, nv = model_.nv;
  const auto arg = firstsecond == crocoddyl::first ? pinocchio::ARG0 : pinocchio::ARG1;
  q0_ = x.head(nq);
  dq_ = dx.head(nv);
  transported_ = Jin.topRows(nv);  // (the library's instantiation takes a MatrixXd)
  pinlib::d_integrate_transport(model_, q0_, dq_, transported_, arg);
  Jin.topRows(nv) = transported_;
}

}  // namespace uvms
