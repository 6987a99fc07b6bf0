#pragma once
/// \file
/// \brief `coulomb_friction`: dry friction opposing the bending rate (smoothed).

#include <cmath>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief \f$\tau_k = -F_c \tanh(\dot q_k / v_s)\f$ per coordinate, with the smoothing speed
/// \f$v_s\f$ = `kSmoothingSpeed` (rad/s): a smooth Coulomb law keeps the ODE Lipschitz for the
/// implicit integrator. Parameter `Fc` (N m).
struct CoulombFriction : EffectBase {
  static constexpr const char* name = "coulomb_friction";
  static constexpr const char* param_name = "Fc";
  static constexpr double kSmoothingSpeed = 0.02;
  template <class S, class Q, class P, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q&, const Q& qd, const P&, Tau& tau) const {
    using std::tanh;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -= S(param(i)) * tanh(qd(j.q_offset + k) * S(1.0 / kSmoothingSpeed));
    }
  }
};

}  // namespace softrne
