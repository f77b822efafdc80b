#include "system.hpp"

#include "joint_box.hpp"
#include "pinocchio_kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/multibody/joint/joint-free-flyer.hpp>

namespace uvms {

namespace {

// A free object whose velocity the period's impulses changed by at most this [m/s, rad/s]
// keeps the smooth step's end (period.py's PUSHED_M_S)
constexpr double kPushed = 1.0e-9;

// The robot's joints, n free-flyers under the universe (_system_model of system.py), then
// every fixture's joints, its root joints under the universe (fixtures.system_model).
Model system_model(const Model& robot, std::size_t n_objects,
                   const std::vector<FixtureBody>& fixtures) {
  Model model = robot;
  for (std::size_t k = 0; k < n_objects; ++k) {
    model.addJoint(0, pinocchio::JointModelFreeFlyer(), pinocchio::SE3::Identity(),
                   "free_object_" + std::to_string(k));
  }
  for (std::size_t k = 0; k < fixtures.size(); ++k) {
    const Model& own = fixtures[k].body.model();
    std::vector<pinocchio::JointIndex> ids{0};
    for (pinocchio::JointIndex j = 1; j < static_cast<pinocchio::JointIndex>(own.njoints); ++j) {
      ids.push_back(model.addJoint(ids[own.parents[j]], own.joints[j], own.jointPlacements[j],
                                   "fixture_" + std::to_string(k) + "/" + own.names[j]));
    }
  }
  return model;
}

std::vector<FixtureBody> checked(std::vector<FixtureBody> fixtures) {
  for (const auto& f : fixtures) {
    const Model& model = f.body.model();
    const auto n = static_cast<Eigen::Index>(model.nv);
    if (model.nq != model.nv) {
      throw InputError("system: a fixture's joints are revolute or prismatic (nq = nv)");
    }
    if (f.damping.size() != n || f.coulomb.size() != n || f.lower.size() != n ||
        f.upper.size() != n) {
      throw InputError("system: a fixture needs damping, coulomb, lower and upper (" +
                       std::to_string(n) + ",) each");
    }
    if ((f.coulomb.array() < 0.0).any() || (f.damping.array() < 0.0).any() ||
        f.coulomb.hasNaN() || f.damping.hasNaN() || f.lower.hasNaN() || f.upper.hasNaN()) {
      throw InputError("system: a fixture's damping and friction are >= 0, its limits numbers");
    }
  }
  return fixtures;
}

std::vector<Dynamics> copies(const std::vector<const Dynamics*>& objects) {
  std::vector<Dynamics> out;
  out.reserve(objects.size());
  for (const Dynamics* body : objects) {
    if (body == nullptr) throw InputError("system: a free object without dynamics");
    if (body->nq() != 7 || body->nv() != 6) {
      throw InputError("system: a free object is one floating body (nq 7, nv 6)");
    }
    out.emplace_back(*body);
  }
  return out;
}

// The rotation of a pose [p; quaternion x, y, z, w].
Eigen::Matrix3d rotation_of(const Eigen::Ref<const Eigen::VectorXd>& pose) {
  return Eigen::Quaterniond(pose[6], pose[3], pose[4], pose[5]).normalized().toRotationMatrix();
}

void add_wrench(Dynamics& dynamics, int joint_id, const Vec3& point, const Vec3& force) {
  Vec6 wrench = Vec6::Zero();
  wrench.head<3>() = force;
  dynamics.add_world_wrench(joint_id, point, wrench);
}

}  // namespace

System::System(Plant& plant, const std::vector<const Dynamics*>& objects,
               std::vector<FixtureBody> fixtures)
    : plant_(plant),
      objects_(copies(objects)),
      fixtures_(checked(std::move(fixtures))),
      model_(system_model(plant.dynamics().model(), objects.size(), fixtures_)),
      robot_data_(plant.dynamics().model()),
      nq_robot_(plant.dynamics().nq()),
      nv_robot_(plant.dynamics().nv()),
      stepper_(model_),
      acceleration_(model_.nv) {
  object_worlds.resize(objects_.size());
  object_memory.resize(objects_.size());
  rigid_found_.resize(objects_.size());
  Eigen::Index at_q = nq_robot_ + 7 * static_cast<Eigen::Index>(objects_.size());
  Eigen::Index at_v = nv_robot_ + 6 * static_cast<Eigen::Index>(objects_.size());
  for (const auto& f : fixtures_) {
    fixture_q_.push_back(at_q);
    fixture_v_.push_back(at_v);
    at_q += f.body.nq();
    at_v += f.body.nv();
  }
}

Dynamics& System::body_of(int side) {
  const auto k = static_cast<std::size_t>(side);
  return k < objects_.size() ? objects_[k] : fixtures_[k - objects_.size()].body;
}

const Data& System::data_of(int side) {
  return side < 0 ? *robot_at_ : body_of(side).data();
}

const Model& System::model_of(int side) const {
  if (side < 0) return plant_.dynamics().model();
  const auto k = static_cast<std::size_t>(side);
  return k < objects_.size() ? objects_[k].model() : fixtures_[k - objects_.size()].body.model();
}

void System::check() const {
  const int n = static_cast<int>(objects_.size() + fixtures_.size());
  for (const auto& set : sets) {
    if (set.a < -1 || set.a >= n || set.b < -1 || set.b >= n) {
      throw InputError(
          "system: a pair set's bodies are not the robot, a free object or a fixture");
    }
    set.pairs.check(model_of(set.a), model_of(set.b));
  }
  if (object_worlds.size() != objects_.size() || object_memory.size() != objects_.size()) {
    throw InputError("system: one world (or none) and one friction state per free object");
  }
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    if (object_worlds[k]) object_worlds[k]->check(objects_[k].model());
  }
}

