#pragma once
/// \file
/// \brief `actuator_lag`: the torque follows the recorded pressure with a first-order lag.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Each chamber of the listed joints gets a state \f$\bar p\f$ (Pa) with
/// \f$\dot{\bar p} = (p - \bar p)/T\f$, and \f$\bar p\f$ replaces p in \f$K_{prs}p\f$ (and in
/// every other effect). Parameter `T` (s). Models valve/tube dynamics or pressures that are
/// commanded rather than measured. T = 0 is singular, so the neutral value is the lower
/// bound, 1 ms: practically no lag at the arm's bandwidth (a few Hz). The states start at
/// the first recorded pressures.
struct ActuatorLag : Effect<ActuatorLag> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "actuator_lag";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{{{"T", 1e-3, 2.0, true, 1e-3, "s"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint, Scope::PerChamber};
  /// \brief Which joints it can act on.
  /// \param[in] j A joint of the arm.
  /// \return True if it can act on j.
  static bool applies_to(const ArmJoint& j) { return j.num_inputs > 0; }
  /// Its effective pressures replace the recorded ones (applied before the others).
  static constexpr bool replaces_pressures = true;

  /// \brief Its states (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \return How many states it has on this arm.
  int num_states(const std::vector<ArmJoint>& arm) const {
    int n = 0;
    for (int j : joints) n += arm[static_cast<std::size_t>(j)].num_inputs;
    return n;
  }
  /// \brief Changes the pressures that drive the joints (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in] x Its own slice of the effect states.
  /// \param[in,out] p The pressures, Pa: recorded on entry, effective on return.
  template <class S, class X, class P>
  void effective_pressures(const std::vector<ArmJoint>& arm, const X& x, P& p) const {
    int s = 0;
    for (int jj : joints) {
      const ArmJoint& j = arm[static_cast<std::size_t>(jj)];
      for (int c = 0; c < j.num_inputs; ++c) p(j.input_offset + c) = x(s++);
    }
  }
  /// \brief Time derivative of its states (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in] x Its own slice of the effect states.
  /// \param[in] p The recorded pressures, Pa.
  /// \param[out] xd The states' time derivatives.
  template <class S, class X, class Q, class Qd, class P, class Xd>
  void state_derivative(const std::vector<ArmJoint>& arm, const X& x, const Q&, const Qd&,
                        const P& p, Xd& xd) const {
    int s = 0;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int c = 0; c < j.num_inputs; ++c, ++s)
        xd(s) = (p(j.input_offset + c) - x(s)) * S(1.0 / value(arm, i, 0, c));
    }
  }
  /// \brief Its states at the first sample (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in] p The recorded pressures at the first sample, Pa.
  /// \param[out] x Its own states, set here.
  template <class Q, class P, class X>
  void initial_states(const std::vector<ArmJoint>& arm, const Q&, const P& p, X& x) const {
    int s = 0;
    for (int jj : joints) {
      const ArmJoint& j = arm[static_cast<std::size_t>(jj)];
      for (int c = 0; c < j.num_inputs; ++c) x(s++) = p(j.input_offset + c);
    }
  }
};

}  // namespace softrne
