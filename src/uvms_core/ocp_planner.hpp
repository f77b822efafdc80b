// A shooting problem of a UVMS in water and its solver, compiled (mirror of
// uvms_pin/ocp/problems.py shooting_problem and solve): N running nodes of dt_s, each the
// UnderwaterActionModel (ocp_action.hpp) of its own terms and time integrated by crocoddyl's
// Euler or RK4, the terminal node's model integrated over 0 s; solved by crocoddyl's
// SolverBoxFDDP (the input bounds as a box) or SolverFDDP, from a warm start, without Python
// per node. What the MPC needs between solves: the initial state, the environment's placement
// (set_contact) and each node's desired contact force (set_force_target).
#pragma once

#include <memory>
#include <vector>

#include <crocoddyl/core/optctrl/shooting.hpp>
#include <crocoddyl/core/solvers/fddp.hpp>

#include "ocp_action.hpp"

namespace uvms {

enum class OcpIntegrator { kEuler, kRk4 };
enum class OcpSolver { kBoxFddp, kFddp };

struct OcpProblemSpec {
  double dt_s = 0.02;
  OcpIntegrator integrator = OcpIntegrator::kEuler;
  OcpSolver solver = OcpSolver::kBoxFddp;
  Eigen::MatrixXd input_matrix;  // B_u (nv, nu)
  Eigen::VectorXd lower, upper;  // bounds on u (empty: none)
  FlowField flow;
  std::vector<double> times_s;  // each node's time, the flow's (N + 1: running, terminal) [s]
  int contact_frame = -1;  // the end-effector's frame with a contact in the dynamics, else -1
};

struct OcpSolveResult {
  double cost = 0.0;
  int iterations = 0;
  double regularization = 0.0;  // the solver's preg after the solve
};

class OcpPlanner {
 public:
  // running: one term list per running node (their number is N), terminal: the last node's.
  OcpPlanner(const Dynamics& dynamics, const OcpProblemSpec& spec,
             std::vector<std::vector<OcpTerm>> running, std::vector<OcpTerm> terminal,
             const Eigen::VectorXd& x0);

  int nodes() const { return static_cast<int>(models_.size()) - 1; }
  int nu() const { return static_cast<int>(spec_.input_matrix.cols()); }
  const Eigen::MatrixXd& input_matrix() const { return spec_.input_matrix; }
  void set_x0(const Eigen::VectorXd& x0);
  // the environment the contact terms and dynamics use (a problem with a contact only)
  void set_contact(const Contact& contact);
  // node k's (0..N; N the terminal) contact-force cost's f_d [N, world axes]
  void set_force_target(int node, const Vec3& target_N);
  // iterations at most, from (xs, us) (N + 1 and N vectors), the line search's step lengths,
  // the initial regularization (NaN: the solver's smallest); SimulationFailure with the first
  // message a node held during the solve
  OcpSolveResult solve(const std::vector<Eigen::VectorXd>& xs,
                       const std::vector<Eigen::VectorXd>& us, int iterations,
                       double regularization, const std::vector<double>& step_lengths);
  const std::vector<Eigen::VectorXd>& xs() const { return solver_->get_xs(); }
  const std::vector<Eigen::VectorXd>& us() const { return solver_->get_us(); }
  // the solver's own line-search step lengths (crocoddyl's ten, 1 down to 1/512)
  const std::vector<double>& default_step_lengths() const { return default_steps_; }

  // One node's differential model at (x, u) (the tests compare it with the Python reference):
  // calc and calcDiff, their outputs in a crocoddyl data.
  std::shared_ptr<UnderwaterActionModel::DataBase> evaluate(int node, const Eigen::VectorXd& x,
                                                            const Eigen::VectorXd& u);

 private:
  OcpProblemSpec spec_;
  std::shared_ptr<UvmsState> state_;
  std::shared_ptr<OcpWorkspace> work_;
  std::vector<std::shared_ptr<UnderwaterActionModel>> models_;  // running, then terminal
  std::shared_ptr<crocoddyl::ShootingProblemTpl<double>> problem_;
  std::unique_ptr<crocoddyl::SolverFDDP> solver_;
  std::vector<double> default_steps_;
};

}  // namespace uvms
