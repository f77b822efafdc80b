#include "batch_derivatives.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <string>
#include <thread>

namespace uvms {

namespace {

using RowMap = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
using Row = Eigen::Map<const Eigen::VectorXd>;

}  // namespace

BatchDerivatives::BatchDerivatives(const Dynamics& dynamics, int num_threads) {
  if (num_threads <= 0) {
    throw InputError("num_threads must be >= 1, got " + std::to_string(num_threads));
  }
  derivatives_.reserve(size_t(num_threads));
  for (int t = 0; t < num_threads; ++t) {
    derivatives_.push_back(std::make_unique<Derivatives>(dynamics));
  }
}

void BatchDerivatives::one(int thread, int k, const BatchStates& states, const FlowField& flow,
                           bool free_surface, const BatchJacobians& out) {
  Derivatives& derivatives = *derivatives_[size_t(thread)];
  const int nq = this->nq(), nv = this->nv();
  const Eigen::Index block = Eigen::Index(nv) * nv;
  const ConstVec q(Row(states.q + Eigen::Index(k) * nq, nq));
  const ConstVec v(Row(states.v + Eigen::Index(k) * nv, nv));
  const ConstVec tau(Row(states.tau + Eigen::Index(k) * nv, nv));
  const ConstVec ext(states.tau_ext ? Row(states.tau_ext + Eigen::Index(k) * nv, nv)
                                    : Row(nullptr, 0));
  const auto& jacobians = derivatives.forward_dynamics_derivatives(
      q, v, tau, flow, states.tau_ext ? &ext : nullptr, states.time_s[k], free_surface);
  RowMap(out.da_dq + k * block, nv, nv) = jacobians.da_dq;
  RowMap(out.da_dv + k * block, nv, nv) = jacobians.da_dv;
  RowMap(out.da_dtau + k * block, nv, nv) = jacobians.da_dtau;
}

void BatchDerivatives::compute(const BatchStates& states, const FlowField& flow, bool free_surface,
                               const BatchJacobians& out) {
  const int threads = std::max(1, std::min(num_threads(), states.n));
  // the states handed out one at a time, in order, from one counter, not in fixed shares: a
  // thread made for the call starts tens of microseconds after the calling one, and a share
  // of states ends up to a share's imbalance apart; one state (a few microseconds) apart here
  std::atomic<int> next{0};
  // by state: the states are taken in order, so every state before a failed one was taken
  // and finished (or failed) too: the first failed state is the same whatever the timing
  std::vector<std::exception_ptr> errors(size_t(states.n), nullptr);
  const auto run = [&](int t) {
    for (int k = next++; k < states.n; k = next++) {
      try {
        one(t, k, states, flow, free_surface, out);
      } catch (...) {
        errors[size_t(k)] = std::current_exception();
        return;
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(size_t(threads - 1));
  for (int t = 1; t < threads; ++t) pool.emplace_back(run, t);
  run(0);  // the calling thread works too
  for (auto& thread : pool) thread.join();
  for (const auto& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace uvms
