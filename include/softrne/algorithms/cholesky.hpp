#pragma once
/// \file
/// \brief Dense Cholesky factorisation and solve, written out for every scalar type.
///
/// Written out instead of Eigen::LLT because Eigen's triangular solvers skip right-hand-side
/// entries whose value is exactly zero, which silently drops the derivative part of an
/// AutoDiff scalar (e.g. at an equilibrium, where qddot = 0 but its derivatives are not).
/// forward_dynamics (M qddot = tau - C qdot - G) and aba (the articulated inertia D of a
/// segment with more than two coordinates) use the same two functions.

#include <cmath>

#include <Eigen/Core>

namespace softrne {
namespace detail {

/// \brief In-place factorisation L L^T = A: L overwrites the lower triangle of A (the strict
/// upper triangle is neither read nor written). \return false if A is not positive definite.
template <class Mat>
bool cholesky_factor_in_place(Mat& A) {
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
  return true;
}

/// \brief Solves L L^T x = b in place, with L in the lower triangle of `L` (as left by
/// cholesky_factor_in_place).
template <class Mat, class Vec>
void cholesky_solve_factored(const Mat& L, Vec& b) {
  using S = typename Mat::Scalar;
  const Eigen::Index n = L.rows();
  for (Eigen::Index i = 0; i < n; ++i) {  // L y = b
    S s = b(i);
    for (Eigen::Index k = 0; k < i; ++k) s -= L(i, k) * b(k);
    b(i) = s / L(i, i);
  }
  for (Eigen::Index i = n - 1; i >= 0; --i) {  // L^T x = y
    S s = b(i);
    for (Eigen::Index k = i + 1; k < n; ++k) s -= L(k, i) * b(k);
    b(i) = s / L(i, i);
  }
}

/// \brief Factorises A in place and solves A x = b in place. \return false if A is not
/// positive definite (b is then unchanged).
template <class Mat, class Vec>
bool cholesky_solve_in_place(Mat& A, Vec& b) {
  if (!cholesky_factor_in_place(A)) return false;
  cholesky_solve_factored(A, b);
  return true;
}

}  // namespace detail
}  // namespace softrne
