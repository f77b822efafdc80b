// N environments of one plant advanced together over a control period, on T threads
// (mirror of one tick of uvms_pin/sim/closed_loop.py's sampled loop with the controller
// replaced by a given command, as the Gymnasium environments step it):
//   tau_applied = actuation(tau_commanded) (actuation.hpp); (q, v) advanced over the period with it held;
//   lambda = the contact wrench at the new state; the measurement = state + sensor noise.
// Each environment has its own state, contact anchor, sensor-noise tables (drawn from its
// own seed by the caller at reset, uvms_pin/sim/sensors.py's streams) and status. Each
// thread works on its own Plant (its own Pinocchio Data and scratch; the model is copied,
// read-only); an environment's numbers do not depend on the thread that computed them, so
// the results are the same for any T.
#pragma once

#include <atomic>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "actuation.hpp"
#include "plant.hpp"

namespace uvms {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The six noise channels of uvms_pin/sim/sensors.py, in its stream order.
enum NoiseChannel : int { kForce = 0, kTorque, kPosition, kOrientation, kJoints, kVelocity };
constexpr int kNoiseChannels = 6;

// Sensor noise sampled every sample_period_s, smoothstep-blended between samples (sensors.py,
// SampledNoise); rows samples per episode and environment. A silent channel is zero.
struct BatchNoise {
  double sample_period_s = 1e-3;
  int rows = 2;
  std::vector<int> silent = std::vector<int>(kNoiseChannels, 1);  // 1: zero
};

// What became of an environment in the last step.
enum BatchStatus : int { kRunning = 0, kDiverged = 1 };

class BatchPlant {
 public:
  BatchPlant(const Plant& prototype, const FixedStep& integrator, double control_period_s,
             Actuation actuation, BatchNoise noise, int num_envs, int num_threads);
  BatchPlant(const BatchPlant&) = delete;
  BatchPlant& operator=(const BatchPlant&) = delete;
  ~BatchPlant();

  int num_envs() const { return num_envs_; }
  int num_threads() const { return static_cast<int>(plants_.size()); }
  int nq() const { return nq_; }
  int nv() const { return nv_; }

  // Environment i starts at t = 0 from (q0, v0) (quaternion normalised by the caller), with
  // its contact (anchored) and noise tables (rows x width per channel; silent ones ignored).
  void reset(int i, const ConstVec& q0, const ConstVec& v0, const Contact& contact,
             const std::vector<RowMatrix>& noise_tables);
  // Every environment with stepping[i] advanced one control period under tau_commanded
  // (N x nv, row-major); the others are left as they are. A diverged one keeps its state.
  void step(const double* tau_commanded, const bool* stepping);

  // state and outputs, one row per environment
  RowMatrix q, v, q_measured, v_measured, wrench_measured, contact_world, tau_applied;
  Eigen::Matrix<long long, Eigen::Dynamic, 1> tick;  // control periods since the reset
  Eigen::Matrix<int, Eigen::Dynamic, 1> status;     // BatchStatus

 private:
  // Thread `thread` steps the environments it takes from the shared counter until none is
  // left (each takes the next one: the threads stay busy whatever each environment costs).
  void work(int thread);
  // The body of pool thread `thread` (1 .. T - 1): waits for a step, works, says it is done.
  void serve(int thread);
  void stop_pool();  // the pool threads told to quit and joined
  void step_one(int thread, int i, const double* tau_commanded);
  void measure(int thread, int i);
  // channel c's noise of environment i at time_s, into out (the channel's width)
  void noise_at(int c, int i, double time_s, Eigen::Ref<Eigen::VectorXd> out) const;

  int num_envs_, nq_, nv_;
  double period_s_;
  FixedStep integrator_;
  Actuation actuation_;
  BatchNoise noise_;
  bool state_noisy_;
  std::vector<int> widths_;
  std::vector<RowMatrix> tables_;  // channel c: (N rows) x width, env i at rows i*rows..
  std::vector<Contact> contacts_;
  std::vector<std::unique_ptr<Plant>> plants_;  // one per thread
  struct Scratch {
    Eigen::VectorXd tau, dq, noise, q, thrust;
  };
  std::vector<Scratch> scratch_;  // per thread

  // The pool: T - 1 threads started once (the calling thread is the T-th). Between steps a
  // pool thread spins (yielding) for up to 2 ms before it blocks, and so does the calling
  // thread waiting for them: a blocked thread's wake-up cost tens of us on each side of every step,
  // which held T = 2 to 1.7x T = 1 (now 1.87x, benchmarks/bench_gym.py).
  std::vector<std::thread> pool_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  // written under mutex_, read also without it while spinning (atomics)
  std::atomic<long long> round_{0};  // steps started (a pool thread works once per round)
  std::atomic<int> busy_{0};         // pool threads still working on this round
  bool quit_ = false;
  std::atomic<int> next_env_{0};
  const double* round_tau_ = nullptr;
  const bool* round_stepping_ = nullptr;
  std::vector<std::exception_ptr> errors_;  // per thread, of this round
};

}  // namespace uvms
