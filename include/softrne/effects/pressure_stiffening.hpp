#pragma once
/// \file
/// \brief `pressure_stiffening`: stiffness grows with the summed chamber pressure.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Co-contraction stiffens a pneumatic joint: \f$K_{eff} = K(1 + \gamma \sum_k p_k)\f$,
/// so the added force is \f$-\gamma (\sum_k p_k) K q\f$ with the effective pressures (Pa).
/// Parameter `gamma` in 1/MPa (so that typical values are of order one).
struct PressureStiffening : Effect<PressureStiffening> {
  static constexpr const char* name = "pressure_stiffening";
  static constexpr std::array<ParamInfo, 1> param_info{
      {{"gamma", -5.0, 50.0, false, 0.0, "1/MPa"}}};
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  static bool applies_to(const ArmJoint& j) { return j.num_inputs > 0; }

  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q& q, const Qd&, const P& p, const X&,
                  Tau& tau) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      S sum = S(0);
      for (int c = 0; c < j.num_inputs; ++c) sum += p(j.input_offset + c);
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -=
            S(value(arm, i, 0, k) * 1e-6 * j.stiffness(k)) * sum * q(j.q_offset + k);
    }
  }
};

}  // namespace softrne
