#pragma once
/// \file
/// \brief `angle_offset`: a constant bias in a joint's measured angles.

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Measurement model: the sensors report q + b (one b per coordinate of each listed
/// joint). The simulation starts from the first measured row minus b. Parameters `offset`
/// (rad), per coordinate; never shared.
struct AngleOffset : EffectBase {
  static constexpr const char* name = "angle_offset";
  static constexpr const char* param_name = "offset";
  void measurement_offset(const std::vector<ArmJoint>& arm, Eigen::VectorXd& y) const {
    Eigen::Index k = 0;
    for (int jj : joints) {
      const ArmJoint& j = arm[static_cast<std::size_t>(jj)];
      for (int c = 0; c < j.nq; ++c) y(j.q_offset + c) += params(k++);
    }
  }
};

}  // namespace softrne
