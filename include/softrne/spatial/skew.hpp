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
  Eigen::Matrix<S, 3, 3> m;
  m << S(0), -w(2), w(1), w(2), S(0), -w(0), -w(1), w(0), S(0);
  return m;
}

}  // namespace softrne
