#pragma once
/// \file
/// \brief Skew-symmetric (cross-product) matrix.

#include <Eigen/Core>

namespace softrne {

/// \brief \f$[w]_\times\f$ such that \f$[w]_\times x = w \times x\f$ (the paper's \f$[\,]_x\f$
/// of eqs. 6 and 19).
/// \param[in] w A 3-vector.
/// \return The 3x3 skew-symmetric matrix of w.
template <class Derived>
EIGEN_ALWAYS_INLINE Eigen::Matrix<typename Derived::Scalar, 3, 3> skew(
    const Eigen::MatrixBase<Derived>& w) {
  using S = typename Derived::Scalar;
  // Entry by entry: GCC 12 leaves Eigen's comma initializer an out-of-line call per entry
  // (callgrind: 9 % of rnea_derivatives on a revolute chain), so it is not used here.
  Eigen::Matrix<S, 3, 3> m;
  m(0, 0) = S(0);
  m(1, 0) = w(2);
  m(2, 0) = -w(1);
  m(0, 1) = -w(2);
  m(1, 1) = S(0);
  m(2, 1) = w(0);
  m(0, 2) = w(1);
  m(1, 2) = -w(0);
  m(2, 2) = S(0);
  return m;
}

/// \brief \f$a\times b\f$ of two 3-vectors, always inlined: GCC 12 leaves Eigen's cross() an
/// out-of-line call (callgrind on rnea_derivatives: 4 300 instructions per call on rev6 in
/// calls to it), which the derivatives' world composites make dozens of.
/// \param[in] a A 3-vector.
/// \param[in] b A 3-vector.
/// \return Their cross product.
template <class A, class B>
EIGEN_ALWAYS_INLINE Eigen::Matrix<typename A::Scalar, 3, 1> cross3(const Eigen::MatrixBase<A>& a,
                                                                   const Eigen::MatrixBase<B>& b) {
  Eigen::Matrix<typename A::Scalar, 3, 1> c;
  c(0) = a(1) * b(2) - a(2) * b(1);
  c(1) = a(2) * b(0) - a(0) * b(2);
  c(2) = a(0) * b(1) - a(1) * b(0);
  return c;
}

}  // namespace softrne
