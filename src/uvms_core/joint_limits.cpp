#include "joint_limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Cholesky>

namespace uvms {

namespace {

// Bounds lo <= v <= hi on some coordinates (the others free: -inf, +inf).
struct Box {
  Eigen::VectorXd lo, hi;
  int rows = 0;  // the selected rows (a coordinate bounded on both sides counts twice)
};

// The rows of `limits` that can close within h at `speed` (|v| per coordinate), as bounds on v.
Box selected(const JointLimitConstraintsModel& limits, const Eigen::Ref<const Eigen::VectorXd>& q0,
             const Eigen::VectorXd& speed, double h) {
  const Eigen::Index nv = speed.size();
  const double inf = std::numeric_limits<double>::infinity();
  Box box{Eigen::VectorXd::Constant(nv, -inf), Eigen::VectorXd::Constant(nv, inf), 0};
  const auto phi = [&](double gap) { return gap >= 0.0 ? gap : limits.correction * gap; };
  for (std::size_t i = 0; i < limits.q_index.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const int iq = limits.q_index[i], iv = limits.v_index[i];
    const double reach = h * speed[iv] + limits.margin;
    const double lower_gap = q0[iq] - limits.lower_rad[k];
    const double upper_gap = limits.upper_rad[k] - q0[iq];
    if (lower_gap <= reach) {  // sigma = v_j + phi / h >= 0
      box.lo[iv] = -phi(lower_gap) / h;
      ++box.rows;
    }
    if (upper_gap <= reach) {  // sigma = -v_j + phi / h >= 0
      box.hi[iv] = phi(upper_gap) / h;
      ++box.rows;
    }
  }
  return box;
}

enum class Bound : signed char { free = 0, lower = -1, upper = 1 };

// argmin 1/2 (v - v_free)^T M (v - v_free) s.t. lo <= v <= hi, by a primal active set from
// the projection of v_free (feasible: lo <= hi always, see below). Each iteration solves the
// free coordinates with the bound ones held; a step blocked by a bound adds it, a bound whose
// multiplier (M (v - v_free))_j has the wrong sign is released. Finite for M positive definite.
Eigen::VectorXd box_qp(const Eigen::MatrixXd& mass, const Eigen::VectorXd& v_free,
                       const Box& box) {
  const Eigen::Index n = v_free.size();
  Eigen::VectorXd v = v_free.cwiseMax(box.lo).cwiseMin(box.hi);
  std::vector<Bound> at(static_cast<std::size_t>(n), Bound::free);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (v_free[j] < box.lo[j]) at[j] = Bound::lower;
    if (v_free[j] > box.hi[j]) at[j] = Bound::upper;
  }
  const double scale = 1.0 + v_free.cwiseAbs().maxCoeff();
  const int max_iterations = 10 * static_cast<int>(n) + 50;
  std::vector<Eigen::Index> free_idx;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    free_idx.clear();
    for (Eigen::Index j = 0; j < n; ++j) {
      if (at[j] == Bound::free) free_idx.push_back(j);
    }
    // the free coordinates' optimum with the bound ones held: M_FF (v_F - vf_F) = -M_FB dv_B
    const Eigen::VectorXd dv = v - v_free;
    Eigen::VectorXd target = v;
    if (!free_idx.empty()) {
      const auto nf = static_cast<Eigen::Index>(free_idx.size());
      Eigen::MatrixXd m_ff(nf, nf);
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nf);
      for (Eigen::Index a = 0; a < nf; ++a) {
        for (Eigen::Index b = 0; b < nf; ++b) m_ff(a, b) = mass(free_idx[a], free_idx[b]);
        for (Eigen::Index j = 0; j < n; ++j) {
          if (at[j] != Bound::free) rhs[a] -= mass(free_idx[a], j) * dv[j];
        }
      }
      const Eigen::LLT<Eigen::MatrixXd> llt(m_ff);
      if (llt.info() != Eigen::Success) {
        throw SimulationFailure("joint limits: the mass matrix is not positive definite");
      }
      const Eigen::VectorXd dv_free = llt.solve(rhs);
      for (Eigen::Index a = 0; a < nf; ++a) target[free_idx[a]] = v_free[free_idx[a]] + dv_free[a];
    }
    // the longest step towards the target within the bounds
    double alpha = 1.0;
    Eigen::Index blocking = -1;
    for (const Eigen::Index j : free_idx) {
      const double p = target[j] - v[j];
      if (p < 0.0 && target[j] < box.lo[j]) {
        const double a = (box.lo[j] - v[j]) / p;
        if (a < alpha) alpha = a, blocking = j;
      } else if (p > 0.0 && target[j] > box.hi[j]) {
        const double a = (box.hi[j] - v[j]) / p;
        if (a < alpha) alpha = a, blocking = j;
      }
    }
    v += std::max(alpha, 0.0) * (target - v);
    if (blocking >= 0) {
      const bool lower = target[blocking] < box.lo[blocking];
      at[blocking] = lower ? Bound::lower : Bound::upper;
      v[blocking] = lower ? box.lo[blocking] : box.hi[blocking];
      continue;
    }
    // at the optimum of this set: release the bound whose impulse pulls (wrong sign) the most
    const Eigen::VectorXd impulse = mass * (v - v_free);
    Eigen::Index release = -1;
    double worst = 1e-14 * scale * mass.diagonal().maxCoeff();
    for (Eigen::Index j = 0; j < n; ++j) {
      const double pull = at[j] == Bound::lower   ? -impulse[j]
                          : at[j] == Bound::upper ? impulse[j]
                                                  : 0.0;
      if (pull > worst) worst = pull, release = j;
    }
    if (release < 0) return v;
    at[release] = Bound::free;
  }
  throw SimulationFailure("joint limits: the active set did not settle in " +
                          std::to_string(max_iterations) + " iterations");
}

}  // namespace

