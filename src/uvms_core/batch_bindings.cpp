// nanobind section of the batched plant (batch_plant.hpp): uvms_pin._core.BatchPlant and its
// settings; the Python side that fills them is uvms_pin/physics/compiled/batch.py.
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/variant.h>
#include <nanobind/stl/vector.h>

#include <pinocchio/algorithm/joint-configuration.hpp>

#include "batch_derivatives.hpp"
#include "batch_plant.hpp"
#include "pinocchio_kinematics.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using uvms::BatchPlant;
using uvms::InputError;

// A read-only numpy view of a buffer of the batch, kept alive by it.
template <typename Scalar>
nb::ndarray<nb::numpy, const Scalar> view(const Scalar* data, size_t rows, size_t cols) {
  if (cols == 0) return nb::ndarray<nb::numpy, const Scalar>(data, {rows}, nb::handle());
  return nb::ndarray<nb::numpy, const Scalar>(data, {rows, cols}, nb::handle());
}

#define UVMS_BATCH_VIEW(name)                                                                \
  def_prop_ro(                                                                              \
      #name,                                                                                \
      [](const BatchPlant& b) {                                                             \
        return view(b.name.data(), size_t(b.name.rows()), size_t(b.name.cols()));           \
      },                                                                                    \
      nb::rv_policy::reference_internal)

using Commands = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Mask = nb::ndarray<const bool, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

void step(BatchPlant& b, const Commands& tau_commanded, const Mask& stepping) {
  const size_t n = size_t(b.num_envs()), nv = size_t(b.nv());
  if (tau_commanded.shape(0) != n || tau_commanded.shape(1) != nv) {
    throw InputError("tau_commanded must have shape (" + std::to_string(n) + ", " +
                     std::to_string(nv) + "), got (" + std::to_string(tau_commanded.shape(0)) +
                     ", " + std::to_string(tau_commanded.shape(1)) + ")");
  }
  if (stepping.shape(0) != n) {
    throw InputError("stepping must have " + std::to_string(n) + " entries");
  }
  const Eigen::Map<const Eigen::ArrayXd> all(tau_commanded.data(), Eigen::Index(n * nv));
  if (!all.allFinite()) throw InputError("tau_commanded contains a non-finite value");
  nb::gil_scoped_release release;  // the threads run without the interpreter
  b.step(tau_commanded.data(), stepping.data());
}

using States = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Times = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Jacobians = nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;

std::string shape_text(size_t rows, size_t cols) {
  return "(" + std::to_string(rows) + ", " + std::to_string(cols) + ")";
}

// `states` of shape (n, cols) with finite entries, or InputError naming it
void check_states(const char* name, const States& states, size_t n, size_t cols) {
  if (states.shape(0) != n || states.shape(1) != cols) {
    throw InputError(std::string(name) + " must have shape " + shape_text(n, cols) + ", got " +
                     shape_text(states.shape(0), states.shape(1)));
  }
  if (!Eigen::Map<const Eigen::ArrayXd>(states.data(), Eigen::Index(n * cols)).allFinite()) {
    throw InputError(std::string(name) + " contains a non-finite value");
  }
}

void compute_derivatives(uvms::BatchDerivatives& b, const States& q, const States& v,
                         const States& tau, std::optional<States> tau_ext, const Times& time_s,
                         const uvms::FlowField& flow, bool free_surface, Jacobians da_dq,
                         Jacobians da_dv, Jacobians da_dtau) {
  const size_t n = q.shape(0), nq = size_t(b.nq()), nv = size_t(b.nv());
  check_states("q", q, n, nq);
  check_states("v", v, n, nv);
  check_states("tau", tau, n, nv);
  if (tau_ext) check_states("tau_ext", *tau_ext, n, nv);
  if (time_s.shape(0) != n) throw InputError("time_s must have " + std::to_string(n) + " entries");
  for (const Jacobians* out : {&da_dq, &da_dv, &da_dtau}) {
    if (out->shape(0) != n || out->shape(1) != nv || out->shape(2) != nv) {
      throw InputError("the Jacobians' buffers must have shape (n, nv, nv)");
    }
  }
  const uvms::BatchStates states{int(n), q.data(), v.data(), tau.data(),
                                 tau_ext ? tau_ext->data() : nullptr, time_s.data()};
  nb::gil_scoped_release release;  // the threads run without the interpreter
  b.compute(states, flow, free_surface, {da_dq.data(), da_dv.data(), da_dtau.data()});
}

}  // namespace

