// A system of bodies (mirror of uvms_pin/sim/system/system.py and of the integrated step of
// period.py): the robot (a Plant, with its environment, joint stops or limits and fixed world)
// and the world's free objects, each a floating body of its own (a Dynamics of its one-link
// model, the robot's dynamics for a bare vehicle), stepped together over one control period in
// one call. The state stacks the robot's (q, zeta) and each object's (pose (7,), body velocity
// (6,)); the configuration space is the robot's joints and one free-flyer per object. The
// right-hand side is
//
//   zeta_dot = FD_robot(q, zeta, tau + tau_contact,robot)
//   nu_dot_o = FD_o(q_o, nu_o, tau_contact,o)                       (each object o)
//
// with every contact force between two moving bodies exchanged equal and opposite
// (moving_contact.hpp) and each object touching the fixed objects as the robot does
// (world_contact.hpp), in the same water (the plant's flow and free surface).
//
// Fixtures (URDFs whose root is fixed in the world, mirror of uvms_pin/sim/system/fixtures.py)
// follow the objects: their joints in the state and in the model, each fixture's
//
//   qdd_f = FD_f(q_f, qd_f, -D_f qd_f + tau_contact,f)
//
// in the same water, its links a side of the pair sets (side n_objects + k), and at the
// period's end its joints' limits and Coulomb friction by their exact step (joint_box.hpp;
// while the bodies meet through smooth contact forces each fixture's joints are apart from
// the other rows). With rigid_pairs, when a solved contact row acts on a fixture's joints,
// its limits and friction join that one problem instead (fixtures.with_fixtures).
//
// A period: the integrator's substeps on the system's manifold, then every contact's friction
// anchors move (World.commit, PiecePairs.commit) at the period's end, then the constraints
// solved implicitly (period.py, constrained): the robot's joint limits (joint_limits.hpp) and,
// with rigid_objects, each free object's rigid contacts with the fixed world
// (object_contacts.hpp; then the smooth dynamics leave those contacts out). M is block
// diagonal over the bodies; while no row joins two bodies each body is solved alone. With
// rigid_pairs the contacts between moving bodies are rows too, joining two bodies: then every
// row of the system is solved in one problem (moving_constraints.hpp), the robot's joints'
// Coulomb friction among them (box rows). A body with a solved
// row moves from q0 with v+ (the robot q0 (+) h v+, an object by free_body_configuration),
// the others keep the smooth step's end. An attachment holding over the period joins its
// robot link and free object by six bilateral rows, solved with every other row in one problem
// as with rigid_pairs (moving_constraints.hpp).
#pragma once

#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "moving_constraints.hpp"
#include "moving_contact.hpp"
#include "object_contacts.hpp"
#include "plant.hpp"

namespace uvms {

// A fixture of the system: its joints' dynamics (a fixed-base model, its links in the water)
// and what acts along each joint: viscous damping D, Coulomb friction c, position limits.
struct FixtureBody {
  Dynamics body;
  Eigen::VectorXd damping;  // D (nv_f,) [N m s/rad or N s/m]
  Eigen::VectorXd coulomb;  // c (nv_f,) [N m or N], 0: none
  Eigen::VectorXd lower;    // q_min (nv_f,) [rad or m], -inf: none
  Eigen::VectorXd upper;    // q_max, +inf: none
  // some joint has friction or a limit: its joints are stepped at the period's end
  bool constrained() const {
    return (coulomb.array() > 0.0).any() || lower.array().isFinite().any() ||
           upper.array().isFinite().any();
  }
};

// A free object held rigidly by a robot link (mirror of attachments.py's Attachments): from
// attach_at_s until release_at_s [s], at the pose the two have at the start of the first
// period it holds (placed; then placement is the object's pose in the link's joint frame).
struct Attachment {
  int link_joint = 0;  // the robot's joint carrying the link
  int object = 0;      // the free object
  double attach_at_s = 0.0;
  double release_at_s = std::numeric_limits<double>::infinity();
  bool placed = false;
  pinocchio::SE3 placement = pinocchio::SE3::Identity();
  bool held(double time_s) const { return attach_at_s <= time_s && time_s < release_at_s; }
};

class System {
 public:
  // The robot's plant (kept by reference: its owner outlives the system), each free
  // object's floating body (copied) and the fixtures (copied).
  System(Plant& plant, const std::vector<const Dynamics*>& objects,
         std::vector<FixtureBody> fixtures = {});
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // The pair sets (moving.py's _Set: a = -1 the robot, else an object; b likewise) and each
  // object's contacts with the fixed objects (none without fixed objects), with their state.
  std::vector<PairSet> sets;
  std::vector<std::optional<WorldContactModel>> object_worlds;
  std::vector<FrictionMemory> object_memory;
  // the free objects touch the fixed world by rigid contacts (World.free_object_contact)
  bool rigid_objects = false;
  // the moving bodies touch each other by rigid contacts (World.moving_contact)
  bool rigid_pairs = false;
  // a fixture joint's limit is a row once its gap is at most h |v| + this [rad or m]: the
  // margin of the fixtures' JointLimits (sim/system/fixtures.py), set by sim/compiled/system.py
  double fixture_limit_margin = 1.0e-3;

  // Point forces from bodies outside the system (the other robots of a RobotsSystem): the
  // world force [N] at a world point [m] on a joint's body of the robot (side -1) or of an
  // object (side k), added to the contacts' while set (each acceleration reads them).
  struct Push {
    int side = -1;
    int joint_id = 0;
    Vec3 point = Vec3::Zero();
    Vec3 force = Vec3::Zero();
  };
  std::vector<Push> pushes;

