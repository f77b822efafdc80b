#include "batch_plant.hpp"

#include <cmath>
#include <exception>
#include <string>
#include <algorithm>
#include <chrono>
#include <thread>

#include <pinocchio/algorithm/joint-configuration.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms {

// A speed this large [m/s or rad/s] only comes out of a blown-up integration
// (uvms_pin/sim/divergence.py, DIVERGED_SPEED).
constexpr double kDivergedSpeed = 1e4;

BatchPlant::BatchPlant(const Plant& prototype, const FixedStep& integrator,
                       double control_period_s, Actuation actuation, BatchNoise noise,
                       int num_envs, int num_threads)
    : num_envs_(num_envs),
      nq_(prototype.dynamics().nq()),
      nv_(prototype.dynamics().nv()),
      period_s_(control_period_s),
      integrator_(integrator),
      actuation_(std::move(actuation)),
      noise_(std::move(noise)) {
  if (num_envs <= 0) throw InputError("num_envs must be >= 1, got " + std::to_string(num_envs));
  if (num_threads <= 0) {
    throw InputError("num_threads must be >= 1, got " + std::to_string(num_threads));
  }
  if (!(control_period_s > 0.0 && std::isfinite(control_period_s)) || !(integrator.step_s > 0.0)) {
    throw InputError("the batch needs a positive control period and integrator step");
  }
  if (!(noise_.sample_period_s > 0.0) || noise_.rows < 2 ||
      static_cast<int>(noise_.silent.size()) != kNoiseChannels) {
    throw InputError("batch noise: a positive sample period, >= 2 rows and 6 channels");
  }
  if (prototype.world_bounds.radii_m.size() != 0) {
    throw InputError("the batched plant has no world objects (they are integrated in Python)");
  }
  actuation_.check(nv_);
  widths_ = {3, 3, 3, 3, nv_ - 6, nv_};
  state_noisy_ = false;
  for (int c = kPosition; c < kNoiseChannels; ++c) state_noisy_ |= !noise_.silent[c];
  tables_.resize(kNoiseChannels);
  for (int c = 0; c < kNoiseChannels; ++c) {
    if (!noise_.silent[c]) tables_[c] = RowMatrix::Zero(Eigen::Index(num_envs) * noise_.rows, widths_[c]);
  }
  const int threads = std::min(num_threads, num_envs);
  for (int t = 0; t < threads; ++t) {
    auto plant = std::make_unique<Plant>(prototype.dynamics(), prototype.ee_frame_id());
    plant->flow = prototype.flow;
    plant->free_surface = prototype.free_surface;
    plant->disturbance = prototype.disturbance;
    plant->joint_friction = prototype.joint_friction;
    plant->fins = prototype.fins;
    plant->joint_stops = prototype.joint_stops;
    plant->joint_limits = prototype.joint_limits;
    plant->joint_coulomb_Nm = prototype.joint_coulomb_Nm;
    plants_.push_back(std::move(plant));
    scratch_.push_back({Eigen::VectorXd::Zero(nv_), Eigen::VectorXd::Zero(nv_),
                        Eigen::VectorXd::Zero(nv_), Eigen::VectorXd::Zero(nq_),
                        Eigen::VectorXd::Zero(actuation_.n_thrusters())});
  }
  contacts_.assign(num_envs, prototype.contact);
  q = RowMatrix::Zero(num_envs, nq_);
  v = RowMatrix::Zero(num_envs, nv_);
  q_measured = RowMatrix::Zero(num_envs, nq_);
  v_measured = RowMatrix::Zero(num_envs, nv_);
  wrench_measured = RowMatrix::Zero(num_envs, 6);
  contact_world = RowMatrix::Zero(num_envs, 6);
  tau_applied = RowMatrix::Zero(num_envs, nv_);
  tick = Eigen::Matrix<long long, Eigen::Dynamic, 1>::Zero(num_envs);
  status = Eigen::Matrix<int, Eigen::Dynamic, 1>::Zero(num_envs);
  errors_.assign(threads, nullptr);
  // last (a started thread must be joined: no destructor runs if the constructor throws)
  try {
    for (int t = 1; t < threads; ++t) pool_.emplace_back([this, t] { serve(t); });
  } catch (...) {
    stop_pool();
    throw;
  }
}

