// The derivatives of the forward dynamics (derivatives.hpp) at n states at once, on T threads
// (mirror of uvms_pin/physics/derivatives/batch.py, which calls the single derivatives state
// by state): the threads take the states one at a time in order, each differentiating
// with its own Derivatives (its own copy of the dynamics and Pinocchio data), so a state's
// Jacobians do not depend on the thread that computed them: the results equal n single calls
// for any T.
#pragma once

#include <memory>
#include <vector>

#include "derivatives.hpp"

namespace uvms {

// The states of a batch, row-major: q (n x nq), v, tau and tau_ext (n x nv; tau_ext may be
// null: none), time_s (n) [s].
struct BatchStates {
  int n = 0;
  const double* q = nullptr;
  const double* v = nullptr;
  const double* tau = nullptr;
  const double* tau_ext = nullptr;
  const double* time_s = nullptr;
};

// Where the Jacobians go: three (n x nv x nv) row-major blocks, entry [k][i][j] the
// derivative of a_i at state k by the j-th tangent coordinate (resp. v_j, tau_j).
struct BatchJacobians {
  double* da_dq = nullptr;
  double* da_dv = nullptr;
  double* da_dtau = nullptr;
};

class BatchDerivatives {
 public:
  BatchDerivatives(const Dynamics& dynamics, int num_threads);
  BatchDerivatives(const BatchDerivatives&) = delete;
  BatchDerivatives& operator=(const BatchDerivatives&) = delete;

  int num_threads() const { return static_cast<int>(derivatives_.size()); }
  int nq() const { return derivatives_.front()->dynamics().nq(); }
  int nv() const { return derivatives_.front()->dynamics().nv(); }
  const Model& model() const { return derivatives_.front()->dynamics().model(); }

  // Every state's Jacobians in `flow` (shared, read only); after all threads have stopped,
  // the error of the first state that failed rethrown.
  void compute(const BatchStates& states, const FlowField& flow, bool free_surface,
               const BatchJacobians& out);

 private:
  // state k's Jacobians by thread `thread`'s Derivatives
  void one(int thread, int k, const BatchStates& states, const FlowField& flow, bool free_surface,
           const BatchJacobians& out);

  std::vector<std::unique_ptr<Derivatives>> derivatives_;  // one per thread
};

}  // namespace uvms
