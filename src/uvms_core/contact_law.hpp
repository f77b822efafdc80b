// The contact law at one point (mirror of uvms_pin/physics/world/contact_law.py): a
// Hunt-Crossley normal force that never pulls, and Coulomb friction with static and kinetic
// coefficients held by a tangential spring.
//
//   f_n = k delta max(0, 1 + d delta_dot)                                         [N]
//   f_trial = -k_t s - c_t v_t   (s the tangential stretch from the anchor)       [N]
//
// A patch (the points of one piece on one object) sticks while |sum f_trial| <= mu sum f_n
// (mu = mu_s, or mu_k for a patch already slipping: Coulomb's static-kinetic hysteresis);
// otherwise every f_trial of the patch is scaled so that the patch's friction is
// mu_k sum f_n along sum f_trial.
#pragma once

#include <algorithm>
#include <vector>

#include "types.hpp"

namespace uvms {

struct ContactLaw {
  double stiffness_N_m = 2.0e4;             // k, per contact point
  double dissipation_s_m = 1.0;             // d, Hunt-Crossley
  double tangential_stiffness_N_m = 2.0e4;  // k_t, the stick spring per point
  double tangential_damping_N_s_m = 200.0;  // c_t
};

// f_n = k delta max(0, 1 + d delta_dot) [N]: >= 0, zero at zero depth.
inline double normal_force_N(const ContactLaw& law, double depth_m, double rate_m_s) {
  return law.stiffness_N_m * depth_m * std::max(0.0, 1.0 + law.dissipation_s_m * rate_m_s);
}

// The friction of m points (friction_force_N of contact_law.py): stretch and v_t (3, m),
// normal (m), patch (m) ids, mu_stick and mu_kinetic (m) per point, the same within a patch.
// Writes f_t (3, m) and sticking (m).
inline void friction_force_N(const ContactLaw& law, const Eigen::VectorXd& normal_N,
                             const Eigen::Matrix3Xd& stretch_m,
                             const Eigen::Matrix3Xd& tangential_velocity_m_s,
                             const std::vector<int>& patch, const Eigen::VectorXd& mu_stick,
                             const Eigen::VectorXd& mu_kinetic, Eigen::Matrix3Xd& friction_N,
                             std::vector<char>& sticking) {
  const Eigen::Index m = normal_N.size();
  friction_N = -law.tangential_stiffness_N_m * stretch_m -
               law.tangential_damping_N_s_m * tangential_velocity_m_s;
  sticking.assign(static_cast<std::size_t>(m), 0);
  std::vector<char> done(static_cast<std::size_t>(m), 0);
  for (Eigen::Index i = 0; i < m; ++i) {
    if (done[static_cast<std::size_t>(i)]) continue;
    const int group = patch[static_cast<std::size_t>(i)];
    Vec3 total = Vec3::Zero();
    double load = 0.0;
    for (Eigen::Index j = i; j < m; ++j) {
      if (patch[static_cast<std::size_t>(j)] != group) continue;
      total += friction_N.col(j);
      load += normal_N[j];
    }
    const double size = total.norm();
    const bool stick = size <= mu_stick[i] * load;
    const double scale = stick ? 1.0 : mu_kinetic[i] * load / (size > 0.0 ? size : 1.0);
    for (Eigen::Index j = i; j < m; ++j) {
      const auto k = static_cast<std::size_t>(j);
      if (patch[k] != group) continue;
      done[k] = 1;
      sticking[k] = stick ? 1 : 0;
      friction_N.col(j) *= scale;
    }
  }
}

}  // namespace uvms
