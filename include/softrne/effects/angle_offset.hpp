#pragma once
/// \file
/// \brief `angle_offset`: a constant bias in a joint's measured angles.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Measurement model: the sensors report q + b (one b per coordinate of each listed
/// joint; adds b to the measurement offset). The simulation starts from the first measured
/// row with the measurement model inverted. Parameter `offset` (rad), per coordinate only.
struct AngleOffset : Effect<AngleOffset> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "angle_offset";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{
      {{"offset", -0.6, 0.6, false, 0.0, "rad"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 1> scopes{Scope::PerCoordinate};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }

  /// \brief Its part of the measurement model y = gain .* q + offset (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in,out] offset The measurement offsets (size nq); it adds to them.
  void measurement(const std::vector<ArmJoint>& arm, Eigen::VectorXd&,
                   Eigen::VectorXd& offset) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k) offset(j.q_offset + k) += value(arm, i, 0, k);
    }
  }
};

}  // namespace softrne
