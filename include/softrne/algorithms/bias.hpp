#pragma once
/// \file
/// \brief Gravity G(q) and velocity-product forces C(q, qdot) qdot (paper section III-D).

#include <Eigen/Core>

#include "softrne/algorithms/kinematics.hpp"
#include "softrne/algorithms/rnea.hpp"

namespace softrne {

/// \brief G(q): the RNE with qdot = qddot = 0 (section III-D). \return data.gravity_forces
template <class ChainT, class Q>
const typename ChainT::VectorQ& gravity(const ChainT& chain, typename ChainT::Data& data,
                                        const Eigen::MatrixBase<Q>& q) {
  detail::check_argument(chain, "gravity", "q", q);
  data.qdot_zero.setZero();
  compute_kinematics(chain, data, q, data.qdot_zero);
  detail::rnea_passes(chain, data, data.qdot_zero, data.qdot_zero, true, false,
                      data.gravity_forces);
  return data.gravity_forces;
}

/// \brief C(q, qdot) qdot (with_gravity = false, the paper's definition: qddot = g = 0) or
/// C qdot + G (with_gravity = true, one pass instead of two). \return data.bias_forces
template <class ChainT, class Q, class Qd>
const typename ChainT::VectorQ& bias(const ChainT& chain, typename ChainT::Data& data,
                                     const Eigen::MatrixBase<Q>& q,
                                     const Eigen::MatrixBase<Qd>& qdot, bool with_gravity = false) {
  detail::check_argument(chain, "bias", "q", q);
  detail::check_argument(chain, "bias", "qdot", qdot);
  compute_kinematics(chain, data, q, qdot);
  data.qdot_zero.setZero();
  detail::rnea_passes(chain, data, qdot, data.qdot_zero, with_gravity, true, data.bias_forces);
  return data.bias_forces;
}

}  // namespace softrne
