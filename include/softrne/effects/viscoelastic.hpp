#pragma once
/// \file
/// \brief `viscoelastic`: a Maxwell branch (spring and damper in series) in parallel with each
/// coordinate's spring, so the passive force relaxes after a step in the bending angle.

#include <array>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief Per coordinate of each listed joint a state z (rad), the displacement of the
/// branch's damper: \f$\dot z = (q - z)/\tau\f$, and the force \f$-k_b (q - z)\f$. Kinds
/// `k` (branch stiffness, N m/rad, neutral 0) and `tau` (relaxation time, s, log scale).
/// After a step in q the force decays as \f$e^{-t/\tau}\f$: an elastomer that creeps.
/// The branch starts relaxed, z = q0. With k = 0 the states still evolve but no force acts,
/// so `tau` has no neutral of its own; its neutral value is a mid-range 0.5 s.
struct Viscoelastic : Effect<Viscoelastic> {
  /// The effect's name in robot files, reports and `--effects`.
  static constexpr const char* name = "viscoelastic";
  /// Its parameter kinds: name, plausible range, log scale, neutral value, unit.
  static constexpr std::array<ParamInfo, 2> param_info{
      {{"k", 0.0, 200.0, false, 0.0, "N m/rad"}, {"tau", 0.02, 20.0, true, 0.5, "s"}}};
  /// The scopes it may have (the closed loop tries each).
  static constexpr std::array<Scope, 3> scopes{Scope::Shared, Scope::PerJoint,
                                               Scope::PerCoordinate};
  /// \brief Which joints it can act on.
  /// \return True: every joint.
  static bool applies_to(const ArmJoint&) { return true; }

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
  /// \param[in] q The coordinates, rad.
  /// \param[in] z Its own states (the elements' lagged angles, rad).
  /// \param[in,out] tau The generalised forces, N m (rad coordinates); it adds to them.
  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q& q, const Qd&, const P&, const X& z,
                  Tau& tau) const {
    int s = 0;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k, ++s)
        tau(j.q_offset + k) -= S(value(arm, i, 0, k)) * (q(j.q_offset + k) - z(s));
    }
  }
  /// \brief Time derivative of its states (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in] z Its own states (the elements' lagged angles, rad).
  /// \param[in] q The coordinates, rad.
  /// \param[out] zd The states' time derivatives.
  template <class S, class X, class Q, class Qd, class P, class Xd>
  void state_derivative(const std::vector<ArmJoint>& arm, const X& z, const Q& q, const Qd&,
                        const P&, Xd& zd) const {
    int s = 0;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      for (int k = 0; k < j.nq; ++k, ++s)
        zd(s) = (q(j.q_offset + k) - z(s)) * S(1.0 / value(arm, i, 1, k));
    }
  }
  /// \brief Its states at the first sample (the hook of EffectBase).
  /// \param[in] arm The arm's joint table.
  /// \param[in] q0 The coordinates at the first sample, rad.
  /// \param[out] z Its own states, set here.
  template <class Q, class P, class X>
  void initial_states(const std::vector<ArmJoint>& arm, const Q& q0, const P&, X& z) const {
    int s = 0;
    for (int jj : joints) {
      const ArmJoint& j = arm[static_cast<std::size_t>(jj)];
      for (int k = 0; k < j.nq; ++k) z(s++) = q0(j.q_offset + k);
    }
  }
};

}  // namespace softrne
