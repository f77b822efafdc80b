// The derivatives of the free surface's wet-fraction terms (mirror of
// uvms_pin/physics/derivatives/surface.py, which derives them).
//
// Each hull i the surface cuts (0 < f_i < 1) has a wetting x_i = (V_i, m_i, f_i, g_i, f_t,i)
// (12 numbers), a function of its joint's pose: dx_i/dq = (dx_i/d delta) J_j, the pose
// Jacobian by 4-point central differences of Hull::wet over delta = [v; w] (placement ->
// placement exp6(delta)), step 1e-6 of the hull's bounding radius. Through it: the joint's
// wet volume and centre of buoyancy (buoyancy, Froude-Krylov, the flow sampled at r_j),
// its added mass sum f_i M_A,i (added mass, Kirchhoff), the damping f_i D(nu_r) of a damped
// body with a hull, and the wet-fraction wrenches w_i = E_i g_i - (g_i . nu + f_t,i) p_i,
// also differentiated through nu and nu_r.
#include <algorithm>

#include <pinocchio/spatial/explog.hpp>

#include "added_mass.hpp"
#include "damping.hpp"
#include "derivatives.hpp"

namespace uvms {

namespace {

constexpr double kPoseStep = 1e-6;  // per metre of bounding radius
constexpr int kVolume = 0, kMoment = 1, kFraction = 4, kGradient = 5, kRate = 11;
using Wetting12 = Eigen::Matrix<double, 12, 1>;

Wetting12 wetting_vector(const Hull& hull, const pinocchio::SE3& placement,
                         const FlowField& flow, double time_s) {
  const Vec3 center = placement.act(hull.bound_center_m);
  const Wetting w = hull.wet(placement.rotation(), placement.translation(),
                             flow.surface_at(time_s, center.x(), center.y()));
  Wetting12 out;
  out << w.volume_m3, w.moment_m4, w.fraction, w.fraction_gradient, w.fraction_rate;
  return out;
}

// dx/d delta (12, 6) over the joint's LOCAL twist.
Eigen::Matrix<double, 12, 6> wetting_jacobian(const Hull& hull, const pinocchio::SE3& placement,
                                              const FlowField& flow, double time_s) {
  const double step = kPoseStep * std::max(hull.bound_radius_m, 1e-3);
  Eigen::Matrix<double, 12, 6> out;
  for (int k = 0; k < 6; ++k) {
    auto at = [&](double scale) {
      Vec6 delta = Vec6::Zero();
      delta[k] = scale * step;
      return wetting_vector(hull, placement * pinocchio::exp6(pinocchio::Motion(delta)), flow,
                            time_s);
    };
    out.col(k) = (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * step);
  }
  return out;
}

Matrix6x linear_block(const Matrix3x& block) {
  Matrix6x out(6, block.cols());
  out.topRows<3>() = block;
  out.bottomRows<3>().setZero();
  return out;
}

bool holds(const std::vector<int>& joints, int j) {
  return std::find(joints.begin(), joints.end(), j) != joints.end();
}

}  // namespace

void Derivatives::surface_jacobians(const FlowField& flow, double time_s) {
  const auto& d = dynamics_;
  const auto& bodies = d.hydro_.surface_bodies;
  const std::size_t n = bodies.size();
  cut_.assign(n, 0);
  wetting_dq_.resize(n);
  for (std::size_t h = 0; h < n; ++h) {
    if (!(d.fraction_[h] > 0.0 && d.fraction_[h] < 1.0)) continue;
    cut_[h] = 1;
    const auto& m = motion_[bodies[h].joint_id];
    const pinocchio::SE3 placement(m.rotation, m.translation);
    wetting_dq_[h].noalias() = wetting_jacobian(bodies[h].hull, placement, flow, time_s) * m.jacobian;
  }
  const bool moving_water = !flow.waves.empty() || !flow.current_world_m_s.isZero(0.0);
  std::vector<int> joints;
  for (const auto& body : bodies) {
    if (!holds(joints, body.joint_id)) joints.push_back(body.joint_id);
  }
  for (int j : joints) {
    const FlowGradientsAtPoint at_cob =
        moving_water ? flow.gradients_at(time_s, motion_[j].point(d.center_of_buoyancy(j)))
                     : FlowGradientsAtPoint();
    surface_joint_terms(j, at_cob, moving_water);
  }
  for (const auto& body : d.hydro_.damped_bodies) {  // f_i D(nu_r): through f_i
    if (body.hull_index < 0 || !cut_[body.hull_index]) continue;
    const auto& m = motion_[body.joint_id];
    const FlowGradientsAtPoint at_origin =
        moving_water ? flow.gradients_at(time_s, m.point(body.position_in_joint_m))
                     : FlowGradientsAtPoint();
    const FlowSeenByBody seen =
        flow_in_body(m, body.rotation_in_joint, body.position_in_joint_m, at_origin);
    Vec6 relative = body.action_joint_to_body * m.velocity;
    relative.head<3>() -= seen.velocity;
    const Vec6 drag = body.action_joint_to_body.transpose() *
                      damping_wrench(body.linear_damping, body.quadratic_damping, relative);
    dw_dq_[body.joint_id].noalias() += drag * wetting_dq_[body.hull_index].row(kFraction);
  }
}

void Derivatives::surface_joint_terms(int j, const FlowGradientsAtPoint& at_cob,
                                      bool moving_water) {
  const auto& d = dynamics_;
  const auto& bodies = d.hydro_.surface_bodies;
  const auto& m = motion_[j];
  const int nv = d.model_.nv;
  const Mat3& rotation = m.rotation;
  const double volume = d.volume(j);
  const Vec3 cob = d.center_of_buoyancy(j);
  const FlowSeenByBody seen = flow_in_body(m, Mat3::Identity(), cob, at_cob);
  // dV_j, dr_j = (dm_j - r_j dV_j) / V_j
  Eigen::RowVectorXd volume_dq = Eigen::RowVectorXd::Zero(nv);
  Matrix3x moment_dq = Matrix3x::Zero(3, nv);
  for (std::size_t h = 0; h < bodies.size(); ++h) {
    if (bodies[h].joint_id != j || !cut_[h]) continue;
    volume_dq += wetting_dq_[h].row(kVolume);
    moment_dq += wetting_dq_[h].middleRows<3>(kMoment);
  }
  Matrix3x cob_dq = Matrix3x::Zero(3, nv);
  if (volume > 0.0) cob_dq = (moment_dq - cob * volume_dq) / volume;
  const Matrix3x flow_dq = rotation.transpose() * at_cob.gradient * rotation * cob_dq;
  const Matrix3x flow_rate_dq =
      rotation.transpose() * at_cob.acceleration_gradient * rotation * cob_dq;
  Matrix6x& dw_dq = dw_dq_[j];
  Matrix6x& dw_dv = dw_dv_[j];
  if (holds(d.joints_with_volume_, j)) {  // [f; r x f], F = rho V (Du/Dt(p_r) - g)
    const double density = d.hydro_.water_density_kg_m3;
    const Vec3 per_volume = density * (at_cob.acceleration_world - d.model_.gravity.linear());
    const Matrix3x force_dq = per_volume * volume_dq +
                              density * volume * at_cob.acceleration_gradient * rotation * cob_dq;
    const Vec3 force_body = rotation.transpose() * (volume * per_volume);
    const Matrix3x force_body_dq = rotation.transpose() * force_dq;
    dw_dq.topRows<3>() += force_body_dq;
    dw_dq.bottomRows<3>() += skew(cob) * force_body_dq - skew(force_body) * cob_dq;
  }
  if (!holds(d.joints_with_added_mass_, j)) return;
  const Vec3 omega = m.velocity.tail<3>();
  Vec6 relative = m.velocity;
  relative.head<3>() -= seen.velocity;
  Vec6 twist_rate = Vec6::Zero();
  twist_rate.head<3>() = seen.acceleration - omega.cross(seen.velocity);
  const Mat6& added = d.added_mass(j);
  if (moving_water) {  // M_A,j held, the flow sampled at the moved r_j
    dw_dq.noalias() += added * linear_block(flow_rate_dq - skew(omega) * flow_dq);
    dw_dq.noalias() += kirchhoff_jacobian(added, relative) * linear_block(flow_dq);
  }
  const Matrix3x seen_velocity_dq = seen.velocity_by_pose * m.jacobian;
  const Matrix6x relative_dq = m.velocity_dq - linear_block(seen_velocity_dq + flow_dq);
  const Vec6 acceleration = data_.a[j].toVector();
  for (std::size_t h = 0; h < bodies.size(); ++h) {
    if (bodies[h].joint_id != j) continue;
    const Mat6& added_h = bodies[h].added_mass_in_joint;
    if (cut_[h]) {  // M_A,j through f_h
      const Vec6 load =
          added_h * (acceleration - twist_rate) + kirchhoff_wrench(added_h, relative);
      dw_dq.noalias() -= load * wetting_dq_[h].row(kFraction);
    }
    const Vec6& gradient = d.fraction_gradient_[h];
    const double rate_t = d.fraction_rate_[h];
    if (gradient.isZero(0.0) && rate_t == 0.0 && !cut_[h]) continue;
    // w_h = E g - (g . nu + f_t) p,  p = M_A,h nu_r,  E = 1/2 nu_r . p
    const Vec6 momentum = added_h * relative;
    const double energy = 0.5 * relative.dot(momentum);
    const double rate = gradient.dot(m.velocity) + rate_t;
    dw_dq.noalias() += gradient * (momentum.transpose() * relative_dq);
    dw_dq.noalias() -= momentum * (gradient.transpose() * m.velocity_dq);
    dw_dq.noalias() -= rate * (added_h * relative_dq);
    dw_dv.noalias() += gradient * (momentum.transpose() * m.jacobian);
    dw_dv.noalias() -= momentum * (gradient.transpose() * m.jacobian);
    dw_dv.noalias() -= rate * (added_h * m.jacobian);
    if (cut_[h]) {
      const auto gradient_dq = wetting_dq_[h].middleRows<6>(kGradient);
      dw_dq.noalias() += energy * gradient_dq;
      dw_dq.noalias() -= momentum * (m.velocity.transpose() * gradient_dq +
                                     wetting_dq_[h].row(kRate));
    }
  }
}

}  // namespace uvms
