// A compiled shooting problem of a UVMS in water and its solver (ocp_planner.hpp).
#include "ocp_planner.hpp"

#include <cmath>

#include <crocoddyl/core/integrator/euler.hpp>
#include <crocoddyl/core/integrator/rk.hpp>
#include <crocoddyl/core/solvers/box-fddp.hpp>

namespace uvms {

namespace {

std::shared_ptr<crocoddyl::ActionModelAbstractTpl<double>> integrated(
    std::shared_ptr<UnderwaterActionModel> model, OcpIntegrator integrator, double dt_s) {
  if (integrator == OcpIntegrator::kRk4) {
    return std::make_shared<crocoddyl::IntegratedActionModelRKTpl<double>>(
        model, crocoddyl::RKType::four, dt_s);
  }
  return std::make_shared<crocoddyl::IntegratedActionModelEulerTpl<double>>(model, dt_s);
}

void check_state(const Eigen::VectorXd& x, long nx, const char* what) {
  if (x.size() != nx || !x.allFinite()) {
    throw InputError(std::string("ocp ") + what + " must be " + std::to_string(nx) +
                     " finite values (q, v)");
  }
}

}  // namespace

OcpPlanner::OcpPlanner(const Dynamics& dynamics, const OcpProblemSpec& spec,
                       std::vector<std::vector<OcpTerm>> running, std::vector<OcpTerm> terminal,
                       const Eigen::VectorXd& x0)
    : spec_(spec) {
  const Model& model = dynamics.model();
  if (running.empty() || !(spec.dt_s > 0.0 && std::isfinite(spec.dt_s))) {
    throw InputError("ocp: need at least one running node and dt_s > 0");
  }
  if (spec.input_matrix.rows() != model.nv || spec.input_matrix.cols() < 1) {
    throw InputError("ocp input_matrix must be (nv=" + std::to_string(model.nv) + ", nu)");
  }
  const long nu = spec.input_matrix.cols();
  if (spec.lower.size() != 0 &&
      (spec.lower.size() != nu || spec.upper.size() != nu ||
       !(spec.lower.array() <= spec.upper.array()).all())) {
    throw InputError("ocp u bounds: two (nu,) vectors, lower <= upper");
  }
  if (spec.contact_frame >= static_cast<int>(model.nframes)) {
    throw InputError("ocp contact frame " + std::to_string(spec.contact_frame) + " not in model");
  }
  if (spec.times_s.size() != running.size() + 1) {
    throw InputError("ocp times_s: one time per node (N + 1) needed");
  }
  check_state(x0, model.nq + model.nv, "x0");
  state_ = std::make_shared<UvmsState>(model);
  std::optional<int> frame;
  if (spec.contact_frame >= 0) frame = spec.contact_frame;
  work_ = std::make_shared<OcpWorkspace>(dynamics, frame);
  std::vector<std::shared_ptr<crocoddyl::ActionModelAbstractTpl<double>>> nodes;
  const Eigen::VectorXd none;
  for (std::size_t k = 0; k < running.size(); ++k) {
    models_.push_back(std::make_shared<UnderwaterActionModel>(
        state_, work_, std::move(running[k]), spec.input_matrix, spec.flow,
        spec.times_s[k], spec.lower, spec.upper));
    nodes.push_back(integrated(models_.back(), spec.integrator, spec.dt_s));
  }
  models_.push_back(std::make_shared<UnderwaterActionModel>(
      state_, work_, std::move(terminal), spec.input_matrix, spec.flow,
      spec.times_s.back(), none, none));
  auto last = std::make_shared<crocoddyl::IntegratedActionModelEulerTpl<double>>(models_.back(),
                                                                                  0.0);
  problem_ = std::make_shared<crocoddyl::ShootingProblemTpl<double>>(x0, nodes, last);
  // The nodes share one workspace: one thread. The wheel's libcrocoddyl is built with
  // OpenMP, and its ShootingProblem runs calc / calcDiff on CROCODDYL_WITH_NTHREADS threads
  // unless crocoddyl::enableMultithreading() is false, which crocoddyl's Python bindings
  // set only once a Python-derived model exists; our copy of that flag is not the
  // library's (hidden visibility), so the thread count is read and set on the problem.
  // (set_nthreads(1) is silent here: the constructor raised the count, so the flag is on.)
  if (problem_->get_nthreads() != 1) problem_->set_nthreads(1);
  if (spec.solver == OcpSolver::kBoxFddp) {
    solver_ = std::make_unique<crocoddyl::SolverBoxFDDP>(problem_);
  } else {
    solver_ = std::make_unique<crocoddyl::SolverFDDP>(problem_);
  }
  default_steps_ = solver_->get_alphas();
}

void OcpPlanner::set_x0(const Eigen::VectorXd& x0) {
  check_state(x0, state_->get_nx(), "x0");
  problem_->set_x0(x0);
}

void OcpPlanner::set_contact(const Contact& contact) {
  if (!work_->contact_frame) throw InputError("ocp: this problem has no contact");
  work_->contact = contact;
}

void OcpPlanner::set_force_target(int node, const Vec3& target_N) {
  if (node < 0 || node > nodes()) {
    throw InputError("ocp node " + std::to_string(node) + " outside 0.." +
                     std::to_string(nodes()));
  }
  if (!target_N.allFinite()) throw InputError("ocp contact force target_N must be finite");
  for (auto& term : models_[static_cast<std::size_t>(node)]->terms()) {
    if (auto* force = std::get_if<ContactForceCost>(&term.kind)) force->target_N = target_N;
  }
}

OcpSolveResult OcpPlanner::solve(const std::vector<Eigen::VectorXd>& xs,
                                 const std::vector<Eigen::VectorXd>& us, int iterations,
                                 double regularization, const std::vector<double>& step_lengths) {
  if (iterations < 1) throw InputError("ocp iterations must be >= 1");
  const auto n = static_cast<std::size_t>(nodes());
  if (xs.size() != n + 1 || us.size() != n) {
    throw InputError("ocp warm start: N + 1 states and N inputs needed");
  }
  for (const auto& x : xs) check_state(x, state_->get_nx(), "warm start state");
  for (const auto& u : us) {
    if (u.size() != nu() || !u.allFinite()) {
      throw InputError("ocp warm start: each input must be nu finite values");
    }
  }
  if (!step_lengths.empty()) solver_->set_alphas(step_lengths);
  work_->held.clear();
  solver_->solve(xs, us, static_cast<std::size_t>(iterations), false, regularization);
  if (!work_->held.empty()) {
    const std::string message = work_->held;
    work_->held.clear();
    throw SimulationFailure(message);
  }
  return {solver_->get_cost(), static_cast<int>(solver_->get_iter()), solver_->get_preg()};
}

std::shared_ptr<UnderwaterActionModel::DataBase> OcpPlanner::evaluate(int node,
                                                                      const Eigen::VectorXd& x,
                                                                      const Eigen::VectorXd& u) {
  if (node < 0 || node > nodes()) throw InputError("ocp node outside the problem");
  check_state(x, state_->get_nx(), "x");
  if (u.size() != nu()) throw InputError("ocp u must be nu values");
  auto& model = models_[static_cast<std::size_t>(node)];
  auto data = model->createData();
  work_->held.clear();
  model->calc(data, x, u);
  model->calcDiff(data, x, u);
  if (!work_->held.empty()) {
    const std::string message = work_->held;
    work_->held.clear();
    throw SimulationFailure(message);
  }
  return data;
}

}  // namespace uvms
