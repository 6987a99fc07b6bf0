#pragma once
/// \file
/// \brief `quadratic_damping`: damping torque grows with the square of the bending rate.

#include <array>
#include <cmath>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief \f$\tau_k = -c_2 |\dot q_k| \dot q_k\f$ per coordinate (drag of the chambers' air and
/// of the skin). Parameter `c2` (N m s^2/rad^2).
struct QuadraticDamping : Effect<QuadraticDamping> {
  static constexpr const char* name = "quadratic_damping";
  static constexpr std::array<ParamInfo, 1> param_info{
      {{"c2", 0.0, 50.0, false, 0.0, "N m s^2/rad^2"}}};
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  static bool applies_to(const ArmJoint&) { return true; }

  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q&, const Qd& qd, const P&, const X&,
                  Tau& tau) const {
    using std::abs;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k) {
        const S v = qd(j.q_offset + k);
        tau(j.q_offset + k) -= S(value(arm, i, 0, k)) * abs(v) * v;
      }
    }
  }
};

}  // namespace softrne