void System::object_kinematics(const ConstVec& q, const ConstVec& v) {
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    objects_[k].kinematics(q.segment(nq_robot_ + 7 * i, 7), v.segment(nv_robot_ + 6 * i, 6));
  }
  for (std::size_t k = 0; k < fixtures_.size(); ++k) {
    Dynamics& body = fixtures_[k].body;
    body.kinematics(q.segment(fixture_q_[k], body.nq()), v.segment(fixture_v_[k], body.nv()));
  }
}

void System::contacts_at(const Data& robot) {
  robot_at_ = &robot;
  found_sets_.resize(sets.size());
  for (std::size_t s = 0; s < sets.size(); ++s) {
    auto& set = sets[s];
    if (rigid_pairs) {  // the constraints' impulses: no force in the smooth dynamics
      found_sets_[s].forces.touch.clear();
      found_sets_[s].pair.clear();
      continue;
    }
    set.pairs.forces(data_of(set.a), data_of(set.b), set.memory, found_sets_[s]);
  }
  found_objects_.resize(objects_.size());
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    found_objects_[k].touch.clear();
    if (object_worlds[k] && !rigid_objects) {
      object_worlds[k]->forces(objects_[k].data(), object_memory[k], found_objects_[k]);
    }
  }
}

void System::kinematics(const ConstVec& q, const ConstVec& v) {
  pinlib::forward_kinematics(plant_.dynamics().model(), robot_data_, q.head(nq_robot_),
                               v.head(nv_robot_));
  object_kinematics(q, v);
}

void System::contacts(const ConstVec& q, const ConstVec& v) {
  kinematics(q, v);
  contacts_at(robot_data_);
}

void System::add_robot_forces(Dynamics& robot) {
  contacts_at(robot.data());
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const auto& set = sets[s];
    if (set.a >= 0 && set.b >= 0) continue;
    const auto& found = found_sets_[s].forces;
    for (std::size_t i = 0; i < found.touch.size(); ++i) {
      const auto& point = found.touch.point_world_m[i];
      const auto& force = found.force_world_N[i];
      if (set.a < 0) {
        const auto& piece = set.pairs.pieces_a[static_cast<std::size_t>(found.touch.piece[i])];
        add_wrench(robot, piece.joint_id, point, force);
      }
      if (set.b < 0) {
        const auto& piece = set.pairs.pieces_b[static_cast<std::size_t>(found.touch.obj[i])];
        add_wrench(robot, piece.joint_id, point, -force);
      }
    }
  }
  for (const Push& push : pushes) {
    if (push.side < 0) add_wrench(robot, push.joint_id, push.point, push.force);
  }
}

