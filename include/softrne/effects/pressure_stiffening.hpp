#pragma once
/// \file
/// \brief `pressure_stiffening`: stiffness grows with the summed chamber pressure.

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Co-contraction stiffens a pneumatic joint: \f$K_{eff} = K(1 + \gamma \sum_k p_k)\f$,
/// so the added force is \f$-\gamma (\sum_k p_k) K q\f$. Parameter `gamma` in 1/MPa (so that
/// typical values are of order one).
struct PressureStiffening : EffectBase {
  static constexpr const char* name = "pressure_stiffening";
  static constexpr const char* param_name = "gamma";
  template <class S, class Q, class P, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q& q, const Q&, const P& p, Tau& tau) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      S sum = S(0);
      for (int c = 0; c < j.num_inputs; ++c) sum += p(j.input_offset + c);
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -= S(param(i) * 1e-6 * j.stiffness(k)) * sum * q(j.q_offset + k);
    }
  }
};

}  // namespace softrne
