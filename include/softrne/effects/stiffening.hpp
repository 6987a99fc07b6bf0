#pragma once
/// \file
/// \brief `stiffening`: the passive spring hardens with the bending angle.

#include <cmath>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief \f$\tau = -\beta\,\phi^2 K q\f$ on top of \f$-Kq\f$, i.e. the spring becomes
/// \f$-K q (1 + \beta\phi^2)\f$ with \f$\phi^2 = u^2+v^2\f$ (q^2 for a revolute joint).
/// Parameter `beta` (1/rad^2): stiffening near joint limits, as the paper's discussion
/// expects.
struct Stiffening : EffectBase {
  static constexpr const char* name = "stiffening";
  static constexpr const char* param_name = "beta";
  template <class S, class Q, class P, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q& q, const Q&, const P&, Tau& tau) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      S phi2 = S(0);
      for (int k = 0; k < j.nq; ++k) phi2 += q(j.q_offset + k) * q(j.q_offset + k);
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -= S(param(i) * j.stiffness(k)) * phi2 * q(j.q_offset + k);
    }
  }
};

}  // namespace softrne
