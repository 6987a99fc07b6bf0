#pragma once
/// \file
/// \brief `payload`: an unmodelled point mass at the tip.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief A point mass at the distal frame of the last segment. It is added to the chain as
/// a rigid body (ArmDescription::make_chain), so it goes through the RNE (inertia, Coriolis
/// and gravity), not as a torque approximation. Parameter `mass` (kg), shared; its plausible
/// range is up to 3 kg per kg of the arm's declared mass. The listed joints are not used.
struct Payload : Effect<Payload> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "payload";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{
      {{"mass", 0.0, 3.0, false, 0.0, "kg", /*per_arm_mass=*/true}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 1> scopes{Scope::Shared};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }

  /// \brief The point mass it adds at the tip (the hook of EffectBase).
  /// \return kg.
  double tip_mass() const { return params.size() > 0 ? params(0) : 0.0; }
};

}  // namespace softrne
