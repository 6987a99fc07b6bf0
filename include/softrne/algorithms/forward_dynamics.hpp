#pragma once
/// \file
/// \brief Forward dynamics (paper eq. 23) by a dense Cholesky solve.

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "softrne/algorithms/mass_matrix.hpp"

namespace softrne {
namespace detail {

/// \brief In-place Cholesky factorisation L L^T = A (lower triangle) and solve A x = b.
///
/// Written out instead of Eigen::LLT because Eigen's triangular solvers skip right-hand-side
/// entries whose value is exactly zero, which silently drops the derivative part of an
/// AutoDiff scalar (e.g. at an equilibrium, where qddot = 0 but its derivatives are not).
/// \return false if A is not positive definite.
template <class Mat, class Vec>
bool cholesky_solve_in_place(Mat& A, Vec& b) {
  using std::sqrt;
  using S = typename Mat::Scalar;
  const Eigen::Index n = A.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    S d = A(j, j);
    for (Eigen::Index k = 0; k < j; ++k) d -= A(j, k) * A(j, k);
    if (!(d > S(0))) return false;
    const S l = sqrt(d);
    A(j, j) = l;
    for (Eigen::Index i = j + 1; i < n; ++i) {
      S s = A(i, j);
      for (Eigen::Index k = 0; k < j; ++k) s -= A(i, k) * A(j, k);
      A(i, j) = s / l;
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {  // L y = b
    S s = b(i);
    for (Eigen::Index k = 0; k < i; ++k) s -= A(i, k) * b(k);
    b(i) = s / A(i, i);
  }
  for (Eigen::Index i = n - 1; i >= 0; --i) {  // L^T x = y
    S s = b(i);
    for (Eigen::Index k = i + 1; k < n; ++k) s -= A(k, i) * b(k);
    b(i) = s / A(i, i);
  }
  return true;
}

}  // namespace detail

/// \brief \f$\ddot q = M(q)^{-1}(\tau - C(q,\dot q)\dot q - G(q))\f$, where tau holds every
/// other generalised force (pressures \f$K_{prs}p\f$, springs \f$-K q\f$, dampers
/// \f$-K_d\dot q\f$, effects). M and C qdot + G come from one kinematics evaluation
/// (mass_matrix_and_bias); M is factorised by Cholesky in data.mass_factor (M itself stays
/// in data.mass_matrix). Cost O(n nq) for M plus O(nq^3) for the factorisation. If M is not
/// positive definite (it always is for positive masses), qddot is set to NaN.
/// \return data.qddot
template <class ChainT, class Q, class Qd, class Tau>
const typename ChainT::VectorQ& forward_dynamics(const ChainT& chain, typename ChainT::Data& data,
                                                 const Eigen::MatrixBase<Q>& q,
                                                 const Eigen::MatrixBase<Qd>& qdot,
                                                 const Eigen::MatrixBase<Tau>& tau) {
  detail::check_argument(chain, "forward_dynamics", "q", q);
  detail::check_argument(chain, "forward_dynamics", "qdot", qdot);
  detail::check_argument(chain, "forward_dynamics", "tau", tau);
  mass_matrix_and_bias(chain, data, q, qdot);
  data.qddot = tau - data.nonlinear_forces;
  data.mass_factor = data.mass_matrix;
  if (!detail::cholesky_solve_in_place(data.mass_factor, data.qddot))
    data.qddot.setConstant(std::numeric_limits<double>::quiet_NaN());
  return data.qddot;
}

}  // namespace softrne
