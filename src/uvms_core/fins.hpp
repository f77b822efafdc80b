// Fins: gz-sim's LiftDrag on a link (mirror of uvms_pin/hydro/lift_drag.py, the force of a
// flow past a fin, and uvms_pin/physics/fins.py, its wet fraction and its place in the
// dynamics). With v the velocity of the centre of pressure c relative to the water, R the
// fin link's orientation, f = R forward, u = R upward (or f x (f x v^) with radial
// symmetry) and the span s = f x u / |f x u|: no force when |v| <= 0.01 m/s nor, unless
// reversible, when f . v <= 0; the sweep's cos^2 scales the coefficients; the flow in the
// lift-drag plane v_ld = v - (v . s) s; drag along -v_ld, lift along s x v_ld; the angle of
// attack alpha = alpha_0 +- acos(lift . u) wrapped into [-pi/2, pi/2]; q S = rho |v_ld|^2 S / 2
// times c_L, c_D, c_M (slopes below the stall, the post-stall slopes beyond it, a control
// joint's angle adding to c_L and c_M). With a free surface the wrench is scaled by the wet
// fraction clip(1/2 - (c_z - eta) / sqrt(S), 0, 1).
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "dynamics.hpp"
#include "flow.hpp"
#include "types.hpp"

namespace uvms {

// below this speed of the centre of pressure through the water no force acts [m/s] (gz-sim)
constexpr double kFinMinSpeed_m_s = 0.01;

// One fin's LiftDrag parameters, in its link's frame (uvms_pin.hydro.lift_drag.LiftDragParams).
struct LiftDrag {
  double area_m2 = 0.0;
  double fluid_density_kg_m3 = 1.2041;
  double cla = 1.0, cda = 0.01, cma = 0.0;
  double alpha_stall_rad = 0.5 * M_PI, cla_stall = 0.0, cda_stall = 1.0, cma_stall = 0.0;
  double alpha0_rad = 0.0;
  Vec3 cp_m = Vec3::Zero();
  Vec3 forward = Vec3::UnitX();  // unit
  Vec3 upward = Vec3::UnitZ();   // unit, not along forward
  bool radial_symmetry = false, reversible = false;
  double control_joint_rad_to_cl = 4.0, cm_delta = 0.0;
};

// A fin on a joint's body (uvms_pin.model.uvms.Fin): its frame in the joint's, its
// parameters, the configuration index of its control joint (-1: none).
struct Fin {
  int joint_id = 0;
  Mat3 rotation_in_joint = Mat3::Identity();
  Vec3 translation_in_joint = Vec3::Zero();
  LiftDrag params;
  int control_q_index = -1;
};

// c = slope alpha below the stall; beyond +-stall the post-stall slope from there.
inline double past_stall(double slope, double slope_stall, double alpha, double stall) {
  if (alpha > stall) return slope * stall + slope_stall * (alpha - stall);
  if (alpha < -stall) return -slope * stall + slope_stall * (alpha + stall);
  return slope * alpha;
}

inline Vec3 normalized_or_zero(const Vec3& v) {
  const double norm = v.norm();
  return norm > 0.0 ? Vec3(v / norm) : Vec3::Zero();
}

// (the force [N] at the centre of pressure, the moment [N m]), world axes, of the flow
// `velocity` (the centre's velocity less the water's) past a fin whose link is turned by
// `rotation_world`; `control_rad` the control joint's angle (0 without one).
inline std::pair<Vec3, Vec3> lift_drag_wrench(const LiftDrag& p, const Mat3& rotation_world,
                                              const Vec3& velocity, double control_rad) {
  const std::pair<Vec3, Vec3> none{Vec3::Zero(), Vec3::Zero()};
  if (!(velocity.norm() > kFinMinSpeed_m_s)) return none;
  const Vec3 vel_hat = normalized_or_zero(velocity);
  const Vec3 forward = rotation_world * p.forward;
  if (!p.reversible && forward.dot(velocity) <= 0.0) return none;
  const Vec3 upward = p.radial_symmetry ? normalized_or_zero(forward.cross(forward.cross(vel_hat)))
                                        : Vec3(rotation_world * p.upward);
  const Vec3 span = normalized_or_zero(forward.cross(upward));
  const double sin_sweep = std::clamp(span.dot(vel_hat), -1.0, 1.0);
  const Vec3 in_plane = velocity - velocity.dot(span) * span;
  const Vec3 lift = normalized_or_zero(span.cross(in_plane));
  const double turn = std::acos(std::clamp(lift.dot(upward), -1.0, 1.0));
  double alpha = p.alpha0_rad + (lift.dot(forward) >= 0.0 ? turn : -turn);
  while (std::abs(alpha) > 0.5 * M_PI) alpha += alpha > 0.0 ? -M_PI : M_PI;
  const double cos2_sweep = 1.0 - sin_sweep * sin_sweep;
  const double stall = p.alpha_stall_rad;
  double cl = past_stall(p.cla, p.cla_stall, alpha, stall) * cos2_sweep;
  double cm = past_stall(p.cma, p.cma_stall, alpha, stall) * cos2_sweep;
  if (alpha > stall) {  // past the stall the lift and moment keep their sign
    cl = std::max(0.0, cl);
    cm = std::max(0.0, cm);
  } else if (alpha < -stall) {
    cl = std::min(0.0, cl);
    cm = std::min(0.0, cm);
  }
  const double cd = std::abs(past_stall(p.cda, p.cda_stall, alpha, stall) * cos2_sweep);
  cl += p.control_joint_rad_to_cl * control_rad;
  cm += p.cm_delta * control_rad;
  const double pressure_area = 0.5 * p.fluid_density_kg_m3 * in_plane.squaredNorm() * p.area_m2;
  return {pressure_area * (cl * lift - cd * normalized_or_zero(in_plane)),
          pressure_area * cm * span};
}

// w in [0, 1]: the ramp clip(1/2 - (c_z - eta) / sqrt(S), 0, 1) across the flow's surface.
inline double fin_wet_fraction(const Vec3& centre, double area_m2, const FlowField& flow,
                               double time_s) {
  const double eta = flow.surface_at(time_s, centre.x(), centre.y()).elevation_m;
  const double size = std::sqrt(area_m2);
  if (size == 0.0) return centre.z() <= eta ? 1.0 : 0.0;
  return std::clamp(0.5 - (centre.z() - eta) / size, 0.0, 1.0);
}

// The fins of a model, their wrenches added to the dynamics' external wrenches.
struct Fins {
  std::vector<Fin> fins;

