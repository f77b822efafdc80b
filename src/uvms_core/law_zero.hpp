// No input at all, the passive system (mirror of uvms_pin/control/base.py, ZeroController):
// tau = 0 at every tick, no desired values, no state.
#pragma once

#include <vector>

#include "law.hpp"

namespace uvms {

class ZeroLaw final : public SampledLaw {
 public:
  ZeroLaw(int nq, int nv) : nq_(nq), nv_(nv), tau_(Eigen::VectorXd::Zero(nv)) {
    if (nq < 1 || nv < 1) throw InputError("zero law: nq and nv must be >= 1");
  }
  int nq() const override { return nq_; }
  int nv() const override { return nv_; }
  int desired_size() const override { return 0; }
  LawStatus command(const LawInput&) override { return LawStatus::ok; }
  const Eigen::VectorXd& signals() const override { return tau_; }
  Eigen::Index tau_offset() const override { return 0; }
  std::vector<SignalSlot> signal_layout() const override { return {{"tau", 0, nv_}}; }

 private:
  int nq_, nv_;
  Eigen::VectorXd tau_;
};

}  // namespace uvms
