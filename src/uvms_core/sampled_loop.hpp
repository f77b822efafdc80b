// The sampled closed loop in one call per chunk of ticks (mirror of
// uvms_pin/sim/closed_loop.py, ClosedLoop._run_sampled and _tick, for the parts the core
// knows): at each tick t_k = k T
//   measure:  lambda = contact(q, v); wrench_meas = lambda + n_w(t_k);
//             q_meas = integrate(q, [0; n_o(t_k); n_j(t_k)]) with q_meas[:3] = q[:3] + n_p(t_k),
//             v_meas = v + n_v(t_k)   (sensors.py, SensorSuite.measure)
//   command:  tau_c = law(t_k, measurement, desired row k)   (law.hpp: the PPC, ppc.hpp; the
//             force baselines, law_force_baselines.hpp)
//   actuate:  f = clip(B_s^+ tau_c[s], -f_rev, f_fwd), tau_a = [B f; clip(tau_c,arm, +-limits)]
//             (actuation.hpp: actuation.py, ThrustersAndJointLimits with ideal drives; or tau_a = tau_c)
//   log:      every ticks_per_log-th tick, one packed row (see LoopRow)
//   advance:  (q, v) over [t_k, t_k + T] with tau_a held                  (plant.hpp)
// The noise samples n(t_k) and the desired values (f_d(t_k), rpy_d(t_k) for the force laws)
// come in as tables (drawn and evaluated by Python from the run's recorded seed and the
// user's functions), so both loops use the same numbers.
//
// A tick is committed whole or not at all: when anything in it is not the ordinary case (the
// law's status is not ok: a funnel left, the solver declining...; a non-finite tau; the plant's
// step failing or diverging), the chunk stops before that tick and the Python loop runs it,
// raising exactly as it always does. Nothing here touches Python: the caller releases the GIL.
#pragma once

#include <vector>

#include "actuation.hpp"
#include "plant.hpp"
#include "law.hpp"

namespace uvms {

// The loop's fixed settings for one run.
struct LoopSettings {
  FixedStep integrator;
  double period_s = 1e-3;
  int ticks_per_log = 1;
  int final_tick = 0;          // the last tick (logged, not advanced from)
  bool state_noisy = false;    // q, v measured with noise (else as they are)
};

// Where each logged quantity sits in a row (offsets), for nq, nv, m thrusters and the law's
// signal buffer of size n_signals.
struct LoopRow {
  LoopRow(int nq, int nv, int n_thrusters, int n_signals);
  int time, q, v, tau, tau_commanded, contact, measured_wrench, disturbance, signals, command,
      thrust, width;
};

// Noise row layout: wrench (6), orientation (3), position (3), joints (nv - 6), velocity (nv).
inline int noise_width(int nv) { return 6 + 3 + 3 + (nv - 6) + nv; }

// The actuation's state carried from tick to tick (in/out).
struct LoopActuationState {
  Eigen::Ref<Eigen::VectorXd> command, thrust, dropped_max;
};

struct ChunkOutcome {
  int ticks_done = 0;    // ticks committed, from the first
  int rows_written = 0;  // log rows of those ticks
  bool stopped = false;  // true: the next tick (first + ticks_done) is the Python loop's
};

// Ticks first .. first + n_ticks - 1 (at most to settings.final_tick) from (q, v) at tick
// `first`; q, v, the actuation's state and the law's signals are those after the last
// committed tick (law.commit() after each). noise: n_ticks x noise_width(nv); desired:
// n_ticks x law.desired_size(); log: at least the logged ticks' rows, each LoopRow::width wide.
ChunkOutcome run_sampled_chunk(Plant& plant, SampledLaw& law,
                               const Actuation& actuation, const LoopSettings& settings,
                               int first, int n_ticks, Eigen::Ref<Eigen::VectorXd> q,
                               Eigen::Ref<Eigen::VectorXd> v, const double* noise,
                               const double* desired, double* log, LoopActuationState state);

}  // namespace uvms
