#include "world_contact.hpp"

#include <string>

namespace uvms {

void WorldContactModel::check(const Model& model) const {
  auto check_shape = [&](const ContactShape& shape, const char* what) {
    if (shape.joint_id < 0 || shape.joint_id >= static_cast<int>(model.njoints)) {
      throw InputError(std::string("world contact: a ") + what + "'s joint " +
                       std::to_string(shape.joint_id) + " is not in the model");
    }
    if (!shape.geometry) throw InputError(std::string("world contact: a ") + what + " has no geometry");
  };
  for (const auto& piece : pieces) check_shape(piece, "piece");
  for (const auto& object : objects) {
    check_shape(object, "object");
    if (!(object.friction_static >= object.friction_kinetic && object.friction_kinetic >= 0.0)) {
      throw InputError("world contact: an object needs friction_static >= friction_kinetic >= 0");
    }
  }
  if (!(law.stiffness_N_m > 0.0 && law.tangential_stiffness_N_m > 0.0 &&
        law.dissipation_s_m >= 0.0 && law.tangential_damping_N_s_m >= 0.0)) {
    throw InputError("world contact: stiffnesses > 0 and dampings >= 0 expected");
  }
}

void WorldContactModel::forces(const Data& data, const FrictionMemory& memory,
                               ContactForces& out) {
  Touch& found = out.touch;
  touch(data, pieces, objects, touch_work_, found);
  const auto m = static_cast<Eigen::Index>(found.size());
  const int n_objects = static_cast<int>(objects.size());
  out.normal_N.resize(m);
  out.force_world_N.resize(found.size());
  out.stretch_m.resize(found.size());
  out.material_m.resize(found.size());
  stretch_.resize(3, m);
  tangential_velocity_.resize(3, m);
  mu_stick_.resize(m);
  mu_kinetic_.resize(m);
  patch_.resize(found.size());
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Vec3& normal = found.normal_world[k];
    const Vec3& point = found.point_world_m[k];
    const double rate = -found.velocity_world_m_s[k].dot(normal);
    out.normal_N[i] = normal_force_N(law, found.depth_m[k], rate);
    // the tangential stretch from where the point stuck (a new point: no stretch), measured
    // at a point of coal's from the material point the period began at (material_points)
    const ContactKey key{found.piece[k], found.obj[k], found.corner[k]};
    Vec3 measured = point;
    out.material_m[k].setZero();
    if (found.corner[k] < 0) {
      const auto& placement = data.oMi[pieces[static_cast<std::size_t>(found.piece[k])].joint_id];
      out.material_m[k] = placement.actInv(point);
      const auto held = memory.material.find(key);
      if (held != memory.material.end()) measured = placement.act(held->second);
    }
    const auto anchor = memory.anchors.find(key);
    Vec3 stretch = anchor == memory.anchors.end() ? Vec3::Zero() : Vec3(measured - anchor->second);
    stretch -= normal * stretch.dot(normal);
    stretch_.col(i) = stretch;
    out.stretch_m[k] = stretch;
    tangential_velocity_.col(i) = found.velocity_world_m_s[k] + normal * rate;
    const auto& object = objects[static_cast<std::size_t>(found.obj[k])];
    patch_[k] = found.piece[k] * n_objects + found.obj[k];
    mu_stick_[i] =
        memory.slipping.count(patch_[k]) ? object.friction_kinetic : object.friction_static;
    mu_kinetic_[i] = object.friction_kinetic;
  }
  friction_force_N(law, out.normal_N, stretch_, tangential_velocity_, patch_, mu_stick_,
                   mu_kinetic_, friction_, out.sticking);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto k = static_cast<std::size_t>(i);
    out.force_world_N[k] = out.normal_N[i] * found.normal_world[k] + friction_.col(i);
  }
}

void WorldContactModel::add_to(Dynamics& dynamics, const ContactForces& forces) const {
  const Touch& found = forces.touch;
  for (std::size_t k = 0; k < found.size(); ++k) {
    Vec6 wrench = Vec6::Zero();
    wrench.head<3>() = forces.force_world_N[k];
    const auto& piece = pieces[static_cast<std::size_t>(found.piece[k])];
    const auto& object = objects[static_cast<std::size_t>(found.obj[k])];
    dynamics.add_world_wrench(piece.joint_id, found.point_world_m[k], wrench);
    // the reaction on a moving object; a fixed one passes it to the ground
    if (object.joint_id != 0) {
      dynamics.add_world_wrench(object.joint_id, found.point_world_m[k], -wrench);
    }
  }
}

void WorldContactModel::commit(const ContactForces& forces, FrictionMemory& memory) const {
  const Touch& found = forces.touch;
  const int n_objects = static_cast<int>(objects.size());
  std::map<ContactKey, Vec3> kept, material;
  std::set<int> slipping;
  for (std::size_t k = 0; k < found.size(); ++k) {
    const ContactKey key{found.piece[k], found.obj[k], found.corner[k]};
    const Vec3& x = found.point_world_m[k];
    if (found.corner[k] < 0) material[key] = forces.material_m[k];
    if (forces.sticking[k]) {
      const auto anchor = memory.anchors.find(key);
      if (found.corner[k] < 0) {  // the stretch carried over to the new contact point
        kept[key] = x - forces.stretch_m[k];
      } else {
        kept[key] = anchor == memory.anchors.end() ? x : anchor->second;
      }
    } else {
      const Vec3& normal = found.normal_world[k];
      const Vec3 friction = forces.force_world_N[k] - forces.normal_N[static_cast<Eigen::Index>(k)] * normal;
      kept[key] = x + friction / law.tangential_stiffness_N_m;
      slipping.insert(found.piece[k] * n_objects + found.obj[k]);
    }
  }
  memory.anchors.swap(kept);
  memory.slipping.swap(slipping);
  memory.material.swap(material);
}

}  // namespace uvms
