#pragma once
/// \file
/// \brief `quadratic_damping`: damping torque grows with the square of the bending rate.

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief \f$\tau_k = -c_2 |\dot q_k| \dot q_k\f$ per coordinate (drag of the chambers' air and
/// of the skin). Parameter `c2` (N m s^2/rad^2).
struct QuadraticDamping : EffectBase {
  static constexpr const char* name = "quadratic_damping";
  static constexpr const char* param_name = "c2";
  template <class S, class Q, class P, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q&, const Q& qd, const P&, Tau& tau) const {
    using std::abs;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k) {
        const S v = qd(j.q_offset + k);
        tau(j.q_offset + k) -= S(param(i)) * abs(v) * v;
      }
    }
  }
};

}  // namespace softrne
