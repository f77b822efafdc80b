#include "batch_plant.hpp"

#include <cmath>
#include <exception>
#include <string>
#include <thread>

#include <pinocchio/algorithm/joint-configuration.hpp>

namespace uvms {

// A speed this large [m/s or rad/s] only comes out of a blown-up integration
// (uvms_pin/sim/divergence.py, DIVERGED_SPEED).
constexpr double kDivergedSpeed = 1e4;

void BatchActuation::apply(const ConstVec& tau_commanded, Eigen::Ref<Eigen::VectorXd> out) const {
  if (!limited) {
    out = tau_commanded;
    return;
  }
  const Eigen::VectorXd thrust =
      (allocation_pinv * tau_commanded.head<6>()).cwiseMax(lower_N).cwiseMin(upper_N);
  out.head<6>() = allocation * thrust;
  const Eigen::Index nj = tau_commanded.size() - 6;
  if (joint_limits_Nm.size() == 0) {
    out.tail(nj) = tau_commanded.tail(nj);
  } else {
    out.tail(nj) = tau_commanded.tail(nj).cwiseMax(-joint_limits_Nm).cwiseMin(joint_limits_Nm);
  }
}

namespace {

void check_actuation(const BatchActuation& a, int nv) {
  if (!a.limited) return;
  const Eigen::Index m = a.allocation.cols();
  if (a.allocation.rows() != 6 || m == 0 || a.allocation_pinv.rows() != m ||
      a.allocation_pinv.cols() != 6 || a.lower_N.size() != m || a.upper_N.size() != m) {
    throw InputError("batch actuation: B must be 6 x m, B^+ m x 6 and the limits m long");
  }
  if (a.joint_limits_Nm.size() != 0 && a.joint_limits_Nm.size() != nv - 6) {
    throw InputError("batch actuation: " + std::to_string(a.joint_limits_Nm.size()) +
                     " joint limits for " + std::to_string(nv - 6) + " arm joints");
  }
}

}  // namespace

BatchPlant::BatchPlant(const Plant& prototype, const FixedStep& integrator,
                       double control_period_s, BatchActuation actuation, BatchNoise noise,
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
  check_actuation(actuation_, nv_);
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
    plant->joint_stops = prototype.joint_stops;
    plants_.push_back(std::move(plant));
    scratch_.push_back({Eigen::VectorXd::Zero(nv_), Eigen::VectorXd::Zero(nv_),
                        Eigen::VectorXd::Zero(nv_), Eigen::VectorXd::Zero(nq_)});
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
  pinocchio::integrate(plant.dynamics().model(), qi, dq, scratch.q);
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
  actuation_.apply(command, scratch.tau);
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

void BatchPlant::step_range(int thread, int begin, int end, const double* tau_commanded,
                            const bool* stepping) {
  for (int i = begin; i < end; ++i) {
    if (stepping[i]) step_one(thread, i, tau_commanded);
  }
}

void BatchPlant::step(const double* tau_commanded, const bool* stepping) {
  const int threads = num_threads();
  // contiguous blocks: environment i always on the same thread for a given T (not that it
  // matters: an environment's numbers do not depend on the thread)
  std::vector<std::thread> workers;
  std::vector<std::exception_ptr> errors(threads);
  auto block = [&](int t) { return static_cast<int>((Eigen::Index(num_envs_) * t) / threads); };
  for (int t = 1; t < threads; ++t) {
    workers.emplace_back([&, t] {
      try {
        step_range(t, block(t), block(t + 1), tau_commanded, stepping);
      } catch (...) {
        errors[t] = std::current_exception();
      }
    });
  }
  try {
    step_range(0, block(0), block(1), tau_commanded, stepping);
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (auto& w : workers) w.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace uvms
