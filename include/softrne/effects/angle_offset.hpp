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
  static constexpr const char* name = "angle_offset";
  static constexpr std::array<ParamInfo, 1> param_info{
      {{"offset", -0.6, 0.6, false, 0.0, "rad"}}};
  static constexpr std::array<Scope, 1> scopes{Scope::PerCoordinate};
  static bool applies_to(const ArmJoint&) { return true; }

  void measurement(const std::vector<ArmJoint>& arm, Eigen::VectorXd&,
                   Eigen::VectorXd& offset) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k) offset(j.q_offset + k) += value(arm, i, 0, k);
    }
  }
};

}  // namespace softrne
