// Compliant contact at the end-effector (mirror of uvms_pin/physics/contact.py).
// Each model returns lambda: the wrench the end-effector exerts ON the environment, at the
// end-effector point, world axes [N; N m].
#pragma once

#include <algorithm>
#include <variant>

#include "types.hpp"

namespace uvms {

struct NoContact {
  Vec6 wrench_on_environment_world(const Vec3&, const Vec3&) const { return Vec6::Zero(); }
};

// f_e = K_f (p - p_0).
struct LinearSpring {
  Vec3 stiffness_N_m;
  Vec3 anchor_world_m;

  Vec6 wrench_on_environment_world(const Vec3& position_world_m, const Vec3&) const {
    Vec6 out = Vec6::Zero();
    out.head<3>() = stiffness_N_m.cwiseProduct(position_world_m - anchor_world_m);
    return out;
  }
};

// lambda = -n max(0, k d + c d_dot) while the depth d = (p_s - p) . n > 0.
struct CompliantPlane {
  Vec3 normal_world;  // unit
  Vec3 point_world_m;
  double stiffness_N_m;
  double damping_N_s_m;

  Vec6 wrench_on_environment_world(const Vec3& position_world_m,
                                   const Vec3& velocity_world_m_s) const {
    Vec6 out = Vec6::Zero();
    const double depth = (point_world_m - position_world_m).dot(normal_world);
    if (depth <= 0.0) return out;
    const double rate = -velocity_world_m_s.dot(normal_world);
    const double push = std::max(0.0, stiffness_N_m * depth + damping_N_s_m * rate);
    out.head<3>() = -push * normal_world;
    return out;
  }
};

using Contact = std::variant<NoContact, LinearSpring, CompliantPlane>;

inline Vec6 contact_wrench_world(const Contact& contact, const Vec3& position_world_m,
                                 const Vec3& velocity_world_m_s) {
  return std::visit(
      [&](const auto& c) { return c.wrench_on_environment_world(position_world_m, velocity_world_m_s); },
      contact);
}

inline bool has_contact(const Contact& contact) {
  return !std::holds_alternative<NoContact>(contact);
}

}  // namespace uvms
