// The system of bodies in the nanobind module (system.hpp, moving_contact.hpp). The friction's
// state crosses as the Python system's FrictionMemory objects, in one list: the plant's, each
// pair set's, then each free object's against the fixed world (None without one); read before
// and written back after each call, so that it lives in one place for both backends.
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/vector.h>

#include <cmath>
#include <string>

#include "joint_box.hpp"
#include "robots.hpp"
#include "system.hpp"
#include "world_bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using uvms::InputError;
using uvms::System;

// Every memory of the system, in the order of the file's comment.
std::vector<uvms::FrictionMemory*> memories(System& system) {
  std::vector<uvms::FrictionMemory*> out{&system.plant().friction};
  for (auto& set : system.sets) out.push_back(&set.memory);
  for (auto& memory : system.object_memory) out.push_back(&memory);
  return out;
}

std::vector<nb::handle> python_memories(System& system, const nb::handle& given) {
  const std::size_t expected = 1 + system.sets.size() + system.n_objects();
  std::vector<nb::handle> out;
  for (nb::handle memory : given) out.push_back(memory);
  if (out.size() != expected) {
    throw InputError("system: " + std::to_string(expected) +
                     " friction memories expected (the plant's, each pair set's, each "
                     "object's), got " + std::to_string(out.size()));
  }
  return out;
}

void read_all(System& system, const nb::handle& given) {
  const auto from = python_memories(system, given);
  const auto into = memories(system);
  for (std::size_t k = 0; k < into.size(); ++k) {
    if (from[k].is_none()) {
      into[k]->clear();
    } else {
      read_memory(from[k], *into[k]);
    }
  }
}

void write_all(System& system, const nb::handle& given) {
  const auto into = python_memories(system, given);
  const auto from = memories(system);
  for (std::size_t k = 0; k < from.size(); ++k) {
    if (!into[k].is_none()) write_memory(*from[k], into[k]);
  }
}

// A side's kinematics as forces() reads it: each joint's placement in the world (a row of
// rotation, row-major, then translation: (njoints, 12)) and LOCAL velocity ((njoints, 6),
// linear then angular), as the Python side's Pinocchio data holds them after kinematics.
pinocchio::Data side_kinematics(const char* side, const Eigen::MatrixXd& placements,
                                const Eigen::MatrixXd& velocities,
                                const std::vector<uvms::ContactShape>& pieces) {
  const Eigen::Index n = placements.rows();
  if (placements.cols() != 12 || velocities.rows() != n || velocities.cols() != 6) {
    throw InputError(std::string("pairs: side ") + side +
                     " needs placements (njoints, 12) and velocities (njoints, 6)");
  }
  if (!placements.allFinite() || !velocities.allFinite()) {
    throw InputError(std::string("pairs: side ") + side + " has a non-finite kinematics");
  }
  for (const auto& piece : pieces) {
    if (piece.joint_id < 0 || piece.joint_id >= n) {
      throw InputError(std::string("pairs: side ") + side + " has no joint " +
                       std::to_string(piece.joint_id) + " for a piece");
    }
  }
  pinocchio::Data data;
  data.oMi.resize(static_cast<std::size_t>(n));
  data.v.resize(static_cast<std::size_t>(n));
  for (Eigen::Index j = 0; j < n; ++j) {
    uvms::Mat3 rotation;
    for (int r = 0; r < 3; ++r) rotation.row(r) = placements.row(j).segment<3>(3 * r);
    const auto k = static_cast<std::size_t>(j);
    data.oMi[k] = pinocchio::SE3(rotation, placements.row(j).segment<3>(9).transpose());
    data.v[k] = pinocchio::Motion(uvms::Vec6(velocities.row(j).transpose()));
  }
  return data;
}

void check_state(System& system, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  if (q.size() != system.nq() || v.size() != system.nv()) {
    throw InputError("system: q (" + std::to_string(system.nq()) + ",) and v (" +
                     std::to_string(system.nv()) + ",) expected");
  }
  if (!q.allFinite() || !v.allFinite()) throw InputError("system: a non-finite state");
}

// A pair set between sides a and b added to a System's or a RobotsSystem's sets, checked.
template <class Owner>
void add_pair_set(Owner& owner, const uvms::PiecePairsModel& pairs, int a, int b) {
  uvms::PairSet set;
  set.pairs = pairs;
  set.a = a;
  set.b = b;
  owner.sets.push_back(std::move(set));
  owner.check();
}

