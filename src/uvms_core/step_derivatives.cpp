// The Jacobians of one control period (step_derivatives.hpp; mirror of step.py and chart.py).
#include "step_derivatives.hpp"

#include <array>
#include <cmath>
#include <string>

#include <pinocchio/algorithm/joint-configuration.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms {

namespace {

// b_k = |B_2k| / (2k)!, k = 1..10 (B_2k the Bernoulli numbers): 1 - gamma = sum b_k theta^2k
// with gamma(theta) = (theta/2) cot(theta/2)
constexpr std::array<double, 10> kB = {
    (1.0 / 6.0) / 2.0,
    (1.0 / 30.0) / 24.0,
    (1.0 / 42.0) / 720.0,
    (1.0 / 30.0) / 40320.0,
    (5.0 / 66.0) / 3628800.0,
    (691.0 / 2730.0) / 479001600.0,
    (7.0 / 6.0) / 87178291200.0,
    (3617.0 / 510.0) / 20922789888000.0,
    (43867.0 / 798.0) / 6402373705728000.0,
    (174611.0 / 330.0) / 2432902008176640000.0};

// below this rotation angle [rad] the coefficients are summed from their series
constexpr double kSeriesBelowRad = 1.0;

// sum_{k >= first_k} weight(k) b_k theta^(2k - power_shift)
template <class Weight>
double series(double theta, Weight weight, int first_k, int power_shift) {
  double out = 0.0;
  for (int k = first_k; k <= static_cast<int>(kB.size()); ++k) {
    out += weight(k) * kB[k - 1] * std::pow(theta, 2 * k - power_shift);
  }
  return out;
}

struct Gamma {
  double one_minus, first, second;  // 1 - gamma, gamma', gamma''
};

Gamma gamma_derivatives(double theta) {
  const double s = std::sin(0.5 * theta), c = std::cos(0.5 * theta);
  return {1.0 - 0.5 * theta * c / s, 0.5 * c / s - 0.25 * theta / (s * s),
          -0.5 / (s * s) + 0.25 * theta * c / (s * s * s)};
}

// (c_k, c_k'/theta), k = 0..4, of Jr^-1 = sum c_k ad^k: (1, 1/2, beta) on so(3),
// (1, 1/2, c2, 0, c4) on se(3) (chart.py so3_coefficients, se3_coefficients)
void coefficients(double theta, bool se3, std::array<double, 5>& c, std::array<double, 5>& slope) {
  c = {1.0, 0.5, 0.0, 0.0, 0.0};
  slope = {0.0, 0.0, 0.0, 0.0, 0.0};
  const bool small = theta < kSeriesBelowRad;
  if (!se3) {
    if (small) {
      c[2] = series(theta, [](int) { return 1.0; }, 1, 2);
      slope[2] = series(theta, [](int k) { return 2.0 * (k - 1); }, 2, 4);
    } else {
      const Gamma g = gamma_derivatives(theta);
      c[2] = g.one_minus / (theta * theta);
      slope[2] = -g.first / std::pow(theta, 3) - 2.0 * g.one_minus / std::pow(theta, 4);
    }
    return;
  }
  if (small) {
    c[2] = series(theta, [](int k) { return 2.0 - k; }, 1, 2);
    slope[2] = series(theta, [](int k) { return 2.0 * (k - 1) * (2.0 - k); }, 2, 4);
    c[4] = series(theta, [](int k) { return 1.0 - k; }, 2, 4);
    slope[4] = series(theta, [](int k) { return 2.0 * (k - 2) * (1.0 - k); }, 3, 6);
  } else {
    const Gamma g = gamma_derivatives(theta);
    c[2] = 2.0 * g.one_minus / (theta * theta) + 0.5 * g.first / theta;
    slope[2] = -4.0 * g.one_minus / std::pow(theta, 4) - 2.5 * g.first / std::pow(theta, 3) +
               0.5 * g.second / (theta * theta);
    c[4] = g.one_minus / std::pow(theta, 4) + 0.5 * g.first / std::pow(theta, 3);
    slope[4] = -4.0 * g.one_minus / std::pow(theta, 6) - 2.5 * g.first / std::pow(theta, 5) +
               0.5 * g.second / std::pow(theta, 4);
  }
}

// ad_delta: phi^ on so(3); [[phi^, rho^], [0, phi^]] on se(3)
template <int N>
Eigen::Matrix<double, N, N> ad(const Eigen::Matrix<double, N, 1>& delta) {
  Eigen::Matrix<double, N, N> out = Eigen::Matrix<double, N, N>::Zero();
  const Mat3 rotation = skew(delta.template tail<3>());
  if constexpr (N == 6) {
    out.template topLeftCorner<3, 3>() = rotation;
    out.template bottomRightCorner<3, 3>() = rotation;
    out.template topRightCorner<3, 3>() = skew(delta.template head<3>());
  } else {
    out = rotation;
  }
  return out;
}

}  // namespace

