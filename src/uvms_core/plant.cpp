#include "plant.hpp"

#include <limits>

#include "joint_box.hpp"
#include "pinocchio_kinematics.hpp"

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

namespace uvms {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

Plant::Plant(const Dynamics& dynamics, int ee_frame_id)
    : dynamics_(dynamics), stepper_(dynamics_.model()) {
  const auto& model = dynamics_.model();
  if (ee_frame_id < 0 || ee_frame_id >= static_cast<int>(model.nframes)) {
    throw InputError("end-effector frame " + std::to_string(ee_frame_id) +
                     " is not a frame of the model");
  }
  ee_frame_id_ = static_cast<pinocchio::FrameIndex>(ee_frame_id);
  ee_joint_id_ = model.frames[ee_frame_id_].parentJoint;
}

namespace {

// Tip position and linear velocity (world) after the dynamics' kinematics pass.
std::pair<Vec3, Vec3> tip_state(const Model& model, Data& data, pinocchio::FrameIndex frame) {
  const Vec3 position = pinocchio::updateFramePlacement(model, data, frame).translation();
  const Vec3 velocity =
      pinocchio::getFrameVelocity(model, data, frame, pinocchio::LOCAL_WORLD_ALIGNED).linear();
  return {position, velocity};
}

}  // namespace

Vec6 Plant::contact_wrench(const ConstVec& q, const ConstVec& v) {
  if (!has_contact(contact)) return Vec6::Zero();
  dynamics_.kinematics(q, v);
  const auto [position, velocity] = tip_state(dynamics_.model(), dynamics_.data(), ee_frame_id_);
  return contact_wrench_world(contact, position, velocity);
}

const Eigen::VectorXd& Plant::acceleration(double time_s, const ConstVec& q, const ConstVec& v,
                                           const ConstVec& tau, const Vec6* contact_world) {
  dynamics_.kinematics(q, v);
  dynamics_.fluid_wrenches(time_s, flow, dynamics_.needs_bias_acceleration(), free_surface);
  if (has_contact(contact)) {
    const auto [position, velocity] =
        tip_state(dynamics_.model(), dynamics_.data(), ee_frame_id_);
    const Vec6 lambda = contact_world != nullptr
                            ? *contact_world
                            : contact_wrench_world(contact, position, velocity);
    // the robot receives -lambda at the tip
    dynamics_.add_world_wrench(static_cast<int>(ee_joint_id_), position, -lambda);
  }
  if (world && world_active_) {
    world->forces(dynamics_.data(), friction, world_forces_);
    world->add_to(dynamics_, world_forces_);
  }
  if (moving_contacts) moving_contacts(dynamics_);
  if (fins.active()) fins.add_to(dynamics_, q, flow, time_s, free_surface);
  if (disturbance) {
    // delta acts against tau on the vehicle body (joint 1, free-flyer: LOCAL Jacobian [I 0])
    dynamics_.add_local_wrench(1, -disturbance->at(time_s));
  }
  if (joint_friction.active() || joint_stops) {
    tau_total_ = tau;
    if (joint_friction.active()) joint_friction.subtract_from(v, tau_total_);
    if (joint_stops) joint_stops->add_torque(q, v, tau_total_);
    return dynamics_.accelerations(q, v, tau_total_, nullptr);
  }
  return dynamics_.accelerations(q, v, tau, nullptr);
}

bool Plant::world_clear(const ConstVec& q, const ConstVec& v, double horizon_s) {
  if (world_bounds.radii_m.size() == 0) return true;
  if (static_cast<Eigen::Index>(world_bounds.joint_ids.size()) != world_bounds.radii_m.size() ||
      world_bounds.centers_in_joint.cols() != world_bounds.radii_m.size()) {
    throw InputError("world bounds: one joint, centre and radius per piece");
  }
  for (const int j : world_bounds.joint_ids) {
    if (j < 0 || j >= static_cast<int>(dynamics_.model().njoints)) {
      throw InputError("world bounds: joint " + std::to_string(j) + " is not in the model");
    }
  }
  dynamics_.kinematics(q, v);
  return world_bounds.clear(dynamics_.data(), horizon_s);
}

std::pair<Eigen::VectorXd, Eigen::VectorXd> Plant::advance(double t0, const ConstVec& q0,
                                                           const ConstVec& v0,
                                                           const ConstVec& tau, double t1,
                                                           const FixedStep& integrator) {
  stepper_.q = q0;
  stepper_.v = v0;
  // a world: the broad phase first (nothing within reach: no contact persists, the friction
  // forgets its anchors and the period runs without the world), else the contacts
  bool settle = false;
  if (world) {
    check_world();
    world_active_ = !world_clear(q0, v0, t1 - t0);
    if (!world_active_) friction.clear();
    settle = world_active_;
  }
  auto rhs = [&](double t, const Eigen::VectorXd& q,
                 const Eigen::VectorXd& v) -> const Eigen::VectorXd& {
    return acceleration(t, q, v, tau);
  };
  try {
    stepper_.advance(rhs, t0, t1, integrator);
  } catch (...) {
    world_active_ = true;
    throw;
  }
  world_active_ = true;
  if (settle) {  // the anchors move (World.commit), at the period's end
    world->commit(world_forces(stepper_.q, stepper_.v), friction);
  }
  // a smooth step that diverged is returned as it is: the loop names the divergence
  if (!(stepper_.q.allFinite() && stepper_.v.allFinite())) return {stepper_.q, stepper_.v};
  Eigen::VectorXd q1 = stepper_.q, v1 = stepper_.v;
  constrain_joints(t0, q0, v0, t1 - t0, q1, v1);
  return {q1, v1};
}

bool Plant::constrain_joints(double t0, const ConstVec& q0, const ConstVec& v0, double h,
                             Eigen::VectorXd& q1, Eigen::VectorXd& v1) {
  const Model& model = dynamics_.model();
  if (joint_coulomb_Nm.size() > 0) {
    if (joint_coulomb_Nm.size() != model.nv) {
      throw InputError("plant: joint_coulomb_Nm needs one number per velocity coordinate");
    }
    // every joint's friction is a row (period.py: the robot moves from q0 with v+); each
    // limited joint's limits bound its rate (the rows the reference selects are those that
    // can bind: the others leave the same solution)
    Eigen::VectorXd gap_low = Eigen::VectorXd::Constant(model.nv, kInfinity);
    Eigen::VectorXd gap_high = Eigen::VectorXd::Constant(model.nv, kInfinity);
    double correction = 0.2;
    if (joint_limits) {
      const auto& limits = *joint_limits;
      correction = limits.correction;
      for (std::size_t i = 0; i < limits.q_index.size(); ++i) {
        const auto k = static_cast<Eigen::Index>(i);
        gap_low[limits.v_index[i]] = q0[limits.q_index[i]] - limits.lower_rad[k];
        gap_high[limits.v_index[i]] = limits.upper_rad[k] - q0[limits.q_index[i]];
      }
    }
    const Eigen::MatrixXd& mass = dynamics_.mass_matrix_in(q0, flow, t0, free_surface);
    const JointBoxStep step =
        joint_box_step(v1, mass, joint_coulomb_Nm, gap_low, gap_high, h, correction);
    v1 = step.velocity;
    pinlib::integrate(model, q0, (h * v1).eval(), q1);
    return true;
  }
  if (!joint_limits) return false;
  // the smooth step's own speeds: its start, its end and its mean over the period (RK4's
  // end may cross a limit that its end velocity would not reach), as period.py's constrained
  limit_speed_.resize(model.nv);
  pinlib::difference(model, q0, q1, limit_speed_);
  limit_speed_ = (limit_speed_.cwiseAbs() / h).cwiseMax(v0.cwiseAbs()).cwiseMax(v1.cwiseAbs());
  if (!joint_limits->within_reach(q0, limit_speed_, h)) return false;
  // M(q0) with the added mass (wet fractions at t0), as System.mass_matrix
  const Eigen::MatrixXd& mass = dynamics_.mass_matrix_in(q0, flow, t0, free_surface);
  if (!joint_limits->constrain(mass, q0, v1, h, limit_speed_)) return false;
  pinlib::integrate(model, q0, (h * v1).eval(), q1);
  return true;
}

void Plant::check_world() {
  if (!world) return;
  world->check(dynamics_.model());
  if (static_cast<Eigen::Index>(world->pieces.size()) != world_bounds.radii_m.size()) {
    throw InputError("world contact: the world bounds must hold one sphere per piece");
  }
}

const ContactForces& Plant::world_forces(const ConstVec& q, const ConstVec& v) {
  world_forces_.touch.clear();
  world_forces_.force_world_N.clear();
  world_forces_.normal_N.resize(0);
  world_forces_.sticking.clear();
  if (!world) return world_forces_;
  check_world();
  dynamics_.kinematics(q, v);
  world->forces(dynamics_.data(), friction, world_forces_);
  return world_forces_;
}

std::pair<Eigen::VectorXd, Eigen::VectorXd> Plant::chart(const ConstVec& q0,
                                                         const ConstVec& delta,
                                                         const ConstVec& v) {
  stepper_.q = q0;
  stepper_.delta = delta;
  stepper_.v = v;
  pinlib::integrate(dynamics_.model(), stepper_.q, stepper_.delta, stepper_.q_stage);
  stepper_.chart_rate(stepper_.q, stepper_.delta, stepper_.v, stepper_.d1);
  return {stepper_.q_stage, stepper_.d1};
}

}  // namespace uvms
