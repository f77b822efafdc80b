#include "robots.hpp"

#include <cmath>
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

std::pair<Eigen::VectorXd, Eigen::VectorXd> RobotsSystem::advance(
    double t0, const ConstVec& q0, const ConstVec& v0, const std::vector<Eigen::VectorXd>& taus,
    double t1, const FixedStep& integrator) {
  auto out = integrate(t0, q0, v0, taus, t1, integrator);
  Eigen::VectorXd& q1 = out.first;
  Eigen::VectorXd& v1 = out.second;
  // a smooth step that diverged is returned as it is: the loop names the divergence
  if (!(q1.allFinite() && v1.allFinite())) return out;
  // every anchor moves at the smooth step's end: each system's own (its fixed world, its pairs,
  // its objects'), then the sets between the sides
  for (std::size_t k = 0; k < systems_.size(); ++k) {
    System& system = *systems_[k];
    system.settle(q1.segment(q_at_[k], system.nq()), v1.segment(v_at_[k], system.nv()));
  }
  kinematics(q1, v1);
  found_.resize(sets.size());
  for (std::size_t s = 0; s < sets.size(); ++s) {
    PairSet& set = sets[s];
    set.pairs.forces(data_of(set.a), data_of(set.b), set.memory, found_[s]);
    set.pairs.commit(data_of(set.b), found_[s], set.memory);
  }
  // then each system's constraints, from its start (they act within a system only)
  for (std::size_t k = 0; k < systems_.size(); ++k) {
    System& system = *systems_[k];
    Eigen::VectorXd q1_k = q1.segment(q_at_[k], system.nq());
    Eigen::VectorXd v1_k = v1.segment(v_at_[k], system.nv());
    system.constrain(t0, q0.segment(q_at_[k], system.nq()), v0.segment(v_at_[k], system.nv()), t1,
                     q1_k, v1_k);
    q1.segment(q_at_[k], system.nq()) = q1_k;
    v1.segment(v_at_[k], system.nv()) = v1_k;
  }
  return out;
}

void RobotsSystem::kinematics(const ConstVec& q, const ConstVec& v) {
  for (std::size_t k = 0; k < systems_.size(); ++k) {
    System& system = *systems_[k];
    system.kinematics(q.segment(q_at_[k], system.nq()), v.segment(v_at_[k], system.nv()));
  }
}

void RobotsSystem::side_state(std::size_t side, Eigen::Index& at_q, Eigen::Index& at_v,
                              Eigen::Index& nv) const {
  if (side < systems_.size()) {  // a robot: its system's first block
    at_q = q_at_[side];
    at_v = v_at_[side];
    nv = systems_[side]->plant().dynamics().model().nv;
    return;
  }
  // the first system's object i: a free-flyer after its robot
  const auto i = static_cast<Eigen::Index>(side - systems_.size());
  const Model& robot = systems_[0]->plant().dynamics().model();
  at_q = q_at_[0] + robot.nq + 7 * i;
  at_v = v_at_[0] + robot.nv + 6 * i;
  nv = 6;
}

void RobotsSystem::root_spheres(const ConstVec& q, const ConstVec& v, double horizon_s) {
  const std::size_t n_sides = systems_.size() + systems_[0]->n_objects();
  if (reach_m.size() != n_sides) {
    throw InputError("robots: one reach per side (the robots, then the first's objects)");
  }
  if (q.size() != model_.nq || v.size() != model_.nv) throw InputError("robots: q, v sizes");
  // each side's sphere about its root (robot_reach.reach_sphere)
  centers_.resize(n_sides);
  radii_.resize(n_sides);
  for (std::size_t side = 0; side < n_sides; ++side) {
    Eigen::Index at_q = 0, at_v = 0, nv = 0;
    side_state(side, at_q, at_v, nv);
    centers_[side] = q.segment<3>(at_q);
    const double reach = reach_m[side];
    if (std::isinf(reach)) {
      radii_[side] = reach;
      continue;
    }
    const double speed = v.segment<3>(at_v).norm() + v.segment<3>(at_v + 3).norm() * reach +
                         2.0 * reach * v.segment(at_v + 6, nv - 6).cwiseAbs().sum();
    radii_[side] = reach + 2.0 * speed * horizon_s + clearance_m;
  }
}