template <int N>
void exp_inverse_and_derivative(const Eigen::Matrix<double, N, 1>& delta,
                                const Eigen::Matrix<double, N, 1>& w,
                                Eigen::Matrix<double, N, N>& inverse,
                                Eigen::Matrix<double, N, N>& derivative) {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  const double theta = delta.template tail<3>().norm();
  std::array<double, 5> c, slope;
  coefficients(theta, N == 6, c, slope);
  const int terms = N == 6 ? 5 : 3;
  const Mat ad_delta = ad<N>(delta);
  std::array<Mat, 5> powers;  // ad^k
  std::array<Vec, 5> images;  // ad^k w
  powers[0].setIdentity();
  images[0] = w;
  for (int k = 1; k < terms; ++k) {
    powers[k] = ad_delta * powers[k - 1];
    images[k] = ad_delta * images[k - 1];
  }
  Vec phi_bar = Vec::Zero();
  phi_bar.template tail<3>() = delta.template tail<3>();
  inverse.setZero();
  derivative.setZero();
  for (int k = 0; k < terms; ++k) {
    inverse += c[k] * powers[k];
    if (slope[k] != 0.0) derivative += slope[k] * images[k] * phi_bar.transpose();
    if (c[k] == 0.0) continue;
    for (int j = 0; j < k; ++j) derivative -= c[k] * powers[j] * ad<N>(images[k - 1 - j]);
  }
}

template void exp_inverse_and_derivative<3>(const Vec3&, const Vec3&, Mat3&, Mat3&);
template void exp_inverse_and_derivative<6>(const Vec6&, const Vec6&, Mat6&, Mat6&);

StepDerivatives::StepDerivatives(const Dynamics& dynamics) : derivatives_(dynamics) {
  const Model& model = derivatives_.dynamics().model();
  for (int j = 1; j < model.njoints; ++j) {
    const auto& joint = model.joints[j];
    const std::string kind = joint.shortname();
    if (kind == "JointModelFreeFlyer") {
      se3_.push_back(joint.idx_v());
    } else if (kind == "JointModelSpherical") {
      so3_.push_back(joint.idx_v());
    } else if (unknown_chart_.empty() &&
               (kind.rfind("JointModelComposite", 0) == 0 ||
                kind.rfind("JointModelMimic", 0) == 0 ||
                !(joint.nq() == joint.nv() || (joint.nq() == 2 && joint.nv() == 1)))) {
      unknown_chart_ = "the chart derivatives know free-flyer, spherical, revolute, prismatic "
                       "and continuous joints; joint '" + model.names[j] + "' is " + kind;
    }
  }
  const int nq = model.nq, nv = model.nv;
  q_.resize(nq);
  q_next_.resize(nq);
  v_.resize(nv);
  a_.resize(nv);
  j0_.setZero(nv, nv);
  j1_.setZero(nv, nv);
  chart_inverse_.setZero(nv, nv);
  chart_slope_.setZero(nv, nv);
  local_.setZero(2 * nv, 3 * nv);
}

