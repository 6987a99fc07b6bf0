#pragma once
/// \file
/// \brief `chamber_gain`: a chamber's pressure acts more or less than declared.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief The effective pressure of each chamber of the listed joints is scaled,
/// \f$p_c \to g_c\,p_c\f$, before it drives the joint (and every other effect): a chamber
/// whose area, wall stiffness or sensor calibration differs from the declaration, or a leak.
/// Kind `gain` (dimensionless, neutral 1), per chamber (or one per joint, or shared). It
/// commutes with actuator_lag (both linear), which ArmDynamics applies first.
struct ChamberGain : Effect<ChamberGain> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "chamber_gain";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{{{"gain", 0.05, 2.0, false, 1.0, "1"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint, Scope::PerChamber};
  /// \brief Which joints it can act on.
  /// \param[in] j A joint of the arm.
  /// \return True if it can act on j.
  static bool applies_to(const ArmJoint& j) { return j.num_inputs > 0; }

  /// \brief Changes the pressures that drive the joints (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in,out] p The pressures, Pa: recorded on entry, effective on return.
  template <class S, class X, class P>
  void effective_pressures(const std::vector<ArmJoint>& arm, const X&, P& p) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int c = 0; c < j.num_inputs; ++c) p(j.input_offset + c) *= S(value(arm, i, 0, c));
    }
  }
};

}  // namespace softrne
