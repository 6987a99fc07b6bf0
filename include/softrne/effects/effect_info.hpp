#pragma once
/// \file
/// \brief Generic readers of the effects' self-description (each effect's header): allowed
/// scopes, parameter kinds, names, bounds. Used by the model, the fitter, the closed loop and
/// the robot-file reader, so none of them lists effect-specific numbers.

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "softrne/effects/effect_list.hpp"

namespace softrne {

/// \brief The scopes the effect's parameters may have.
/// \param[in] e An effect.
/// \return Its type's `scopes`.
inline std::vector<Scope> effect_scopes(const AnyEffect& e) {
  return std::visit(
      [](const auto& x) {
        using E = std::decay_t<decltype(x)>;
        return std::vector<Scope>(E::scopes.begin(), E::scopes.end());
      },
      e);
}

/// \brief Whether `s` is one of the effect's allowed scopes.
/// \param[in] e An effect.
/// \param[in] s A scope.
/// \return True if e's type allows s.
inline bool effect_scope_allowed(const AnyEffect& e, Scope s) {
  const auto scopes = effect_scopes(e);
  return std::find(scopes.begin(), scopes.end(), s) != scopes.end();
}

/// \brief Whether the effect can act on joint j (e.g. pressure effects need chambers).
/// \param[in] e An effect.
/// \param[in] j A joint of the arm.
/// \return Its type's applies_to(j).
inline bool effect_applies_to(const AnyEffect& e, const ArmJoint& j) {
  return std::visit([&](const auto& x) { return std::decay_t<decltype(x)>::applies_to(j); }, e);
}

namespace detail {
template <class E, class = void>
struct HasReducesTo : std::false_type {};
template <class E>
struct HasReducesTo<E, std::void_t<decltype(E::reduces_to)>> : std::true_type {};
}  // namespace detail

/// \brief The name of the simpler effect this one contains as a limit (its header's
/// `reduces_to`: the simpler effect's kinds are this one's first kinds, the others go to a
/// limit), or "" if none. The closed loop refits the simpler one beside it, so parsimony can
/// choose.
/// \param[in] e An effect.
/// \return The simpler effect's name, or "".
inline std::string effect_reduces_to(const AnyEffect& e) {
  return std::visit(
      [](const auto& x) -> std::string {
        using E = std::decay_t<decltype(x)>;
        if constexpr (detail::HasReducesTo<E>::value) return E::reduces_to;
        else return {};
      },
      e);
}

namespace detail {
template <class E, class = void>
struct HasMaxAtol : std::false_type {};
template <class E>
struct HasMaxAtol<E, std::void_t<decltype(E::max_atol)>> : std::true_type {};
}  // namespace detail

/// \brief The loosest integrator atol at which the effect's force is resolved (its header's
/// `max_atol`: a sharp feature such as smoothed Coulomb friction), or +infinity if it sets
/// none. fit::simulate_dataset integrates no looser than its model's effects require.
/// \param[in] e An effect.
/// \return The absolute tolerance, rad (or +infinity).
inline double effect_max_atol(const AnyEffect& e) {
  return std::visit(
      [](const auto& x) -> double {
        using E = std::decay_t<decltype(x)>;
        if constexpr (detail::HasMaxAtol<E>::value) return E::max_atol;
        else return std::numeric_limits<double>::infinity();
      },
      e);
}

/// \brief Number of parameter kinds per unit (2 for viscoelastic: k and tau).
/// \param[in] e An effect.
/// \return The size of its type's param_info.
inline int effect_num_kinds(const AnyEffect& e) {
  return std::visit(
      [](const auto& x) { return static_cast<int>(std::decay_t<decltype(x)>::param_info.size()); },
      e);
}

/// \brief The parameters of `simpler`, the effect `rich` reduces to (effect_reduces_to) on the
/// same scope and joints, taken from `rich`'s: per unit, `rich`'s first kinds (the layout is
/// `params(unit * num_kinds + kind)`, effect_base.hpp).
/// \param[in] rich The richer effect, fitted.
/// \param[in] simpler The simpler effect (its name is effect_reduces_to(rich)).
/// \return The simpler effect's params.
/// \throws std::invalid_argument if rich does not reduce to simpler.
inline Eigen::VectorXd effect_reduced_params(const AnyEffect& rich, const AnyEffect& simpler) {
  if (effect_reduces_to(rich) != effect_name(simpler))
    throw std::invalid_argument("effect_reduced_params: '" + effect_name(rich) + "' does not reduce to '" +
                                effect_name(simpler) + "'");
  const int kr = effect_num_kinds(rich), ks = effect_num_kinds(simpler);
  const Eigen::VectorXd& p = effect_base(rich).params;
  const Eigen::Index units = p.size() / kr;
  Eigen::VectorXd out(units * ks);
  for (Eigen::Index u = 0; u < units; ++u) out.segment(u * ks, ks) = p.segment(u * kr, ks);
  return out;
}

/// \brief Description of parameter kind `kind`.
/// \param[in] e An effect.
/// \param[in] kind Index of the kind (0 <= kind < effect_num_kinds(e)).
/// \return Its name, range, scale, neutral value and unit.
inline ParamInfo effect_param_info(const AnyEffect& e, int kind) {
  return std::visit(
      [&](const auto& x) {
        return std::decay_t<decltype(x)>::param_info[static_cast<std::size_t>(kind)];
      },
      e);
}

/// \brief Number of parameters of an effect (by its scope and listed joints).
/// \param[in] e An effect.
/// \param[in] joints The arm's joint table.
/// \return The size its params must have.
inline int effect_num_params(const AnyEffect& e, const std::vector<ArmJoint>& joints) {
  return effect_base(e).num_units(joints) * effect_num_kinds(e);
}

/// \brief The suffixes that name the units of `scope` on the listed joints: "" (shared),
/// ".joint2" (joint name), ".u1" (coordinate name), ".p1_2" (pressure channel name).
/// \param[in] listed The indices of the listed joints in `joints`.
/// \param[in] scope The effect's scope.
/// \param[in] joints The arm's joint table.
/// \param[in] coordinate_names Names of the arm's coordinates (u1, v1, ...).
/// \param[in] pressure_names Names of the arm's pressure columns (p1_0, ...).
/// \return One suffix per unit.
inline std::vector<std::string> effect_unit_suffixes(
    const std::vector<int>& listed, Scope scope, const std::vector<ArmJoint>& joints,
    const std::vector<std::string>& coordinate_names,
    const std::vector<std::string>& pressure_names) {
  std::vector<std::string> out;
  if (scope == Scope::Shared) return {""};
  for (int ji : listed) {
    const ArmJoint& j = joints[static_cast<std::size_t>(ji)];
    if (scope == Scope::PerJoint) {
      out.push_back("." + j.name);
    } else if (scope == Scope::PerCoordinate) {
      for (int k = 0; k < j.nq; ++k)
        out.push_back("." + coordinate_names[static_cast<std::size_t>(j.q_offset + k)]);
    } else {
      for (int c = 0; c < j.num_inputs; ++c)
        out.push_back("." + pressure_names[static_cast<std::size_t>(j.input_offset + c)]);
    }
  }
  return out;
}

/// \brief Names of an effect's parameters, in the order of its `params` (formats.md section
/// 4): the kind name plus the unit's suffix, e.g. `beta`, `beta.joint2`, `offset.u1`,
/// `gain.p1_2`, and for several kinds `k.joint1`, `tau.joint1`, `k.joint2`, ...
/// \param[in] e An effect.
/// \param[in] joints The arm's joint table.
/// \param[in] coordinate_names Names of the arm's coordinates.
/// \param[in] pressure_names Names of the arm's pressure columns.
/// \return One name per entry of its params.
inline std::vector<std::string> effect_param_names(const AnyEffect& e,
                                                   const std::vector<ArmJoint>& joints,
                                                   const std::vector<std::string>& coordinate_names,
                                                   const std::vector<std::string>& pressure_names) {
  const EffectBase& b = effect_base(e);
  const int nk = effect_num_kinds(e);
  std::vector<std::string> names;
  for (const std::string& suffix :
       effect_unit_suffixes(b.joints, b.scope, joints, coordinate_names, pressure_names))
    for (int k = 0; k < nk; ++k) names.push_back(effect_param_info(e, k).name + suffix);
  return names;
}

/// \brief Search range, scale and neutral value of one parameter.
struct EffectBounds {
  double lower, upper;
  /// \var lower
  /// \brief Smallest value the fit tries.
  /// \var upper
  /// \brief Largest value the fit tries.
  bool log_scale;  ///< the fit searches log(value)
  double neutral;  ///< the value at which the effect does nothing
};

/// \brief Bounds of params(param_index), from the effect's ParamInfo; ranges marked
/// per_arm_mass are multiplied by `arm_mass` (kg, the declared segments' mass).
/// \param[in] e An effect.
/// \param[in] param_index Index into its params.
/// \param[in] arm_mass The declared segments' mass, kg.
/// \return The parameter's search range, scale and neutral value.
inline EffectBounds effect_param_bounds(const AnyEffect& e, int param_index, double arm_mass) {
  const ParamInfo info = effect_param_info(e, param_index % effect_num_kinds(e));
  const double f = info.per_arm_mass ? arm_mass : 1.0;
  return {info.lower * f, info.upper * f, info.log_scale, info.neutral};
}

}  // namespace softrne
