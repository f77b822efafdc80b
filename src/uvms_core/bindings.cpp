// nanobind module uvms_pin._core: the compiled counterparts of uvms-pin's concepts, one
// section per concept, each a struct with named fields (the Python side that fills them is
// uvms_pin/physics/compiled/, the integrators' and the plant's in uvms_pin/sim/, and
// uvms_pin/control/ppc_kernel.py).
// Bad input raises uvms_pin.errors.ParameterError, a failed solve SimulationError.
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/variant.h>
#include <nanobind/stl/vector.h>

#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/config.hpp>

#include "derivatives.hpp"
#include "pinocchio_kinematics.hpp"
#include "plant.hpp"
#include "ppc.hpp"
#include "source_hash.hpp"
#include "world_bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

void bind_sampled_laws(nb::module_& m);  // loop_bindings.cpp
void bind_sampled_loop(nb::module_& m);  // loop_bindings.cpp
void bind_step_derivatives(nb::module_& m);  // step_bindings.cpp
void bind_system(nb::module_& m);  // system_bindings.cpp
void bind_robots(nb::module_& m);  // system_bindings.cpp
void bind_perception(nb::module_& m);  // perception_bindings.cpp
void bind_ocp(nb::module_& m);  // ocp_bindings.cpp

namespace {

using uvms::ConstVec;
using uvms::InputError;

// ---- vectors from Python ---------------------------------------------------------------

using Array1 = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

std::string shape_of(nb::handle x) {
  if (nb::hasattr(x, "shape")) return nb::repr(x.attr("shape")).c_str();
  return std::string("a ") + nb::type_name(x.type()).c_str();
}

// A vector argument, read without a copy when it is a contiguous float64 array and converted
// once otherwise (numpy.asarray: a list, another dtype); `ok` is false when it is not a 1-D
// array of numbers. Nothing is raised here: the caller decides what bad input means.
struct VectorArg {
  Array1 array;
  bool ok = false;
  bool complex = false;  // a complex array: refused, not cast (the imaginary part dropped)