const Eigen::VectorXd& System::acceleration(double time_s, const ConstVec& q,
                                            const ConstVec& v, const ConstVec& tau) {
  object_kinematics(q, v);
  // the robot: its plant's acceleration, the moving contacts computed and added once its
  // kinematics is done (add_robot_forces)
  plant_.moving_contacts = [this](Dynamics& robot) { add_robot_forces(robot); };
  try {
    acceleration_.head(nv_robot_) =
        plant_.acceleration(time_s, q.head(nq_robot_), v.head(nv_robot_), tau);
  } catch (...) {
    plant_.moving_contacts = nullptr;
    throw;
  }
  plant_.moving_contacts = nullptr;
  // each object: its water, then its contacts (f on a, -f on b; the fixed world's reaction
  // goes to the ground)
  const FlowField& flow = plant_.flow;
  for (std::size_t k = 0; k < objects_.size() + fixtures_.size(); ++k) {
    Dynamics& body = body_of(static_cast<int>(k));
    body.fluid_wrenches(time_s, flow, body.needs_bias_acceleration(), plant_.free_surface);
  }
  // a piece on a fixture's root link (joint 0, fixed in the world) moves nothing
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const auto& set = sets[s];
    const auto& found = found_sets_[s].forces;
    for (std::size_t i = 0; i < found.touch.size(); ++i) {
      const auto& point = found.touch.point_world_m[i];
      const auto& force = found.force_world_N[i];
      if (set.a >= 0) {
        const auto& piece = set.pairs.pieces_a[static_cast<std::size_t>(found.touch.piece[i])];
        if (piece.joint_id > 0) add_wrench(body_of(set.a), piece.joint_id, point, force);
      }
      if (set.b >= 0) {
        const auto& piece = set.pairs.pieces_b[static_cast<std::size_t>(found.touch.obj[i])];
        if (piece.joint_id > 0) add_wrench(body_of(set.b), piece.joint_id, point, -force);
      }
    }
  }
  for (const Push& push : pushes) {
    if (push.side >= 0 && push.joint_id > 0) {
      add_wrench(body_of(push.side), push.joint_id, push.point, push.force);
    }
  }
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    Dynamics& body = objects_[k];
    if (object_worlds[k] && !rigid_objects) object_worlds[k]->add_to(body, found_objects_[k]);
    const auto i = static_cast<Eigen::Index>(k);
    acceleration_.segment(nv_robot_ + 6 * i, 6) = body.accelerations(
        q.segment(nq_robot_ + 7 * i, 7), v.segment(nv_robot_ + 6 * i, 6), zero_tau_, nullptr);
  }
  // each fixture: its joints' viscous friction -D qd as their input
  for (std::size_t k = 0; k < fixtures_.size(); ++k) {
    FixtureBody& f = fixtures_[k];
    const auto v_f = v.segment(fixture_v_[k], f.body.nv());
    const Eigen::VectorXd viscous = -f.damping.cwiseProduct(v_f);
    acceleration_.segment(fixture_v_[k], f.body.nv()) =
        f.body.accelerations(q.segment(fixture_q_[k], f.body.nq()), v_f, viscous, nullptr);
  }
  return acceleration_;
}

void System::settle(const ConstVec& q, const ConstVec& v) {
  if (plant_.world) {  // the robot's fixed world (Plant.settle)
    plant_.world->commit(plant_.world_forces(q.head(nq_robot_), v.head(nv_robot_)),
                         plant_.friction);
  }
  contacts(q, v);
  for (std::size_t s = 0; s < sets.size() && !rigid_pairs; ++s) {  // rigid: by constrain()
    sets[s].pairs.commit(data_of(sets[s].b), found_sets_[s], sets[s].memory);
  }
  for (std::size_t k = 0; k < objects_.size(); ++k) {  // rigid: committed by constrain()
    if (object_worlds[k] && !rigid_objects) {
      object_worlds[k]->commit(found_objects_[k], object_memory[k]);
    }
  }
}

std::pair<Eigen::VectorXd, Eigen::VectorXd> System::advance(double t0, const ConstVec& q0,
                                                            const ConstVec& v0,
                                                            const ConstVec& tau, double t1,
                                                            const FixedStep& integrator) {
  if (q0.size() != model_.nq || v0.size() != model_.nv || tau.size() != nv_robot_) {
    throw InputError("system advance: q0 (" + std::to_string(model_.nq) + "), v0 (" +
                     std::to_string(model_.nv) + ") and the robot's tau (" +
                     std::to_string(nv_robot_) + ") expected");
  }
  if (!(t1 > t0) || !(integrator.step_s > 0.0)) {
    throw InputError("advance needs t1 > t0 and a positive step");
  }
  check();
  stepper_.q = q0;
  stepper_.v = v0;
  auto rhs = [&](double t, const Eigen::VectorXd& q,
                 const Eigen::VectorXd& v) -> const Eigen::VectorXd& {
    return acceleration(t, q, v, tau);
  };
  stepper_.advance(rhs, t0, t1, integrator);
  // a smooth step that diverged is returned as it is: the loop names the divergence
  if (!(stepper_.q.allFinite() && stepper_.v.allFinite())) return {stepper_.q, stepper_.v};
  settle(stepper_.q, stepper_.v);
  Eigen::VectorXd q1 = stepper_.q, v1 = stepper_.v;
  constrain(t0, q0, v0, t1, q1, v1);
  return {q1, v1};
}

