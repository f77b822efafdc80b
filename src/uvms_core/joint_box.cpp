#include "joint_box.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "types.hpp"

namespace uvms {

namespace {

// coordinate descent stops when no rate changes by more than this [rad/s or m/s]
constexpr double kBoxSettled = 1.0e-15;
constexpr int kBoxMaxSweeps = 10000;

double box_sign(double x) { return static_cast<double>((x > 0.0) - (x < 0.0)); }

double soft_threshold(double b, double threshold) {
  return box_sign(b) * std::max(std::abs(b) - threshold, 0.0);
}

double phi(double gap, double correction) { return gap >= 0.0 ? gap : correction * gap; }

// The joints left moving freely (strictly inside their limits, not stuck) solved exactly
// with the others held; the descent's own v when that moves a joint across 0 or past a limit.
Eigen::VectorXd polished(const Eigen::VectorXd& v, const Eigen::VectorXd& v_free,
                         const Eigen::MatrixXd& mass, const Eigen::VectorXd& bound,
                         const Eigen::VectorXd& low, const Eigen::VectorXd& high) {
  const Eigen::Index n = v.size();
  std::vector<Eigen::Index> free, held;
  for (Eigen::Index j = 0; j < n; ++j) {
    ((v[j] != 0.0 && v[j] > low[j] && v[j] < high[j]) ? free : held).push_back(j);
  }
  if (free.empty()) return v;
  const auto nf = static_cast<Eigen::Index>(free.size());
  Eigen::MatrixXd mass_ff(nf, nf);
  Eigen::VectorXd rhs(nf);
  for (Eigen::Index a = 0; a < nf; ++a) {
    const Eigen::Index i = free[static_cast<std::size_t>(a)];
    for (Eigen::Index b = 0; b < nf; ++b) mass_ff(a, b) = mass(i, free[static_cast<std::size_t>(b)]);
    double r = bound[i] * box_sign(v[i]);
    for (const Eigen::Index k : held) r += mass(i, k) * (v[k] - v_free[k]);
    rhs[a] = r;
  }
  const Eigen::VectorXd step = mass_ff.partialPivLu().solve(rhs);
  Eigen::VectorXd out = v;
  for (Eigen::Index a = 0; a < nf; ++a) {
    const Eigen::Index i = free[static_cast<std::size_t>(a)];
    out[i] = v_free[i] - step[a];
    if (box_sign(out[i]) != box_sign(v[i]) || out[i] < low[i] || out[i] > high[i]) return v;
  }
  return out;
}

}  // namespace

JointBoxStep joint_box_step(const Eigen::VectorXd& v_free, const Eigen::MatrixXd& mass,
                            const Eigen::VectorXd& coulomb, const Eigen::VectorXd& gap_low,
                            const Eigen::VectorXd& gap_high, double period_s,
                            double correction) {
  const Eigen::Index n = v_free.size();
  if (mass.rows() != n || mass.cols() != n || coulomb.size() != n || gap_low.size() != n ||
      gap_high.size() != n) {
    throw InputError("joint box step: v_free (n,), M (n, n), c, gaps (n,) expected");
  }
  if (!(period_s > 0.0) || (coulomb.array() < 0.0).any() ||
      !(mass.diagonal().array() > 0.0).all()) {
    throw InputError("joint box step: need h > 0, c >= 0 and M_jj > 0");
  }
  const double h = period_s;
  Eigen::VectorXd low(n), high(n), v(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    low[j] = -phi(gap_low[j], correction) / h;
    high[j] = phi(gap_high[j], correction) / h;
    if (low[j] > high[j]) low[j] = high[j] = 0.5 * (low[j] + high[j]);  // both past: their middle
    v[j] = std::min(std::max(0.0, low[j]), high[j]);
  }
  for (int sweep = 0; sweep < kBoxMaxSweeps; ++sweep) {
    double moved = 0.0;
    for (Eigen::Index j = 0; j < n; ++j) {
      const double mjj = mass(j, j);
      const double others = mass.row(j).dot(v - v_free) - mjj * (v[j] - v_free[j]);
      const double b = v_free[j] - others / mjj;
      const double next =
          std::min(std::max(soft_threshold(b, coulomb[j] * h / mjj), low[j]), high[j]);
      moved = std::max(moved, std::abs(next - v[j]));
      v[j] = next;
    }
    if (moved <= kBoxSettled) break;
  }
  const Eigen::VectorXd bound = coulomb * h;
  JointBoxStep out;
  out.velocity = polished(v, v_free, mass, bound, low, high);
  const Eigen::VectorXd total = mass * (out.velocity - v_free);
  out.friction_impulse.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double vj = out.velocity[j];
    out.friction_impulse[j] =
        vj != 0.0 ? -bound[j] * box_sign(vj) : std::min(std::max(total[j], -bound[j]), bound[j]);
  }
  out.limit_impulse = total - out.friction_impulse;
  return out;
}

}  // namespace uvms