void StepDerivatives::stage(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  a_ = derivatives_.dynamics().forward_dynamics(q, v, *tau_, *flow_, tau_ext_, t);
  const auto& out = derivatives_.forward_dynamics_derivatives(q, v, *tau_, *flow_, tau_ext_, t);
  a_q_ = out.da_dq;
  a_v_ = out.da_dv;
  a_tau_ = out.da_dtau;
}

void StepDerivatives::chart_rate(const Eigen::VectorXd& delta, const Eigen::VectorXd& velocity) {
  const int nv = static_cast<int>(delta.size());
  chart_inverse_.setIdentity(nv, nv);
  chart_slope_.setZero(nv, nv);
  for (int i : se3_) {
    Mat6 inverse, slope;
    exp_inverse_and_derivative<6>(delta.segment<6>(i), velocity.segment<6>(i), inverse, slope);
    chart_inverse_.block<6, 6>(i, i) = inverse;
    chart_slope_.block<6, 6>(i, i) = slope;
  }
  for (int i : so3_) {
    Mat3 inverse, slope;
    exp_inverse_and_derivative<3>(delta.segment<3>(i), velocity.segment<3>(i), inverse, slope);
    chart_inverse_.block<3, 3>(i, i) = inverse;
    chart_slope_.block<3, 3>(i, i) = slope;
  }
}

void StepDerivatives::euler_substep(double t, double h) {
  const Model& model = derivatives_.dynamics().model();
  const int nv = model.nv;
  stage(t, q_, v_);
  v_ += h * a_;
  const Eigen::VectorXd w = h * v_;
  pinlib::d_integrate(model, q_, w, j0_, pinocchio::ARG0);
  pinlib::d_integrate(model, q_, w, j1_, pinocchio::ARG1);
  local_.setZero();
  auto dv_next = local_.bottomRows(nv);
  dv_next.leftCols(nv) = h * a_q_;
  dv_next.middleCols(nv, nv) = h * a_v_;
  dv_next.middleCols(nv, nv).diagonal().array() += 1.0;
  dv_next.rightCols(nv) = h * a_tau_;
  auto dq_next = local_.topRows(nv);
  dq_next.noalias() = h * j1_ * dv_next;
  dq_next.leftCols(nv) += j0_;
  pinlib::integrate(model, q_, w, q_next_);
  q_ = q_next_;
}

