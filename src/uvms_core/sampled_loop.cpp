#include "sampled_loop.hpp"

#include <cmath>
#include <utility>

#include <pinocchio/algorithm/joint-configuration.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms {

namespace {

// divergence.py, DIVERGED_SPEED: a speed [m/s or rad/s] only a blown-up integration gives.
constexpr double kDivergedSpeed = 1e4;

bool diverged(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  return !q.allFinite() || !v.allFinite() || v.cwiseAbs().maxCoeff() > kDivergedSpeed;
}

// The work of one tick, committed only when the whole tick succeeded.
struct Tick {
  explicit Tick(int nq, int nv, int m)
      : q_meas(nq), v_meas(nv), dq(nv), tau_applied(nv), tau_commanded(nv), command(m),
        thrust(m), dropped(0) {}
  Eigen::VectorXd q_meas, v_meas, dq, tau_applied, tau_commanded, command, thrust, dropped;
  Vec6 contact, wrench;
};

}  // namespace

LoopRow::LoopRow(int nq, int nv, int n_thrusters, int n_signals) {
  time = 0;
  q = 1;
  v = q + nq;
  tau = v + nv;
  tau_commanded = tau + nv;
  contact = tau_commanded + nv;
  measured_wrench = contact + 6;
  disturbance = measured_wrench + 6;
  signals = disturbance + 6;
  command = signals + n_signals;
  thrust = command + n_thrusters;
  width = thrust + n_thrusters;
}

ChunkOutcome run_sampled_chunk(Plant& plant, SampledLaw& law,
                               const Actuation& actuation, const LoopSettings& settings,
                               int first, int n_ticks, Eigen::Ref<Eigen::VectorXd> q,
                               Eigen::Ref<Eigen::VectorXd> v, const double* noise,
                               const double* desired, double* log, LoopActuationState state) {
  const auto& model = plant.dynamics().model();
  const int nq = model.nq, nv = model.nv, nj = nv - 6;
  const int m = static_cast<int>(state.thrust.size());
  const LoopRow row(nq, nv, m, static_cast<int>(law.signals().size()));
  const int width = noise_width(nv);
  const int desired_width = law.desired_size();
  Tick w(nq, nv, m);
  Eigen::VectorXd q_now = q, v_now = v;
  ChunkOutcome out;
  for (int i = 0; i < n_ticks && first + i <= settings.final_tick; ++i) {
    const int tick = first + i;
    const double time_s = static_cast<double>(tick) * settings.period_s;
    const double* n = noise + static_cast<std::ptrdiff_t>(i) * width;
    // ---- measure (sensors.py, SensorSuite.measure)
    w.contact = plant.contact_wrench(q_now, v_now);
    w.wrench = w.contact + Eigen::Map<const Vec6>(n);
    const double* q_in = q_now.data();
    const double* v_in = v_now.data();
    if (settings.state_noisy) {
      w.dq.setZero();
      w.dq.segment<3>(3) = Eigen::Map<const Vec3>(n + 6);
      w.dq.tail(nj) = Eigen::Map<const Eigen::VectorXd>(n + 12, nj);
      pinlib::integrate(model, q_now, w.dq, w.q_meas);
      w.q_meas.head<3>() = q_now.head<3>() + Eigen::Map<const Vec3>(n + 9);
      w.v_meas = v_now + Eigen::Map<const Eigen::VectorXd>(n + 12 + nj, nv);
      q_in = w.q_meas.data();
      v_in = w.v_meas.data();
    }
    // ---- command (law.hpp); anything but ok is the Python loop's tick
    LawInput input;
    input.time_s = time_s;
    input.q = q_in;
    input.v = v_in;
    input.wrench_world = w.wrench.data();
    input.desired = desired + static_cast<std::ptrdiff_t>(i) * desired_width;
    if (law.command(input) != LawStatus::ok) {
      out.stopped = true;
      return out;
    }
    const Eigen::VectorXd& signals = law.signals();
    w.tau_commanded = signals.segment(law.tau_offset(), nv);
    if (!w.tau_commanded.allFinite()) {
      out.stopped = true;
      return out;
    }
    // ---- actuate (actuation.py)
    w.command = state.command;
    w.thrust = state.thrust;
    w.dropped = state.dropped_max;
    actuation.track_dropped(w.tau_commanded, w.dropped);
    actuation.apply(w.tau_commanded, w.tau_applied, w.thrust);
    if (actuation.thrusters) actuation.commands(w.thrust, w.command);
    // ---- log (log.py, RolloutLog.on_sample): written now, counted once the tick commits
    const bool logged = tick % settings.ticks_per_log == 0;
    if (logged) {
      double* r = log + static_cast<std::ptrdiff_t>(out.rows_written) * row.width;
      r[row.time] = time_s;
      Eigen::Map<Eigen::VectorXd>(r + row.q, nq) = q_now;
      Eigen::Map<Eigen::VectorXd>(r + row.v, nv) = v_now;
      Eigen::Map<Eigen::VectorXd>(r + row.tau, nv) = w.tau_applied;
      Eigen::Map<Eigen::VectorXd>(r + row.tau_commanded, nv) = w.tau_commanded;
      Eigen::Map<Vec6>(r + row.contact) = w.contact;
      Eigen::Map<Vec6>(r + row.measured_wrench) = w.wrench;
      Eigen::Map<Vec6> disturbance(r + row.disturbance);
      if (plant.disturbance) {
        disturbance = plant.disturbance->at(time_s);
      } else {
        disturbance.setZero();
      }
      Eigen::Map<Eigen::VectorXd>(r + row.signals, signals.size()) = signals;
      Eigen::Map<Eigen::VectorXd>(r + row.command, m) = w.command;
      Eigen::Map<Eigen::VectorXd>(r + row.thrust, m) = w.thrust;
    }
    // ---- advance (plant.hpp), unless this is the run's last tick
    if (tick < settings.final_tick) {
      try {
        auto [q_next, v_next] = plant.advance(time_s, q_now, v_now, w.tau_applied,
                                              time_s + settings.period_s, settings.integrator);
        if (diverged(q_next, v_next)) {
          out.stopped = true;
          return out;
        }
        q_now = std::move(q_next);
        v_now = std::move(v_next);
      } catch (const std::exception&) {  // the Python loop's step says why
        out.stopped = true;
        return out;
      }
    }
    // ---- commit
    law.commit();
    state.command = w.command;
    state.thrust = w.thrust;
    state.dropped_max = w.dropped;
    q = q_now;
    v = v_now;
    out.ticks_done = i + 1;
    out.rows_written += logged ? 1 : 0;
  }
  return out;
}

}  // namespace uvms
