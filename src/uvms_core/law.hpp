// The control law of the sampled closed loop (sampled_loop.hpp): what the loop asks of a
// compiled controller, whichever it is (the PPC, ppc.hpp; the force baselines,
// law_force_baselines.hpp). Each is the mirror of its Python controller's `compute`.
//
// At tick t the loop hands the law the measurement (q, v, the measured wrench) and that
// tick's row of the desired table (the values of the user's functions of time at t,
// evaluated by Python: f_d(t), rpy_d(t) for the force laws). The law answers:
//   ok:       signals() hold this tick's values, tau (nv) among them at tau_offset();
//   declined: the Python controller decides this tick (it raises, or takes a route the law
//             does not mirror), and nothing of the law changed.
// A law with state (an integral, an anchor) computes the next state with the command and
// takes it only at commit(), once the loop commits the whole tick; its state is a named
// struct the Python side reads and writes between chunks, so the Python controller and the
// compiled law hand the run to each other tick for tick.
#pragma once

#include <cmath>
#include <vector>

#include "types.hpp"

namespace uvms {

// All n entries of x finite (a measurement or a desired row a law may decline).
inline bool all_finite(const double* x, Eigen::Index n) {
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!std::isfinite(x[j])) return false;
  }
  return true;
}

enum class LawStatus : int {
  ok = 0,
  declined = 1,  // the Python controller evaluates this tick
};

// One tick's input (pointers into the loop's buffers, valid for the call).
struct LawInput {
  double time_s = 0.0;
  const double* q = nullptr;             // nq, measured
  const double* v = nullptr;             // nv, measured
  const double* wrench_world = nullptr;  // 6: force [N] then torque [N m], world axes
  const double* desired = nullptr;       // desired_size() entries: this tick's row
};

// Where one signal sits in a law's signal buffer.
struct SignalSlot {
  const char* name;
  Eigen::Index offset, size;
};

class SampledLaw {
 public:
  virtual ~SampledLaw() = default;
  virtual int nq() const = 0;
  virtual int nv() const = 0;
  // Entries of one tick's row of the desired table.
  virtual int desired_size() const = 0;
  // The command at in.time_s (see the header comment).
  virtual LawStatus command(const LawInput& in) = 0;
  // The tick of the last ok command is committed: a law with state takes its next state.
  virtual void commit() {}
  // The last ok command's signals, packed; tau (nv) at tau_offset().
  virtual const Eigen::VectorXd& signals() const = 0;
  virtual Eigen::Index tau_offset() const = 0;
  // (name, offset, size) of each signal in signals(), in order: the only place the layout
  // is written (the Python side reads its views from it).
  virtual std::vector<SignalSlot> signal_layout() const = 0;
};

}  // namespace uvms
