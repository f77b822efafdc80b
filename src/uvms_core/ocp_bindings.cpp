// nanobind bindings of the compiled OCP (ocp_costs.hpp, ocp_planner.hpp); the Python side is
// uvms_pin/ocp/compiled.py (it translates uvms_pin.ocp's terms and problems).
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/variant.h>
#include <nanobind/stl/vector.h>

#include "law_mpc.hpp"
#include "ocp_planner.hpp"

namespace nb = nanobind;
using namespace nb::literals;

void bind_ocp(nb::module_& m) {
  using uvms::OcpPlanner;
  nb::class_<uvms::FramePoseCost>(m, "FramePoseCost", "r = log6(T_target^-1 T_f) (ocp_costs.hpp).")
      .def(
          "__init__",
          [](uvms::FramePoseCost* self, int frame_id, const uvms::Mat3& rotation,
             const uvms::Vec3& translation) {
            new (self) uvms::FramePoseCost{frame_id, pinocchio::SE3(rotation, translation)};
          },
          "frame_id"_a, "rotation"_a, "translation"_a);
  nb::class_<uvms::FrameRotationCost>(m, "FrameRotationCost",
                                      "r = log3(R_target^T R_f) (ocp_costs.hpp).")
      .def(nb::init<int, uvms::Mat3>(), "frame_id"_a, "rotation"_a);
  nb::class_<uvms::FramePositionCost>(m, "FramePositionCost",
                                      "r = p_f - p_target [m] (ocp_costs.hpp).")
      .def(nb::init<int, uvms::Vec3>(), "frame_id"_a, "target_m"_a);
  nb::class_<uvms::EffortCost>(m, "EffortCost", "r = u (ocp_costs.hpp).")
      .def(nb::init<int>(), "size"_a);
  nb::class_<uvms::StateDeviationCost>(m, "StateDeviationCost",
                                       "r = (q (-) q_ref, v - v_ref) (ocp_costs.hpp).")
      .def(nb::init<Eigen::VectorXd>(), "x_ref"_a);
  nb::class_<uvms::ContactForceCost>(m, "ContactForceCost", "r = f - f_d [N] (ocp_costs.hpp).")
      .def(nb::init<uvms::Vec3>(), "target_N"_a);
  nb::class_<uvms::JointLimitCost>(m, "JointLimitCost",
                                   "r = q_j - clip(q_j, lo_j, hi_j) (ocp_costs.hpp).")
      .def(nb::init<std::vector<int>, std::vector<int>, Eigen::VectorXd, Eigen::VectorXd>(),
           "q_index"_a, "v_index"_a, "lower"_a, "upper"_a);
  nb::class_<uvms::OcpTerm>(m, "OcpTerm", "A cost kind and its weights (scale W's diagonal).")
      .def(nb::init<uvms::CostKind, Eigen::VectorXd>(), "kind"_a, "weights"_a);

  nb::enum_<uvms::OcpIntegrator>(m, "OcpIntegrator")
      .value("euler", uvms::OcpIntegrator::kEuler)
      .value("rk4", uvms::OcpIntegrator::kRk4);
  nb::enum_<uvms::OcpSolver>(m, "OcpSolver")
      .value("box_fddp", uvms::OcpSolver::kBoxFddp)
      .value("fddp", uvms::OcpSolver::kFddp);
  nb::class_<uvms::OcpProblemSpec>(m, "OcpProblemSpec", "A shooting problem's setting (ocp_planner.hpp).")
      .def(nb::init<>())
      .def_rw("dt_s", &uvms::OcpProblemSpec::dt_s)
      .def_rw("integrator", &uvms::OcpProblemSpec::integrator)
      .def_rw("solver", &uvms::OcpProblemSpec::solver)
      .def_rw("input_matrix", &uvms::OcpProblemSpec::input_matrix)
      .def_rw("lower", &uvms::OcpProblemSpec::lower)
      .def_rw("upper", &uvms::OcpProblemSpec::upper)
      .def_rw("flow", &uvms::OcpProblemSpec::flow)
      .def_rw("times_s", &uvms::OcpProblemSpec::times_s)
      .def_rw("contact_frame", &uvms::OcpProblemSpec::contact_frame);
  nb::class_<uvms::OcpSolveResult>(m, "OcpSolveResult")
      .def_ro("cost", &uvms::OcpSolveResult::cost)
      .def_ro("iterations", &uvms::OcpSolveResult::iterations)
      .def_ro("regularization", &uvms::OcpSolveResult::regularization);
  nb::class_<OcpPlanner>(m, "OcpPlanner",
                         "A compiled shooting problem and its FDDP solver (ocp_planner.hpp).")
      .def(nb::init<const uvms::Dynamics&, const uvms::OcpProblemSpec&,
                    std::vector<std::vector<uvms::OcpTerm>>, std::vector<uvms::OcpTerm>,
                    const Eigen::VectorXd&>(),
           "dynamics"_a, "spec"_a, "running"_a, "terminal"_a, "x0"_a)
      .def_prop_ro("nodes", &OcpPlanner::nodes)
      .def_prop_ro("nu", &OcpPlanner::nu)
      .def_prop_ro("default_step_lengths", &OcpPlanner::default_step_lengths)
      .def("set_x0", &OcpPlanner::set_x0, "x0"_a)
      .def("set_contact", &OcpPlanner::set_contact, "contact"_a)
      .def("set_force_target", &OcpPlanner::set_force_target, "node"_a, "target_N"_a)
      .def("solve", &OcpPlanner::solve, "xs"_a, "us"_a, "iterations"_a, "regularization"_a,
           "step_lengths"_a, nb::call_guard<nb::gil_scoped_release>())
      .def_prop_ro("xs", &OcpPlanner::xs)
      .def_prop_ro("us", &OcpPlanner::us)
      .def(
          "evaluate",
          [](OcpPlanner& p, int node, const Eigen::VectorXd& x, const Eigen::VectorXd& u) {
            const auto d = p.evaluate(node, x, u);
            nb::dict out;
            out["xout"] = Eigen::VectorXd(d->xout);
            out["cost"] = d->cost;
            out["r"] = Eigen::VectorXd(d->r);
            out["Fx"] = Eigen::MatrixXd(d->Fx);
            out["Fu"] = Eigen::MatrixXd(d->Fu);
            out["Lx"] = Eigen::VectorXd(d->Lx);
            out["Lu"] = Eigen::VectorXd(d->Lu);
            out["Lxx"] = Eigen::MatrixXd(d->Lxx);
            out["Luu"] = Eigen::MatrixXd(d->Luu);
            out["Lxu"] = Eigen::MatrixXd(d->Lxu);
            return out;
          },
          "node"_a, "x"_a, "u"_a,
          "Node k's differential model at (x, u), calc then calcDiff: its crocoddyl outputs "
          "(xout, cost, r, Fx, Fu, Lx, Lu, Lxx, Luu, Lxu) as a dict.");

  // ---- the MPC as a law of the sampled loop (law_mpc.hpp) -----------------------------------
  using uvms::MpcLaw;
  using uvms::MpcLawSettings;
  using uvms::MpcLawState;
  nb::class_<MpcLawSettings>(m, "MpcLawSettings", "The MPC law's settings (law_mpc.hpp).")
      .def(nb::init<>())
      .def_rw("period_s", &MpcLawSettings::period_s)
      .def_rw("dt_s", &MpcLawSettings::dt_s)
      .def_rw("iterations", &MpcLawSettings::iterations)
      .def_rw("cold_iterations", &MpcLawSettings::cold_iterations)
      .def_rw("warm_start", &MpcLawSettings::warm_start)
      .def_rw("replan_step_lengths", &MpcLawSettings::replan_step_lengths)
      .def_rw("force_task", &MpcLawSettings::force_task)
      .def_rw("ee_frame_id", &MpcLawSettings::ee_frame_id)
      .def_rw("rpy_desired", &MpcLawSettings::rpy_desired)
      .def_rw("contact", &MpcLawSettings::contact)
      .def_rw("place_at_tip", &MpcLawSettings::place_at_tip);
  nb::class_<MpcLawState>(m, "MpcLawState", "The MPC law's state, handed to and from Python.")
      .def(nb::init<>())
      .def_rw("has_plan", &MpcLawState::has_plan)
      .def_rw("last_plan_s", &MpcLawState::last_plan_s)
      .def_rw("xs", &MpcLawState::xs)
      .def_rw("us", &MpcLawState::us)
      .def_rw("regularization", &MpcLawState::regularization)
      .def_rw("tau", &MpcLawState::tau)
      .def_rw("cost", &MpcLawState::cost)
      .def_rw("u0", &MpcLawState::u0)
      .def_rw("contact_point_m", &MpcLawState::contact_point_m)
      .def_rw("placed_contact", &MpcLawState::placed_contact);
  nb::class_<MpcLaw, uvms::SampledLaw>(m, "MpcLaw", "The MPC's re-plans as a law (law_mpc.hpp).")
      .def(
          "__init__",
          [](MpcLaw* self, OcpPlanner& planner, const std::string& model_text,
             const MpcLawSettings& s) {
            new (self) MpcLaw(planner, uvms::model_from_text(model_text), s);
          },
          "planner"_a, "model_text"_a, "settings"_a, nb::keep_alive<1, 2>())
      .def_rw("state", &MpcLaw::state);
}