  bool active() const { return !fins.empty(); }

  // After dynamics.kinematics(q, v): each fin's wrench at its centre of pressure on its
  // joint's body, in `flow` at `time_s` (cut by its surface with `free_surface`).
  void add_to(Dynamics& dynamics, const ConstVec& q, const FlowField& flow, double time_s,
              bool free_surface) const {
    const Data& data = dynamics.data();
    for (const Fin& fin : fins) {
      if (fin.joint_id <= 0 || fin.joint_id >= static_cast<int>(dynamics.model().njoints) ||
          fin.control_q_index >= static_cast<int>(q.size())) {
        throw InputError("fins: a fin's joint or control index is not in the model");
      }
      const pinocchio::SE3& joint = data.oMi[fin.joint_id];
      const Mat3 rotation = joint.rotation() * fin.rotation_in_joint;
      const Vec3 origin = joint.act(Vec3(fin.translation_in_joint));
      const Vec3 centre = origin + rotation * fin.params.cp_m;
      const double wet =
          free_surface ? fin_wet_fraction(centre, fin.params.area_m2, flow, time_s) : 1.0;
      if (wet == 0.0) continue;  // in the air: no lift, no drag
      const pinocchio::Motion motion = joint.act(data.v[fin.joint_id]);  // at the world origin
      const Vec3 velocity = Vec3(motion.linear() + motion.angular().cross(centre)) -
                            flow.at(time_s, centre).velocity_world;
      const double control = fin.control_q_index < 0 ? 0.0 : q[fin.control_q_index];
      const auto [force, moment] = lift_drag_wrench(fin.params, rotation, velocity, control);
      Vec6 wrench;
      wrench << wet * force, wet * moment;
      dynamics.add_world_wrench(fin.joint_id, centre, wrench);
    }
  }
};

}  // namespace uvms
