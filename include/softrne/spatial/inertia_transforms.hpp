#pragma once
/// \file
/// \brief Turning and shifting a 3x3 inertia: \f$R A R^T\f$ and the parallel-axis theorem.
///
/// The composite-body sweeps (mass_matrix.hpp, articulated_body.hpp) and the own bodies'
/// inertia (own_inertia.hpp) carry inertias as (mass, first moment, inertia about an origin)
/// and move them from frame to frame with these two.

#include <Eigen/Core>

namespace softrne {
namespace detail {

/// \brief \f$R A R^T\f$ for symmetric A (upper triangle formed, then mirrored: the result is
/// exactly symmetric).
template <class Scalar>
EIGEN_ALWAYS_INLINE Eigen::Matrix<Scalar, 3, 3> rotate_symmetric(
    const Eigen::Matrix<Scalar, 3, 3>& R, const Eigen::Matrix<Scalar, 3, 3>& A) {
  const Eigen::Matrix<Scalar, 3, 3> RA = R * A;
  Eigen::Matrix<Scalar, 3, 3> B;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) B(i, j) = RA.row(i).dot(R.row(j));
  B(1, 0) = B(0, 1);
  B(2, 0) = B(0, 2);
  B(2, 1) = B(1, 2);
  return B;
}

/// \brief A += 2 (r.w) 1 - (r w^T + w r^T), the parallel-axis shift: for w = h + m r / 2 it
/// moves the inertia of a body of mass m and first moment h (about the old origin) to an
/// origin at -r (bodies at rho become rho + r). With h = 0 (A about the centre of mass) it adds
/// \f$-m[r]_\times^2 = m(|r|^2 1 - r r^T)\f$.
template <class Scalar>
EIGEN_ALWAYS_INLINE void add_shift(Eigen::Matrix<Scalar, 3, 3>& A,
                                   const Eigen::Matrix<Scalar, 3, 1>& r,
                                   const Eigen::Matrix<Scalar, 3, 1>& w) {
  const Scalar d = Scalar(2) * r.dot(w);
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      const Scalar s = r(i) * w(j) + w(i) * r(j);
      if (i == j)
        A(i, i) += d - s;
      else {
        A(i, j) -= s;
        A(j, i) -= s;
      }
    }
}

}  // namespace detail
}  // namespace softrne
