// Several robots in one sea, integrated together over a control period (mirror of
// uvms_pin/sim/system/robots.py, Robots.acceleration and the integrator's loop of
// Robots._together): each robot's system of bodies (system.hpp: its plant, and for the first
// the world's free objects) and the pair sets between robots and between the other robots and
// the first system's objects (sides: robot k is k, the first system's object i is n + i). The
// right-hand side is each robot's system's, with the contacts between the sides added to its
// bodies as point forces (System::pushes: f on a's body at x, -f on b's; the same as the
// reference's J^T f added to the input, the dynamics being linear in it). The anchors are read
// only: the reference moves them at the period's end, and solves each system's constraints.
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

 private:
  const Data& data_of(int side);
  const Model& model_of(int side) const;
  void push(int side, int joint_id, const Vec3& point, const Vec3& force);

  std::vector<System*> systems_;
  std::vector<Eigen::Index> q_at_, v_at_;
  Model model_;  // every system's joints, each system's tree under the universe
  ManifoldStepper stepper_;
  Eigen::VectorXd acceleration_;
  std::vector<PairContacts> found_;
};

}  // namespace uvms
