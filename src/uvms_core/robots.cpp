#include "robots.hpp"

#include <string>

namespace uvms {

namespace {

// Every system's model in order, each system's tree under the universe (joined_model of
// robots.py).
Model joined(const std::vector<System*>& systems) {
  Model out;
  for (std::size_t k = 0; k < systems.size(); ++k) {
    if (systems[k] == nullptr) throw InputError("robots: a robot without a system");
    const Model& model = systems[k]->model();
    const auto offset = static_cast<pinocchio::JointIndex>(out.njoints - 1);
    for (pinocchio::JointIndex j = 1; j < static_cast<pinocchio::JointIndex>(model.njoints); ++j) {
      const pinocchio::JointIndex parent = model.parents[j];
      out.addJoint(parent == 0 ? 0 : parent + offset, model.joints[j], model.jointPlacements[j],
                   "robot_" + std::to_string(k) + "/" + model.names[j]);
    }
  }
  return out;
}

}  // namespace

RobotsSystem::RobotsSystem(const std::vector<System*>& systems)
    : systems_(systems), model_(joined(systems)), stepper_(model_), acceleration_(model_.nv) {
  Eigen::Index at_q = 0, at_v = 0;
  for (const System* system : systems_) {
    q_at_.push_back(at_q);
    v_at_.push_back(at_v);
    at_q += system->nq();
    at_v += system->nv();
  }
}

const Data& RobotsSystem::data_of(int side) {
  const auto n = static_cast<int>(systems_.size());
  return side < n ? systems_[static_cast<std::size_t>(side)]->robot_data()
                  : systems_[0]->object_data(static_cast<std::size_t>(side - n));
}

const Model& RobotsSystem::model_of(int side) const {
  const auto n = static_cast<int>(systems_.size());
  return side < n ? systems_[static_cast<std::size_t>(side)]->plant().dynamics().model()
                  : systems_[0]->object_model(static_cast<std::size_t>(side - n));
}

void RobotsSystem::check() const {
  const auto n = static_cast<int>(systems_.size() + systems_[0]->n_objects());
  for (const auto& set : sets) {
    if (set.a < 0 || set.a >= n || set.b < 0 || set.b >= n) {
      throw InputError("robots: a pair set's sides are not a robot or the first's object");
    }
    set.pairs.check(model_of(set.a), model_of(set.b));
  }
}

void RobotsSystem::push(int side, int joint_id, const Vec3& point, const Vec3& force) {
  const auto n = static_cast<int>(systems_.size());
  System::Push out;
  out.joint_id = joint_id;
  out.point = point;
  out.force = force;
  if (side < n) {
    out.side = -1;
    systems_[static_cast<std::size_t>(side)]->pushes.push_back(out);
  } else {
    out.side = side - n;
    systems_[0]->pushes.push_back(out);
  }
}

const Eigen::VectorXd& RobotsSystem::acceleration(double time_s, const ConstVec& q,
                                                  const ConstVec& v,
                                                  const std::vector<Eigen::VectorXd>& taus) {
  if (taus.size() != systems_.size()) throw InputError("robots: one input tau per robot");
  for (std::size_t k = 0; k < systems_.size(); ++k) {
    if (taus[k].size() != systems_[k]->plant().dynamics().nv() || !taus[k].allFinite()) {
      throw InputError("robots: robot " + std::to_string(k) + "'s tau: its nv finite numbers");
    }
  }
  for (std::size_t k = 0; k < systems_.size(); ++k) {
    System& system = *systems_[k];
    system.pushes.clear();
    system.kinematics(q.segment(q_at_[k], system.nq()), v.segment(v_at_[k], system.nv()));
  }
  found_.resize(sets.size());
  for (std::size_t s = 0; s < sets.size(); ++s) {
    PairSet& set = sets[s];
    set.pairs.forces(data_of(set.a), data_of(set.b), set.memory, found_[s]);
    const auto& found = found_[s].forces;
    for (std::size_t i = 0; i < found.touch.size(); ++i) {
      const auto& a = set.pairs.pieces_a[static_cast<std::size_t>(found.touch.piece[i])];
      const auto& b = set.pairs.pieces_b[static_cast<std::size_t>(found.touch.obj[i])];
      push(set.a, a.joint_id, found.touch.point_world_m[i], found.force_world_N[i]);
      push(set.b, b.joint_id, found.touch.point_world_m[i], -found.force_world_N[i]);
    }
  }
  try {
    for (std::size_t k = 0; k < systems_.size(); ++k) {
      System& system = *systems_[k];
      acceleration_.segment(v_at_[k], system.nv()) = system.acceleration(
          time_s, q.segment(q_at_[k], system.nq()), v.segment(v_at_[k], system.nv()), taus[k]);
    }
  } catch (...) {
    for (System* system : systems_) system->pushes.clear();
    throw;
  }
  for (System* system : systems_) system->pushes.clear();
  return acceleration_;
}

std::pair<Eigen::VectorXd, Eigen::VectorXd> RobotsSystem::integrate(
    double t0, const ConstVec& q0, const ConstVec& v0, const std::vector<Eigen::VectorXd>& taus,
    double t1, const FixedStep& integrator) {
  if (q0.size() != model_.nq || v0.size() != model_.nv) {
    throw InputError("robots: q0 (" + std::to_string(model_.nq) + ",) and v0 (" +
                     std::to_string(model_.nv) + ",) expected");
  }
  if (!(t1 > t0) || !(integrator.step_s > 0.0)) {
    throw InputError("integrate needs t1 > t0 and a positive step");
  }
  check();
  for (System* system : systems_) system->check();
  stepper_.q = q0;
  stepper_.v = v0;
  auto rhs = [&](double t, const Eigen::VectorXd& q,
                 const Eigen::VectorXd& v) -> const Eigen::VectorXd& {
    return acceleration(t, q, v, taus);
  };
  stepper_.advance(rhs, t0, t1, integrator);
  return {stepper_.q, stepper_.v};
}

}  // namespace uvms
