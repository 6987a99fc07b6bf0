#pragma once
/// \file
/// \brief `input_delay`: the recorded pressures act later than they are recorded.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief A pure transport delay d (s) of every pressure channel: the joints feel
/// \f$p(t - d)\f$, clamped to the first sample before the record starts (tubes between the
/// sensor and the chamber, or a logging clock offset). The simulator reads the recorded
/// pressures at t - ArmDescription::input_delay(). Kind `delay` (s, neutral 0), shared only:
/// one delay for the whole arm (the listed joints only say which joints have inputs).
struct InputDelay : Effect<InputDelay> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "input_delay";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{{{"delay", 0.0, 0.5, false, 0.0, "s"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 1> scopes{Scope::Shared};
  /// \brief Which joints it can act on.
  /// \param[in] j A joint of the arm.
  /// \return True if it can act on j.
  static bool applies_to(const ArmJoint& j) { return j.num_inputs > 0; }

  /// \brief The transport delay of the recorded pressures (the hook of EffectBase).
  /// \return s.
  double input_delay() const { return params.size() > 0 ? params(0) : 0.0; }
};

}  // namespace softrne
