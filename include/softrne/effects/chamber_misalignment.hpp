#pragma once
/// \file
/// \brief `chamber_misalignment`: the chamber layout is rotated about the joint axis.

#include <array>
#include <cmath>

#include "softrne/effects/effect_base.hpp"

namespace softrne {

/// \brief The pressure torque of a CC joint is rotated by \f$\psi\f$ about the joint axis:
/// \f$\tau = R(\psi) K_{prs} p\f$ with the planar rotation R; the effect adds
/// \f$(R(\psi) - 1) K_{prs} p\f$ (effective pressures). Parameter `psi` (rad).
struct ChamberMisalignment : Effect<ChamberMisalignment> {
  static constexpr const char* name = "chamber_misalignment";
  static constexpr std::array<ParamInfo, 1> param_info{{{"psi", -1.5, 1.5, false, 0.0, "rad"}}};
  static constexpr std::array<Scope, 2> scopes{Scope::Shared, Scope::PerJoint};
  static bool applies_to(const ArmJoint& j) { return j.is_cc() && j.num_inputs > 0; }

  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>& arm, const Q&, const Qd&, const P& p, const X&,
                  Tau& tau) const {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const ArmJoint& j = arm[static_cast<std::size_t>(joints[i])];
      if (!j.is_cc()) continue;
      S tu = S(0), tv = S(0);
      for (int c = 0; c < j.num_inputs; ++c) {
        tu += S(j.pressure_to_torque(0, c)) * p(j.input_offset + c);
        tv += S(j.pressure_to_torque(1, c)) * p(j.input_offset + c);
      }
      const double psi = value(arm, i);
      const double c = std::cos(psi) - 1.0, s = std::sin(psi);
      tau(j.q_offset) += S(c) * tu - S(s) * tv;
      tau(j.q_offset + 1) += S(s) * tu + S(c) * tv;
    }
  }
};

}  // namespace softrne
