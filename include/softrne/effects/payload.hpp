#pragma once
/// \file
/// \brief `payload`: an unmodelled point mass at the tip.

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief A point mass at the distal frame of the last segment. It is added to the chain as
/// a rigid body, so it goes through the RNE (inertia, Coriolis and gravity), not as a torque
/// approximation. Parameter `mass` (kg), shared.
struct Payload : EffectBase {
  static constexpr const char* name = "payload";
  static constexpr const char* param_name = "mass";
  double tip_mass() const { return params(0); }
};

}  // namespace softrne