void bind_batch_derivatives(nb::module_& m) {
  nb::class_<uvms::BatchDerivatives>(
      m, "BatchDerivatives",
      "The forward dynamics' derivatives at n states on T threads (batch_derivatives.hpp).")
      .def(nb::init<const uvms::Dynamics&, int>(), "dynamics"_a, "num_threads"_a)
      .def_prop_ro("num_threads", &uvms::BatchDerivatives::num_threads)
      .def("compute", &compute_derivatives, "q"_a, "v"_a, "tau"_a, "tau_ext"_a.none(), "time_s"_a,
           "flow"_a, "free_surface"_a, "da_dq"_a, "da_dv"_a, "da_dtau"_a,
           "fill da_dq, da_dv, da_dtau (n, nv, nv) at the n states (GIL released)")
      .def(
          "first_off_manifold",
          [](const uvms::BatchDerivatives& b, const States& q, double norm_tolerance) {
            // the first row of q (n, nq) off the configuration manifold (a unit part's norm
            // beyond norm_tolerance of 1), -1 if none: the caller's check names its joint
            const size_t n = q.shape(0), nq = size_t(b.nq());
            check_states("q", q, n, nq);
            for (size_t k = 0; k < n; ++k) {
              const Eigen::Map<const Eigen::VectorXd> row(q.data() + k * nq, Eigen::Index(nq));
              if (!uvms::pinlib::is_normalized(b.model(), row, norm_tolerance)) return long(k);
            }
            return -1L;
          },
          "q"_a, "norm_tolerance"_a);
}

void bind_batch_plant(nb::module_& m) {
  nb::class_<uvms::BatchNoise>(m, "BatchNoise", "Sensor-noise layout of a batch (batch_plant.hpp).")
      .def(nb::init<>())
      .def_rw("sample_period_s", &uvms::BatchNoise::sample_period_s)
      .def_rw("rows", &uvms::BatchNoise::rows)
      .def_rw("silent", &uvms::BatchNoise::silent);
  nb::class_<BatchPlant>(m, "BatchPlant", "N environments of one plant on T threads (batch_plant.hpp).")
      .def(nb::init<const uvms::Plant&, const uvms::FixedStep&, double, uvms::Actuation,
                    uvms::BatchNoise, int, int>(),
           "prototype"_a, "integrator"_a, "control_period_s"_a, "actuation"_a, "noise"_a,
           "num_envs"_a, "num_threads"_a)
      .def_prop_ro("num_envs", &BatchPlant::num_envs)
      .def_prop_ro("num_threads", &BatchPlant::num_threads)
      .def("reset", &BatchPlant::reset, "i"_a, "q0"_a, "v0"_a, "contact"_a, "noise_tables"_a,
           "environment i to t = 0 at (q0, v0), with its contact and noise tables")
      .def("step", &step, "tau_commanded"_a, "stepping"_a,
           "advance the environments with stepping[i] one control period (GIL released)")
      .UVMS_BATCH_VIEW(q)
      .UVMS_BATCH_VIEW(v)
      .UVMS_BATCH_VIEW(q_measured)
      .UVMS_BATCH_VIEW(v_measured)
      .UVMS_BATCH_VIEW(wrench_measured)
      .UVMS_BATCH_VIEW(contact_world)
      .UVMS_BATCH_VIEW(tau_applied)
      .def_prop_ro(
          "tick", [](const BatchPlant& b) { return view(b.tick.data(), size_t(b.tick.rows()), 0); },
          nb::rv_policy::reference_internal)
      .def_prop_ro(
          "status",
          [](const BatchPlant& b) { return view(b.status.data(), size_t(b.status.rows()), 0); },
          nb::rv_policy::reference_internal);
}
