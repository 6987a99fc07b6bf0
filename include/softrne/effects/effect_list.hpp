#pragma once
/// \file
/// \brief The one place that lists every effect type.

#include <string>
#include <variant>
#include <vector>

#include "softrne/effects/actuator_lag.hpp"
#include "softrne/effects/angle_offset.hpp"
#include "softrne/effects/chamber_misalignment.hpp"
#include "softrne/effects/coulomb_friction.hpp"
#include "softrne/effects/payload.hpp"
#include "softrne/effects/pressure_stiffening.hpp"
#include "softrne/effects/quadratic_damping.hpp"
#include "softrne/effects/stiffening.hpp"

namespace softrne {

using AnyEffect = std::variant<Stiffening, PressureStiffening, ActuatorLag, CoulombFriction,
                               QuadraticDamping, ChamberMisalignment, Payload, AngleOffset>;

/// \brief Names of all effects, in the order of AnyEffect.
inline std::vector<std::string> effect_names() {
  return {Stiffening::name,      PressureStiffening::name, ActuatorLag::name,
          CoulombFriction::name, QuadraticDamping::name,   ChamberMisalignment::name,
          Payload::name,         AngleOffset::name};
}

/// \brief A default-constructed effect of the given name; false if the name is unknown.
inline bool make_effect(const std::string& name, AnyEffect& out) {
  bool found = false;
  auto try_one = [&](auto tag) {
    using E = decltype(tag);
    if (!found && name == E::name) {
      out = E{};
      found = true;
    }
  };
  try_one(Stiffening{});
  try_one(PressureStiffening{});
  try_one(ActuatorLag{});
  try_one(CoulombFriction{});
  try_one(QuadraticDamping{});
  try_one(ChamberMisalignment{});
  try_one(Payload{});
  try_one(AngleOffset{});
  return found;
}

/// \brief Name of the effect held.
inline std::string effect_name(const AnyEffect& e) {
  return std::visit([](const auto& x) { return std::string(std::decay_t<decltype(x)>::name); }, e);
}

/// \brief The common part (joints, shared, params) of the effect held.
inline EffectBase& effect_base(AnyEffect& e) {
  return std::visit([](auto& x) -> EffectBase& { return x; }, e);
}
inline const EffectBase& effect_base(const AnyEffect& e) {
  return std::visit([](const auto& x) -> const EffectBase& { return x; }, e);
}

}  // namespace softrne
