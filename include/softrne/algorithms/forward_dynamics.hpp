#pragma once
/// \file
/// \brief Forward dynamics (paper eq. 23) by a dense Cholesky solve.

#include <limits>

#include <Eigen/Core>

#include "softrne/algorithms/cholesky.hpp"
#include "softrne/algorithms/mass_matrix.hpp"

namespace softrne {
namespace detail {

/// \brief The last step of forward_dynamics(), once data.mass_matrix and data.nonlinear_forces
/// hold M and C qdot + G: M's Cholesky factor into data.mass_factor and \f$\ddot q = M^{-1}(\tau
/// - C\dot q - G)\f$ into data.qddot (NaN if M is not positive definite). aba_derivatives()
/// shares it (its M comes from the derivatives' composites).
template <class Data, class Tau>
void solve_for_qddot(Data& data, const Eigen::MatrixBase<Tau>& tau) {
  data.qddot = tau - data.nonlinear_forces;
  data.mass_factor = data.mass_matrix;
  if (!cholesky_solve_in_place(data.mass_factor, data.qddot))
    data.qddot.setConstant(std::numeric_limits<double>::quiet_NaN());
}

}  // namespace detail

/// \brief \f$\ddot q = M(q)^{-1}(\tau - C(q,\dot q)\dot q - G(q))\f$, where tau holds every
/// other generalised force (pressures \f$K_{prs}p\f$, springs \f$-K q\f$, dampers
/// \f$-K_d\dot q\f$, effects). M and C qdot + G come from one kinematics evaluation
/// (mass_matrix_and_bias); M is factorised by Cholesky in data.mass_factor (M itself stays
/// in data.mass_matrix). Cost O(n nq) for M plus O(nq^3) for the factorisation. If M is not
/// positive definite (it always is for positive masses), qddot is set to NaN.
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model.
/// \param[in,out] data Its workspace, made by chain.make_data(); also leaves M in
///   data.mass_matrix, its factor in data.mass_factor and C qdot + G in data.nonlinear_forces.
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \param[in] qdot Their rates (dim chain.num_coordinates()).
/// \param[in] tau Every generalised force other than inertia and gravity (dim
///   chain.num_coordinates()): \f$K_{prs}p - K q - K_d\dot q\f$ + effects in eq. 23.
/// \return The accelerations, stored in data.qddot (NaN if M is not positive definite).
/// \throws std::invalid_argument (DynamicChain only) if q, qdot or tau has another size than
///   the chain or data was made for another chain.
template <class ChainT, class Q, class Qd, class Tau>
const typename ChainT::VectorQ& forward_dynamics(const ChainT& chain, typename ChainT::Data& data,
                                                 const Eigen::MatrixBase<Q>& q,
                                                 const Eigen::MatrixBase<Qd>& qdot,
                                                 const Eigen::MatrixBase<Tau>& tau) {
  detail::check_argument(chain, "forward_dynamics", "q", q);
  detail::check_argument(chain, "forward_dynamics", "qdot", qdot);
  detail::check_argument(chain, "forward_dynamics", "tau", tau);
  mass_matrix_and_bias(chain, data, q, qdot);
  detail::solve_for_qddot(data, tau);
  return data.qddot;
}

}  // namespace softrne
