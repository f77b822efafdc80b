// The simulated world (mirror of uvms_pin/sim/plant.py): a UVMS in a flow, touching a compliant
// environment at its end-effector and pushed by a disturbance:
//   M zeta_dot + h + J_c^T lambda + [delta; 0] = tau + [0; tau_f(v)] + tau_stop,
// tau_f the friction of the arm's joint drives (joint_friction.hpp), tau_stop the compliant
// stops at the joint limits (joint_stops.hpp), and with a world (world_contact.hpp) + tau_world,
// the contacts of every body's collision shapes with the world's objects.
// It advances the plant over one control period with the input held, in one call; the joint
// limits may instead be constraints solved implicitly at the period's end (joint_limits.hpp).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <utility>

#include "contact.hpp"
#include "derivatives_task_contact.hpp"
#include "derivatives_world_contact.hpp"
#include "disturbance.hpp"
#include "dynamics.hpp"
#include "fins.hpp"
#include "integrators.hpp"
#include "joint_friction.hpp"
#include "joint_limits.hpp"
#include "joint_stops.hpp"
#include "world_bounds.hpp"
#include "world_contact.hpp"

namespace uvms {

class Plant {
 public:
  Plant(const Dynamics& dynamics, int ee_frame_id);
  Plant(const Plant&) = delete;
  Plant& operator=(const Plant&) = delete;

  FlowField flow;
  bool free_surface = false;  // the bodies are cut by the flow's free surface
  Contact contact;
  Disturbance disturbance;
  JointFriction joint_friction;
  Fins fins;  // gz-sim's LiftDrag fins (fins.hpp), none by default
  JointStops joint_stops;  // compliant stops at the arm joints' limits, or none
  // or the limits as constraints solved implicitly at the end of each period (advance)
  JointLimitConstraints joint_limits;
  // The arm joints' Coulomb friction as a constraint [N m or N] (nv: 0 on the vehicle's
  // coordinates and on the joints without; empty: none): at the period's end, with the joint
  // limits, the exact step of joint_box.hpp over the robot's velocity (mirror of period.py's
  // constrained with `JointCoulombFriction` rows): the robot then moves from q0 with v+.
  Eigen::VectorXd joint_coulomb_Nm;

  // lambda at (q, v): what the end-effector exerts on the environment [N; N m], world axes.
  Vec6 contact_wrench(const ConstVec& q, const ConstVec& v);
  // zeta_dot; contact_world given = use it instead of the contact model (continuous loop).
  const Eigen::VectorXd& acceleration(double time_s, const ConstVec& q, const ConstVec& v,
                                      const ConstVec& tau, const Vec6* contact_world = nullptr);
  // Whether no piece can reach a world object within horizon_s from (q, v)
  // (world_bounds.hpp); true without bounds.
  bool world_clear(const ConstVec& q, const ConstVec& v, double horizon_s);
  WorldBoundsModel world_bounds;
  // The world's contacts, or none; with one, a period in which something may touch is
  // integrated with them (the anchors of `friction` held) and ends with World.commit.
  std::optional<WorldContactModel> world;
  FrictionMemory friction;  // the world contacts' state between periods (see world_contact.hpp)
  // The forces of the bodies that move beside it (the moving contacts of a system of bodies,
  // system.hpp): called by acceleration() after the kinematics and the other external
  // wrenches, to add its own to the dynamics; set by the system for each of its
  // evaluations, empty otherwise.
  std::function<void(Dynamics&)> moving_contacts;
  // The contact points and forces at (q, v) with `friction` (World.forces); no world: none.
  const ContactForces& world_forces(const ConstVec& q, const ConstVec& v);

  // (da/dq, da/dv, da/dtau) of acceleration() with the world's contacts at `friction`'s
  // anchors and the end-effector's contact, q along the tangent (plant_derivatives.cpp,
  // mirror of uvms_pin/sim/plant_derivatives.py).
  const ForwardDynamicsDerivatives& acceleration_derivatives(double time_s, const ConstVec& q,
                                                             const ConstVec& v,
                                                             const ConstVec& tau);
  // The end-effector contact's tau_ext and its derivatives at (q, v)
  // (derivatives_task_contact.hpp; zero without a contact).
  const TaskContactDerivatives& contact_derivatives(const ConstVec& q, const ConstVec& v);

  // (q, v) at t1 from (q0, v0) at t0 with tau held, in the integrator's substeps; with
  // joint_limits, their implicit velocity step follows (joint_limits.hpp): when a row is
  // solved, q1 = q0 (+) (t1 - t0) v+, else the substeps' own (mirror of
  // uvms_pin/sim/system/period.py, constrained).
  std::pair<Eigen::VectorXd, Eigen::VectorXd> advance(double t0, const ConstVec& q0,
                                                      const ConstVec& v0, const ConstVec& tau,
                                                      double t1, const FixedStep& integrator);

  // The local chart of the adaptive integrators (integrators.py, Adaptive): the
  // configuration q = integrate(q0, delta) and delta_dot = Jint(q0, delta)^-1 v.
  std::pair<Eigen::VectorXd, Eigen::VectorXd> chart(const ConstVec& q0, const ConstVec& delta,
                                                    const ConstVec& v);

  // The end of a period [t0, t0 + h] whose smooth step went from (q0, v0) to (q1, v1): the
  // joint limits' implicit step, or with joint_coulomb_Nm the joints' exact step with their
  // friction and limits; (q1, v1) replaced when a row acted. Returns whether one did.
  bool constrain_joints(double t0, const ConstVec& q0, const ConstVec& v0, double h,
                        Eigen::VectorXd& q1, Eigen::VectorXd& v1);

  Dynamics& dynamics() { return dynamics_; }
  const Dynamics& dynamics() const { return dynamics_; }
  int ee_frame_id() const { return static_cast<int>(ee_frame_id_); }

 private:
  Dynamics dynamics_;
  pinocchio::FrameIndex ee_frame_id_;
  pinocchio::JointIndex ee_joint_id_;
  ManifoldStepper stepper_;
  Eigen::VectorXd tau_total_;
  Eigen::VectorXd limit_speed_;  // the joint limits' least selection speed (advance)
  bool world_active_ = true;  // false over a period the broad phase cleared
  ContactForces world_forces_;
  // acceleration_derivatives' own (built on first use): the water's derivatives (a copy of
  // the dynamics), the world contacts', the end-effector contact's, the plant's generalized
  // forces and their Jacobians
  std::unique_ptr<Derivatives> derivatives_;
  std::unique_ptr<WorldContactDerivatives> world_derivatives_;
  std::unique_ptr<TaskContactDerivatives> task_derivatives_;
  Eigen::VectorXd force_tau_;
  Eigen::MatrixXd force_dq_, force_dv_;
  ForwardDynamicsDerivatives acceleration_derivatives_;
  void check_world();  // tau - the joint friction + the joint stops' torque
};

}  // namespace uvms
