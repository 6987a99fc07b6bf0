#pragma once
/// \file
/// \brief `coulomb_friction`: dry friction opposing the bending rate (smoothed).

#include <array>
#include <cmath>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief \f$\tau_k = -F_c \tanh(\dot q_k / v_s)\f$ per coordinate, with the smoothing speed
/// \f$v_s\f$ = `kSmoothingSpeed` (rad/s): a smooth Coulomb law keeps the ODE Lipschitz for the
/// implicit integrator. Parameter `Fc` (N m).
struct CoulombFriction : Effect<CoulombFriction> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "coulomb_friction";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 1> param_info{{{"Fc", 0.0, 5.0, false, 0.0, "N m"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }
  /// v_s, rad/s: the tanh's smoothing speed (see above).
  static constexpr double kSmoothingSpeed = 0.02;
  /// The loosest integrator atol (rad) at which simulations resolve this force (read by
  /// effect_max_atol): its tanh switches within v_s of each velocity reversal. At 1e-5 the
  /// held-out gain of a true Coulomb friction fell from -66 % / -74 % to -35 % / -43 % in
  /// the folds (random arm 1007), and a soft Dahl element was chosen in its place.
  static constexpr double max_atol = 1e-6;

  /// \brief Adds its generalised forces to tau (the hook of EffectBase; eq. 23's right-hand side).
  /// \param[in] arm The arm's joint table.
  /// \param[in] qd Their rates, rad/s.
  /// \param[in,out] tau The generalised forces, N m (rad coordinates); it adds to them.
  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q&, const Qd& qd, const P&, const X&,
                  Tau& tau) const {
    using std::tanh;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -=
            S(value(arm, i, 0, k)) * tanh(qd(j.q_offset + k) * S(1.0 / kSmoothingSpeed));
    }
  }
};

}  // namespace softrne
