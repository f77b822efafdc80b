// The world's contacts in the nanobind module (world_contact.hpp, contact_shapes.hpp): the
// shapes, the law, the compiled world of a plant, and the plant's operations with a world.
// The friction's state crosses as the Python plant's FrictionMemory (anchors: a dict
// (piece, object, corner) -> anchor (3,) [m]; slipping: a set of patches; material: a dict
// (piece, object, -1) -> material point (3,) [m]), read before and written back after each
// call, so that the state lives in one place for both backends.
#include "world_bindings.hpp"

#include "pinocchio_kinematics.hpp"

#include <nanobind/eigen/dense.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/shared_ptr.h>
#include <nanobind/stl/vector.h>

#include <string>

namespace nb = nanobind;
using namespace nb::literals;

using uvms::InputError;
using uvms::Plant;
using Rows3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

void read_memory(nb::handle memory, uvms::FrictionMemory& out) {
  out.clear();
  if (!nb::hasattr(memory, "anchors") || !nb::hasattr(memory, "slipping")) {
    throw InputError("friction: a FrictionMemory (anchors, slipping) expected");
  }
  auto read_points = [](nb::handle points, std::map<uvms::ContactKey, uvms::Vec3>& into) {
    for (auto [key, value] : nb::borrow<nb::dict>(points)) {
      if (!nb::isinstance<nb::tuple>(key) || nb::len(key) != 3) {
        throw InputError("friction: an anchor's key must be (piece, object, corner)");
      }
      const nb::tuple k = nb::borrow<nb::tuple>(key);
      const uvms::ContactKey point{nb::cast<int>(k[0]), nb::cast<int>(k[1]),
                                   nb::cast<int>(k[2])};
      into[point] = nb::cast<uvms::Vec3>(value);
    }
  };
  read_points(memory.attr("anchors"), out.anchors);
  if (nb::hasattr(memory, "material")) read_points(memory.attr("material"), out.material);
  for (nb::handle patch : memory.attr("slipping")) out.slipping.insert(nb::cast<int>(patch));
}

void write_memory(const uvms::FrictionMemory& memory, nb::handle out) {
  auto points = [](const std::map<uvms::ContactKey, uvms::Vec3>& from) {
    nb::dict into;
    for (const auto& [key, point] : from) {
      into[nb::make_tuple(key[0], key[1], key[2])] = nb::cast(uvms::Vec3(point));
    }
    return into;
  };
  nb::set slipping;
  for (const int patch : memory.slipping) slipping.add(nb::int_(patch));
  out.attr("anchors") = points(memory.anchors);
  out.attr("slipping") = slipping;
  out.attr("material") = points(memory.material);
}

