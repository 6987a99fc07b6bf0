#pragma once
/// \file
/// \brief Gravity G(q) and velocity-product forces C(q, qdot) qdot (paper section III-D).

#include <Eigen/Core>

#include "softrne/algorithms/kinematics.hpp"
#include "softrne/algorithms/rnea.hpp"

namespace softrne {

/// \brief The gravity forces G(q) of eq. 23: the RNE with qdot = qddot = 0 (paper section
/// III-D).
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model: its segments and gravity (base frame).
/// \param[in,out] data Its workspace, made by chain.make_data().
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \return G(q), stored in data.gravity_forces.
/// \throws std::invalid_argument (DynamicChain only) if q has another size than the chain or
///   data was made for another chain.
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

/// \brief The velocity-product forces C(q, qdot) qdot of eq. 23: the RNE with qddot = g = 0
/// (paper section III-D), or C qdot + G in one pass instead of two.
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model: its segments, gravity and inertia_rate.
/// \param[in,out] data Its workspace, made by chain.make_data().
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \param[in] qdot Their rates (dim chain.num_coordinates()).
/// \param[in] with_gravity false: C qdot (the paper's definition); true: C qdot + G.
/// \return C qdot (or C qdot + G), stored in data.bias_forces.
/// \throws std::invalid_argument (DynamicChain only) if q or qdot has another size than the
///   chain or data was made for another chain.
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

namespace detail {

/// \brief C(q, qdot) qdot + G(q) into data.nonlinear_forces, leaving data's kinematics at
/// (q, qdot): the first half of the forward dynamics (eq. 23), shared by
/// mass_matrix_and_bias(), aba() and aba_derivatives().
template <class ChainT, class Q, class Qd>
void kinematics_and_nonlinear_forces(const ChainT& chain, typename ChainT::Data& data,
                                     const Eigen::MatrixBase<Q>& q,
                                     const Eigen::MatrixBase<Qd>& qdot) {
  compute_kinematics(chain, data, q, qdot);
  data.qdot_zero.setZero();
  rnea_passes(chain, data, qdot, data.qdot_zero, true, true, data.nonlinear_forces);
}

}  // namespace detail
}  // namespace softrne
