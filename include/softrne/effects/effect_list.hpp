#pragma once
/// \file
/// \brief The one place that lists every effect type, and the functions that enumerate them.
/// What an effect is (its parameters, scopes, joints) is read from its own header by
/// effect_info.hpp.

#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "softrne/effects/actuator_lag.hpp"
#include "softrne/effects/angle_offset.hpp"
#include "softrne/effects/chamber_gain.hpp"
#include "softrne/effects/chamber_misalignment.hpp"
#include "softrne/effects/coulomb_friction.hpp"
#include "softrne/effects/hysteresis.hpp"
#include "softrne/effects/input_delay.hpp"
#include "softrne/effects/mass_scale.hpp"
#include "softrne/effects/payload.hpp"
#include "softrne/effects/pressure_stiffening.hpp"
#include "softrne/effects/quadratic_damping.hpp"
#include "softrne/effects/sensor_gain.hpp"
#include "softrne/effects/stiffening.hpp"
#include "softrne/effects/viscoelastic.hpp"

namespace softrne {

/// \brief Any effect: the one list of effect types (a new effect is added here and in its own
/// header only).
using AnyEffect =
    std::variant<Stiffening, PressureStiffening, ActuatorLag, CoulombFriction, QuadraticDamping,
                 ChamberMisalignment, Payload, AngleOffset, Viscoelastic, ChamberGain, InputDelay,
                 Hysteresis, MassScale, SensorGain>;

namespace detail {
template <class F, std::size_t... I>
void for_each_effect_type(F&& f, std::index_sequence<I...>) {
  (f(std::variant_alternative_t<I, AnyEffect>{}), ...);
}
}  // namespace detail

/// \brief Calls f(E{}) for every effect type E, in the order of AnyEffect.
/// \param[in] f A generic callable taking an effect by value.
template <class F>
void for_each_effect_type(F&& f) {
  detail::for_each_effect_type(f, std::make_index_sequence<std::variant_size_v<AnyEffect>>{});
}

/// \brief Names of all effects, in the order of AnyEffect.
/// \return The names ("stiffening", ...).
inline std::vector<std::string> effect_names() {
  std::vector<std::string> names;
  for_each_effect_type([&](auto tag) { names.push_back(decltype(tag)::name); });
  return names;
}

/// \brief A default-constructed effect of the given name; false if the name is unknown.
/// \param[in] name An effect's name.
/// \param[out] out The effect (unchanged if the name is unknown).
/// \return True if the name is known.
inline bool make_effect(const std::string& name, AnyEffect& out) {
  bool found = false;
  for_each_effect_type([&](auto tag) {
    using E = decltype(tag);
    if (!found && name == E::name) {
      out = E{};
      found = true;
    }
  });
  return found;
}

/// \brief Name of the effect held.
/// \param[in] e An effect.
/// \return Its type's name.
inline std::string effect_name(const AnyEffect& e) {
  return std::visit([](const auto& x) { return std::string(std::decay_t<decltype(x)>::name); }, e);
}

/// \brief The common part (joints, scope, params) of the effect held.
/// \param[in] e An effect.
/// \return Its EffectBase, to change.
inline EffectBase& effect_base(AnyEffect& e) {
  return std::visit([](auto& x) -> EffectBase& { return x; }, e);
}
/// \brief The common part (joints, scope, params) of the effect held.
/// \param[in] e An effect.
/// \return Its EffectBase.
inline const EffectBase& effect_base(const AnyEffect& e) {
  return std::visit([](const auto& x) -> const EffectBase& { return x; }, e);
}

}  // namespace softrne
