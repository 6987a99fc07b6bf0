#pragma once
/// \file
/// \brief `hysteresis`: rate-independent hysteresis of the bending, a Dahl friction model.

#include <array>
#include <cmath>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Per coordinate of each listed joint a state F (N m) with the Dahl law
/// \f$\dot F = \sigma(\dot q - |\dot q|_\epsilon F / F_{max})\f$ and the force \f$-F\f$:
/// F follows q with slope \f$\sigma\f$ after a reversal and saturates at \f$\pm F_{max}\f$,
/// tracing a loop that does not depend on the rate (dF/dq depends on the direction only).
/// Kinds `Fmax` (saturation, N m, neutral 0) and `sigma` (Dahl stiffness, N m/rad, log
/// scale; no neutral of its own, mid-range 100).
///
/// Smoothness for BDF: \f$|\dot q|_\epsilon = \sqrt{\dot q^2 + \epsilon^2}\f$ with
/// \f$\epsilon\f$ = `kSmoothingSpeed` = 1e-4 rad/s, smooth at reversals and never below
/// \f$|\dot q|\f$, so \f$|F| \le F_{max}\f$ still holds. The price is a creep of F towards
/// 0 while the arm is at rest, at the relative rate \f$\sigma\epsilon/F_{max}\f$, and a loss
/// of about \f$2\sigma\epsilon^2/|\ddot q|\f$ at each reversal; 1e-4 rad/s keeps both small
/// (a reversal at 0.1 rad/s^2 with sigma = 100 N m/rad loses 2e-5 N m) against the bending
/// rates that matter (0.01 to 1 rad/s). Neutral is exact: with
/// F_max = 0 the law's limit is F = 0, so dF/dt = 0 from F(0) = 0 (no division by zero) and
/// no force acts. F starts at 0 (no memory before the record).
struct Hysteresis : Effect<Hysteresis> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "hysteresis";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 2> param_info{
      {{"Fmax", 0.0, 5.0, false, 0.0, "N m"}, {"sigma", 1.0, 1e4, true, 100.0, "N m/rad"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }
  /// epsilon, rad/s: the smoothing speed of |qdot| (see above).
  static constexpr double kSmoothingSpeed = 1e-4;
  /// As sigma grows, F reaches +-Fmax within a vanishing angle after each reversal: the
  /// element becomes Coulomb friction with Fc = Fmax (kind 0 of both). Data from Coulomb
  /// friction are fitted by a stiff Dahl element about as well, so the loop refits
  /// coulomb_friction beside it and keeps the simpler one unless the Dahl stiffness earns
  /// its parameter (effect_reduces_to).
  static constexpr const char* reduces_to = "coulomb_friction";

  /// \brief Its states (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \return How many states it has on this arm.
  int num_states(const std::vector<ArmJoint>& arm) const {
    int n = 0;
    for (int j : joints) n += arm[static_cast<std::size_t>(j)].nq;
    return n;
  }
  /// \brief Adds its generalised forces to tau (the hook of EffectBase; eq. 23's right-hand side).
  /// \param[in] arm The arm's joint table.
  /// \param[in] F Its own states (the elements' forces, N m).
  /// \param[in,out] tau The generalised forces, N m (rad coordinates); it adds to them.
  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q&, const Qd&, const P&, const X& F,
                  Tau& tau) const {
    int s = 0;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k, ++s) tau(j.q_offset + k) -= F(s);
    }
  }
  /// \brief Time derivative of its states (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in] F Its own states (the elements' forces, N m).
  /// \param[in] qd Their rates, rad/s.
  /// \param[out] Fd The states' time derivatives.
  template <class S, class X, class Q, class Qd, class P, class Xd>
  void state_derivative(const std::vector<ArmJoint>& arm, const X& F, const Q&, const Qd& qd,
                        const P&, Xd& Fd) const {
    using std::sqrt;
    const double eps2 = kSmoothingSpeed * kSmoothingSpeed;
    int s = 0;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k, ++s) {
        const double f_max = value(arm, i, 0, k), sigma = value(arm, i, 1, k);
        if (!(f_max > 0)) {
          Fd(s) = S(0);
          continue;
        }
        const S v = qd(j.q_offset + k);
        Fd(s) = S(sigma) * (v - sqrt(v * v + S(eps2)) * F(s) * S(1.0 / f_max));
      }
    }
  }
  /// \brief Its states at the first sample (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[out] F Its own states, set here.
  template <class Q, class P, class X>
  void initial_states(const std::vector<ArmJoint>& arm, const Q&, const P&, X& F) const {
    for (int s = 0; s < num_states(arm); ++s) F(s) = 0;
  }
};

}  // namespace softrne
