#pragma once
/// \file
/// \brief From joint torques to chamber pressures (feed-forward control): the non-negative
/// allocation with the least pressure over antagonistic chambers, plus a common bias.

#include <algorithm>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

namespace softrne {

/// \brief Chamber pressures p >= 0 with \f$K_{prs}\,p = \tau\f$ for one CC joint whose chambers
/// each push one coordinate one way (eq. 24: \f$\tau_u = dA(p_0 - p_1)\f$,
/// \f$\tau_v = dA(p_2 - p_3)\f$): per coordinate, \f$|\tau|/k\f$ goes into the chamber that
/// pushes its way and the opposite one is vented, on top of a common bias (co-contraction,
/// which stiffens nothing in eq. 23 but leaves a feedback room to push both ways). The bias of
/// a pair is balanced by the chambers' arms, so it adds no torque. Allocates nothing.
/// \param[in] K_prs The joint's pressure map, 2 x nc, N m/Pa.
/// \param[in] tau The torques (tau_u, tau_v) the chambers must produce, N m.
/// \param[in] bias The pressure left in every chamber, Pa (>= 0).
/// \param[out] p The nc chamber pressures, Pa.
/// \throws std::invalid_argument if a coordinate has no chamber pushing each way, or a chamber
///   pushes both coordinates (the map is not of the antagonistic kind).
template <class K, class Tau, class P>
void antagonistic_pressures(const K& K_prs, const Tau& tau, double bias, P&& p) {
  p.setConstant(bias);
  for (Eigen::Index r = 0; r < 2; ++r) {
    Eigen::Index up = 0, down = 0;
    K_prs.row(r).maxCoeff(&up);
    K_prs.row(r).minCoeff(&down);
    const double k_up = K_prs(r, up), k_down = -K_prs(r, down);
    if (!(k_up > 0 && k_down > 0) || K_prs(1 - r, up) != 0 || K_prs(1 - r, down) != 0)
      throw std::invalid_argument(
          "antagonistic_pressures: the pressure map has no pair of chambers that push coordinate " +
          std::to_string(r) + " each way and nothing else");
    p(up) = bias + std::max(tau(r), 0.0) / k_up;
    p(down) = bias * k_up / k_down + std::max(-tau(r), 0.0) / k_down;
  }
}

}  // namespace softrne