  // The free objects held by the robot's links: each holding period's velocities are solved
  // with the other rows in one problem (constrain_coupled, its six bilateral rows).
  std::vector<Attachment> attachments;
  // A run starts: no attachment placed (each is placed at the start of its first period).
  void forget_attachments() {
    for (auto& held : attachments) held.placed = false;
  }

  int nq() const { return model_.nq; }
  int nv() const { return model_.nv; }
  const Model& model() const { return model_; }
  std::size_t n_objects() const { return objects_.size(); }
  std::size_t n_fixtures() const { return fixtures_.size(); }
  Plant& plant() { return plant_; }

  // Checks the sets and the object worlds against the models (InputError otherwise).
  void check() const;
  // The system's acceleration (nv,) with tau (the robot's nv) held, the anchors read only.
  const Eigen::VectorXd& acceleration(double time_s, const ConstVec& q, const ConstVec& v,
                                      const ConstVec& tau);
  // The contacts at (q, v) (after which found_sets() and found_objects() hold them).
  void contacts(const ConstVec& q, const ConstVec& v);
  // The kinematics at (q, v) of the robot (robot_data()) and of the objects (object_data()).
  void kinematics(const ConstVec& q, const ConstVec& v);
  const Data& robot_data() const { return robot_data_; }
  const Data& object_data(std::size_t k) { return objects_[k].data(); }
  const Model& object_model(std::size_t k) const { return objects_[k].model(); }
  // each pair set's contacts: at the last contacts() (compliant), or over the last period
  // solved (rigid_pairs: the mean forces of its impulses)
  const std::vector<PairContacts>& found_sets() {
    rigid_sets_.resize(sets.size());  // none solved yet: none touching
    return rigid_pairs ? rigid_sets_ : found_sets_;
  }
  // object k's contacts with the fixed world: at the last contacts() (compliant), or over
  // the last period solved (rigid_objects: the mean forces of its impulses)
  const ContactForces& found_object(std::size_t k) const {
    return rigid_objects ? rigid_found_[k] : found_objects_[k];
  }
  // After a control period at (q, v): every contact's anchors move (System.settle).
  void settle(const ConstVec& q, const ConstVec& v);
  // The constraint solves since the system was built that stalled and were accepted
  // (object_contacts.hpp's StalledSolves), of the objects' and the coupled steps.
  StalledSolves stalled_solves() const {
    StalledSolves out = object_step_.stalled;
    out.count += coupled_step_.stalled.count;
    out.worst_residual_m_s =
        std::max(out.worst_residual_m_s, coupled_step_.stalled.worst_residual_m_s);
    return out;
  }
  // The constraints of the period (see the file's comment) on (q1, v1), the smooth step's end
  // from (q0, v0), after settle() there (advance's last part; a RobotsSystem's too).
  void constrain(double t0, const ConstVec& q0, const ConstVec& v0, double t1,
                 Eigen::VectorXd& q1, Eigen::VectorXd& v1);
  // (q, v) at t1 from (q0, v0) at t0 with tau held (see the file's comment).
  std::pair<Eigen::VectorXd, Eigen::VectorXd> advance(double t0, const ConstVec& q0,
                                                      const ConstVec& v0, const ConstVec& tau,
                                                      double t1, const FixedStep& integrator);

 private:
  void object_kinematics(const ConstVec& q, const ConstVec& v);
  // Each fixture's joints by their exact step (joint_box.hpp), after the smooth step.
  void constrain_fixtures(double t0, const ConstVec& q0, const ConstVec& v0, double h,
                          Eigen::VectorXd& q1, Eigen::VectorXd& v1);
  // ... with rigid_pairs: every row of the system in one solve (moving_constraints.hpp).
  void constrain_coupled(double t0, const ConstVec& q0, const ConstVec& v0, double t1,
                         Eigen::VectorXd& q1, Eigen::VectorXd& v1);
  // Every moving contact, after the objects' kinematics, the robot's in robot.
  void contacts_at(const Data& robot);
  // The moving contacts' forces on the robot's bodies (the plant's moving_contacts, called
  // after its own kinematics: the robot's is done once an evaluation).
  void add_robot_forces(Dynamics& robot);
  // the data of side k of a set (-1: the robot's, of the last contacts_at; then the free
  // objects; then the fixtures)
  const Data& data_of(int side);
  const Model& model_of(int side) const;
  // the body of side k >= 0 (a free object, or a fixture after them)
  Dynamics& body_of(int side);

  Plant& plant_;
  std::vector<Dynamics> objects_;
  std::vector<FixtureBody> fixtures_;
  std::vector<Eigen::Index> fixture_q_, fixture_v_;  // each fixture's first index in q, v
  Model model_;  // the robot's joints, one free-flyer per object, the fixtures' joints
  Data robot_data_;  // the robot's kinematics for contacts() and settle()
  const Data* robot_at_ = nullptr;  // the robot's data of the contacts being computed
  int nq_robot_, nv_robot_;
  ManifoldStepper stepper_;
  std::vector<PairContacts> found_sets_;
  std::vector<ContactForces> found_objects_;
  std::vector<ContactForces> rigid_found_;  // each object's contacts of the last period
  std::vector<PairContacts> rigid_sets_;    // each set's contacts of the last period
  ObjectContactStep object_step_;
  CoupledConstraintStep coupled_step_;
  Eigen::VectorXd acceleration_, limit_speed_;
  const Eigen::VectorXd zero_tau_ = Eigen::VectorXd::Zero(6);
};

}  // namespace uvms
