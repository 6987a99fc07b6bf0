#pragma once
/// \file
/// \brief `stiffening`: the passive spring hardens with the bending angle.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief \f$\tau = -\beta\,\phi^2 K q\f$ on top of \f$-Kq\f$, i.e. the spring becomes
/// \f$-K q (1 + \beta\phi^2)\f$ with \f$\phi^2 = u^2+v^2\f$ (q^2 for a revolute joint).
/// Parameter `beta` (1/rad^2): stiffening near joint limits, as the paper's discussion
/// expects. Per coordinate, \f$\beta_k\f$ multiplies coordinate k's spring.
struct Stiffening : Effect<Stiffening> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "stiffening";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{
      {{"beta", -1.0, 20.0, false, 0.0, "1/rad^2"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }

  /// \brief Adds its generalised forces to tau (the hook of EffectBase; eq. 23's right-hand side).
  /// \param[in] arm The arm's joint table.
  /// \param[in] q The coordinates, rad.
  /// \param[in,out] tau The generalised forces, N m (rad coordinates); it adds to them.
  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q& q, const Qd&, const P&, const X&,
                  Tau& tau) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      S phi2 = S(0);
      for (int k = 0; k < j.nq; ++k) phi2 += q(j.q_offset + k) * q(j.q_offset + k);
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -= S(value(arm, i, 0, k) * j.stiffness(k)) * phi2 * q(j.q_offset + k);
    }
  }
};

}  // namespace softrne