std::vector<nb::handle> items(const nb::handle& list) {
  std::vector<nb::handle> out;
  for (nb::handle h : list) out.push_back(h);
  return out;
}

// Each robot's system's memories (a list per system, System's order), then each between
// set's: read before a RobotsSystem call (its integration reads the anchors only).
void read_robots(uvms::RobotsSystem& robots, const nb::handle& systems, const nb::handle& own) {
  const auto per_system = items(systems), per_set = items(own);
  if (per_system.size() != robots.n_robots() || per_set.size() != robots.sets.size()) {
    throw InputError("robots: one list of memories per robot's system and one memory per set");
  }
  for (std::size_t k = 0; k < per_system.size(); ++k) read_all(robots.system(k), per_system[k]);
  for (std::size_t s = 0; s < per_set.size(); ++s) read_memory(per_set[s], robots.sets[s].memory);
}

// ... and written back after a call that moved them (RobotsSystem::advance).
void write_robots(uvms::RobotsSystem& robots, const nb::handle& systems, const nb::handle& own) {
  const auto per_system = items(systems), per_set = items(own);
  for (std::size_t k = 0; k < per_system.size(); ++k) write_all(robots.system(k), per_system[k]);
  for (std::size_t s = 0; s < per_set.size(); ++s) write_memory(robots.sets[s].memory, per_set[s]);
}

void check_robots_state(uvms::RobotsSystem& robots, const Eigen::VectorXd& q,
                        const Eigen::VectorXd& v) {
  if (q.size() != robots.nq() || v.size() != robots.nv()) {
    throw InputError("robots: q (" + std::to_string(robots.nq()) + ",) and v (" +
                     std::to_string(robots.nv()) + ",) expected");
  }
  if (!q.allFinite() || !v.allFinite()) throw InputError("robots: a non-finite state");
}

// A period of the robots: integrate() alone (the anchors read only), or the whole advance()
// (the anchors moved at its end: the memories written back).
auto robots_period(bool whole) {
  return [whole](uvms::RobotsSystem& r, double t0, const Eigen::VectorXd& q0,
                 const Eigen::VectorXd& v0, const std::vector<Eigen::VectorXd>& taus, double t1,
                 const uvms::FixedStep& integrator, nb::handle systems, nb::handle memories) {
    check_robots_state(r, q0, v0);
    read_robots(r, systems, memories);
    if (!whole) return r.integrate(t0, q0, v0, taus, t1, integrator);
    auto out = r.advance(t0, q0, v0, taus, t1, integrator);
    write_robots(r, systems, memories);
    return out;
  };
}

}  // namespace

