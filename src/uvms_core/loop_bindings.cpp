// nanobind bindings of the sampled closed loop (sampled_loop.hpp); the Python side is
// uvms_pin/sim/compiled_loop.py. One call runs a chunk of ticks with the GIL released.
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "law_force_baselines.hpp"
#include "law_task_priority.hpp"
#include "law_tracking.hpp"
#include "law_zero.hpp"
#include "ppc.hpp"
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

// The fields every force task's settings share (ForceTaskSettings), on a derived struct.
template <typename Settings>
void bind_task_settings(nb::class_<Settings>& c) {
  c.def(nb::init<>())
      .def_rw("ee_frame_id", &Settings::ee_frame_id)
      .def_rw("velocity_weights", &Settings::velocity_weights)
      .def_rw("null_space_gain_per_s", &Settings::null_space_gain_per_s)
      .def_rw("limited_q_index", &Settings::limited_q_index)
      .def_rw("limited_v_index", &Settings::limited_v_index)
      .def_rw("null_space_target", &Settings::null_space_target)
      .def_rw("half_range", &Settings::half_range)
      .def_rw("max_condition_bound", &Settings::max_condition_bound)
      .def_rw("refine_above_condition_bound", &Settings::refine_above_condition_bound)
      .def_rw("min_abs_cos_pitch", &Settings::min_abs_cos_pitch);
}

// ForceLoopGains' fields on a derived struct.
template <typename Settings>
void bind_loop_gains(nb::class_<Settings>& c) {
  c.def_rw("kp_force_m_s_per_N", &Settings::kp_force_m_s_per_N)
      .def_rw("ki_force_m_s2_per_N", &Settings::ki_force_m_s2_per_N)
      .def_rw("k_orientation_per_s", &Settings::k_orientation_per_s)
      .def_rw("integral_limit_Ns", &Settings::integral_limit_Ns);
}

void bind_force_baselines(nb::module_& m) {
  using uvms::ForceLoopState;
  using uvms::ImpedanceState;
  nb::class_<ForceLoopState>(m, "ForceLoopState",
                             "ForceOrientationLoop's integral and last sample "
                             "(law_force_baselines.hpp).")
      .def(nb::init<>())
      .def_rw("integral_Ns", &ForceLoopState::integral_Ns)
      .def_rw("started", &ForceLoopState::started)
      .def_rw("last_time_s", &ForceLoopState::last_time_s)
      .def_rw("last_force_error_N", &ForceLoopState::last_force_error_N);
  nb::class_<ImpedanceState>(m, "ImpedanceState", "The impedance's anchor and posture.")
      .def(nb::init<>())
      .def_rw("anchored", &ImpedanceState::anchored)
      .def_rw("anchor_world_m", &ImpedanceState::anchor_world_m)
      .def_rw("posture_q", &ImpedanceState::posture_q);

  nb::class_<uvms::ZeroLaw, uvms::SampledLaw>(m, "ZeroLaw", "No input at all (law_zero.hpp).")
      .def(nb::init<int, int>(), "nq"_a, "nv"_a);

  using uvms::PiForceSettings;
  nb::class_<PiForceSettings> pi_settings(m, "PiForceSettings", "PI force law's settings.");
  bind_task_settings(pi_settings);
  bind_loop_gains(pi_settings);
  pi_settings.def_rw("damping", &PiForceSettings::damping);
  nb::class_<uvms::PiForceLaw, uvms::SampledLaw>(m, "PiForceLaw",
                                                 "The PI force law (law_force_baselines.hpp).")
      .def(
          "__init__",
          [](uvms::PiForceLaw* self, const std::string& model_text, const PiForceSettings& s) {
            new (self) uvms::PiForceLaw(uvms::model_from_text(model_text), s);
          },
          "model_text"_a, "settings"_a)
      .def_rw("state", &uvms::PiForceLaw::state);

  using uvms::ImpedanceSettings;
  nb::class_<ImpedanceSettings> imp_settings(m, "ImpedanceSettings", "Impedance law's settings.");
  bind_task_settings(imp_settings);
  imp_settings.def_rw("stiffness_N_m", &ImpedanceSettings::stiffness_N_m)
      .def_rw("damping_N_s_m", &ImpedanceSettings::damping_N_s_m)
      .def_rw("stiffness_Nm_rad", &ImpedanceSettings::stiffness_Nm_rad)
      .def_rw("damping_Nm_s_rad", &ImpedanceSettings::damping_Nm_s_rad)
      .def_rw("velocity_damping", &ImpedanceSettings::velocity_damping)
      .def_rw("posture_stiffness_Nm_rad", &ImpedanceSettings::posture_stiffness_Nm_rad);
  nb::class_<uvms::ImpedanceLaw, uvms::SampledLaw>(m, "ImpedanceLaw",
                                                   "The impedance law (law_force_baselines.hpp).")
      .def(
          "__init__",
          [](uvms::ImpedanceLaw* self, const std::string& model_text,
             const ImpedanceSettings& s) {
            new (self) uvms::ImpedanceLaw(uvms::model_from_text(model_text), s);
          },
          "model_text"_a, "settings"_a)
      .def_rw("state", &uvms::ImpedanceLaw::state);

  using uvms::ComputedTorqueSettings;
  nb::class_<ComputedTorqueSettings> ct_settings(m, "ComputedTorqueSettings",
                                                 "Computed-torque law's settings.");
  bind_task_settings(ct_settings);
  bind_loop_gains(ct_settings);
  ct_settings.def_rw("velocity_gain_per_s", &ComputedTorqueSettings::velocity_gain_per_s);
  nb::class_<uvms::ComputedTorqueLaw, uvms::SampledLaw>(
      m, "ComputedTorqueLaw", "The computed-torque law (law_force_baselines.hpp).")
      .def(nb::init<const uvms::Dynamics&, ComputedTorqueSettings>(), "dynamics"_a,
           "settings"_a)
      .def_rw("state", &uvms::ComputedTorqueLaw::state);
}