void System::constrain(double t0, const ConstVec& q0, const ConstVec& v0, double t1,
                       Eigen::VectorXd& q1, Eigen::VectorXd& v1) {
  const bool holding = std::any_of(attachments.begin(), attachments.end(),
                                   [&](const Attachment& a) { return a.held(t0); });
  if (rigid_pairs || holding) {
    constrain_coupled(t0, q0, v0, t1, q1, v1);
    return;
  }
  const double h = t1 - t0;
  constrain_fixtures(t0, q0, v0, h, q1, v1);
  // the robot's joint limits (and Coulomb friction): its plant's step (Plant::constrain_joints)
  Eigen::VectorXd q1_robot = q1.head(nq_robot_), v1_robot = v1.head(nv_robot_);
  if (plant_.constrain_joints(t0, q0.head(nq_robot_), v0.head(nv_robot_), h, q1_robot,
                              v1_robot)) {
    q1.head(nq_robot_) = q1_robot;
    v1.head(nv_robot_) = v1_robot;
  }
  if (!rigid_objects) return;
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    if (!object_worlds[k]) continue;
    const auto i = static_cast<Eigen::Index>(k);
    const auto q0_k = q0.segment(nq_robot_ + 7 * i, 7);
    Dynamics& body = objects_[k];
    const Vec6 travelled =
        pinlib::differenced(body.model(), q0_k, q1.segment(nq_robot_ + 7 * i, 7));
    const Vec6 least = (travelled.cwiseAbs() / h).cwiseMax(v0.segment(nv_robot_ + 6 * i, 6).cwiseAbs());
    const Mat6 mass = body.mass_matrix_in(q0_k, plant_.flow, t0, plant_.free_surface);
    body.kinematics(q0_k, v0.segment(nv_robot_ + 6 * i, 6));
    // the smooth step's body velocity at q_free expressed at q0, where the rows act
    // (_objects_moved of period.py)
    const Eigen::Matrix3d r0 = rotation_of(q0_k);
    const Eigen::Matrix3d turn = r0.transpose() * rotation_of(q1.segment(nq_robot_ + 7 * i, 7));
    Vec6 v_k = v1.segment(nv_robot_ + 6 * i, 6);
    v_k << turn * v_k.head<3>(), turn * v_k.tail<3>();
    const Vec6 v_free = v_k;
    // an object the impulses did not move keeps the smooth step's end (period.py's _end)
    if (object_step_.constrain(*object_worlds[k], object_memory[k], body.data(), mass, v_k, h,
                               least, rigid_found_[k]) &&
        (v_k - v_free).cwiseAbs().maxCoeff() > kPushed) {
      const Eigen::Matrix<double, 7, 1> q_end = free_body_configuration(q0_k, v_k, h);
      q1.segment(nq_robot_ + 7 * i, 7) = q_end;
      v1.segment(nv_robot_ + 6 * i, 3) = rotation_of(q_end).transpose() * r0 * v_k.head<3>();
      v1.segment(nv_robot_ + 6 * i + 3, 3) = v_k.tail<3>();
    }
    object_worlds[k]->commit(rigid_found_[k], object_memory[k]);
  }
}