void bind_robots(nb::module_& m) {
  using uvms::RobotsSystem;
  nb::class_<RobotsSystem>(m, "RobotsSystem",
                           "Several robots' systems integrated together over a period "
                           "(robots.hpp).")
      .def(
          "__init__",
          [](RobotsSystem* self, const std::vector<System*>& systems) {
            new (self) RobotsSystem(systems);
          },
          "systems"_a, nb::keep_alive<1, 2>(),
          "Each robot's compiled system, in order (kept alive).")
      .def_prop_ro("nq", &RobotsSystem::nq)
      .def_prop_ro("nv", &RobotsSystem::nv)
      .def(
          "add_pairs",
          &add_pair_set<RobotsSystem>,
          "pairs"_a, "a"_a, "b"_a,
          "A set of pairs between side a and b (robot k: k; the first system's object i: "
          "the number of robots + i).")
      .def(
          "acceleration",
          [](RobotsSystem& r, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
             const std::vector<Eigen::VectorXd>& taus, nb::handle systems,
             nb::handle memories) -> Eigen::VectorXd {
            check_robots_state(r, q, v);
            read_robots(r, systems, memories);
            return r.acceleration(t, q, v, taus);
          },
          "time_s"_a, "q"_a, "v"_a, "taus"_a, "system_memories"_a, "memories"_a,
          "The joined acceleration at the anchors of the memories (read only).")
      .def(
          "integrate", robots_period(false),
          "t0"_a, "q0"_a, "v0"_a, "taus"_a, "t1"_a, "integrator"_a, "system_memories"_a,
          "memories"_a,
          "(q, v) at t1 by the integrator's steps (the anchors read only: the caller moves "
          "them and solves each system's constraints).")
      .def_rw("reach_m", &RobotsSystem::reach_m,
              "Each side's reach from its root joint [m] (inf: no bound): the robots, then the "
              "first system's objects (the bound test's, near).")
      .def_rw("clearance_m", &RobotsSystem::clearance_m,
              "The clearance added to every sphere of the bound test [m].")
      .def(
          "advance", robots_period(true),
          "t0"_a, "q0"_a, "v0"_a, "taus"_a, "t1"_a, "integrator"_a, "system_memories"_a,
          "memories"_a,
          "(q, v) at t1: the integrator's steps, every anchor moved at the smooth step's end "
          "(the memories written back), then each system's constraints (Robots._together).")
      .def(
          "near",
          [](RobotsSystem& r, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
             double horizon_s) {
            check_robots_state(r, q, v);
            return r.near(q, v, horizon_s);
          },
          "q"_a, "v"_a, "horizon_s"_a,
          "Whether some pair of sides may touch within horizon_s (Robots.near).")
      .def(
          "root_spheres",
          [](RobotsSystem& r, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
             double horizon_s) {
            check_robots_state(r, q, v);
            r.root_spheres(q, v, horizon_s);
            const auto n = static_cast<Eigen::Index>(r.root_radii().size());
            Eigen::MatrixXd centers(n, 3);
            for (Eigen::Index k = 0; k < n; ++k) centers.row(k) = r.root_centers()[k].transpose();
            const Eigen::VectorXd radii =
                Eigen::Map<const Eigen::VectorXd>(r.root_radii().data(), n);
            return std::make_pair(centers, radii);
          },
          "q"_a, "v"_a, "horizon_s"_a,
          "near's first test: (centres (sides, 3) [m], radii (sides,) [m]) of each side's "
          "sphere about its root over horizon_s (robot_reach.reach_sphere; inf: no bound).")
      .def(
          "object_wrenches",
          [](RobotsSystem& r, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
             nb::handle systems, nb::handle memories) -> Eigen::MatrixXd {
            check_robots_state(r, q, v);
            read_robots(r, systems, memories);
            return r.object_wrenches(q, v);
          },
          "q"_a, "v"_a, "system_memories"_a, "memories"_a,
          "Each robot's wrench on the free objects (n_robots, 6): the force [N] and its "
          "moment about the world's origin [N m], world axes (Robots.object_wrenches).");
}