// The task-priority law (law_task_priority.hpp), its settings and its dynamic levels'.
void bind_task_priority_law(nb::module_& m) {
  using uvms::TaskPrioritySettings;
  nb::class_<TaskPrioritySettings>(m, "TaskPrioritySettings",
                                   "The tracking task and the kinematic level's gains "
                                   "(task_priority.hpp).")
      .def(nb::init<>())
      .def_rw("vehicle_target", &TaskPrioritySettings::vehicle_target)
      .def_rw("vehicle_frame", &TaskPrioritySettings::vehicle_frame)
      .def_rw("frame_id", &TaskPrioritySettings::frame_id)
      .def_rw("rotation_reference", &TaskPrioritySettings::rotation_reference)
      .def_rw("rows", &TaskPrioritySettings::rows)
      .def_rw("position_gain_per_s", &TaskPrioritySettings::position_gain_per_s)
      .def_rw("orientation_gain_per_s", &TaskPrioritySettings::orientation_gain_per_s)
      .def_rw("attitude_gain_per_s", &TaskPrioritySettings::attitude_gain_per_s)
      .def_rw("joint_limit_margin_rad", &TaskPrioritySettings::joint_limit_margin_rad)
      .def_rw("joint_limit_gain_per_s", &TaskPrioritySettings::joint_limit_gain_per_s)
      .def_rw("manipulability_threshold", &TaskPrioritySettings::manipulability_threshold)
      .def_rw("manipulability_gain", &TaskPrioritySettings::manipulability_gain)
      .def_rw("velocity_weights", &TaskPrioritySettings::velocity_weights)
      .def_rw("damping", &TaskPrioritySettings::damping)
      .def_rw("passive_velocities", &TaskPrioritySettings::passive_velocities);
  using uvms::InverseDynamicsSettings;
  nb::class_<InverseDynamicsSettings>(m, "InverseDynamicsSettings",
                                      "InverseDynamicsLevel's gains (dynamic_level.hpp).")
      .def(nb::init<>())
      .def_rw("velocity_gain_per_s", &InverseDynamicsSettings::velocity_gain_per_s)
      .def_rw("integral_gain_per_s2", &InverseDynamicsSettings::integral_gain_per_s2)
      .def_rw("integral_limit", &InverseDynamicsSettings::integral_limit);
  using uvms::InverseDynamicsState;
  nb::class_<InverseDynamicsState>(m, "InverseDynamicsState",
                                   "InverseDynamicsLevel's integral and last call.")
      .def(nb::init<>())
      .def_rw("integral", &InverseDynamicsState::integral)
      .def_rw("started", &InverseDynamicsState::started)
      .def_rw("last_time_s", &InverseDynamicsState::last_time_s);
  using uvms::PpcVelocitySettings;
  nb::class_<PpcVelocitySettings>(m, "PpcVelocitySettings",
                                  "PpcVelocityLevel's gain and funnel (dynamic_level.hpp).")
      .def(nb::init<>())
      .def_rw("gain", &PpcVelocitySettings::gain)
      .def_rw("rho0", &PpcVelocitySettings::rho0)
      .def_rw("rho_inf", &PpcVelocitySettings::rho_inf)
      .def_rw("decay_rate_per_s", &PpcVelocitySettings::decay_rate_per_s);
  using uvms::TaskPriorityLaw;
  nb::class_<TaskPriorityLaw, uvms::SampledLaw>(m, "TaskPriorityLaw",
                                                "The task-priority law (law_task_priority.hpp).")
      .def(
          "__init__",
          [](TaskPriorityLaw* self, const std::string& model_text,
             const TaskPrioritySettings& s, const uvms::Dynamics& dynamics,
             const InverseDynamicsSettings& level) {
            new (self) TaskPriorityLaw(uvms::model_from_text(model_text), s, dynamics, level);
          },
          "model_text"_a, "settings"_a, "dynamics"_a, "level"_a,
          "With the inverse-dynamics level on `dynamics`.")
      .def(
          "__init__",
          [](TaskPriorityLaw* self, const std::string& model_text,
             const TaskPrioritySettings& s, const PpcVelocitySettings& level) {
            new (self) TaskPriorityLaw(uvms::model_from_text(model_text), s, level);
          },
          "model_text"_a, "settings"_a, "level"_a, "With the PPC's velocity level.")
      .def_prop_rw("state", &TaskPriorityLaw::state, &TaskPriorityLaw::set_state,
                   "The inverse-dynamics level's committed state.");
}