void JointLimitConstraintsModel::check(Eigen::Index nq, Eigen::Index nv) const {
  const auto n = static_cast<std::size_t>(lower_rad.size());
  if (upper_rad.size() != lower_rad.size() || q_index.size() != n || v_index.size() != n) {
    throw InputError("joint limits: one q index, v index and pair of limits per joint");
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    if (q_index[i] < 0 || q_index[i] >= nq || v_index[i] < 0 || v_index[i] >= nv) {
      throw InputError("joint limits: a joint index is outside the model's q or v");
    }
    if (!(std::isfinite(lower_rad[k]) && std::isfinite(upper_rad[k]) &&
          lower_rad[k] < upper_rad[k])) {
      throw InputError("joint limits: each joint needs finite limits, lower < upper");
    }
  }
  if (!(std::isfinite(margin) && margin >= 0.0)) {
    throw InputError("joint limits: the margin must be >= 0");
  }
  if (!(std::isfinite(correction) && correction > 0.0 && correction <= 1.0)) {
    throw InputError("joint limits: the correction must be in (0, 1]");
  }
}

bool JointLimitConstraintsModel::within_reach(const Eigen::Ref<const Eigen::VectorXd>& q0,
                                              const Eigen::VectorXd& speed, double h) const {
  check(q0.size(), speed.size());
  return selected(*this, q0, speed, h).rows > 0;
}

bool JointLimitConstraintsModel::constrain(const Eigen::MatrixXd& mass,
                                           const Eigen::Ref<const Eigen::VectorXd>& q0,
                                           Eigen::VectorXd& v, double h,
                                           const Eigen::VectorXd& least_speed) const {
  check(q0.size(), v.size());
  if (!(std::isfinite(h) && h > 0.0)) throw InputError("joint limits: the period must be > 0");
  if (least_speed.size() != v.size() || !least_speed.allFinite()) {
    throw InputError("joint limits: least_speed must hold nv finite numbers");
  }
  const Eigen::VectorXd v_free = v;
  Eigen::VectorXd speed = v_free.cwiseAbs().cwiseMax(least_speed.cwiseAbs());
  Box box = selected(*this, q0, speed, h);
  if (box.rows == 0) return false;
  for (int round = 0; round < kWideningRounds; ++round) {
    v = box_qp(mass, v_free, box);
    speed = speed.cwiseMax(v.cwiseAbs());
    Box wider = selected(*this, q0, speed, h);
    if (wider.rows == box.rows) return true;
    box = std::move(wider);
  }
  v = box_qp(mass, v_free, box);
  return true;
}

}  // namespace uvms