bool RobotsSystem::near(const ConstVec& q, const ConstVec& v, double horizon_s) {
  root_spheres(q, v, horizon_s);
  const std::vector<Vec3>& centers = centers_;
  const std::vector<double>& radii = radii_;
  std::vector<std::size_t>& close = close_;
  close.clear();
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const auto a = static_cast<std::size_t>(sets[s].a), b = static_cast<std::size_t>(sets[s].b);
    if (!sets[s].pairs.pairs.empty() && (centers[a] - centers[b]).norm() < radii[a] + radii[b]) {
      close.push_back(s);
    }
  }
  if (close.empty()) return false;
  kinematics(q, v);
  // a piece's sphere over the horizon (touch.reach_spheres), its centre in the world
  auto sphere = [&](int side, const ContactShape& piece, Vec3& center) {
    const Data& data = data_of(side);
    const auto j = static_cast<std::size_t>(piece.joint_id);
    const Vec3 local = piece.placement_in_joint.translation();
    const auto& twist = data.v[j];
    const double speed = twist.linear().norm() +
                         twist.angular().norm() * (local.norm() + piece.bound_radius_m);
    center = data.oMi[j].act(local);
    return piece.bound_radius_m + 2.0 * speed * horizon_s + clearance_m;
  };
  for (const std::size_t s : close) {
    const PairSet& set = sets[s];
    for (const auto& [i, j] : set.pairs.pairs) {
      Vec3 center_a, center_b;
      const double r_a = sphere(set.a, set.pairs.pieces_a[static_cast<std::size_t>(i)], center_a);
      const double r_b = sphere(set.b, set.pairs.pieces_b[static_cast<std::size_t>(j)], center_b);
      if ((center_a - center_b).norm() < r_a + r_b) return true;
    }
  }
  return false;
}

Eigen::MatrixXd RobotsSystem::object_wrenches(const ConstVec& q, const ConstVec& v) {
  if (q.size() != model_.nq || v.size() != model_.nv) throw InputError("robots: q, v sizes");
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(systems_.size()), 6);
  // f on the robot (side a) at x: -f on the object, its moment x (-f) about the origin
  auto add = [&](std::size_t robot, const ContactForces& found) {
    const auto k = static_cast<Eigen::Index>(robot);
    for (std::size_t i = 0; i < found.touch.size(); ++i) {
      const Vec3 on_object = -found.force_world_N[i];
      out.row(k).head<3>() += on_object.transpose();
      out.row(k).tail<3>() += found.touch.point_world_m[i].cross(on_object).transpose();
    }
  };
  System& first = *systems_[0];
  first.contacts(q.segment(q_at_[0], first.nq()), v.segment(v_at_[0], first.nv()));
  const auto& own = first.found_sets();
  const auto n_objects = static_cast<int>(first.n_objects());
  for (std::size_t s = 0; s < first.sets.size(); ++s) {
    const PairSet& set = first.sets[s];
    if (set.a < 0 && set.b >= 0 && set.b < n_objects) add(0, own[s].forces);
  }
  kinematics(q, v);
  const auto n = static_cast<int>(systems_.size());
  found_.resize(sets.size());
  for (std::size_t s = 0; s < sets.size(); ++s) {
    PairSet& set = sets[s];
    if (set.a >= n || set.b < n) continue;  // a robot's set with an object only
    set.pairs.forces(data_of(set.a), data_of(set.b), set.memory, found_[s]);
    add(static_cast<std::size_t>(set.a), found_[s].forces);
  }
  return out;
}

}  // namespace uvms