void BatchPlant::reset(int i, const ConstVec& q0, const ConstVec& v0, const Contact& contact,
                       const std::vector<RowMatrix>& noise_tables) {
  if (i < 0 || i >= num_envs_) throw InputError("no environment " + std::to_string(i));
  if (q0.size() != nq_ || v0.size() != nv_ || !q0.allFinite() || !v0.allFinite()) {
    throw InputError("reset: q0 and v0 must be finite, of the model's sizes");
  }
  if (static_cast<int>(noise_tables.size()) != kNoiseChannels) {
    throw InputError("reset: one noise table per channel (6)");
  }
  for (int c = 0; c < kNoiseChannels; ++c) {
    if (noise_.silent[c]) continue;
    const RowMatrix& table = noise_tables[c];
    if (table.rows() != noise_.rows || table.cols() != widths_[c] || !table.allFinite()) {
      throw InputError("reset: noise table " + std::to_string(c) + " must be " +
                       std::to_string(noise_.rows) + " x " + std::to_string(widths_[c]) +
                       " finite numbers");
    }
    tables_[c].middleRows(Eigen::Index(i) * noise_.rows, noise_.rows) = table;
  }
  q.row(i) = q0.transpose();
  v.row(i) = v0.transpose();
  tau_applied.row(i).setZero();
  contacts_[i] = contact;
  tick(i) = 0;
  status(i) = kRunning;
  plants_[0]->contact = contact;
  measure(0, i);
}

void BatchPlant::noise_at(int c, int i, double time_s, Eigen::Ref<Eigen::VectorXd> out) const {
  // sensors.py, SampledNoise.__call__: row k and k + 1, smoothstep between them
  const double position = std::max(time_s, 0.0) / noise_.sample_period_s;
  const long long k =
      std::min(static_cast<long long>(position + 1e-9), static_cast<long long>(noise_.rows - 2));
  const double s = std::min(std::max(position - static_cast<double>(k), 0.0), 1.0);
  const Eigen::Index row = Eigen::Index(i) * noise_.rows + k;
  const auto here = tables_[c].row(row).transpose();
  if (s < 1e-9) {
    out = here;
    return;
  }
  const auto after = tables_[c].row(row + 1).transpose();
  const double blend = s * s * (3.0 - 2.0 * s);
  out = here + blend * (after - here);
}

void BatchPlant::measure(int thread, int i) {
  Plant& plant = *plants_[thread];
  Scratch& scratch = scratch_[thread];
  const double time_s = static_cast<double>(tick(i)) * period_s_;
  const Eigen::VectorXd qi = q.row(i).transpose(), vi = v.row(i).transpose();
  const Vec6 lambda = plant.contact_wrench(qi, vi);
  contact_world.row(i) = lambda.transpose();
  Vec6 wrench = lambda;
  for (int c : {kForce, kTorque}) {
    if (noise_.silent[c]) continue;
    auto part = scratch.noise.head(3);
    noise_at(c, i, time_s, part);
    wrench.segment<3>(c == kForce ? 0 : 3) += part;
  }
  wrench_measured.row(i) = wrench.transpose();
  if (!state_noisy_) {
    q_measured.row(i) = q.row(i);
    v_measured.row(i) = v.row(i);
    return;
  }
  // sensors.py, SensorSuite.measure: orientation and joints by integrate, the position
  // noise a world offset, the velocity noise added
  Eigen::VectorXd& dq = scratch.dq;
  dq.setZero();
  if (!noise_.silent[kOrientation]) noise_at(kOrientation, i, time_s, dq.segment(3, 3));
  if (!noise_.silent[kJoints]) noise_at(kJoints, i, time_s, dq.tail(nv_ - 6));
  pinlib::integrate(plant.dynamics().model(), qi, dq, scratch.q);
  if (!noise_.silent[kPosition]) {
    auto part = scratch.noise.head(3);
    noise_at(kPosition, i, time_s, part);
    scratch.q.head<3>() = qi.head<3>() + part;
  } else {
    scratch.q.head<3>() = qi.head<3>();
  }
  q_measured.row(i) = scratch.q.transpose();
  if (!noise_.silent[kVelocity]) {
    noise_at(kVelocity, i, time_s, scratch.noise);
    v_measured.row(i) = (vi + scratch.noise).transpose();
  } else {
    v_measured.row(i) = v.row(i);
  }
}

