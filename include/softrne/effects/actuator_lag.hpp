#pragma once
/// \file
/// \brief `actuator_lag`: the torque follows the recorded pressure with a first-order lag.

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Each chamber of the listed joints gets a state \f$\bar p\f$ with
/// \f$\dot{\bar p} = (p - \bar p)/T\f$, and \f$\bar p\f$ replaces p in \f$K_{prs}p\f$ (and in
/// every other effect). Parameter `T` (s). Models valve/tube dynamics or pressures that are
/// commanded rather than measured.
struct ActuatorLag : EffectBase {
  static constexpr const char* name = "actuator_lag";
  static constexpr const char* param_name = "T";
  int num_states(const std::vector<ArmJoint>& arm) const {
    int n = 0;
    for (int j : joints) n += arm[static_cast<std::size_t>(j)].num_inputs;
    return n;
  }
  template <class S, class X, class P>
  void effective_pressures(const std::vector<ArmJoint>& arm, const X& x, P& p) const {
    int s = 0;
    for (int jj : joints) {
      const ArmJoint& j = arm[static_cast<std::size_t>(jj)];
      for (int c = 0; c < j.num_inputs; ++c) p(j.input_offset + c) = x(s++);
    }
  }
  template <class S, class X, class P, class Xd>
  void state_derivative(const std::vector<ArmJoint>& arm, const X& x, const P& p, Xd& xd) const {
    int s = 0;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      const double inv_T = 1.0 / param(i);
      for (int c = 0; c < j.num_inputs; ++c, ++s) xd(s) = (p(j.input_offset + c) - x(s)) * S(inv_T);
    }
  }
  template <class X, class P>
  void initial_states(const std::vector<ArmJoint>& arm, const P& p, X& x) const {
    int s = 0;
    for (int jj : joints) {
      const ArmJoint& j = arm[static_cast<std::size_t>(jj)];
      for (int c = 0; c < j.num_inputs; ++c) x(s++) = p(j.input_offset + c);
    }
  }
};

}  // namespace softrne