void System::constrain_fixtures(double t0, const ConstVec& q0, const ConstVec& v0, double h,
                                Eigen::VectorXd& q1, Eigen::VectorXd& v1) {
  for (std::size_t k = 0; k < fixtures_.size(); ++k) {
    FixtureBody& f = fixtures_[k];
    const int n = f.body.nv();
    if (n == 0 || !f.constrained()) continue;
    const auto q0_f = q0.segment(fixture_q_[k], n);
    const Eigen::VectorXd v_free = v1.segment(fixture_v_[k], n);
    const Eigen::MatrixXd& mass = f.body.mass_matrix_in(q0_f, plant_.flow, t0, plant_.free_surface);
    const Eigen::VectorXd gap_low = q0_f - f.lower, gap_high = f.upper - q0_f;
    const JointBoxStep step = joint_box_step(v_free, mass, f.coulomb, gap_low, gap_high, h);
    // a joint with friction, one its limit pushed, or one whose limit the period can reach
    // (a limit it may have swung through and back), is a row: its rate is the step's, and
    // the fixture moves from q0 with v+ (period.py's _end); the others keep v_free
    bool acting = false;
    Eigen::VectorXd v_plus = v_free;
    for (int j = 0; j < n; ++j) {
      // the speeds a limit is reached at: the smooth step's end, start and mean (its joints
      // are revolute or prismatic: q_free - q0 is the travel), as fixtures.with_fixtures
      const double travel = std::abs(q1[fixture_q_[k] + j] - q0_f[j]) / h;
      const double speed =
          std::max({std::abs(v_free[j]), std::abs(v0[fixture_v_[k] + j]), travel});
      const double reach = h * speed + fixture_limit_margin;
      const bool near = gap_low[j] <= reach || gap_high[j] <= reach;
      if (f.coulomb[j] > 0.0 || step.limit_impulse[j] != 0.0 || near) {
        v_plus[j] = step.velocity[j];
        acting = true;
      }
    }
    if (!acting) continue;
    v1.segment(fixture_v_[k], n) = v_plus;
    q1.segment(fixture_q_[k], n) = q0_f + h * v_plus;
  }
}

