// Several robots in one sea, integrated together over a control period (mirror of
// uvms_pin/sim/system/robots.py, Robots.acceleration and the integrator's loop of
// Robots._together): each robot's system of bodies (system.hpp: its plant, and for the first
// the world's free objects) and the pair sets between robots and between the other robots and
// the first system's objects (sides: robot k is k, the first system's object i is n + i). The
// right-hand side is each robot's system's, with the contacts between the sides added to its
// bodies as point forces (System::pushes: f on a's body at x, -f on b's; the same as the
// reference's J^T f added to the input, the dynamics being linear in it). integrate() reads the
// anchors only; advance() is the whole period of Robots._together: the integration, then every
// anchor moved at the smooth step's end (each system's System::settle, each set's commit), then
// each system's constraints (System::constrain: its joint limits, its objects' rigid contacts).
// near() is the bound test of Robots.near (between_robots.RobotContacts.near) and
// object_wrenches() each robot's force/torque sensor's wrench on the free objects
// (Robots.object_wrenches).
#pragma once

#include <utility>
#include <vector>

#include "system.hpp"

namespace uvms {

class RobotsSystem {
 public:
  // Each robot's system (kept by reference: their owners outlive this).
  explicit RobotsSystem(const std::vector<System*>& systems);
  RobotsSystem(const RobotsSystem&) = delete;
  RobotsSystem& operator=(const RobotsSystem&) = delete;

  std::vector<PairSet> sets;  // between the sides (the file's comment)
  // each side's reach from its root joint [m] (robot_reach.robot_reach_m; inf: no bound), the
  // robots then the first system's objects, and the clearance added to every sphere [m]
  // (touch.CLEARANCE_M): the bound test's (near)
  std::vector<double> reach_m;
  double clearance_m = 0.05;

  int nq() const { return model_.nq; }
  int nv() const { return model_.nv; }
  std::size_t n_robots() const { return systems_.size(); }
  System& system(std::size_t k) { return *systems_[k]; }

  // Checks the sets against the sides' models (InputError otherwise).
  void check() const;
  // The joined acceleration (nv,) with each robot's input taus[k] (its nv) held.
  const Eigen::VectorXd& acceleration(double time_s, const ConstVec& q, const ConstVec& v,
                                      const std::vector<Eigen::VectorXd>& taus);
  // (q, v) at t1 from (q0, v0) at t0 by the integrator's steps on the joined manifold.
  std::pair<Eigen::VectorXd, Eigen::VectorXd> integrate(double t0, const ConstVec& q0,
                                                        const ConstVec& v0,
                                                        const std::vector<Eigen::VectorXd>& taus,
                                                        double t1, const FixedStep& integrator);
  // The period (the file's comment): integrate(), then every anchor moved at the smooth step's
  // end, then each system's constraints; a smooth step that diverged is returned as it is.
  std::pair<Eigen::VectorXd, Eigen::VectorXd> advance(double t0, const ConstVec& q0,
                                                      const ConstVec& v0,
                                                      const std::vector<Eigen::VectorXd>& taus,
                                                      double t1, const FixedStep& integrator);
  // Whether some pair of sides may touch within horizon_s from (q, v): first each side's
  // sphere about its root, radius R + 2 s h + clearance with s = |v| + |w| R + 2 R sum |qd_j|
  // (robot_reach.reach_sphere), then for two sides whose spheres meet every pair's pieces'
  // spheres, radius r + 2 (|v_j| + |w_j| (|c| + r)) h + clearance (touch.reach_spheres).
  bool near(const ConstVec& q, const ConstVec& v, double horizon_s);
  // near()'s first test: each side's sphere about its root over horizon_s (centre, radius;
  // inf: no bound), the robots then the first system's objects, kept until the next call.
  void root_spheres(const ConstVec& q, const ConstVec& v, double horizon_s);
  const std::vector<Vec3>& root_centers() const { return centers_; }
  const std::vector<double>& root_radii() const { return radii_; }
  // Each robot's wrench on the free objects at (q, v) (n_robots x 6, world axes): the force
  // [N] its pieces exert on them, summed, and its moment about the world's origin [N m],
  // sum of x (-f) with f the force on the robot at x: the first robot's from its system's
  // pairs with its objects, the others' from their sets with the objects (the anchors read
  // only).
  Eigen::MatrixXd object_wrenches(const ConstVec& q, const ConstVec& v);

 private:
  const Data& data_of(int side);
  const Model& model_of(int side) const;
  void push(int side, int joint_id, const Vec3& point, const Vec3& force);
  // where side k's root state starts in the joined q and v, and its velocity's size
  void side_state(std::size_t side, Eigen::Index& at_q, Eigen::Index& at_v, Eigen::Index& nv) const;
  // every system's kinematics at (q, v) (its robot's and its objects' data)
  void kinematics(const ConstVec& q, const ConstVec& v);

  std::vector<System*> systems_;
  std::vector<Eigen::Index> q_at_, v_at_;
  Model model_;  // every system's joints, each system's tree under the universe
  ManifoldStepper stepper_;
  Eigen::VectorXd acceleration_;
  std::vector<PairContacts> found_;
  // near()'s work: each side's sphere about its root, the sets whose sides' spheres meet
  std::vector<Vec3> centers_;
  std::vector<double> radii_;
  std::vector<std::size_t> close_;
};

}  // namespace uvms
