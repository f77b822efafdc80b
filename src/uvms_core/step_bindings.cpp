// nanobind bindings of one control period's Jacobians (step_derivatives.hpp); the Python side
// is uvms_pin/physics/compiled/step.py (shapes and finiteness are checked there first).
#include <optional>

#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/stl/optional.h>

#include "step_derivatives.hpp"

namespace nb = nanobind;
using namespace nb::literals;

void bind_step_derivatives(nb::module_& m) {
  using uvms::StepDerivatives;
  using uvms::StepJacobians;
  using Vector = Eigen::Ref<const Eigen::VectorXd>;
  nb::class_<StepJacobians>(
      m, "StepJacobians",
      "A period's end state (q, v) and dx_dx (2 nv, 2 nv), dx_dtau (2 nv, nv) (step_derivatives.hpp).")
      .def_ro("q", &StepJacobians::q)
      .def_ro("v", &StepJacobians::v)
      .def_ro("dx_dx", &StepJacobians::dx_dx)
      .def_ro("dx_dtau", &StepJacobians::dx_dtau);
  nb::class_<StepDerivatives>(
      m, "StepDerivatives",
      "The Jacobians of one control period of a fixed-step integrator (step_derivatives.hpp).")
      .def(nb::init<const uvms::Dynamics&>(), "dynamics"_a)
      .def(
          "period",
          [](StepDerivatives& s, const Vector& q, const Vector& v, const Vector& tau,
             const uvms::FlowField& flow, double time_s, const std::optional<Eigen::VectorXd>& tau_ext,
             double period_s, const uvms::FixedStep& integrator) -> StepJacobians {
            if (!tau_ext) return s.period(q, v, tau, flow, nullptr, time_s, period_s, integrator);
            const uvms::ConstVec ext(*tau_ext);
            return s.period(q, v, tau, flow, &ext, time_s, period_s, integrator);
          },
          "q"_a, "v"_a, "tau"_a, "flow"_a, "time_s"_a, "tau_ext"_a.none(), "period_s"_a,
          "integrator"_a);
}
