// nanobind bindings of the sampled closed loop (sampled_loop.hpp); the Python side is
// uvms_pin/sim/compiled_loop.py. One call runs a chunk of ticks with the GIL released.
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/vector.h>

#include "sampled_loop.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using Out1 = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using In2 = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Out2 = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

void require(bool ok, const std::string& what) {
  if (!ok) throw uvms::InputError("run_sampled_chunk: " + what);
}

Eigen::Map<Eigen::VectorXd> map(Out1& a) {
  return {a.data(), static_cast<Eigen::Index>(a.shape(0))};
}

}  // namespace

void bind_sampled_loop(nb::module_& m) {
  using uvms::Actuation;
  using uvms::LoopSettings;
  nb::class_<Actuation>(m, "Actuation",
                        "Thrusters and joint limits, or none (actuation.hpp); the closed loop's "
                        "and the batched plant's.")
      .def(nb::init<>())
      .def_rw("thrusters", &Actuation::thrusters)
      .def_rw("allocation", &Actuation::allocation)
      .def_rw("allocation_pinv", &Actuation::allocation_pinv)
      .def_rw("lower_N", &Actuation::lower_N)
      .def_rw("upper_N", &Actuation::upper_N)
      .def_rw("full_forward_N", &Actuation::full_forward_N)
      .def_rw("full_reverse_N", &Actuation::full_reverse_N)
      .def_rw("joint_limits_Nm", &Actuation::joint_limits_Nm)
      .def_rw("residual", &Actuation::residual)
      .def_rw("components", &Actuation::components)
      .def(
          "apply",
          [](const Actuation& a, const Eigen::VectorXd& tau_commanded) {
            a.check(static_cast<int>(tau_commanded.size()));
            Eigen::VectorXd tau_applied(tau_commanded.size());
            Eigen::VectorXd thrust = Eigen::VectorXd::Zero(a.n_thrusters());
            a.apply(tau_commanded, tau_applied, thrust);
            return nb::make_tuple(tau_applied, thrust);
          },
          "tau_commanded"_a, "(tau_applied, thrusts f): actuation.py's apply, ideal drives");
  nb::class_<LoopSettings>(m, "LoopSettings", "The loop's settings (sampled_loop.hpp).")
      .def(nb::init<>())
      .def_rw("integrator", &LoopSettings::integrator)
      .def_rw("period_s", &LoopSettings::period_s)
      .def_rw("ticks_per_log", &LoopSettings::ticks_per_log)
      .def_rw("final_tick", &LoopSettings::final_tick)
      .def_rw("state_noisy", &LoopSettings::state_noisy);
  m.def(
      "loop_row",
      [](int nq, int nv, int n_thrusters, int n_signals) {
        const uvms::LoopRow r(nq, nv, n_thrusters, n_signals);
        nb::dict out;
        out["time"] = nb::make_tuple(r.time, r.q);
        out["q"] = nb::make_tuple(r.q, r.v);
        out["v"] = nb::make_tuple(r.v, r.tau);
        out["tau"] = nb::make_tuple(r.tau, r.tau_commanded);
        out["tau_commanded"] = nb::make_tuple(r.tau_commanded, r.contact);
        out["contact"] = nb::make_tuple(r.contact, r.measured_wrench);
        out["measured_wrench"] = nb::make_tuple(r.measured_wrench, r.disturbance);
        out["disturbance"] = nb::make_tuple(r.disturbance, r.signals);
        out["signals"] = nb::make_tuple(r.signals, r.command);
        out["command"] = nb::make_tuple(r.command, r.thrust);
        out["thrust"] = nb::make_tuple(r.thrust, r.width);
        return out;
      },
      "nq"_a, "nv"_a, "n_thrusters"_a, "n_signals"_a,
      "{name: (start, stop)} of each quantity in a logged row (LoopRow)");
  m.def("noise_width", &uvms::noise_width, "nv"_a, "Entries of one tick's noise row.");
  m.def(
      "run_sampled_chunk",
      [](uvms::Plant& plant, uvms::PrescribedPerformanceController& law,
         const Actuation& actuation, const LoopSettings& settings, int first, int n_ticks,
         Out1 q, Out1 v, In2 noise, In2 desired, Out2 log, Out1 command, Out1 thrust,
         Out1 dropped_max) {
        const auto& model = plant.dynamics().model();
        require(law.nq() == model.nq && law.nv() == model.nv, "the law's model is not the plant's");
        require(static_cast<int>(q.shape(0)) == model.nq && static_cast<int>(v.shape(0)) == model.nv,
                "q, v of the wrong size");
        require(n_ticks >= 0 && first >= 0 && settings.ticks_per_log >= 1 &&
                    settings.period_s > 0.0 && settings.integrator.step_s > 0.0,
                "bad tick range or settings");
        require(static_cast<int>(noise.shape(0)) >= n_ticks &&
                    static_cast<int>(noise.shape(1)) == uvms::noise_width(model.nv),
                "noise table of the wrong shape");
        require(static_cast<int>(desired.shape(0)) >= n_ticks && desired.shape(1) == 6,
                "desired table of the wrong shape");
        const int m_thrusters = static_cast<int>(thrust.shape(0));
        require(command.shape(0) == thrust.shape(0), "command and thrust sizes differ");
        if (actuation.thrusters) {
          require(actuation.allocation.rows() == 6 && actuation.allocation.cols() == m_thrusters &&
                      actuation.allocation_pinv.rows() == m_thrusters &&
                      actuation.allocation_pinv.cols() == 6 &&
                      actuation.lower_N.size() == m_thrusters &&
                      actuation.upper_N.size() == m_thrusters &&
                      actuation.full_forward_N.size() == m_thrusters &&
                      actuation.full_reverse_N.size() == m_thrusters,
                  "thruster arrays of the wrong shape");
          require(actuation.joint_limits_Nm.size() == 0 ||
                      actuation.joint_limits_Nm.size() == model.nv - 6,
                  "joint limits of the wrong size");
          const auto c = static_cast<Eigen::Index>(actuation.components.size());
          require(actuation.residual.size() == 0 ||
                      (actuation.residual.rows() == c && actuation.residual.cols() == c),
                  "residual of the wrong shape");
          require(actuation.residual.size() == 0 || dropped_max.shape(0) == static_cast<size_t>(c),
                  "dropped_max of the wrong size");
          for (const int k : actuation.components) require(k >= 0 && k < 6, "bad component");
        }
        const uvms::LoopRow row(model.nq, model.nv, m_thrusters,
                                static_cast<int>(law.signals().size()));
        const int logged = n_ticks == 0 ? 0 : (first + n_ticks - 1) / settings.ticks_per_log -
                                                  (first - 1 + settings.ticks_per_log) /
                                                      settings.ticks_per_log + 1;
        require(static_cast<int>(log.shape(1)) == row.width &&
                    static_cast<int>(log.shape(0)) >= logged,
                "log buffer of the wrong shape");
        uvms::ChunkOutcome outcome;
        {
          nb::gil_scoped_release release;  // other runs' threads go on meanwhile
          outcome = uvms::run_sampled_chunk(
              plant, law, actuation, settings, first, n_ticks, map(q), map(v), noise.data(),
              desired.data(), log.data(), {map(command), map(thrust), map(dropped_max)});
        }
        return nb::make_tuple(outcome.ticks_done, outcome.rows_written, outcome.stopped);
      },
      "plant"_a, "law"_a, "actuation"_a, "settings"_a, "first"_a, "n_ticks"_a, "q"_a, "v"_a,
      "noise"_a, "desired"_a, "log"_a, "command"_a, "thrust"_a, "dropped_max"_a,
      "(ticks done, rows written, stopped: the next tick is Python's); sampled_loop.hpp");
}