void BatchPlant::step_one(int thread, int i, const double* tau_commanded) {
  Plant& plant = *plants_[thread];
  Scratch& scratch = scratch_[thread];
  const Eigen::Map<const Eigen::VectorXd> command(tau_commanded + Eigen::Index(i) * nv_, nv_);
  actuation_.apply(command, scratch.tau, scratch.thrust);
  tau_applied.row(i) = scratch.tau.transpose();
  plant.contact = contacts_[i];
  const double t0 = static_cast<double>(tick(i)) * period_s_;
  const double t1 = t0 + period_s_;  // closed_loop.py: t1 = t0 + period
  const Eigen::VectorXd qi = q.row(i).transpose(), vi = v.row(i).transpose();
  try {
    auto [q1, v1] = plant.advance(t0, qi, vi, scratch.tau, t1, integrator_);
    // divergence.py, diverged: a non-finite state or a speed no UVMS reaches
    if (!q1.allFinite() || !v1.allFinite() || v1.cwiseAbs().maxCoeff() > kDivergedSpeed) {
      status(i) = kDiverged;
      return;
    }
    q.row(i) = q1.transpose();
    v.row(i) = v1.transpose();
  } catch (const std::exception&) {  // a failed solve (SimulationFailure) is a divergence
    status(i) = kDiverged;
    return;
  }
  tick(i) += 1;
  measure(thread, i);
}

void BatchPlant::work(int thread) {
  try {
    for (int i = next_env_.fetch_add(1); i < num_envs_; i = next_env_.fetch_add(1)) {
      if (round_stepping_[i]) step_one(thread, i, round_tau_);
    }
  } catch (...) {
    errors_[thread] = std::current_exception();
  }
}

namespace {

// Spin (yielding) on a condition for up to 2 ms before blocking on a condition variable: a
// step's serial part (the Python between two steps) is ~0.1 ms, and waking a blocked thread
// costs tens of us of every step on each side. A thread left idle longer (a policy's forward
// pass, an episode's end) sleeps.
template <typename Ready>
void spin_until(Ready ready) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(2000);
  while (!ready() && std::chrono::steady_clock::now() < until) std::this_thread::yield();
}

}  // namespace

void BatchPlant::serve(int thread) {
  long long served = 0;
  for (;;) {
    spin_until([&] { return round_.load() != served; });
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return quit_ || round_ != served; });
      if (quit_) return;
      served = round_;
    }
    work(thread);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (--busy_ == 0) done_.notify_one();
    }
  }
}

void BatchPlant::step(const double* tau_commanded, const bool* stepping) {
  // an environment's numbers do not depend on the thread that steps it (each thread has its
  // own Plant, a copy of the prototype; the contact is the environment's own)
  round_tau_ = tau_commanded;
  round_stepping_ = stepping;
  next_env_.store(0);
  std::fill(errors_.begin(), errors_.end(), nullptr);
  if (!pool_.empty()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = static_cast<int>(pool_.size());
      ++round_;
    }
    wake_.notify_all();
  }
  work(0);
  if (!pool_.empty()) {
    spin_until([&] { return busy_.load() == 0; });
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return busy_ == 0; });
  }
  for (const auto& e : errors_) {
    if (e) std::rethrow_exception(e);
  }
}

void BatchPlant::stop_pool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
  }
  wake_.notify_all();
  for (auto& t : pool_) t.join();
  pool_.clear();
}

BatchPlant::~BatchPlant() { stop_pool(); }

}  // namespace uvms
