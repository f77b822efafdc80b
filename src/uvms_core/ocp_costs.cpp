// The cost terms of an underwater OCP (ocp_costs.hpp).
#include "ocp_costs.hpp"

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/spatial/explog.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms {

namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

// the frame's LOCAL Jacobian, in the work buffer (Pinocchio writes its support columns only)
const Matrix6x& frame_jacobian(const TermState& at, int frame_id) {
  Matrix6x& jacobian = at.work.frame_jacobian;
  jacobian.setZero();
  pinlib::get_frame_jacobian(at.model, at.data, frame_id, pinocchio::LOCAL, jacobian);
  return jacobian;
}

}  // namespace

int residual_size(const CostKind& kind, int nv) {
  return std::visit(
      Overloaded{[](const FramePoseCost&) { return 6; },
                 [](const FrameRotationCost&) { return 3; },
                 [](const FramePositionCost&) { return 3; },
                 [](const EffortCost& c) { return c.size; },
                 [nv](const StateDeviationCost&) { return 2 * nv; },
                 [](const ContactForceCost&) { return 3; },
                 [](const JointLimitCost& c) { return static_cast<int>(c.q_index.size()); }},
      kind);
}

void term_residual(const CostKind& kind, const TermState& at, const Eigen::VectorXd& x,
                   const Eigen::VectorXd& u, Eigen::Ref<Eigen::VectorXd> out) {
  const int nq = at.model.nq, nv = at.model.nv;
  std::visit(
      Overloaded{
          [&](const FramePoseCost& c) {
            out = pinocchio::log6(c.target.actInv(at.data.oMf[c.frame_id])).toVector();
          },
          [&](const FrameRotationCost& c) {
            const Mat3 error = c.rotation.transpose() * at.data.oMf[c.frame_id].rotation();
            out = pinocchio::log3(error);
          },
          [&](const FramePositionCost& c) {
            out = at.data.oMf[c.frame_id].translation() - c.target_m;
          },
          [&](const EffortCost&) { out = u; },
          [&](const StateDeviationCost& c) {
            out.head(nv) = pinlib::differenced(at.model, c.x_ref.head(nq), x.head(nq));
            out.tail(nv) = x.tail(nv) - c.x_ref.tail(nv);
          },
          [&](const ContactForceCost& c) { out = at.wrench_world->head<3>() - c.target_N; },
          [&](const JointLimitCost& c) {
            for (std::size_t k = 0; k < c.q_index.size(); ++k) {
              const double q = x[c.q_index[k]];
              out[k] = q - std::min(std::max(q, c.lower[k]), c.upper[k]);
            }
          }},
      kind);
}

void term_jacobian(const CostKind& kind, const TermState& at, const Eigen::VectorXd& x,
                   const Eigen::VectorXd& u, Eigen::Ref<Eigen::MatrixXd> out) {
  const int nq = at.model.nq, nv = at.model.nv;
  out.setZero();
  std::visit(
      Overloaded{
          [&](const FramePoseCost& c) {
            Mat6 jlog;
            pinocchio::Jlog6(c.target.actInv(at.data.oMf[c.frame_id]), jlog);
            out.leftCols(nv) = jlog * frame_jacobian(at, c.frame_id);
          },
          [&](const FrameRotationCost& c) {
            const Mat3 error = c.rotation.transpose() * at.data.oMf[c.frame_id].rotation();
            Mat3 jlog;
            pinocchio::Jlog3(error, jlog);
            out.leftCols(nv) = jlog * frame_jacobian(at, c.frame_id).bottomRows<3>();
          },
          [&](const FramePositionCost& c) {
            out.leftCols(nv) = at.data.oMf[c.frame_id].rotation() *
                               frame_jacobian(at, c.frame_id).topRows<3>();
          },
          [&](const EffortCost& c) {
            out.rightCols(c.size).setIdentity();
          },
          [&](const StateDeviationCost& c) {
            // (Pinocchio writes each joint's diagonal block only)
            Eigen::MatrixXd& jq = at.work.configuration;
            jq.setZero();
            pinlib::d_difference(at.model, c.x_ref.head(nq), x.head(nq), jq, pinocchio::ARG1);
            out.topLeftCorner(nv, nv) = jq;
            out.block(nv, nv, nv, nv).setIdentity();
          },
          [&](const ContactForceCost&) {
            out.leftCols(nv) = at.wrench_dq->topRows<3>();
            out.middleCols(nv, nv) = at.wrench_dv->topRows<3>();
          },
          [&](const JointLimitCost& c) {
            for (std::size_t k = 0; k < c.q_index.size(); ++k) {
              const double q = x[c.q_index[k]];
              if (q < c.lower[k] || q > c.upper[k]) out(k, c.v_index[k]) = 1.0;
            }
          }},
      kind);
}

}  // namespace uvms