namespace {

Eigen::VectorXd checked(const char* name, const Eigen::VectorXd& x, int n) {
  if (x.size() != n) {
    throw InputError(std::string(name) + " must have shape (" + std::to_string(n) + ",), got (" +
                     std::to_string(x.size()) + ",)");
  }
  if (!x.allFinite()) throw InputError(std::string(name) + " contains a non-finite value");
  return x;
}

Rows3 rows(const std::vector<uvms::Vec3>& columns) {
  Rows3 out(static_cast<Eigen::Index>(columns.size()), 3);
  for (std::size_t k = 0; k < columns.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = columns[k];
  return out;
}

}  // namespace

// World.forces as plain arrays (the fields of ContactForces and its Touch).
nb::dict forces_dict(const uvms::ContactForces& forces) {
  const uvms::Touch& t = forces.touch;
  nb::dict out;
  out["piece"] = t.piece;
  out["obj"] = t.obj;
  out["corner"] = t.corner;
  out["point_world_m"] = rows(t.point_world_m);
  out["normal_world"] = rows(t.normal_world);
  out["depth_m"] = t.depth_m;
  out["velocity_world_m_s"] = rows(t.velocity_world_m_s);
  out["force_world_N"] = rows(forces.force_world_N);
  out["normal_N"] = Eigen::VectorXd(forces.normal_N);
  nb::list sticking;
  for (const char stick : forces.sticking) sticking.append(nb::bool_(stick != 0));
  out["sticking"] = sticking;
  out["stretch_m"] = rows(forces.stretch_m);
  out["material_m"] = rows(forces.material_m);
  return out;
}

void bind_world(nb::module_& m) {
  using uvms::ContactKind;
  using uvms::ContactShape;
  nb::enum_<ContactKind>(m, "ContactKind", "The geometry of a contact shape (contact_shapes.hpp).")
      .value("plane", ContactKind::plane)
      .value("box", ContactKind::box)
      .value("sphere", ContactKind::sphere)
      .value("cylinder", ContactKind::cylinder)
      .value("ellipsoid", ContactKind::ellipsoid)
      .value("convex", ContactKind::convex);
  nb::class_<ContactShape>(m, "ContactShape",
                           "A coal shape on a joint, 0 = fixed in the world (contact_shapes.hpp).")
      .def(nb::init<>())
      .def_rw("joint_id", &ContactShape::joint_id)
      .def_rw("body", &ContactShape::body)
      .def_rw("corners_m", &ContactShape::corners_m)
      .def_rw("bound_radius_m", &ContactShape::bound_radius_m)
      .def_rw("friction_static", &ContactShape::friction_static)
      .def_rw("friction_kinetic", &ContactShape::friction_kinetic)
      .def_ro("kind", &ContactShape::kind)
      .def(
          "set_placement",
          [](ContactShape& s, const uvms::Mat3& rotation, const uvms::Vec3& translation) {
            if (!rotation.allFinite() || !translation.allFinite()) {
              throw InputError("contact shape: a non-finite placement");
            }
            s.placement_in_joint = pinocchio::SE3(rotation, translation);
          },
          "rotation"_a, "translation_m"_a, "Its frame in its joint's frame.")
      .def("set_geometry", &ContactShape::set_geometry, "kind"_a, "sizes"_a, "points"_a,
           "The coal geometry of a kind from its sizes or points (contact_shapes.hpp).");
  nb::class_<uvms::ContactLaw>(m, "ContactLaw", "Hunt-Crossley and Coulomb (contact_law.hpp).")
      .def(nb::init<>())
      .def_rw("stiffness_N_m", &uvms::ContactLaw::stiffness_N_m)
      .def_rw("dissipation_s_m", &uvms::ContactLaw::dissipation_s_m)
      .def_rw("tangential_stiffness_N_m", &uvms::ContactLaw::tangential_stiffness_N_m)
      .def_rw("tangential_damping_N_s_m", &uvms::ContactLaw::tangential_damping_N_s_m);
  nb::class_<uvms::WorldContactModel>(m, "WorldContact",
                                      "Shapes and law of the world's contacts (world_contact.hpp).")
      .def(nb::init<>())
      .def_rw("pieces", &uvms::WorldContactModel::pieces)
      .def_rw("objects", &uvms::WorldContactModel::objects)
      .def_rw("law", &uvms::WorldContactModel::law);
}

void bind_plant_world(nb::class_<Plant>& plant) {
  plant.def_rw("world", &Plant::world)
      .def(
          "advance_in_world",
          [](Plant& p, double t0, const Eigen::VectorXd& q0, const Eigen::VectorXd& v0,
             const Eigen::VectorXd& tau, double t1, const uvms::FixedStep& integrator,
             nb::handle friction) {
            const int nq = p.dynamics().nq(), nv = p.dynamics().nv();
            const auto q = checked("q0", q0, nq), v = checked("v0", v0, nv);
            const auto u = checked("tau", tau, nv);
            if (!(t1 > t0) || !(integrator.step_s > 0.0)) {
              throw InputError("advance needs t1 > t0 and a positive step");
            }
            read_memory(friction, p.friction);
            auto out = p.advance(t0, q, v, u, t1, integrator);
            write_memory(p.friction, friction);
            return out;
          },
          "t0"_a, "q0"_a, "v0"_a, "tau"_a, "t1"_a, "integrator"_a, "friction"_a,
          "advance() with the world's contacts; friction (a FrictionMemory) is read and "
          "written back (World.commit at the period's end).")
      .def(
          "acceleration_in_world",
          [](Plant& p, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
             const Eigen::VectorXd& tau, nb::handle friction) -> Eigen::VectorXd {
            const int nq = p.dynamics().nq(), nv = p.dynamics().nv();
            const auto qc = checked("q", q, nq), vc = checked("v", v, nv);
            const auto u = checked("tau", tau, nv);
            uvms::pinlib::require_on_manifold(p.dynamics().model(), q);
            read_memory(friction, p.friction);
            return p.acceleration(t, qc, vc, u);
          },
          "time_s"_a, "q"_a, "v"_a, "tau"_a, "friction"_a,
          "zeta_dot with the world's contacts at the anchors of friction (read only).")
      .def(
          "world_forces",
          [](Plant& p, const Eigen::VectorXd& q, const Eigen::VectorXd& v, nb::handle friction) {
            const auto qc = checked("q", q, p.dynamics().nq());
            const auto vc = checked("v", v, p.dynamics().nv());
            read_memory(friction, p.friction);
            return forces_dict(p.world_forces(qc, vc));
          },
          "q"_a, "v"_a, "friction"_a, "The contact points and forces (World.forces) as arrays.")
      .def(
          "acceleration_derivatives",
          [](Plant& p, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
             const Eigen::VectorXd& tau, nb::handle friction) {
            const int nq = p.dynamics().nq(), nv = p.dynamics().nv();
            const auto qc = checked("q", q, nq), vc = checked("v", v, nv);
            const auto u = checked("tau", tau, nv);
            read_memory(friction, p.friction);
            return uvms::ForwardDynamicsDerivatives(p.acceleration_derivatives(t, qc, vc, u));
          },
          "time_s"_a, "q"_a, "v"_a, "tau"_a, "friction"_a,
          "(da/dq, da/dv, da/dtau) of acceleration_in_world with the world's contacts at the "
          "anchors of friction (read only), the end-effector's contact, the joint friction and "
          "stops (plant_derivatives.cpp).")
      .def(
          "contact_derivatives",
          [](Plant& p, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
            const auto qc = checked("q", q, p.dynamics().nq());
            const auto vc = checked("v", v, p.dynamics().nv());
            const auto& task = p.contact_derivatives(qc, vc);
            nb::dict out;
            out["wrench_world"] = uvms::Vec6(task.wrench_world());
            out["tau_ext"] = Eigen::VectorXd(task.generalized_force());
            out["wrench_dq"] = Eigen::MatrixXd(task.wrench_dq());
            out["wrench_dv"] = Eigen::MatrixXd(task.wrench_dv());
            out["tau_dq"] = Eigen::MatrixXd(task.tau_dq());
            out["tau_dv"] = Eigen::MatrixXd(task.tau_dv());
            return out;
          },
          "q"_a, "v"_a,
          "The end-effector contact's lambda, tau_ext = -J^T lambda and their derivatives "
          "(wrench_dq, wrench_dv, tau_dq, tau_dv) at (q, v), q along the tangent, as a dict "
          "(derivatives_task_contact.hpp; task_contact.contact_derivatives).");
}