void System::constrain_coupled(double t0, const ConstVec& q0, const ConstVec& v0, double t1,
                               Eigen::VectorXd& q1, Eigen::VectorXd& v1) {
  const double h = t1 - t0;
  const Model& robot = plant_.dynamics().model();
  SystemAtStart at;
  at.robot = &robot;
  at.robot_data = &robot_data_;
  at.q0_robot = q0.head(nq_robot_);
  at.limits = plant_.joint_limits ? &*plant_.joint_limits : nullptr;
  at.sets = &sets;
  // the least speeds: the smooth step's start and its mean over the period (period.py)
  Eigen::VectorXd least(model_.nv), travelled(nv_robot_);
  pinlib::difference(robot, at.q0_robot, q1.head(nq_robot_), travelled);
  least.head(nv_robot_) = (travelled.cwiseAbs() / h).cwiseMax(v0.head(nv_robot_).cwiseAbs());
  std::vector<Eigen::MatrixXd> masses{
      plant_.dynamics().mass_matrix_in(at.q0_robot, plant_.flow, t0, plant_.free_surface)};
  Eigen::VectorXd v = v1;
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const auto q0_k = q0.segment(nq_robot_ + 7 * i, 7);
    Dynamics& body = objects_[k];
    const Vec6 moved = pinlib::differenced(body.model(), q0_k, q1.segment(nq_robot_ + 7 * i, 7));
    least.segment<6>(nv_robot_ + 6 * i) =
        (moved.cwiseAbs() / h).cwiseMax(v0.segment(nv_robot_ + 6 * i, 6).cwiseAbs());
    masses.emplace_back(body.mass_matrix_in(q0_k, plant_.flow, t0, plant_.free_surface));
    body.kinematics(q0_k, v0.segment(nv_robot_ + 6 * i, 6));
    at.objects.push_back(&body.data());
    const bool rigid_world = rigid_objects && object_worlds[k].has_value();
    at.object_worlds.push_back(rigid_world ? &*object_worlds[k] : nullptr);
    at.object_memory.push_back(&object_memory[k]);
    // the smooth step's body velocity at q_free expressed at q0, where the rows act
    const Eigen::Matrix3d turn =
        rotation_of(q0_k).transpose() * rotation_of(q1.segment(nq_robot_ + 7 * i, 7));
    v.segment<3>(nv_robot_ + 6 * i) = turn * v1.segment<3>(nv_robot_ + 6 * i);
    v.segment<3>(nv_robot_ + 6 * i + 3) = turn * v1.segment<3>(nv_robot_ + 6 * i + 3);
  }
  // each fixture: its joints' model and data at q0, its least speeds and its mass
  for (std::size_t k = 0; k < fixtures_.size(); ++k) {
    FixtureBody& f = fixtures_[k];
    const int n = f.body.nv();
    const auto q0_f = q0.segment(fixture_q_[k], n);
    least.segment(fixture_v_[k], n) = ((q1.segment(fixture_q_[k], n) - q0_f).cwiseAbs() / h)
                                          .cwiseMax(v0.segment(fixture_v_[k], n).cwiseAbs());
    masses.emplace_back(f.body.mass_matrix_in(q0_f, plant_.flow, t0, plant_.free_surface));
    at.fixtures.push_back({&f.body.model(), &f.body.data(), q0_f, fixture_v_[k], &f.lower,
                           &f.upper, &f.coulomb});
  }
  at.joint_coulomb = plant_.joint_coulomb_Nm;
  at.pair_rows = rigid_pairs;
  // each attachment holding over the period, placed where the two are at q0 when it begins
  // (attachments.py's _place_due): the robot's kinematics at q0, each object's above
  bool kinematics = false;
  for (Attachment& held : attachments) {
    if (held.object < 0 || static_cast<std::size_t>(held.object) >= objects_.size() ||
        held.link_joint < 1 || held.link_joint >= robot.njoints) {
      throw InputError("system: an attachment's link joint or object is not the system's");
    }
    if (!held.held(t0)) continue;
    if (!held.placed) {
      if (!kinematics) pinlib::forward_kinematics(robot, robot_data_, at.q0_robot);
      kinematics = true;
      held.placement = robot_data_.oMi[static_cast<std::size_t>(held.link_joint)].actInv(
          at.objects[static_cast<std::size_t>(held.object)]->oMi[1]);
      held.placed = true;
    }
    at.attachments.push_back({held.link_joint, held.object, held.placement});
  }
  const Eigen::VectorXd v_free = v;
  bool solved = coupled_step_.constrain(at, masses, v, h, least);
  // a rigid contact acting on a fixture's joints: the fixtures' own rows join it in one
  // problem; else each fixture's joints take their exact step (fixtures.with_fixtures)
  bool fixtures_joined = false;
  for (std::size_t k = 0; k < fixtures_.size() && solved; ++k) {
    fixtures_joined = fixtures_joined || coupled_step_.acting(1 + objects_.size() + k);
  }
  if (fixtures_joined) {
    at.fixture_rows = true;
    v = v_free;
    solved = coupled_step_.constrain(at, masses, v, h, least);
    for (std::size_t k = 0; k < fixtures_.size(); ++k) {
      if (!coupled_step_.acting(1 + objects_.size() + k)) continue;
      const int n = fixtures_[k].body.nv();
      v1.segment(fixture_v_[k], n) = v.segment(fixture_v_[k], n);
      q1.segment(fixture_q_[k], n) = q0.segment(fixture_q_[k], n) + h * v.segment(fixture_v_[k], n);
    }
  } else {
    constrain_fixtures(t0, q0, v0, h, q1, v1);
  }
  if (solved && coupled_step_.acting(0)) {
    v1.head(nv_robot_) = v.head(nv_robot_);
    Eigen::VectorXd q1_robot(nq_robot_);
    pinlib::integrate(robot, at.q0_robot, (h * v.head(nv_robot_)).eval(), q1_robot);
    q1.head(nq_robot_) = q1_robot;
  }
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const auto part = Eigen::seqN(nv_robot_ + 6 * i, 6);
    if (solved && coupled_step_.acting(1 + k) &&
        (v(part) - v_free(part)).cwiseAbs().maxCoeff() > kPushed) {
      const auto q0_k = q0.segment(nq_robot_ + 7 * i, 7);
      const Vec6 v_k = v.segment<6>(nv_robot_ + 6 * i);
      const Eigen::Matrix<double, 7, 1> q_end = free_body_configuration(q0_k, v_k, h);
      q1.segment(nq_robot_ + 7 * i, 7) = q_end;
      v1.segment(nv_robot_ + 6 * i, 3) =
          rotation_of(q_end).transpose() * rotation_of(q0_k) * v_k.head<3>();
      v1.segment(nv_robot_ + 6 * i + 3, 3) = v_k.tail<3>();
    }
    if (rigid_objects && object_worlds[k]) {
      rigid_found_[k] = coupled_step_.object_forces(k);
      object_worlds[k]->commit(rigid_found_[k], object_memory[k]);
    }
  }
  if (!rigid_pairs) return;  // compliant pairs: their memories are settle()'s
  // each pair set: its forces of the period kept, which pairs slid (their next cone mu_k)
  rigid_sets_.resize(sets.size());
  for (std::size_t s = 0; s < sets.size(); ++s) {
    rigid_sets_[s] = coupled_step_.pair_forces(s);
    FrictionMemory& memory = sets[s].memory;
    memory.clear();
    const auto& found = rigid_sets_[s];
    for (std::size_t c = 0; c < found.pair.size(); ++c) {
      if (!found.forces.sticking[c]) memory.slipping.insert(found.pair[c]);
    }
  }
}

}  // namespace uvms
