// nanobind module uvms_pin._core: the compiled Dynamics and Plant.
// Bad input raises uvms_pin.errors.ParameterError, a failed solve SimulationError.
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <pinocchio/config.hpp>

#include "plant.hpp"
#include "ppc.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using uvms::ConstVec;
using uvms::InputError;

template <int... Shape>
using Array = nb::ndarray<const double, nb::shape<Shape...>, nb::c_contig, nb::device::cpu>;

void check_vector(const char* name, const ConstVec& x, Eigen::Index n) {
  if (x.size() != n) {
    throw InputError(std::string(name) + " must have shape (" + std::to_string(n) +
                     ",), got (" + std::to_string(x.size()) + ",)");
  }
  if (!x.allFinite()) throw InputError(std::string(name) + " contains a non-finite value");
}

uvms::Vec3 vec3(const char* name, const ConstVec& x) {
  check_vector(name, x, 3);
  return x;
}

uvms::Vec6 vec6(const char* name, const ConstVec& x) {
  check_vector(name, x, 6);
  return x;
}

template <int R, int C, typename Arr>
Eigen::Matrix<double, R, C> matrix_at(const Arr& a, std::size_t k) {
  // numpy stacks are row-major
  return Eigen::Map<const Eigen::Matrix<double, R, C, (C > 1 ? Eigen::RowMajor : Eigen::ColMajor)>>(
      a.data() + k * R * C);
}

uvms::HydroBodies hydro_bodies(double rho, const Array<-1, 6, 6>& added,
                               const Array<-1>& volume, const Array<-1, 3>& cob,
                               const std::vector<int>& damped_joint,
                               const Array<-1, 6, 6>& damped_action,
                               const Array<-1, 3, 3>& damped_rotation,
                               const Array<-1, 3>& damped_position,
                               const Array<-1, 6, 6>& damped_linear,
                               const Array<-1, 6>& damped_quadratic) {
  uvms::HydroBodies out;
  out.water_density_kg_m3 = rho;
  const std::size_t nj = added.shape(0);
  if (volume.shape(0) != nj || cob.shape(0) != nj) {
    throw InputError("added_mass, volume and center_of_buoyancy need one entry per joint");
  }
  for (std::size_t j = 0; j < nj; ++j) {
    out.added_mass_per_joint.push_back(matrix_at<6, 6>(added, j));
    out.volume_per_joint_m3.push_back(volume.data()[j]);
    out.center_of_buoyancy_per_joint_m.push_back(matrix_at<3, 1>(cob, j));
  }
  const std::size_t nd = damped_joint.size();
  if (damped_action.shape(0) != nd || damped_rotation.shape(0) != nd ||
      damped_position.shape(0) != nd || damped_linear.shape(0) != nd ||
      damped_quadratic.shape(0) != nd) {
    throw InputError("damped-body arrays need one entry per damped body");
  }
  for (std::size_t k = 0; k < nd; ++k) {
    out.damped_bodies.push_back({damped_joint[k], matrix_at<6, 6>(damped_action, k),
                                 matrix_at<3, 3>(damped_rotation, k),
                                 matrix_at<3, 1>(damped_position, k),
                                 matrix_at<6, 6>(damped_linear, k),
                                 matrix_at<6, 1>(damped_quadratic, k)});
  }
  return out;
}

uvms::FlowField current_flow(const ConstVec& current_world) {
  uvms::FlowField flow;
  flow.current_world_m_s = vec3("current_world", current_world);
  return flow;
}

// A uniform current plus wave components: rows [amplitude_m, angular_frequency_rad_s,
// wavenumber_rad_m, heading_rad, phase_rad] of ``waves`` (m x 5), all in water of depth d.
uvms::FlowField wave_flow(const ConstVec& current_world, const Eigen::MatrixXd& waves,
                          double water_depth_m) {
  uvms::FlowField flow = current_flow(current_world);
  if (waves.size() != 0 && waves.cols() != 5) {
    throw uvms::InputError("waves must have 5 columns (amplitude, angular frequency, "
                           "wavenumber, heading, phase), got " + std::to_string(waves.cols()));
  }
  if (!waves.allFinite() || !(water_depth_m > 0.0)) {
    throw uvms::InputError("waves must be finite and water_depth_m positive");
  }
  for (Eigen::Index i = 0; i < waves.rows(); ++i) {
    flow.waves.push_back({waves(i, 0), waves(i, 1), waves(i, 2), waves(i, 3), waves(i, 4)});
  }
  flow.water_depth_m = water_depth_m;
  return flow;
}

