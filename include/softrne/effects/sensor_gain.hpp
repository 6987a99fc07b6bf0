#pragma once
/// \file
/// \brief `sensor_gain`: the angle sensors read a scaled angle.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Measurement model: the sensors report s q (s dimensionless, neutral 1) per
/// coordinate of each listed joint (multiplies the measurement gain; an angle_offset b adds
/// to it: y = s q + b). A miscalibrated encoder or a tracker mounted off the arc's end. The
/// simulation starts from the first measured row with the measurement model inverted.
struct SensorGain : Effect<SensorGain> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "sensor_gain";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{{{"gain", 0.5, 1.5, false, 1.0, "1"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }

  /// \brief Its part of the measurement model y = gain .* q + offset (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in,out] gain The measurement gains (size nq); it multiplies them.
  void measurement(const std::vector<ArmJoint>& arm, Eigen::VectorXd& gain,
                   Eigen::VectorXd&) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k) gain(j.q_offset + k) *= value(arm, i, 0, k);
    }
  }
};

}  // namespace softrne
