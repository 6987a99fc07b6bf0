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
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "quadratic_damping";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{
      {{"c2", 0.0, 50.0, false, 0.0, "N m s^2/rad^2"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }

  /// \brief Adds its generalised forces to tau (the hook of EffectBase; eq. 23's right-hand side).
  /// \param[in] arm The arm's joint table.
  /// \param[in] qd Their rates, rad/s.
  /// \param[in,out] tau The generalised forces, N m (rad coordinates); it adds to them.
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