void check_state(uvms::Dynamics& d, const ConstVec& q, const ConstVec& v) {
  check_vector("q", q, d.nq());
  check_vector("v", v, d.nv());
}

}  // namespace

NB_MODULE(_core, m) {
  m.doc() = "Compiled dynamics and plant of uvms-pin (C++ on Pinocchio's C++ API).";
  m.attr("API_VERSION") = 1;
  m.attr("PINOCCHIO_VERSION") = PINOCCHIO_VERSION;
  m.attr("SOURCE_HASH") = UVMS_CORE_SOURCE_HASH;

  // the project's own exceptions, raised directly from C++
  nb::object errors = nb::module_::import_("uvms_pin.errors");
  // references kept for the process lifetime (no destructor after the interpreter ends)
  static PyObject* parameter_error = nb::object(errors.attr("ParameterError")).release().ptr();
  static PyObject* simulation_error = nb::object(errors.attr("SimulationError")).release().ptr();
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const uvms::InputError& e) {
      PyErr_SetString(parameter_error, e.what());
    } catch (const uvms::SimulationFailure& e) {
      PyErr_SetString(simulation_error, e.what());
    }
  });

  nb::class_<uvms::Dynamics>(m, "Dynamics")
      .def(
          "__init__",
          [](uvms::Dynamics* self, const std::string& model_text, double rho,
             const Array<-1, 6, 6>& added, const Array<-1>& volume, const Array<-1, 3>& cob,
             const std::vector<int>& damped_joint, const Array<-1, 6, 6>& damped_action,
             const Array<-1, 3, 3>& damped_rotation, const Array<-1, 3>& damped_position,
             const Array<-1, 6, 6>& damped_linear, const Array<-1, 6>& damped_quadratic) {
            new (self) uvms::Dynamics(
                uvms::model_from_text(model_text),
                hydro_bodies(rho, added, volume, cob, damped_joint, damped_action,
                             damped_rotation, damped_position, damped_linear,
                             damped_quadratic));
          },
          "model_text"_a, "water_density_kg_m3"_a, "added_mass_per_joint"_a,
          "volume_per_joint_m3"_a, "center_of_buoyancy_per_joint_m"_a, "damped_joint"_a,
          "damped_action"_a, "damped_rotation"_a, "damped_position"_a, "damped_linear"_a,
          "damped_quadratic"_a)
      .def_prop_ro("nq", &uvms::Dynamics::nq)
      .def_prop_ro("nv", &uvms::Dynamics::nv)
      .def(
          "mass_matrix",
          [](uvms::Dynamics& d, const ConstVec& q) -> Eigen::MatrixXd {
            check_vector("q", q, d.nq());
            return d.mass_matrix(q);
          },
          "q"_a)
      .def(
          "bias_forces",
          [](uvms::Dynamics& d, const ConstVec& q, const ConstVec& v,
             const ConstVec& current_world) -> Eigen::VectorXd {
            check_state(d, q, v);
            return d.bias_forces(q, v, current_flow(current_world));
          },
          "q"_a, "v"_a, "current_world"_a)
      .def(
          "bias_forces_in_waves",
          [](uvms::Dynamics& d, const ConstVec& q, const ConstVec& v,
             const ConstVec& current_world, const Eigen::MatrixXd& waves, double water_depth_m,
             double time_s) -> Eigen::VectorXd {
            check_state(d, q, v);
            return d.bias_forces(q, v, wave_flow(current_world, waves, water_depth_m), time_s);
          },
          "q"_a, "v"_a, "current_world"_a, "waves"_a, "water_depth_m"_a, "time_s"_a)
      .def(
          "forward_dynamics_in_waves",
          [](uvms::Dynamics& d, const ConstVec& q, const ConstVec& v, const ConstVec& tau,
             const ConstVec& current_world, const Eigen::MatrixXd& waves, double water_depth_m,
             double time_s, std::optional<Eigen::VectorXd> tau_ext) -> Eigen::VectorXd {
            check_state(d, q, v);
            check_vector("tau", tau, d.nv());
            const uvms::FlowField flow = wave_flow(current_world, waves, water_depth_m);
            if (!tau_ext) return d.forward_dynamics(q, v, tau, flow, nullptr, time_s);
            check_vector("tau_ext", *tau_ext, d.nv());
            const ConstVec ext(*tau_ext);
            return d.forward_dynamics(q, v, tau, flow, &ext, time_s);
          },
          "q"_a, "v"_a, "tau"_a, "current_world"_a, "waves"_a, "water_depth_m"_a, "time_s"_a,
          "tau_ext"_a = nb::none())
      .def(
          "forward_dynamics",
          [](uvms::Dynamics& d, const ConstVec& q, const ConstVec& v, const ConstVec& tau,
             const ConstVec& current_world,
             std::optional<Eigen::VectorXd> tau_ext) -> Eigen::VectorXd {
            check_state(d, q, v);
            check_vector("tau", tau, d.nv());
            const uvms::FlowField flow = current_flow(current_world);
            if (!tau_ext) return d.forward_dynamics(q, v, tau, flow, nullptr);
            check_vector("tau_ext", *tau_ext, d.nv());
            const ConstVec ext(*tau_ext);
            return d.forward_dynamics(q, v, tau, flow, &ext);
          },
          "q"_a, "v"_a, "tau"_a, "current_world"_a, "tau_ext"_a = nb::none());

  nb::class_<uvms::Plant>(m, "Plant")
      .def(nb::init<const uvms::Dynamics&, int>(), "dynamics"_a, "ee_frame_id"_a)
      .def(
          "set_current",
          [](uvms::Plant& p, const ConstVec& c) { p.flow = current_flow(c); }, "current_world"_a)
      .def(
          "set_flow",
          [](uvms::Plant& p, const ConstVec& c, const Eigen::MatrixXd& waves, double depth) {
            p.flow = wave_flow(c, waves, depth);
          },
          "current_world"_a, "waves"_a, "water_depth_m"_a)
      .def("clear_contact", [](uvms::Plant& p) { p.contact = uvms::NoContact{}; })
      .def(
          "set_spring",
          [](uvms::Plant& p, const ConstVec& stiffness, const ConstVec& anchor) {
            p.contact = uvms::LinearSpring{vec3("stiffness_N_m", stiffness),
                                           vec3("anchor_world_m", anchor)};
          },
          "stiffness_N_m"_a, "anchor_world_m"_a)
      .def(
          "set_plane",
          [](uvms::Plant& p, const ConstVec& normal, const ConstVec& point, double k, double c) {
            p.contact = uvms::CompliantPlane{vec3("normal_world", normal),
                                             vec3("point_world_m", point), k, c};
          },
          "normal_world"_a, "point_world_m"_a, "stiffness_N_m"_a, "damping_N_s_m"_a)
      .def("clear_disturbance", [](uvms::Plant& p) { p.disturbance.reset(); })
      .def(
          "set_sinusoidal_disturbance",
          [](uvms::Plant& p, const ConstVec& amplitude, double period_s, double phase_rad) {
            p.disturbance = uvms::SinusoidalDisturbance{vec6("amplitude", amplitude), period_s,
                                                        phase_rad};
          },
          "amplitude"_a, "period_s"_a, "phase_rad"_a)
      .def(
          "contact_wrench",
          [](uvms::Plant& p, const ConstVec& q, const ConstVec& v) -> Eigen::VectorXd {
            check_state(p.dynamics(), q, v);
            return p.contact_wrench(q, v);
          },
          "q"_a, "v"_a)
      .def(
          "acceleration",
          [](uvms::Plant& p, double t, const ConstVec& q, const ConstVec& v, const ConstVec& tau,
             std::optional<Eigen::VectorXd> contact_world) -> Eigen::VectorXd {
            check_state(p.dynamics(), q, v);
            check_vector("tau", tau, p.dynamics().nv());
            if (!contact_world) return p.acceleration(t, q, v, tau);
            const uvms::Vec6 lambda = vec6("contact_world", *contact_world);
            return p.acceleration(t, q, v, tau, &lambda);
          },
          "time_s"_a, "q"_a, "v"_a, "tau"_a, "contact_world"_a = nb::none())
      .def(
          "advance",
          [](uvms::Plant& p, double t0, const ConstVec& q0, const ConstVec& v0,
             const ConstVec& tau, double t1, double max_step_s, bool rk4) {
            check_state(p.dynamics(), q0, v0);
            check_vector("tau", tau, p.dynamics().nv());
            if (!(t1 > t0) || !(max_step_s > 0.0)) {
              throw InputError("advance needs t1 > t0 and a positive step");
            }
            return p.advance(t0, q0, v0, tau, t1, max_step_s, rk4);
          },
          "t0"_a, "q0"_a, "v0"_a, "tau"_a, "t1"_a, "max_step_s"_a, "rk4"_a)
      .def(
          "chart",
          [](uvms::Plant& p, const ConstVec& q0, const ConstVec& delta, const ConstVec& v) {
            check_vector("q0", q0, p.dynamics().nq());
            check_vector("delta", delta, p.dynamics().nv());
            check_vector("v", v, p.dynamics().nv());
            return p.chart(q0, delta, v);
          },
          "q0"_a, "delta"_a, "v"_a);

  // the prescribed-performance controller's law (ppc.hpp); the Python controller validates
  // and sizes its parameters and runs its reference for every call not returned as ok (0)
  using Ppc = uvms::PrescribedPerformanceController;
  using Vector1 = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
  m.attr("PPC_STATUS") = nb::make_tuple("ok", "first-level funnel", "second-level funnel",
                                        "solver declined", "Euler singularity", "bad input");
  nb::class_<Ppc>(m, "PrescribedPerformanceController")
      .def(
          "__init__",
          [](Ppc* self, const std::string& model_text, int ee_frame_id, const ConstVec& k_x,
             const ConstVec& rho0_x, const ConstVec& rho_inf_x, const ConstVec& l_x_per_s,
             const Eigen::VectorXd& k_zeta, const Eigen::VectorXd& rho0_zeta,
             const Eigen::VectorXd& rho_inf_zeta, const Eigen::VectorXd& l_zeta_per_s,
             const Eigen::VectorXd& velocity_weights, double null_space_gain_per_s,
             const std::vector<int>& limited_q_index, const std::vector<int>& limited_v_index,
             const Eigen::VectorXd& null_space_target, const Eigen::VectorXd& half_range,
             double max_condition_bound, double refine_above_condition_bound, double xi_clamp,
             double min_abs_cos_pitch) {
            uvms::PpcSettings s;
            s.ee_frame_id = ee_frame_id;
            s.k_x = vec6("k_x", k_x);
            s.rho0_x = vec6("rho0_x", rho0_x);
            s.rho_inf_x = vec6("rho_inf_x", rho_inf_x);
            s.l_x_per_s = vec6("l_x_per_s", l_x_per_s);
            s.k_zeta = k_zeta;
            s.rho0_zeta = rho0_zeta;
            s.rho_inf_zeta = rho_inf_zeta;
            s.l_zeta_per_s = l_zeta_per_s;
            s.velocity_weights = velocity_weights;
            s.null_space_gain_per_s = null_space_gain_per_s;
            s.limited_q_index = limited_q_index;
            s.limited_v_index = limited_v_index;
            s.null_space_target = null_space_target;
            s.half_range = half_range;
            s.max_condition_bound = max_condition_bound;
            s.refine_above_condition_bound = refine_above_condition_bound;
            s.xi_clamp = xi_clamp;
            s.min_abs_cos_pitch = min_abs_cos_pitch;
            new (self) Ppc(uvms::model_from_text(model_text), std::move(s));
          },
          "model_text"_a, "ee_frame_id"_a, "k_x"_a, "rho0_x"_a, "rho_inf_x"_a, "l_x_per_s"_a,
          "k_zeta"_a, "rho0_zeta"_a, "rho_inf_zeta"_a, "l_zeta_per_s"_a, "velocity_weights"_a,
          "null_space_gain_per_s"_a, "limited_q_index"_a, "limited_v_index"_a,
          "null_space_target"_a, "half_range"_a, "max_condition_bound"_a,
          "refine_above_condition_bound"_a, "xi_clamp"_a, "min_abs_cos_pitch"_a)
      .def_prop_ro("nq", &Ppc::nq)
      .def_prop_ro("nv", &Ppc::nv)
      .def(
          "compute",
          [](Ppc& c, double time_s, const Vector1& q, const Vector1& v, const Vector1& wrench,
             const Vector1& force_desired, const Vector1& rpy_desired, bool extended) {
            const auto size = [](const Vector1& a) { return Eigen::Index(a.shape(0)); };
            return static_cast<int>(c.compute(time_s, q.data(), size(q), v.data(), size(v),
                                              wrench.data(), size(wrench), force_desired.data(),
                                              size(force_desired), rpy_desired.data(),
                                              size(rpy_desired), extended));
          },
          "time_s"_a, "q"_a, "v"_a, "wrench_world"_a, "force_desired"_a, "rpy_desired"_a,
          "extended"_a)
      .def(
          "signals",
          [](Ppc& c) {
            // a read-only view of the last ok call's packed signals (it lives with c)
            const Eigen::VectorXd& s = c.signals();
            return nb::ndarray<nb::numpy, const double, nb::ndim<1>>(
                s.data(), {static_cast<std::size_t>(s.size())}, nb::handle());
          },
          nb::rv_policy::reference_internal)
      .def("zeta_offset", &Ppc::zeta_offset, "k"_a)
      .def("margin_offset", &Ppc::margin_offset);
}
