#pragma once
/// \file
/// \brief `mass_scale`: the declared masses and inertias are wrong by a factor.

#include <array>
#include <cstddef>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief The masses and inertias of segments are s times the declared ones (dimensionless,
/// neutral 1, log scale): weighed parts that miss the air hoses, the skin or the fittings.
/// Shared: every segment of the chain. Per joint: the joint's own segment and the rigid
/// links that follow it up to the next joint (a revolute joint is massless, so only its
/// links). Applied by ArmDescription::make_chain, so it goes through the RNE (inertia,
/// Coriolis and gravity); a CC joint's inertia follows its mass.
struct MassScale : Effect<MassScale> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "mass_scale";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{{{"scale", 0.3, 3.0, true, 1.0, "1"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 2> scopes{Scope::Shared, Scope::PerJoint};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }

  /// \brief Multiplies the masses and inertias of the segments it acts on (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in,out] segment One mass factor per segment; it multiplies them.
  void mass_scale(const std::vector<ArmJoint>& arm, std::vector<double>& segment) const {
    if (scope == Scope::Shared) {
      for (double& s : segment) s *= params(0);
      return;
    }
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const std::size_t ji = static_cast<std::size_t>(joints[i]);
      const std::size_t end = ji + 1 < arm.size() ? static_cast<std::size_t>(arm[ji + 1].segment)
                                                  : segment.size();
      for (std::size_t s = static_cast<std::size_t>(arm[ji].segment); s < end; ++s)
        segment[s] *= value(arm, i);
    }
  }
};

}  // namespace softrne