// The prioritized recursion of the kinematic level (task_priority.hpp), for the tests.
void bind_prioritized_velocity(nb::module_& m) {
  m.def(
      "prioritized_velocity",
      [](const std::vector<std::pair<Eigen::MatrixXd, Eigen::VectorXd>>& tasks,
         const Eigen::VectorXd& weights, double damping,
         const std::optional<Eigen::VectorXd>& secondary) {
        const auto n = weights.size();
        if (n == 0 || !(weights.array() > 0.0).all() || !(damping > 0.0)) {
          throw uvms::InputError("prioritized_velocity: weights and damping must be positive");
        }
        std::vector<uvms::PriorityTask> list;
        for (const auto& [jacobian, rate] : tasks) {
          if (jacobian.cols() != n || rate.size() != jacobian.rows()) {
            throw uvms::InputError("prioritized_velocity: a task's J must be m x " +
                                   std::to_string(n) + " and its x of m entries");
          }
          list.push_back({jacobian, rate});
        }
        if (secondary && secondary->size() != n) {
          throw uvms::InputError("prioritized_velocity: secondary needs " + std::to_string(n) +
                                 " entries");
        }
        return uvms::prioritized_velocity(list, weights, damping,
                                          secondary ? &*secondary : nullptr);
      },
      "tasks"_a, "weights"_a, "damping"_a, "secondary"_a = nb::none(),
      "task_priority.py's prioritized_velocity (task_priority.hpp).");
}

