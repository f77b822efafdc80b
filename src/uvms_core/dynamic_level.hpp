// Dynamic levels of the task-priority controller: joint torques and the vehicle's body wrench
// that make zeta follow a reference zeta_r (nv) (mirror of
// uvms_pin/control/tracking/dynamic_level.py; the names below are the Python ones).
//
//   InverseDynamicsLevel (model-based), e = zeta_r - zeta:
//     I     <- clip(I + dt e, -integral_limit, integral_limit)   (dt: since the last call)
//     tau    = M(q) (K_v e + K_i I) + h(q, zeta)                 (the level's own Dynamics,
//                                                                  still water)
//   PpcVelocityLevel (model-free), e = zeta - zeta_r, rho(t) = (rho0 - rho_inf) e^{-l t} +
//     rho_inf, xi = e / rho:  tau = -k / rho r(xi) eps(xi), r = 2 / (1 - xi^2),
//     eps = 2 artanh(xi).
//
// A level declines a call (false: the Python level evaluates it, and raises) where the Python
// one raises: a velocity error out of its funnel (|xi| >= 1 or NaN), a failing dynamics call.
// The integral is state: computed with the torque, taken at commit() (law.hpp).
#pragma once

#include "dynamics.hpp"

namespace uvms {

class VelocityLevel {
 public:
  virtual ~VelocityLevel() = default;
  // tau (nv) at time_s for the measured (q, v) and the reference zeta_r; false: declined.
  virtual bool torque(double time_s, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                      const Eigen::VectorXd& zeta_r, Eigen::Ref<Eigen::VectorXd> tau) = 0;
  // The tick of the last torque is committed: the level takes its next state.
  virtual void commit() {}
};

// InverseDynamicsLevel's gains (nv each): K_v [1/s] > 0, K_i [1/s^2] >= 0, |I| [m, rad] > 0.
struct InverseDynamicsSettings {
  Eigen::VectorXd velocity_gain_per_s, integral_gain_per_s2, integral_limit;
};

// InverseDynamicsLevel's state: `integral` and `last_time_s` (None: started = false).
struct InverseDynamicsState {
  Eigen::VectorXd integral;
  bool started = false;
  double last_time_s = 0.0;
};

class InverseDynamicsLevel : public VelocityLevel {
 public:
  // `dynamics`: the model the level believes in (copied).
  InverseDynamicsLevel(const Dynamics& dynamics, InverseDynamicsSettings settings);
  bool torque(double time_s, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
              const Eigen::VectorXd& zeta_r, Eigen::Ref<Eigen::VectorXd> tau) override;
  void commit() override { state = next_; }
  InverseDynamicsState state;  // the committed state (the Python level's, between chunks)

 private:
  Dynamics dynamics_;
  InverseDynamicsSettings s_;
  FlowField still_water_;
  InverseDynamicsState next_;
  Eigen::VectorXd error_, acceleration_;
};

// PpcVelocityLevel's gain k (nv) > 0 [N or N m] and funnel rho0 > rho_inf > 0, l > 0 (nv each).
struct PpcVelocitySettings {
  Eigen::VectorXd gain, rho0, rho_inf, decay_rate_per_s;
};

class PpcVelocityLevel : public VelocityLevel {
 public:
  PpcVelocityLevel(int nv, PpcVelocitySettings settings);
  bool torque(double time_s, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
              const Eigen::VectorXd& zeta_r, Eigen::Ref<Eigen::VectorXd> tau) override;

 private:
  PpcVelocitySettings s_;
  Eigen::VectorXd gap_, bound_, xi_;  // rho0 - rho_inf (the funnel's _gap), rho(t), xi
};

}  // namespace uvms
