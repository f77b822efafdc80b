// The constraints of a system of bodies solved together once a control period, when two moving
// bodies touch by rigid contacts (mirror of uvms_pin/physics/constraints/moving_contacts.py
// with step.py, period.py's constrained and fixtures.py's with_fixtures): the robot's joint
// limits and Coulomb friction, each free object's rigid contacts with the fixed world (with
// rigid_objects), the rigid contacts between moving bodies (a fixture's links among them) and,
// when such a contact acts on a fixture's joints, their limits and Coulomb friction: one
// Coulomb problem over the system's velocity.
//
// A joint's Coulomb friction c is a box row, J = e_j, |lambda_j| <= c h (joint_friction.py:
// it sticks inside the box, slips against the friction at its edge); a fixture's limits are
// rows as the robot's, on its own coordinates.
//
// Rows (at the period's start q0): a joint limit's (lower: gap q_j - q_min, J = +e_j; upper:
// q_max - q_j, J = -e_j), an object's fixed-world contact's (object_contacts.hpp, on its six
// columns) and, for each pair (a, b) of pieces of two moving bodies that can touch within the
// period, coal's signed distance between the shapes: the nearest point x on a, the normal n out
// of b, the gap r, and the three rows
//
//   J v = C^T (J_a(x) - J_b(x)) v      (C = (t1, t2, n); J_a, J_b the world velocity of each
//                                       body's material point at x)
//
// so that one impulse acts on a and its opposite on b at x. A pair is selected when
// r <= h |J_n| |v| + margin; the broad phase first asks that the pieces' bounding spheres be
// within h (s_a + s_b) + margin, s a bound on the speed of a piece's points,
// |J_lin(c)| |v| + |J_ang| |v| R (moving_contacts.py's _reach_speed). mu is mu_k while the pair
// slid over the last period, mu_s otherwise.
//
// With M block diagonal over the bodies (the robot's nv_r x nv_r, each object's 6 x 6, each
// fixture's nv_f x nv_f, added mass included), G = J M^-1 J^T couples the bodies through the
// pairs' rows; the problem
//   v+ = v_free + M^-1 J^T lambda,  sigma = G lambda + J v_free + phi(r) / h,
//   limits: 0 <= lambda _|_ sigma >= 0;  friction: the box;
//   contacts: the Coulomb cone, maximal dissipation
// is solved by the projected Gauss-Seidel of object_contacts.hpp (coulomb_gauss_seidel, 1e-10
// m/s on the rows' velocities); the Python reference's ADMM stops at 1e-8. Rows selected with
// the speed max(|v_free|, least_speed), widened with the solved velocity (at most 4 rounds,
// then once more), as step.py.
#pragma once

#include <vector>

#include "joint_limits.hpp"
#include "moving_contact.hpp"
#include "object_contacts.hpp"

namespace uvms {

// A fixture at the period's start (system.hpp's FixtureBody): its fixed-base model, its data
// (the step computes its joint Jacobians at q0), its first coordinate in the system's v, and
// along each joint its limits (-inf/+inf: none) and Coulomb friction c (0: none).
struct FixtureAtStart {
  const Model* model = nullptr;
  Data* data = nullptr;
  Eigen::VectorXd q0;
  Eigen::Index offset = 0;
  const Eigen::VectorXd* lower = nullptr;    // [rad or m]
  const Eigen::VectorXd* upper = nullptr;    // [rad or m]
  const Eigen::VectorXd* coulomb = nullptr;  // [N m or N]
};

// A free object held by a robot link over the period (attachments.py): the link's joint, the
// object, and the object's pose P in the link's joint frame kept since it began to hold. Six
// bilateral rows, Pinocchio's FrameAnchorConstraintModel with c1 = L P and c2 = O:
//   J v = Ad(oM_c1)^-1 (J_O - J_L) v,   e = log6(oM_c1^-1 oM_O)   [m; rad]
// (J_L, J_O the WORLD spatial Jacobians of the link's joint and of the object's free-flyer),
// held at J v+ = -beta e / h whatever the sign: the impulse of any sign (a box without bound).
struct AttachmentAtStart {
  int link_joint = 0;
  int object = 0;
  pinocchio::SE3 placement = pinocchio::SE3::Identity();
};

// What the coupled step reads of a system at the period's start q0.
struct SystemAtStart {
  const Model* robot = nullptr;  // the robot's model
  Data* robot_data = nullptr;    // its data: the step computes its joint Jacobians at q0
  Eigen::VectorXd q0_robot;
  const JointLimitConstraintsModel* limits = nullptr;  // the robot's limits, or none
  std::vector<const Data*> objects;  // each object's kinematics at q0 (its placements)
  // each object's fixed world touched by rigid contacts (none: no row), its friction state
  std::vector<const WorldContactModel*> object_worlds;
  std::vector<const FrictionMemory*> object_memory;
  const std::vector<PairSet>* sets = nullptr;  // the pairs between moving bodies
  // the robot's joints' Coulomb friction c (its nv) [N m or N], or empty: none. A joint with
  // c > 0 is a box row |lambda| <= c h (joint_friction.py); with it the robot always moves
  // from q0 with v+ (period.py: its friction rows are always solved)
  Eigen::VectorXd joint_coulomb;
  // the fixtures (pair sides n_objects + k), after the objects in v
  std::vector<FixtureAtStart> fixtures;
  // the fixtures' own rows join the problem: their joints' limits (rows selected as the
  // robot's) and Coulomb friction (box rows), as fixtures.with_fixtures does when a rigid
  // contact acts on a fixture's joints
  bool fixture_rows = false;
  // the contacts between moving bodies are rows (World.moving_contact rigid); else they are
  // the smooth dynamics' compliant forces and only the other rows are solved
  bool pair_rows = true;
  // the attachments holding over the period
  std::vector<AttachmentAtStart> attachments;
};

class CoupledConstraintStep {
 public:
  double margin = 1.0e-3;   // [m, rad] the allowance of a row's selection
  double correction = 0.2;  // beta, the fraction of a penetration removed per period