void bind_tracking_laws(nb::module_& m) {
  using uvms::ResolvedAccelerationSettings;
  nb::class_<ResolvedAccelerationSettings> ra_settings(
      m, "ResolvedAccelerationSettings", "Resolved-acceleration law's settings (law_tracking.hpp).");
  ra_settings.def(nb::init<>())
      .def_rw("vehicle_target", &ResolvedAccelerationSettings::vehicle_target)
      .def_rw("vehicle_frame", &ResolvedAccelerationSettings::vehicle_frame)
      .def_rw("frame_id", &ResolvedAccelerationSettings::frame_id)
      .def_rw("rotation_reference", &ResolvedAccelerationSettings::rotation_reference)
      .def_rw("rows", &ResolvedAccelerationSettings::rows)
      .def_rw("position_gain_per_s2", &ResolvedAccelerationSettings::position_gain_per_s2)
      .def_rw("velocity_gain_per_s", &ResolvedAccelerationSettings::velocity_gain_per_s)
      .def_rw("null_space_damping_per_s", &ResolvedAccelerationSettings::null_space_damping_per_s)
      .def_rw("velocity_weights", &ResolvedAccelerationSettings::velocity_weights);
  nb::class_<uvms::ResolvedAccelerationLaw, uvms::SampledLaw>(
      m, "ResolvedAccelerationLaw", "The resolved-acceleration law (law_tracking.hpp).")
      .def(nb::init<const uvms::Dynamics&, ResolvedAccelerationSettings>(), "dynamics"_a,
           "settings"_a);
  bind_task_priority_law(m);
  bind_prioritized_velocity(m);
}

}  // namespace

// The law interface (law.hpp) and the PPC's settings: bound before the laws deriving from
// it (the PPC's binding, bindings.cpp).
void bind_sampled_laws(nb::module_& m) {
  using uvms::PpcSettings;
  nb::class_<PpcSettings> ppc_settings(m, "PpcSettings",
                                       "Gains, funnels and solver settings (ppc.hpp).");
  bind_task_settings(ppc_settings);
  ppc_settings.def_rw("k_x", &PpcSettings::k_x)
      .def_rw("rho0_x", &PpcSettings::rho0_x)
      .def_rw("rho_inf_x", &PpcSettings::rho_inf_x)
      .def_rw("l_x_per_s", &PpcSettings::l_x_per_s)
      .def_rw("k_zeta", &PpcSettings::k_zeta)
      .def_rw("rho0_zeta", &PpcSettings::rho0_zeta)
      .def_rw("rho_inf_zeta", &PpcSettings::rho_inf_zeta)
      .def_rw("l_zeta_per_s", &PpcSettings::l_zeta_per_s)
      .def_rw("xi_clamp", &PpcSettings::xi_clamp);
  using uvms::SampledLaw;
  nb::class_<SampledLaw>(m, "SampledLaw", "A compiled control law of the sampled loop (law.hpp).")
      .def_prop_ro("nq", &SampledLaw::nq)
      .def_prop_ro("nv", &SampledLaw::nv)
      .def_prop_ro("desired_size", &SampledLaw::desired_size)
      .def_prop_ro("tau_offset", &SampledLaw::tau_offset)
      .def(
          "signals",
          [](SampledLaw& c) {
            // a read-only view of the last ok command's packed signals (it lives with c)
            const Eigen::VectorXd& s = c.signals();
            return nb::ndarray<nb::numpy, const double, nb::ndim<1>>(
                s.data(), {static_cast<std::size_t>(s.size())}, nb::handle());
          },
          nb::rv_policy::reference_internal)
      .def(
          "signal_layout",
          [](SampledLaw& c) {
            nb::dict out;
            for (const auto& slot : c.signal_layout()) {
              out[slot.name] = nb::make_tuple(slot.offset, slot.offset + slot.size);
            }
            return out;
          },
          "{name: (start, stop)} of each signal in signals(), in order");
}

void bind_sampled_loop(nb::module_& m) {
  bind_force_baselines(m);
  bind_tracking_laws(m);
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
      [](uvms::Plant& plant, uvms::SampledLaw& law,
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
        require(static_cast<int>(desired.shape(0)) >= n_ticks &&
                    static_cast<int>(desired.shape(1)) == law.desired_size(),
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
