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
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "pressure_stiffening";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{
      {{"gamma", -5.0, 50.0, false, 0.0, "1/MPa"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  /// \brief Which joints it can act on.
  /// \param[in] j A joint of the arm.
  /// \return True if it can act on j.
  static bool applies_to(const ArmJoint& j) { return j.num_inputs > 0; }

  /// \brief Adds its generalised forces to tau (the hook of EffectBase; eq. 23's right-hand side).
  /// \param[in] arm The arm's joint table.
  /// \param[in] q The coordinates, rad.
  /// \param[in] p The effective pressures, Pa.
  /// \param[in,out] tau The generalised forces, N m (rad coordinates); it adds to them.
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