  // v (in: v_free (the system's nv; each object's body velocity at its pose in q0), out: v+)
  // over the period h; masses: the robot's M(q0) then each object's, then each fixture's.
  // Returns whether any row was solved; then acting(), object_forces() and pair_forces() say
  // what acted.
  bool constrain(const SystemAtStart& at, const std::vector<Eigen::MatrixXd>& masses,
                 Eigen::VectorXd& v, double h, const Eigen::VectorXd& least_speed);
  // Whether a solved row acts on body k (0: the robot, 1 + i: object i, 1 + n_objects + f:
  // fixture f): some row has a non-zero column of its coordinates (period.py's _end).
  bool acting(std::size_t k) const { return acting_[k] != 0; }
  // Object i's fixed-world contacts of the period (their mean forces), and set s's pairs.
  const ContactForces& object_forces(std::size_t i) const { return object_found_[i]; }
  const PairContacts& pair_forces(std::size_t s) const { return pair_found_[s]; }
  // the solves of this step that stalled and were accepted (object_contacts.hpp)
  StalledSolves stalled;

 private:
  // One selected contact between two moving bodies: its set, pair, candidate and frame.
  struct PairRow {
    int set = 0, pair = 0;
    ContactCandidate point;
    Eigen::Matrix3d frame;
  };
  std::vector<ContactCandidate> patch_;  // one pair's candidates (add_pair_rows' scratch)
  // whether side is a free object (not the robot, -1, nor a fixture, after the objects)
  static bool free_object(const SystemAtStart& at, int side);
  int select(const SystemAtStart& at, const Eigen::VectorXd& speed, double h);
  void add_pair_rows(const SystemAtStart& at, const Eigen::VectorXd& speed, double h);
  // The world velocity Jacobian (3 x nv) of side's material point at x, and a bound on the
  // speed of the points of the piece (side -1: the robot, else an object).
  Eigen::MatrixXd side_jacobian(const SystemAtStart& at, int side, const ContactShape& piece,
                                const Vec3& x) const;
  // the same point's velocity (3 rows) over the piece's body's angular velocity (3 rows), in
  // world axes (6 x nv): one joint Jacobian for both
  Eigen::MatrixXd side_twist_jacobian(const SystemAtStart& at, int side,
                                      const ContactShape& piece, const Vec3& x) const;
  double piece_speed(const SystemAtStart& at, int side, const ContactShape& piece,
                     const Eigen::VectorXd& speed) const;
  void solve(const std::vector<Eigen::MatrixXd>& masses, const Eigen::VectorXd& v_free,
             Eigen::VectorXd& v);
  void forces(const SystemAtStart& at, const Eigen::VectorXd& v, double h);

  Eigen::Index nv_ = 0, nv_robot_ = 0;
  std::vector<ObjectContactStep> object_steps_;
  std::vector<Eigen::Index> object_rows_;  // each object's first fixed-world row
  std::vector<PairRow> pair_rows_;
  Eigen::Index first_pair_row_ = 0;
  std::vector<Eigen::RowVectorXd> rows_;
  std::vector<double> drift_, mu_;
  std::vector<Eigen::Index> unilateral_, cone_rows_;
  std::vector<BoxRow> boxes_;
  // the data of side k of a pair (-1 the robot, then the objects, then the fixtures)
  const Data& side_data(const SystemAtStart& at, int side) const;
  // the fixtures' own rows (at.fixture_rows): their limits, then their friction
  void add_fixture_rows(const SystemAtStart& at, const Eigen::VectorXd& speed, double h);
  // each attachment's six bilateral rows
  void add_attachment_rows(const SystemAtStart& at, double h);
  // A row sign e_iv (a joint's limit or friction) with its drift; returns its index.
  Eigen::Index add_coordinate_row(Eigen::Index iv, double sign, double drift);
  // phi(r) / h's numerator: a gap r >= 0 as it is, a penetration by the correction
  double phi(double gap) const { return gap >= 0.0 ? gap : correction * gap; }
  // each body's range of columns in v (robot, objects, fixtures)
  std::vector<std::pair<Eigen::Index, Eigen::Index>> bodies_;
  std::vector<char> acting_;
  Eigen::MatrixXd jacobian_, minv_jt_, delassus_, robot_jacobians_;
  Eigen::VectorXd impulse_;
  std::vector<ContactForces> object_found_;
  std::vector<PairContacts> pair_found_;
};

}  // namespace uvms
