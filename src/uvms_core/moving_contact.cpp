#include "moving_contact.hpp"

#include <cmath>
#include <string>
#include <utility>

namespace uvms {


void PiecePairsModel::check(const Model& model_a, const Model& model_b) const {
  auto check_pieces = [](const std::vector<ContactShape>& pieces, const Model& model) {
    // joint 0: a link fixed in the world (a fixture's root), at rest where its model puts it
    for (const auto& piece : pieces) {
      if (piece.joint_id < 0 || piece.joint_id >= static_cast<int>(model.njoints)) {
        throw InputError("moving contact: a piece's joint " + std::to_string(piece.joint_id) +
                         " is not a joint of its model");
      }
      if (!piece.geometry) throw InputError("moving contact: a piece has no geometry");
    }
  };
  check_pieces(pieces_a, model_a);
  check_pieces(pieces_b, model_b);
  const auto n = pairs.size();
  if (friction_static.size() != n || friction_kinetic.size() != n) {
    throw InputError("moving contact: one (mu_s, mu_k) per pair expected");
  }
  for (std::size_t k = 0; k < n; ++k) {
    const auto [a, b] = pairs[k];
    if (a < 0 || a >= static_cast<int>(pieces_a.size()) || b < 0 ||
        b >= static_cast<int>(pieces_b.size())) {
      throw InputError("moving contact: pair " + std::to_string(k) + " is not a pair of pieces");
    }
    if (!(friction_static[k] >= friction_kinetic[k] && friction_kinetic[k] >= 0.0)) {
      throw InputError("moving contact: a pair needs friction_static >= friction_kinetic >= 0");
    }
  }
}

void PiecePairsModel::forces(const Data& data_a, const Data& data_b,
                             const FrictionMemory& memory, PairContacts& out) {
  ContactForces& found = out.forces;
  Touch& touch = found.touch;
  touch.clear();
  out.pair.clear();
  if (boxes_a_.size() != pieces_a.size() || boxes_b_.size() != pieces_b.size()) {
    boxes_a_.clear();
    boxes_b_.clear();
    for (const auto& piece : pieces_a) boxes_a_.push_back(local_box(piece));
    for (const auto& piece : pieces_b) boxes_b_.push_back(local_box(piece));
  }
  // each piece placed once (a set of every piece against every piece has n_a n_b pairs)
  where_a_.resize(pieces_a.size());
  where_b_.resize(pieces_b.size());
  for (std::size_t i = 0; i < pieces_a.size(); ++i) where_a_[i] = placement_of(data_a, pieces_a[i]);
  for (std::size_t j = 0; j < pieces_b.size(); ++j) where_b_[j] = placement_of(data_b, pieces_b[j]);
  // the pairs that overlap (touching of pairs.py): bounding spheres, then coal's point
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& pa = pieces_a[static_cast<std::size_t>(pairs[k][0])];
    const auto& pb = pieces_b[static_cast<std::size_t>(pairs[k][1])];
    const pinocchio::SE3& where_a = where_a_[static_cast<std::size_t>(pairs[k][0])];
    const pinocchio::SE3& where_b = where_b_[static_cast<std::size_t>(pairs[k][1])];
    const double gap = (where_a.translation() - where_b.translation()).norm();
    if (gap >= pa.bound_radius_m + pb.bound_radius_m) continue;
    if (sphere_misses(where_a.translation(), pa.bound_radius_m, boxes_b_[pairs[k][1]], where_b) ||
        sphere_misses(where_b.translation(), pb.bound_radius_m, boxes_a_[pairs[k][0]], where_a)) {
      continue;
    }
    Vec3 point, normal;
    double depth = 0.0;
    if (!narrow_.deepest(k, pa, where_a, pb, where_b, point, normal, depth)) continue;
    out.pair.push_back(static_cast<int>(k));
    touch.piece.push_back(pairs[k][0]);
    touch.obj.push_back(pairs[k][1]);
    touch.corner.push_back(-1);
    touch.point_world_m.push_back(point);
    touch.normal_world.push_back(normal);
    touch.depth_m.push_back(depth);
    touch.velocity_world_m_s.push_back(point_velocity(data_a, pa, point) -
                                       point_velocity(data_b, pb, point));
  }
  const auto m = static_cast<Eigen::Index>(touch.size());
  found.normal_N.resize(m);
  found.force_world_N.resize(touch.size());
  found.stretch_m.resize(touch.size());
  found.material_m.resize(touch.size());
  stretch_.resize(3, m);
  tangential_velocity_.resize(3, m);
  mu_stick_.resize(m);
  mu_kinetic_.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const int pair = out.pair[k];
    const Vec3& normal = touch.normal_world[k];
    const Vec3& point = touch.point_world_m[k];
    const double rate = -touch.velocity_world_m_s[k].dot(normal);
    found.normal_N[i] = normal_force_N(law, touch.depth_m[k], rate);
    // the stretch from a's material point the period began at (material_points of
    // world.py) to the anchor kept in b's joint frame (none: no stretch)
    const ContactKey key{pair, 0, -1};
    const auto& a_at = data_a.oMi[static_cast<std::size_t>(
        pieces_a[static_cast<std::size_t>(touch.piece[k])].joint_id)];
    found.material_m[k] = a_at.actInv(point);
    const auto held = memory.material.find(key);
    const Vec3 measured = held == memory.material.end() ? point : Vec3(a_at.act(held->second));
    const auto anchor = memory.anchors.find(key);
    Vec3 stretch = Vec3::Zero();
    if (anchor != memory.anchors.end()) {
      const auto& b_at = data_b.oMi[static_cast<std::size_t>(
          pieces_b[static_cast<std::size_t>(touch.obj[k])].joint_id)];
      stretch = measured - b_at.act(anchor->second);
    }
    stretch -= normal * stretch.dot(normal);
    stretch_.col(i) = stretch;
    found.stretch_m[k] = stretch;
    tangential_velocity_.col(i) = touch.velocity_world_m_s[k] + normal * rate;
    const auto p = static_cast<std::size_t>(pair);
    mu_stick_[i] = memory.slipping.count(pair) ? friction_kinetic[p] : friction_static[p];
    mu_kinetic_[i] = friction_kinetic[p];
  }
  friction_force_N(law, found.normal_N, stretch_, tangential_velocity_, out.pair, mu_stick_,
                   mu_kinetic_, friction_, found.sticking);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto k = static_cast<std::size_t>(i);
    found.force_world_N[k] = found.normal_N[i] * touch.normal_world[k] + friction_.col(i);
  }
}

void PiecePairsModel::commit(const Data& data_b, const PairContacts& contacts,
                             FrictionMemory& memory) const {
  const ContactForces& found = contacts.forces;
  const Touch& touch = found.touch;
  std::map<ContactKey, Vec3> kept, material;
  std::set<int> slipping;
  for (std::size_t i = 0; i < touch.size(); ++i) {
    const int pair = contacts.pair[i];
    const ContactKey key{pair, 0, -1};
    const Vec3& x = touch.point_world_m[i];
    material[key] = found.material_m[i];
    Vec3 moved;
    if (found.sticking[i]) {
      moved = x - found.stretch_m[i];
    } else {
      const Vec3 friction =
          found.force_world_N[i] - found.normal_N[static_cast<Eigen::Index>(i)] * touch.normal_world[i];
      moved = x + friction / law.tangential_stiffness_N_m;
      slipping.insert(pair);
    }
    const auto& b_at = data_b.oMi[static_cast<std::size_t>(
        pieces_b[static_cast<std::size_t>(touch.obj[i])].joint_id)];
    kept[key] = b_at.actInv(moved);
  }
  memory.anchors.swap(kept);
  memory.slipping.swap(slipping);
  memory.material.swap(material);
}

}  // namespace uvms