void StepDerivatives::rk4_substep(double t, double h) {
  static constexpr std::array<double, 4> kTimes = {0.0, 0.5, 0.5, 1.0};
  static constexpr std::array<double, 4> kWeights = {1.0 / 6.0, 2.0 / 6.0, 2.0 / 6.0, 1.0 / 6.0};
  const Model& model = derivatives_.dynamics().model();
  const int nv = model.nv;
  // d(.)/d(dq0, dv0, dtau) of each stage's quantity (nv, 3 nv)
  Eigen::MatrixXd e_v = Eigen::MatrixXd::Zero(nv, 3 * nv);
  e_v.middleCols(nv, nv).setIdentity();
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(nv), v = v_, rate(nv);
  Eigen::VectorXd rate_sum = Eigen::VectorXd::Zero(nv), accel_sum = Eigen::VectorXd::Zero(nv);
  Eigen::MatrixXd d_delta = Eigen::MatrixXd::Zero(nv, 3 * nv), d_v = e_v, d_rate(nv, 3 * nv),
                  d_accel(nv, 3 * nv), d_q(nv, 3 * nv);
  Eigen::MatrixXd d_rate_sum = Eigen::MatrixXd::Zero(nv, 3 * nv), d_accel_sum = d_rate_sum;
  Eigen::VectorXd q_stage(model.nq);
  for (int i = 0; i < 4; ++i) {
    pinlib::integrate(model, q_, delta, q_stage);
    pinlib::d_integrate(model, q_, delta, j0_, pinocchio::ARG0);
    pinlib::d_integrate(model, q_, delta, j1_, pinocchio::ARG1);
    chart_rate(delta, v);
    rate.noalias() = chart_inverse_ * v;  // d_i = Jint(delta_i)^-1 v_i
    d_rate.noalias() = chart_inverse_ * d_v;
    d_rate.noalias() += chart_slope_ * d_delta;
    stage(t + kTimes[i] * h, q_stage, v);
    // dq_i along the tangent at q_i, carried back to q0's: J0 dq0 + J1 d delta_i
    d_q.noalias() = j1_ * d_delta;
    d_q.leftCols(nv) += j0_;
    d_accel.noalias() = a_q_ * d_q;
    d_accel.noalias() += a_v_ * d_v;
    d_accel.rightCols(nv) += a_tau_;
    rate_sum += kWeights[i] * rate;
    d_rate_sum += kWeights[i] * d_rate;
    accel_sum += kWeights[i] * a_;
    d_accel_sum += kWeights[i] * d_accel;
    if (i + 1 < 4) {  // the next stage: delta = c h d_i, v = v0 + c h a_i
      const double step = kTimes[i + 1] * h;
      delta = step * rate;
      d_delta = step * d_rate;
      v = v_ + step * a_;
      d_v = e_v + step * d_accel;
    }
  }
  delta = h * rate_sum;
  pinlib::d_integrate(model, q_, delta, j0_, pinocchio::ARG0);
  pinlib::d_integrate(model, q_, delta, j1_, pinocchio::ARG1);
  auto dq_next = local_.topRows(nv);
  dq_next.noalias() = h * j1_ * d_rate_sum;
  dq_next.leftCols(nv) += j0_;
  local_.bottomRows(nv) = e_v + h * d_accel_sum;
  pinlib::integrate(model, q_, delta, q_next_);
  q_ = q_next_;
  v_ += h * accel_sum;
}

const StepJacobians& StepDerivatives::period(const ConstVec& q, const ConstVec& v,
                                             const ConstVec& tau, const FlowField& flow,
                                             const ConstVec* tau_ext, double time_s,
                                             double period_s, const FixedStep& integrator) {
  const Model& model = derivatives_.dynamics().model();
  const int nq = model.nq, nv = model.nv;
  if (q.size() != nq || v.size() != nv || tau.size() != nv ||
      (tau_ext != nullptr && tau_ext->size() != nv)) {
    throw InputError("StepDerivatives.period: q, v, tau or tau_ext has the wrong size");
  }
  if (!(period_s > 0.0 && std::isfinite(period_s))) {
    throw InputError("period_s must be positive and finite, got " + std::to_string(period_s));
  }
  if (!(integrator.step_s > 0.0 && std::isfinite(integrator.step_s))) {
    throw InputError("step_s must be positive and finite, got " +
                     std::to_string(integrator.step_s));
  }
  tau_ = &tau;
  flow_ = &flow;
  tau_ext_ = tau_ext;
  q_ = q;
  v_ = v;
  if (integrator.method == Method::rk4 && !unknown_chart_.empty()) {
    throw InputError(unknown_chart_);
  }
  const auto [n, h] = substeps(0.0, period_s, integrator.step_s);
  out_.dx_dx.setIdentity(2 * nv, 2 * nv);  // d(q_k, v_k)/d(q_0, v_0)
  out_.dx_dtau.setZero(2 * nv, nv);        // d(q_k, v_k)/dtau
  for (int k = 0; k < n; ++k) {
    if (integrator.method == Method::rk4) {
      rk4_substep(time_s + k * h, h);
    } else {
      euler_substep(time_s + k * h, h);
    }
    const auto state = local_.leftCols(2 * nv);
    out_.dx_dtau = (state * out_.dx_dtau + local_.rightCols(nv)).eval();
    out_.dx_dx = (state * out_.dx_dx).eval();
  }
  out_.q = q_;
  out_.v = v_;
  tau_ = tau_ext_ = nullptr;
  flow_ = nullptr;
  return out_;
}

}  // namespace uvms
