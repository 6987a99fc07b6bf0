#pragma once
/// \file
/// \brief `chamber_misalignment`: the chamber layout is rotated about the joint axis.

#include <array>
#include <cmath>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief The pressure torque of a CC joint is rotated by \f$\psi\f$ about the joint axis:
/// \f$\tau = R(\psi) K_{prs} p\f$ with the planar rotation R; the effect adds
/// \f$(R(\psi) - 1) K_{prs} p\f$ (effective pressures). Parameter `psi` (rad).
struct ChamberMisalignment : Effect<ChamberMisalignment> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "chamber_misalignment";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{{{"psi", -1.5, 1.5, false, 0.0, "rad"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 2> scopes{Scope::Shared, Scope::PerJoint};
  /// \brief Which joints it can act on.
  /// \param[in] j A joint of the arm.
  /// \return True if it can act on j.
  static bool applies_to(const ArmJoint& j) { return j.is_cc() && j.num_inputs > 0; }

  /// \brief Adds its generalised forces to tau (the hook of EffectBase; eq. 23's right-hand side).
  /// \param[in] arm The arm's joint table.
  /// \param[in] p The effective pressures, Pa.
  /// \param[in,out] tau The generalised forces, N m (rad coordinates); it adds to them.
  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q&, const Qd&, const P& p, const X&,
                  Tau& tau) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      if (!j.is_cc()) continue;
      S tu = S(0), tv = S(0);
      for (int c = 0; c < j.num_inputs; ++c) {
        tu += S(j.pressure_to_torque(0, c)) * p(j.input_offset + c);
        tv += S(j.pressure_to_torque(1, c)) * p(j.input_offset + c);
      }
      const double psi = value(arm, i);
      const double c = std::cos(psi) - 1.0, s = std::sin(psi);
      tau(j.q_offset) += S(c) * tu - S(s) * tv;
      tau(j.q_offset + 1) += S(s) * tu + S(c) * tv;
    }
  }
};

}  // namespace softrne