void bind_system(nb::module_& m) {
  m.def(
      "joint_box_step",
      [](const Eigen::VectorXd& v_free, const Eigen::MatrixXd& mass, const Eigen::VectorXd& coulomb,
         const Eigen::VectorXd& gap_low, const Eigen::VectorXd& gap_high, double period_s) {
        const uvms::JointBoxStep step =
            uvms::joint_box_step(v_free, mass, coulomb, gap_low, gap_high, period_s);
        return nb::make_tuple(step.velocity, step.friction_impulse, step.limit_impulse);
      },
      "v_free"_a, "mass"_a, "coulomb"_a, "gap_low"_a, "gap_high"_a, "period_s"_a,
      "(v+, friction impulse, limit impulse) of one body's joints (joint_box.hpp; the "
      "reference: uvms_pin.physics.constraints.joint_box.joint_box_step).");
  using uvms::PiecePairsModel;
  nb::class_<PiecePairsModel>(m, "PiecePairs",
                              "Pairs of pieces of two moving bodies (moving_contact.hpp).")
      .def(nb::init<>())
      .def_rw("pieces_a", &PiecePairsModel::pieces_a)
      .def_rw("pieces_b", &PiecePairsModel::pieces_b)
      .def_rw("pairs", &PiecePairsModel::pairs)
      .def_rw("friction_static", &PiecePairsModel::friction_static)
      .def_rw("friction_kinetic", &PiecePairsModel::friction_kinetic)
      .def_rw("law", &PiecePairsModel::law)
      .def(
          "forces",
          [](PiecePairsModel& pairs, const Eigen::MatrixXd& placements_a,
             const Eigen::MatrixXd& velocities_a, const Eigen::MatrixXd& placements_b,
             const Eigen::MatrixXd& velocities_b, nb::handle friction) {
            const auto data_a = side_kinematics("a", placements_a, velocities_a, pairs.pieces_a);
            const auto data_b = side_kinematics("b", placements_b, velocities_b, pairs.pieces_b);
            if (pairs.friction_static.size() != pairs.pairs.size() ||
                pairs.friction_kinetic.size() != pairs.pairs.size()) {
              throw InputError("pairs: one (mu_s, mu_k) per pair expected");
            }
            uvms::FrictionMemory memory;
            read_memory(friction, memory);
            uvms::PairContacts found;
            pairs.forces(data_a, data_b, memory, found);
            nb::dict out = forces_dict(found.forces);
            out["pair"] = found.pair;
            return out;
          },
          "placements_a"_a, "velocities_a"_a, "placements_b"_a, "velocities_b"_a, "friction"_a,
          "The touching pairs and their forces (PiecePairs.forces) from each side's joint "
          "placements (njoints, 12: rotation row-major, translation) and LOCAL velocities "
          "(njoints, 6), with the anchors of friction (a FrictionMemory, read only), as a "
          "dict of arrays.");
  nb::class_<System>(m, "System",
                     "The robot's plant and the free objects, one period in one call "
                     "(system.hpp).")
      .def(
          "__init__",
          [](System* self, uvms::Plant& plant, const std::vector<const uvms::Dynamics*>& objects) {
            new (self) System(plant, objects);
          },
          "plant"_a, "objects"_a, nb::keep_alive<1, 2>(),
          "The plant (kept alive) and each free object's floating body (copied).")
      .def(
          "__init__",
          [](System* self, uvms::Plant& plant, const std::vector<const uvms::Dynamics*>& objects,
             const std::vector<const uvms::Dynamics*>& fixtures,
             const std::vector<Eigen::VectorXd>& damping,
             const std::vector<Eigen::VectorXd>& coulomb,
             const std::vector<Eigen::VectorXd>& lower,
             const std::vector<Eigen::VectorXd>& upper) {
            const std::size_t n = fixtures.size();
            if (damping.size() != n || coulomb.size() != n || lower.size() != n ||
                upper.size() != n) {
              throw InputError("system: damping, coulomb, lower and upper: one per fixture");
            }
            std::vector<uvms::FixtureBody> bodies;
            for (std::size_t k = 0; k < n; ++k) {
              if (fixtures[k] == nullptr) throw InputError("system: a fixture without dynamics");
              bodies.push_back({*fixtures[k], damping[k], coulomb[k], lower[k], upper[k]});
            }
            new (self) System(plant, objects, std::move(bodies));
          },
          "plant"_a, "objects"_a, "fixtures"_a, "damping"_a, "coulomb"_a, "lower"_a, "upper"_a,
          nb::keep_alive<1, 2>(),
          "The plant (kept alive), each free object's floating body and each fixture's "
          "joints (copied) with, per fixture, its joints' viscous damping, Coulomb friction "
          "and limits (-inf, inf: none).")
      .def_prop_ro(
          "stalled_solves",
          [](const System& self) {
            const uvms::StalledSolves stalled = self.stalled_solves();
            return std::make_pair(stalled.count, stalled.worst_residual_m_s);
          },
          "(count, worst residual [m/s]) of the constraint solves that stalled in a cycle "
          "below the acceptable residual and were kept (object_contacts.hpp).")
      .def_prop_ro("nq", &System::nq)
      .def_prop_ro("nv", &System::nv)
      .def_rw("rigid_objects", &System::rigid_objects,
              "The free objects touch the fixed world by rigid contacts solved at each "
              "period's end (object_contacts.hpp).")
      .def_rw("rigid_pairs", &System::rigid_pairs,
              "The moving bodies touch each other by rigid contacts, every row of the "
              "system solved in one problem at each period's end (moving_constraints.hpp).")
      .def_rw("fixture_limit_margin", &System::fixture_limit_margin,
              "A fixture joint's limit is a row of its exact step once its gap is at most "
              "h |v| + this [rad or m] (the fixtures' JointLimits margin).")
      .def(
          "rigid_contacts",
          [](System& s) {
            nb::list sets, objects;
            for (const auto& found : s.found_sets()) {
              nb::dict out = forces_dict(s.rigid_pairs ? found.forces : uvms::ContactForces{});
              out["pair"] = s.rigid_pairs ? found.pair : std::vector<int>{};
              sets.append(out);
            }
            for (std::size_t k = 0; k < s.n_objects(); ++k) {
              if (s.object_worlds[k] && s.rigid_objects) {
                objects.append(forces_dict(s.found_object(k)));
              } else {
                objects.append(nb::none());
              }
            }
            return nb::make_tuple(sets, objects);
          },
          "The rigid contacts of the last period solved: (each pair set's, each object's "
          "with the fixed world or None), as dicts of arrays; empty where they are "
          "compliant.")
      .def(
          "add_pairs",
          &add_pair_set<System>,
          "pairs"_a, "a"_a, "b"_a, "A set of pairs between side a and b (-1: the robot).")
      .def(
          "add_attachment",
          [](System& s, int link_joint, int object, double attach_at_s, double release_at_s) {
            if (object < 0 || static_cast<std::size_t>(object) >= s.n_objects()) {
              throw InputError("system: no free object " + std::to_string(object));
            }
            const int njoints = s.plant().dynamics().model().njoints;
            if (link_joint < 1 || link_joint >= njoints) {
              throw InputError("system: the robot has no joint " + std::to_string(link_joint));
            }
            if (!(std::isfinite(attach_at_s) && attach_at_s >= 0.0) ||
                !(release_at_s > attach_at_s)) {
              throw InputError("system: an attachment holds from attach_at_s >= 0 until a "
                               "later release_at_s (inf: the run's end)");
            }
            uvms::Attachment held;
            held.link_joint = link_joint;
            held.object = object;
            held.attach_at_s = attach_at_s;
            held.release_at_s = release_at_s;
            s.attachments.push_back(held);
          },
          "link_joint"_a, "object"_a, "attach_at_s"_a, "release_at_s"_a,
          "Free object `object` held by the robot's joint `link_joint` from attach_at_s "
          "until release_at_s [s] (inf: none), at the pose the two have when it begins.")
      .def("forget_attachments", &System::forget_attachments,
           "A run starts: each attachment is placed anew at the start of its first period.")
      .def(
          "set_object_world",
          [](System& s, std::size_t k, const uvms::WorldContactModel& world) {
            if (k >= s.n_objects()) throw InputError("system: no free object " + std::to_string(k));
            s.object_worlds[k] = world;
            s.check();
          },
          "k"_a, "world"_a, "Free object k's contacts with the fixed objects.")
      .def(
          "advance",
          [](System& s, double t0, const Eigen::VectorXd& q0, const Eigen::VectorXd& v0,
             const Eigen::VectorXd& tau, double t1, const uvms::FixedStep& integrator,
             nb::handle friction) {
            check_state(s, q0, v0);
            if (!tau.allFinite()) throw InputError("system: tau contains a non-finite value");
            read_all(s, friction);
            auto out = s.advance(t0, q0, v0, tau, t1, integrator);
            write_all(s, friction);
            return out;
          },
          "t0"_a, "q0"_a, "v0"_a, "tau"_a, "t1"_a, "integrator"_a, "friction"_a,
          "The system's (q, v) at t1; the friction memories are read and written back "
          "(every anchor moved at the period's end).")
      .def(
          "acceleration",
          [](System& s, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
             const Eigen::VectorXd& tau, nb::handle friction) -> Eigen::VectorXd {
            check_state(s, q, v);
            read_all(s, friction);
            return s.acceleration(t, q, v, tau);
          },
          "time_s"_a, "q"_a, "v"_a, "tau"_a, "friction"_a,
          "The system's acceleration at the anchors of the friction memories (read only).")
      .def(
          "contacts",
          [](System& s, const Eigen::VectorXd& q, const Eigen::VectorXd& v, nb::handle friction) {
            check_state(s, q, v);
            read_all(s, friction);
            s.contacts(q, v);
            nb::list sets, objects;
            for (const auto& found : s.found_sets()) {
              nb::dict out = forces_dict(found.forces);
              out["pair"] = found.pair;
              sets.append(out);
            }
            for (std::size_t k = 0; k < s.n_objects(); ++k) {
              if (s.object_worlds[k]) {
                objects.append(forces_dict(s.found_object(k)));
              } else {
                objects.append(nb::none());
              }
            }
            return nb::make_tuple(sets, objects);
          },
          "q"_a, "v"_a, "friction"_a,
          "(each pair set's touching pairs, each object's contacts with the fixed world or "
          "None) at (q, v), as dicts of arrays (MovingContacts.contacts).")
      .def(
          "settle",
          [](System& s, const Eigen::VectorXd& q, const Eigen::VectorXd& v, nb::handle friction) {
            check_state(s, q, v);
            read_all(s, friction);
            s.settle(q, v);
            write_all(s, friction);
          },
          "q"_a, "v"_a, "friction"_a, "Every anchor moves (System.settle).");
}
