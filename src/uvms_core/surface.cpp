// The free surface as the bodies see it (mirror of uvms_pin/physics/surface.py).
//
// Each hull whose bounding sphere lies below -max|eta| is wet (f = 1), above +max|eta| dry
// (f = 0): one bound check per body, and nothing more when every body is deep. Over any other
// hull the surface is level at the elevation eta under its bounding sphere's centre: the hull
// is deep (dry) when the sphere lies below (above) it, else cut (hull.hpp). Per joint touched:
//   V_j = sum V_sub,i,  r_j = sum V_sub,i r_sub,i / V_j,  M_A,j = sum f_i M_A,i + M_A(no hull),
// and the added mass that changes with f adds, per cut body (Lagrange's equations of
// T_i = f_i 1/2 nu_r^T M_A,i nu_r; see uvms_pin/physics/reference.py, wet_fraction_wrenches):
//   w_i = (1/2 nu_r^T M_A,i nu_r) g_i - (g_i . nu + f_t,i) M_A,i nu_r.
#include <string>

#include "dynamics.hpp"

namespace uvms {

void Dynamics::check_surface_bodies() const {
  const int nj = model_.njoints;
  if (!hydro_.surface_bodies.empty() &&
      hydro_.added_mass_without_hull_per_joint.size() != static_cast<std::size_t>(nj)) {
    throw InputError("added_mass_without_hull_per_joint must have njoints = " +
                     std::to_string(nj) + " entries");
  }
  for (const auto& body : hydro_.surface_bodies) {
    if (body.joint_id < 1 || body.joint_id >= nj) {
      throw InputError("hull on joint " + std::to_string(body.joint_id) +
                       ", which the model does not have");
    }
    if (!(body.hull.geometric_volume_m3 > 0.0) || body.hull.pieces.empty()) {
      throw InputError("a hull needs pieces of positive volume");
    }
    for (const auto& piece : body.hull.pieces) {
      if (piece.kind != ShapeKind::polyhedron) continue;
      if (piece.triangles.rows() < 4 || piece.triangles.minCoeff() < 0 ||
          piece.triangles.maxCoeff() >= piece.vertices.rows()) {
        throw InputError("a polyhedron hull piece names vertices it does not have");
      }
    }
  }
}

void Dynamics::update_wet_state(double time_s, const FlowField& flow, bool free_surface) {
  wet_active_ = false;
  const auto& bodies = hydro_.surface_bodies;
  if (!free_surface || bodies.empty()) return;
  const double bound = flow.elevation_bound_m();
  bool all_deep = true;
  for (std::size_t h = 0; h < bodies.size(); ++h) {
    const auto& hull = bodies[h].hull;
    const Vec3 center = data_.oMi[bodies[h].joint_id].act(hull.bound_center_m);
    const double top = center.z() + hull.bound_radius_m, bottom = center.z() - hull.bound_radius_m;
    deep_[h] = top <= -bound;
    dry_[h] = bottom >= bound;
    if (!deep_[h] && !dry_[h]) {  // the level surface over this hull decides
      surface_[h] = flow.surface_at(time_s, center.x(), center.y());
      deep_[h] = top <= surface_[h].elevation_m;
      dry_[h] = bottom >= surface_[h].elevation_m;
    }
    all_deep = all_deep && deep_[h];
  }
  if (all_deep) return;
  wet_active_ = true;
  cut_.clear();
  for (std::size_t h = 0; h < bodies.size(); ++h) {
    const auto& body = bodies[h];
    fraction_[h] = deep_[h] ? 1.0 : 0.0;
    fraction_gradient_[h].setZero();
    fraction_rate_[h] = 0.0;
    hull_volume_[h] = deep_[h] ? body.volume_m3 : 0.0;
    hull_moment_[h] = hull_volume_[h] * body.center_of_buoyancy_in_joint_m;
    if (deep_[h] || dry_[h]) continue;
    const auto& placement = data_.oMi[body.joint_id];
    const Wetting wetting =
        body.hull.wet(placement.rotation(), placement.translation(), surface_[h]);
    hull_volume_[h] = wetting.volume_m3;
    hull_moment_[h] = wetting.moment_m4;
    fraction_[h] = wetting.fraction;
    fraction_gradient_[h] = wetting.fraction_gradient;
    fraction_rate_[h] = wetting.fraction_rate;
    cut_.push_back(static_cast<int>(h));
  }
  const int nj = model_.njoints;
  for (int j = 0; j < nj; ++j) {
    wet_touched_[j] = 0;
    wet_volume_[j] = hydro_.volume_per_joint_m3[j];
    wet_cob_[j] = hydro_.center_of_buoyancy_per_joint_m[j];
    wet_added_mass_[j] = hydro_.added_mass_per_joint[j];
  }
  for (std::size_t h = 0; h < bodies.size(); ++h) {
    if (!deep_[h]) wet_touched_[bodies[h].joint_id] = 1;
  }
  for (int j = 0; j < nj; ++j) {
    if (!wet_touched_[j]) continue;
    double total = 0.0;
    Vec3 moment = Vec3::Zero();
    Mat6 added = hydro_.added_mass_without_hull_per_joint[j];
    for (std::size_t h = 0; h < bodies.size(); ++h) {
      if (bodies[h].joint_id != j) continue;
      total += hull_volume_[h];
      moment += hull_moment_[h];
      added += fraction_[h] * bodies[h].added_mass_in_joint;
    }
    wet_volume_[j] = total;
    wet_cob_[j] = total > 0.0 ? Vec3(moment / total) : Vec3::Zero();
    wet_added_mass_[j] = added;
  }
}

void Dynamics::add_wet_fraction_wrenches() {
  for (int h : cut_) {
    const auto& body = hydro_.surface_bodies[h];
    const int j = body.joint_id;
    const Vec6& relative = relative_velocity_[j];
    const Vec6 momentum = body.added_mass_in_joint * relative;
    const double energy = 0.5 * relative.dot(momentum);
    const Vec6& gradient = fraction_gradient_[h];
    const double rate = gradient.dot(data_.v[j].toVector()) + fraction_rate_[h];
    fext_[j].toVector() += energy * gradient - rate * momentum;
  }
}

}  // namespace uvms