  explicit VectorArg(nb::handle x) {
    ok = nb::try_cast(x, array, true);
    if (ok || x.is_none()) return;
    if (nb::hasattr(x, "dtype") && nb::hasattr(x.attr("dtype"), "kind")) {
      complex = nb::cast<std::string>(nb::str(x.attr("dtype").attr("kind"))) == "c";
      if (complex) return;
    }
    try {
      nb::object converted = nb::module_::import_("numpy").attr("asarray")(x, "dtype"_a = "float64");
      ok = nb::try_cast(converted, array, false);
    } catch (const nb::python_error&) {  // not numbers at all (a string, a dict): not ok
      ok = false;
    }
  }
  Eigen::Index size() const { return ok ? Eigen::Index(array.shape(0)) : -1; }
  Eigen::Map<const Eigen::VectorXd> map() const { return {array.data(), size()}; }
};

// The vector ``name`` of n finite numbers, or InputError saying what it is instead.
Eigen::Map<const Eigen::VectorXd> vector(const char* name, nb::handle x, const VectorArg& arg,
                                         Eigen::Index n) {
  if (arg.complex) {
    throw InputError(std::string(name) + " must be " + std::to_string(n) +
                     " real numbers, got a complex array");
  }
  if (!arg.ok || arg.size() != n) {
    throw InputError(std::string(name) + " must have shape (" + std::to_string(n) +
                     ",), got " + (arg.ok ? "(" + std::to_string(arg.size()) + ",)" : shape_of(x)));
  }
  if (!arg.map().allFinite()) throw InputError(std::string(name) + " contains a non-finite value");
  return arg.map();
}

// Declares `name` (a Map) from the Python argument `name_obj` with n entries.
#define UVMS_VECTOR(name, n)            \
  const VectorArg name##_arg(name##_obj); \
  const auto name = vector(#name, name##_obj, name##_arg, (n))

// Declares the configuration `q` of `dynamics` (a Map) from `q_obj`: n finite numbers on
// the configuration manifold (else InputError; the caller names the joint off it). A
// quaternion of norm 0 or 2 would give a rotation that is none, and M, h of it, silently
#define UVMS_CONFIGURATION(dynamics) \
  UVMS_VECTOR(q, (dynamics).nq());   \
  uvms::pinlib::require_on_manifold((dynamics).model(), q)

template <typename Struct>
void check_finite(const char* name, const Struct& values) {
  if (!values.allFinite()) throw InputError(std::string(name) + " contains a non-finite value");
}

// ---- the dynamics (dynamics.hpp) ---------------------------------------------------------

void bind_hulls(nb::module_& m) {
  nb::enum_<uvms::ShapeKind>(m, "ShapeKind", "The shape of a hull piece (hull.hpp).")
      .value("sphere", uvms::ShapeKind::sphere)
      .value("ellipsoid", uvms::ShapeKind::ellipsoid)
      .value("cylinder", uvms::ShapeKind::cylinder)
      .value("polyhedron", uvms::ShapeKind::polyhedron);
  nb::class_<uvms::HullPiece>(m, "HullPiece", "One shape placed in a body frame (hull.hpp).")
      .def(nb::init<>())
      .def_rw("kind", &uvms::HullPiece::kind)
      .def_rw("size", &uvms::HullPiece::size)
      .def_rw("vertices", &uvms::HullPiece::vertices)
      .def_rw("triangles", &uvms::HullPiece::triangles)
      .def_rw("rotation", &uvms::HullPiece::rotation)
      .def_rw("translation_m", &uvms::HullPiece::translation_m)
      .def(
          "below",
          [](const uvms::HullPiece& piece, const uvms::Vec3& normal, double depth) {
            const uvms::WetPart part = piece.below(normal, depth);
            return nb::make_tuple(part.volume_m3, uvms::Vec3(part.moment_m4),
                                  part.waterplane_area_m2, uvms::Vec3(part.waterplane_moment_m3));
          },
          "normal"_a, "depth_m"_a,
          "(V, M, A, M_A) of the part below n . x = d, body frame (submerged.hpp)");
  nb::class_<uvms::Hull>(m, "Hull", "The shapes of one body, fitted to its volume (hull.hpp).")
      .def(nb::init<>())
      .def_rw("pieces", &uvms::Hull::pieces)
      .def_rw("volume_scale", &uvms::Hull::volume_scale)
      .def_rw("geometric_volume_m3", &uvms::Hull::geometric_volume_m3)
      .def_rw("bound_center_m", &uvms::Hull::bound_center_m)
      .def_rw("bound_radius_m", &uvms::Hull::bound_radius_m);
  nb::class_<uvms::SurfaceBody>(m, "SurfaceBody", "A hull on a joint (hydro_bodies.hpp).")
      .def(nb::init<>())
      .def_rw("joint_id", &uvms::SurfaceBody::joint_id)
      .def_rw("hull", &uvms::SurfaceBody::hull)
      .def_rw("volume_m3", &uvms::SurfaceBody::volume_m3)
      .def_rw("center_of_buoyancy_in_joint_m", &uvms::SurfaceBody::center_of_buoyancy_in_joint_m)
      .def_rw("added_mass_in_joint", &uvms::SurfaceBody::added_mass_in_joint);
}

void bind_hydro_bodies(nb::module_& m) {
  nb::class_<uvms::DampedBody>(m, "DampedBody",
                               "One damped link on a joint (hydro_bodies.hpp, DampedBody).")
      .def(nb::init<>())
      .def_rw("joint_id", &uvms::DampedBody::joint_id)
      .def_rw("hull_index", &uvms::DampedBody::hull_index)
      .def_rw("action_joint_to_body", &uvms::DampedBody::action_joint_to_body)
      .def_rw("rotation_in_joint", &uvms::DampedBody::rotation_in_joint)
      .def_rw("position_in_joint_m", &uvms::DampedBody::position_in_joint_m)
      .def_rw("linear_damping", &uvms::DampedBody::linear_damping)
      .def_rw("quadratic_damping", &uvms::DampedBody::quadratic_damping);
  nb::class_<uvms::HydroBodies>(m, "HydroBodies",
                                "The hydrodynamic parameters per joint (hydro_bodies.hpp).")
      .def(nb::init<>())
      .def_rw("water_density_kg_m3", &uvms::HydroBodies::water_density_kg_m3)
      .def_rw("added_mass_per_joint", &uvms::HydroBodies::added_mass_per_joint)
      .def_rw("volume_per_joint_m3", &uvms::HydroBodies::volume_per_joint_m3)
      .def_rw("center_of_buoyancy_per_joint_m",
              &uvms::HydroBodies::center_of_buoyancy_per_joint_m)
      .def_rw("damped_bodies", &uvms::HydroBodies::damped_bodies)
      .def_rw("surface_bodies", &uvms::HydroBodies::surface_bodies)
      .def_rw("added_mass_without_hull_per_joint",
              &uvms::HydroBodies::added_mass_without_hull_per_joint);
}

void bind_flow(nb::module_& m) {
  nb::class_<uvms::WaveComponent>(m, "WaveComponent", "One linear wave (flow.hpp).")
      .def(nb::init<>())
      .def_rw("amplitude_m", &uvms::WaveComponent::amplitude_m)
      .def_rw("angular_frequency_rad_s", &uvms::WaveComponent::angular_frequency_rad_s)
      .def_rw("wavenumber_rad_m", &uvms::WaveComponent::wavenumber_rad_m)
      .def_rw("heading_rad", &uvms::WaveComponent::heading_rad)
      .def_rw("phase_rad", &uvms::WaveComponent::phase_rad);
  nb::class_<uvms::FlowField>(m, "FlowField",
                              "A uniform current plus linear waves in one depth (flow.hpp).")
      .def(nb::init<>())
      .def_rw("current_world_m_s", &uvms::FlowField::current_world_m_s)
      .def_rw("waves", &uvms::FlowField::waves)
      .def_rw("water_depth_m", &uvms::FlowField::water_depth_m);
}

// The flow of a call: None (still water) or a FlowField.
// The flow passed from Python (None: still water), by reference: a FlowField copy per call
// (its wave list) would cost more than the small calls it feeds
const uvms::FlowField& flow_or_still(const uvms::FlowField* flow) {
  static const uvms::FlowField still{};
  return flow != nullptr ? *flow : still;
}

uvms::FlowField current_only(nb::handle current_world_obj) {
  UVMS_VECTOR(current_world, 3);
  uvms::FlowField flow;
  flow.current_world_m_s = current_world;
  return flow;
}

void bind_dynamics(nb::module_& m) {
  using uvms::Dynamics;
  nb::class_<Dynamics>(m, "Dynamics", "M, h and forward dynamics of one UVMS (dynamics.hpp).")
      .def(
          "__init__",
          [](Dynamics* self, const std::string& model_text, const uvms::HydroBodies& hydro) {
            new (self) Dynamics(uvms::model_from_text(model_text), hydro);
          },
          "model_text"_a, "hydro_bodies"_a)
      .def_prop_ro("nq", &Dynamics::nq)
      .def_prop_ro("nv", &Dynamics::nv)
      .def(
          "mass_matrix",
          [](Dynamics& d, nb::handle q_obj) -> Eigen::MatrixXd {
            UVMS_CONFIGURATION(d);
            return d.mass_matrix(q);
          },
          "q"_a.none())
      .def(
          "mass_matrix_in",
          [](Dynamics& d, nb::handle q_obj, const uvms::FlowField* flow,
             double time_s, bool free_surface) -> Eigen::MatrixXd {
            UVMS_CONFIGURATION(d);
            return d.mass_matrix_in(q, flow_or_still(flow), time_s, free_surface);
          },
          "q"_a.none(), "flow"_a.none(), "time_s"_a, "free_surface"_a = false)
      .def(
          "bias_forces",
          [](Dynamics& d, nb::handle q_obj, nb::handle v_obj,
             nb::handle current_world_obj) -> Eigen::VectorXd {
            UVMS_CONFIGURATION(d);
            UVMS_VECTOR(v, d.nv());
            return d.bias_forces(q, v, current_only(current_world_obj));
          },
          "q"_a.none(), "v"_a.none(), "current_world"_a.none())
      .def(
          "bias_forces_in",
          [](Dynamics& d, nb::handle q_obj, nb::handle v_obj,
             const uvms::FlowField* flow, double time_s,
             bool free_surface) -> Eigen::VectorXd {
            UVMS_CONFIGURATION(d);
            UVMS_VECTOR(v, d.nv());
            return d.bias_forces(q, v, flow_or_still(flow), time_s, free_surface);
          },
          "q"_a.none(), "v"_a.none(), "flow"_a.none(), "time_s"_a, "free_surface"_a = false)
      .def(
          "forward_dynamics",
          [](Dynamics& d, nb::handle q_obj, nb::handle v_obj, nb::handle tau_obj,
             nb::handle current_world_obj, nb::handle tau_ext_obj) -> Eigen::VectorXd {
            UVMS_CONFIGURATION(d);
            UVMS_VECTOR(v, d.nv());
            UVMS_VECTOR(tau, d.nv());
            const uvms::FlowField flow = current_only(current_world_obj);
            if (tau_ext_obj.is_none()) return d.forward_dynamics(q, v, tau, flow, nullptr);
            UVMS_VECTOR(tau_ext, d.nv());
            const ConstVec ext(tau_ext);
            return d.forward_dynamics(q, v, tau, flow, &ext);
          },
          "q"_a.none(), "v"_a.none(), "tau"_a.none(), "current_world"_a.none(), "tau_ext"_a.none() = nb::none())
      .def(
          "forward_dynamics_in",
          [](Dynamics& d, nb::handle q_obj, nb::handle v_obj, nb::handle tau_obj,
             const uvms::FlowField* flow, double time_s,
             nb::handle tau_ext_obj, bool free_surface) -> Eigen::VectorXd {
            UVMS_CONFIGURATION(d);
            UVMS_VECTOR(v, d.nv());
            UVMS_VECTOR(tau, d.nv());
            if (tau_ext_obj.is_none()) {
              return d.forward_dynamics(q, v, tau, flow_or_still(flow), nullptr, time_s,
                                        free_surface);
            }
            UVMS_VECTOR(tau_ext, d.nv());
            const ConstVec ext(tau_ext);
            return d.forward_dynamics(q, v, tau, flow_or_still(flow), &ext, time_s, free_surface);
          },
          "q"_a.none(), "v"_a.none(), "tau"_a.none(), "flow"_a.none(), "time_s"_a, "tau_ext"_a.none() = nb::none(),
          "free_surface"_a = false);
}

// ---- the derivatives of the dynamics (derivatives.hpp) --------------------------------------

void bind_derivatives(nb::module_& m) {
  using uvms::Derivatives;
  using uvms::ForwardDynamicsDerivatives;
  nb::class_<ForwardDynamicsDerivatives>(
      m, "ForwardDynamicsDerivatives",
      "da/dq (along the tangent), da/dv and da/dtau, nv x nv each (derivatives.hpp).")
      .def_ro("da_dq", &ForwardDynamicsDerivatives::da_dq)
      .def_ro("da_dv", &ForwardDynamicsDerivatives::da_dv)
      .def_ro("da_dtau", &ForwardDynamicsDerivatives::da_dtau);
  nb::class_<Derivatives>(m, "Derivatives",
                          "The derivatives of one UVMS's forward dynamics (derivatives.hpp).")
      .def(nb::init<const uvms::Dynamics&>(), "dynamics"_a)
      .def(
          "forward_dynamics_derivatives",
          [](Derivatives& d, nb::handle q_obj, nb::handle v_obj, nb::handle tau_obj,
             const uvms::FlowField* flow, double time_s,
             nb::handle tau_ext_obj, bool free_surface) -> ForwardDynamicsDerivatives {
            const int nq = d.dynamics().nq(), nv = d.dynamics().nv();
            UVMS_VECTOR(q, nq);
            UVMS_VECTOR(v, nv);
            UVMS_VECTOR(tau, nv);
            if (tau_ext_obj.is_none()) {
              return d.forward_dynamics_derivatives(q, v, tau, flow_or_still(flow), nullptr,
                                                    time_s, free_surface);
            }
            UVMS_VECTOR(tau_ext, nv);
            const ConstVec ext(tau_ext);
            return d.forward_dynamics_derivatives(q, v, tau, flow_or_still(flow), &ext, time_s,
                                                  free_surface);
          },
          "q"_a.none(), "v"_a.none(), "tau"_a.none(), "flow"_a.none(), "time_s"_a,
          "tau_ext"_a.none() = nb::none(), "free_surface"_a = false)
      .def(
          "call",
          [](Derivatives& d, nb::handle q_obj, nb::handle v_obj, nb::handle tau_obj,
             const uvms::FlowField* flow, double time_s, nb::handle tau_ext_obj,
             bool free_surface, double norm_tolerance,
             nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu> out) {
            // the public call's (uvms_pin.physics.dynamics.forward_dynamics_derivatives):
            // q also on the configuration manifold (its unit parts' norms within
            // norm_tolerance of 1: else InputError, the caller names the joint), and
            // da/dq, da/dv, da/dtau written into out (3, nv, nv), the caller's new array (one
            // allocation: three arrays made here would cost more than the Jacobians' chain)
            const int nq = d.dynamics().nq(), nv = d.dynamics().nv();
            UVMS_VECTOR(q, nq);
            UVMS_VECTOR(v, nv);
            UVMS_VECTOR(tau, nv);
            if (out.shape(0) != 3 || out.shape(1) != std::size_t(nv) ||
                out.shape(2) != std::size_t(nv)) {
              throw InputError("out must have shape (3, nv, nv)");
            }
            uvms::pinlib::require_on_manifold(d.dynamics().model(), q, norm_tolerance);
            const ForwardDynamicsDerivatives* jacobians = nullptr;
            if (tau_ext_obj.is_none()) {
              jacobians = &d.forward_dynamics_derivatives(q, v, tau, flow_or_still(flow),
                                                          nullptr, time_s, free_surface);
            } else {
              UVMS_VECTOR(tau_ext, nv);
              const ConstVec ext(tau_ext);
              jacobians = &d.forward_dynamics_derivatives(q, v, tau, flow_or_still(flow), &ext,
                                                          time_s, free_surface);
            }
            using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
            const Eigen::MatrixXd* parts[3] = {&jacobians->da_dq, &jacobians->da_dv,
                                               &jacobians->da_dtau};
            for (int k = 0; k < 3; ++k) {
              Eigen::Map<RowMajor>(out.data() + std::ptrdiff_t(k) * nv * nv, nv, nv) = *parts[k];
            }
            // finite inputs, a result that is not (a vehicle 1e300 m away: its lever arms'
            // products overflow, inf - inf): SimulationError, never NaN (the reference's
            // checks, uvms_pin.physics.dynamics._finite_result, say the same)
            if (!Eigen::Map<const Eigen::ArrayXd>(out.data(), 3 * nv * nv).isFinite().all()) {
              throw uvms::SimulationFailure(
                  "da/dq, da/dv, da/dtau are not finite for finite inputs: a position or a speed "
                  "beyond what their products hold in floating point");
            }
          },
          "q"_a.none(), "v"_a.none(), "tau"_a.none(), "flow"_a.none(), "time_s"_a,
          "tau_ext"_a.none(), "free_surface"_a, "norm_tolerance"_a, "out"_a);
}

// ---- the environment (contact.hpp, disturbance.hpp) and the integrators -----------------

void bind_environment(nb::module_& m) {
  nb::class_<uvms::NoContact>(m, "NoContact", "No contact (contact.hpp).").def(nb::init<>());
  nb::class_<uvms::LinearSpring>(m, "LinearSpring", "f_e = K_f (p - p_0) (contact.hpp).")
      .def(nb::init<>())
      .def_rw("stiffness_N_m", &uvms::LinearSpring::stiffness_N_m)
      .def_rw("anchor_world_m", &uvms::LinearSpring::anchor_world_m);
  nb::class_<uvms::CompliantPlane>(m, "CompliantPlane",
                                   "A unilateral Kelvin-Voigt plane (contact.hpp).")
      .def(nb::init<>())
      .def_rw("normal_world", &uvms::CompliantPlane::normal_world)
      .def_rw("point_world_m", &uvms::CompliantPlane::point_world_m)
      .def_rw("stiffness_N_m", &uvms::CompliantPlane::stiffness_N_m)
      .def_rw("damping_N_s_m", &uvms::CompliantPlane::damping_N_s_m);
  nb::class_<uvms::SinusoidalDisturbance>(m, "SinusoidalDisturbance",
                                          "delta(t) = a sin(2 pi t / T + phi) (disturbance.hpp).")
      .def(nb::init<>())
      .def_rw("amplitude", &uvms::SinusoidalDisturbance::amplitude)
      .def_rw("period_s", &uvms::SinusoidalDisturbance::period_s)
      .def_rw("phase_rad", &uvms::SinusoidalDisturbance::phase_rad);
  nb::class_<uvms::JointFriction>(
      m, "JointFriction", "-(b v + c tanh(v / s)) on each arm joint (joint_friction.hpp).")
      .def(nb::init<>())
      .def_rw("viscous_Nms", &uvms::JointFriction::viscous_Nms)
      .def_rw("coulomb_Nm", &uvms::JointFriction::coulomb_Nm)
      .def_rw("velocity_scale_rad_s", &uvms::JointFriction::velocity_scale_rad_s);
  nb::class_<uvms::LiftDrag>(m, "LiftDrag", "A fin's LiftDrag parameters (fins.hpp).")
      .def(nb::init<>())
      .def_rw("area_m2", &uvms::LiftDrag::area_m2)
      .def_rw("fluid_density_kg_m3", &uvms::LiftDrag::fluid_density_kg_m3)
      .def_rw("cla", &uvms::LiftDrag::cla)
      .def_rw("cda", &uvms::LiftDrag::cda)
      .def_rw("cma", &uvms::LiftDrag::cma)
      .def_rw("alpha_stall_rad", &uvms::LiftDrag::alpha_stall_rad)
      .def_rw("cla_stall", &uvms::LiftDrag::cla_stall)
      .def_rw("cda_stall", &uvms::LiftDrag::cda_stall)
      .def_rw("cma_stall", &uvms::LiftDrag::cma_stall)
      .def_rw("alpha0_rad", &uvms::LiftDrag::alpha0_rad)
      .def_rw("cp_m", &uvms::LiftDrag::cp_m)
      .def_rw("forward", &uvms::LiftDrag::forward)
      .def_rw("upward", &uvms::LiftDrag::upward)
      .def_rw("radial_symmetry", &uvms::LiftDrag::radial_symmetry)
      .def_rw("reversible", &uvms::LiftDrag::reversible)
      .def_rw("control_joint_rad_to_cl", &uvms::LiftDrag::control_joint_rad_to_cl)
      .def_rw("cm_delta", &uvms::LiftDrag::cm_delta);
  nb::class_<uvms::Fin>(m, "Fin", "A fin on a joint's body (fins.hpp).")
      .def(nb::init<>())
      .def_rw("joint_id", &uvms::Fin::joint_id)
      .def_rw("rotation_in_joint", &uvms::Fin::rotation_in_joint)
      .def_rw("translation_in_joint", &uvms::Fin::translation_in_joint)
      .def_rw("params", &uvms::Fin::params)
      .def_rw("control_q_index", &uvms::Fin::control_q_index);
  nb::class_<uvms::Fins>(m, "Fins", "The fins of a model (fins.hpp).")
      .def(nb::init<>())
      .def_rw("fins", &uvms::Fins::fins);
  m.def(
      "lift_drag_wrench",
      [](const uvms::LiftDrag& params, const uvms::Mat3& rotation_world,
         const uvms::Vec3& velocity_world_m_s, double control_rad) {
        return uvms::lift_drag_wrench(params, rotation_world, velocity_world_m_s, control_rad);
      },
      "params"_a, "rotation_world"_a, "velocity_world_m_s"_a, "control_rad"_a = 0.0,
      "(force [N] at the centre of pressure, moment [N m]), world axes (fins.hpp).");
  nb::class_<uvms::JointStopsModel>(m, "JointStops",
                                    "Compliant stops at the joint limits (joint_stops.hpp).")
      .def(nb::init<>())
      .def_rw("q_index", &uvms::JointStopsModel::q_index)
      .def_rw("v_index", &uvms::JointStopsModel::v_index)
      .def_rw("lower_rad", &uvms::JointStopsModel::lower_rad)
      .def_rw("upper_rad", &uvms::JointStopsModel::upper_rad)
      .def_rw("stiffness_Nm_rad", &uvms::JointStopsModel::stiffness_Nm_rad)
      .def_rw("damping_Nm_s_rad", &uvms::JointStopsModel::damping_Nm_s_rad);
  using uvms::JointLimitConstraintsModel;
  nb::class_<JointLimitConstraintsModel>(
      m, "JointLimits", "The joint limits as constraints solved implicitly (joint_limits.hpp).")
      .def(nb::init<>())
      .def_rw("q_index", &JointLimitConstraintsModel::q_index)
      .def_rw("v_index", &JointLimitConstraintsModel::v_index)
      .def_rw("lower_rad", &JointLimitConstraintsModel::lower_rad)
      .def_rw("upper_rad", &JointLimitConstraintsModel::upper_rad)
      .def_rw("margin", &JointLimitConstraintsModel::margin)
      .def_rw("correction", &JointLimitConstraintsModel::correction)
      .def(
          "constrain",
          [](const JointLimitConstraintsModel& limits, const Eigen::MatrixXd& mass,
             nb::handle q0_obj, nb::handle v_free_obj, double period_s,
             nb::handle least_speed_obj) {
            const Eigen::Index nv = mass.rows();
            if (mass.cols() != nv || !mass.allFinite()) {
              throw InputError("mass must be a square matrix of finite numbers");
            }
            const VectorArg q0_arg(q0_obj);
            const auto q0 = vector("q0", q0_obj, q0_arg, q0_arg.ok ? q0_arg.size() : -1);
            UVMS_VECTOR(v_free, nv);
            Eigen::VectorXd least = Eigen::VectorXd::Zero(nv);
            if (!least_speed_obj.is_none()) {
              UVMS_VECTOR(least_speed, nv);
              least = least_speed;
            }
            Eigen::VectorXd v = v_free;
            const bool solved = limits.constrain(mass, q0, v, period_s, least);
            return std::make_pair(solved, v);
          },
          "mass"_a, "q0"_a, "v_free"_a, "period_s"_a, "least_speed"_a = nb::none(),
          "(whether a row was selected, v+) over period_s from q0 (joint_limits.hpp).");
  using uvms::WorldBoundsModel;
  nb::class_<WorldBoundsModel>(m, "WorldBounds",
                               "The broad phase of the world's contacts (world_bounds.hpp).")
      .def(nb::init<>())
      .def_rw("joint_ids", &WorldBoundsModel::joint_ids)
      .def_rw("centers_in_joint", &WorldBoundsModel::centers_in_joint)
      .def_rw("radii_m", &WorldBoundsModel::radii_m)
      .def_rw("plane_normals", &WorldBoundsModel::plane_normals)
      .def_rw("plane_offsets_m", &WorldBoundsModel::plane_offsets_m)
      .def_rw("sphere_centers_m", &WorldBoundsModel::sphere_centers_m)
      .def_rw("sphere_radii_m", &WorldBoundsModel::sphere_radii_m)
      .def_rw("clearance_m", &WorldBoundsModel::clearance_m);
  nb::enum_<uvms::Method>(m, "Method", "A fixed-step method (integrators.hpp).")
      .value("rk4", uvms::Method::rk4)
      .value("semi_implicit_euler", uvms::Method::semi_implicit_euler);
  nb::class_<uvms::FixedStep>(m, "FixedStep", "A fixed-step integrator (integrators.hpp).")
      .def(nb::init<>())
      .def_rw("method", &uvms::FixedStep::method)
      .def_rw("step_s", &uvms::FixedStep::step_s);
}

// ---- the plant (plant.hpp) -----------------------------------------------------------------

void bind_plant(nb::module_& m) {
  using uvms::Plant;
  auto plant = nb::class_<Plant>(m, "Plant", "A UVMS in water, touching and pushed (plant.hpp).");
  bind_plant_world(plant);
  plant.def(nb::init<const uvms::Dynamics&, int>(), "dynamics"_a, "ee_frame_id"_a)
      .def_rw("flow", &Plant::flow)
      .def_rw("free_surface", &Plant::free_surface)
      .def_rw("contact", &Plant::contact)
      .def_rw("disturbance", &Plant::disturbance)
      .def_rw("joint_friction", &Plant::joint_friction)
      .def_rw("fins", &Plant::fins)
      .def_rw("joint_stops", &Plant::joint_stops)
      .def_rw("joint_limits", &Plant::joint_limits)
      .def_rw("joint_coulomb_Nm", &Plant::joint_coulomb_Nm,
              "The joints' Coulomb friction as a constraint (nv; empty: none).")
      .def_rw("world_bounds", &Plant::world_bounds)
      .def(
          "world_clear",
          [](Plant& p, nb::handle q_obj, nb::handle v_obj, double horizon_s) {
            UVMS_VECTOR(q, p.dynamics().nq());
            UVMS_VECTOR(v, p.dynamics().nv());
            return p.world_clear(q, v, horizon_s);
          },
          "q"_a.none(), "v"_a.none(), "horizon_s"_a)
      .def(
          "contact_wrench",
          [](Plant& p, nb::handle q_obj, nb::handle v_obj) -> Eigen::VectorXd {
            UVMS_VECTOR(q, p.dynamics().nq());
            UVMS_VECTOR(v, p.dynamics().nv());
            return p.contact_wrench(q, v);
          },
          "q"_a.none(), "v"_a.none())
      .def(
          "acceleration",
          [](Plant& p, double t, nb::handle q_obj, nb::handle v_obj, nb::handle tau_obj,
             nb::handle contact_world_obj) -> Eigen::VectorXd {
            UVMS_CONFIGURATION(p.dynamics());
            UVMS_VECTOR(v, p.dynamics().nv());
            UVMS_VECTOR(tau, p.dynamics().nv());
            if (contact_world_obj.is_none()) return p.acceleration(t, q, v, tau);
            UVMS_VECTOR(contact_world, 6);
            const uvms::Vec6 lambda = contact_world;
            return p.acceleration(t, q, v, tau, &lambda);
          },
          "time_s"_a, "q"_a.none(), "v"_a.none(), "tau"_a.none(), "contact_world"_a.none() = nb::none())
      .def(
          "advance",
          [](Plant& p, double t0, nb::handle q0_obj, nb::handle v0_obj, nb::handle tau_obj,
             double t1, const uvms::FixedStep& integrator) {
            UVMS_VECTOR(q0, p.dynamics().nq());
            UVMS_VECTOR(v0, p.dynamics().nv());
            UVMS_VECTOR(tau, p.dynamics().nv());
            if (!(t1 > t0) || !(integrator.step_s > 0.0)) {
              throw InputError("advance needs t1 > t0 and a positive step");
            }
            return p.advance(t0, q0, v0, tau, t1, integrator);
          },
          "t0"_a, "q0"_a.none(), "v0"_a.none(), "tau"_a.none(), "t1"_a, "integrator"_a)
      .def(
          "chart",
          [](Plant& p, nb::handle q0_obj, nb::handle delta_obj, nb::handle v_obj) {
            UVMS_VECTOR(q0, p.dynamics().nq());
            UVMS_VECTOR(delta, p.dynamics().nv());
            UVMS_VECTOR(v, p.dynamics().nv());
            return p.chart(q0, delta, v);
          },
          "q0"_a.none(), "delta"_a.none(), "v"_a.none());
}

// ---- the prescribed-performance controller (ppc.hpp) ---------------------------------------

void bind_ppc(nb::module_& m) {
  using Ppc = uvms::PrescribedPerformanceController;
  using Settings = uvms::PpcSettings;
  m.attr("PPC_STATUS") = nb::make_tuple("ok", "first-level funnel", "second-level funnel",
                                        "solver declined", "Euler singularity", "bad input");
  // PpcSettings: bound with the other laws' settings (loop_bindings.cpp, bind_sampled_laws)
  nb::class_<Ppc, uvms::SampledLaw>(m, "PrescribedPerformanceController",
                                    "The paper's law (ppc.hpp).")
      .def(
          "__init__",
          [](Ppc* self, const std::string& model_text, const Settings& settings) {
            check_finite("k_x", settings.k_x);
            check_finite("k_zeta", settings.k_zeta);
            new (self) Ppc(uvms::model_from_text(model_text), settings);
          },
          "model_text"_a, "settings"_a)
      .def_prop_ro("nq", &Ppc::nq)
      .def_prop_ro("nv", &Ppc::nv)
      .def(
          "compute",
          // the status says what the caller must do; bad input is a status too (the Python
          // reference then raises its own, precise error)
          [](Ppc& c, double time_s, nb::handle q, nb::handle v, nb::handle wrench,
             nb::handle force_desired, nb::handle rpy_desired, bool extended) {
            const VectorArg a[5] = {VectorArg(q), VectorArg(v), VectorArg(wrench),
                                    VectorArg(force_desired), VectorArg(rpy_desired)};
            for (const auto& arg : a) {
              if (!arg.ok) return static_cast<int>(uvms::PpcStatus::bad_input);
            }
            return static_cast<int>(c.compute(
                time_s, a[0].array.data(), a[0].size(), a[1].array.data(), a[1].size(),
                a[2].array.data(), a[2].size(), a[3].array.data(), a[3].size(),
                a[4].array.data(), a[4].size(), extended));
          },
          "time_s"_a, "q"_a.none(), "v"_a.none(), "wrench_world"_a.none(), "force_desired"_a.none(), "rpy_desired"_a.none(),
          "extended"_a);
  // signals() and signal_layout(): the SampledLaw base's (loop_bindings.cpp)
}

}  // namespace

void bind_batch_plant(nb::module_& m);  // batch_bindings.cpp
void bind_batch_derivatives(nb::module_& m);  // batch_bindings.cpp

NB_MODULE(_core, m) {
  m.doc() = "Compiled dynamics, plant and controller of uvms-pin (C++ on Pinocchio's C++ API).";
  m.attr("NORM_TOLERANCE") = uvms::pinlib::kNormTolerance;
  m.attr("MAX_SUBSTEPS") = uvms::kMaxSubsteps;
  m.attr("API_VERSION") = uvms::kApiVersion;
  m.attr("PINOCCHIO_VERSION") = PINOCCHIO_VERSION;
  m.attr("SOURCE_HASH") = uvms::core_source_hash();
  m.def("set_leak_warnings", &nb::set_leak_warnings, "on"_a,
        "Whether nanobind reports this module's objects still alive when it is freed at exit "
        "(on by default; uvms_pin.ocp turns it off: crocoddyl keeps what its nodes reach "
        "alive past that point).");

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

  bind_hulls(m);
  bind_hydro_bodies(m);
  bind_flow(m);
  bind_dynamics(m);
  bind_derivatives(m);
  bind_step_derivatives(m);
  bind_environment(m);
  bind_world(m);
  bind_plant(m);
  bind_system(m);
  bind_robots(m);
  bind_batch_plant(m);
  bind_batch_derivatives(m);
  bind_sampled_laws(m);
  bind_ppc(m);
  bind_sampled_loop(m);
  bind_perception(m);
  bind_ocp(m);
}
