#pragma once
/// \file
/// \brief Products with a rotation about a coordinate axis, skipping its known zeros.
///
/// A rotation about base axis k (a revolute joint whose axis is exactly x, y or z) has
/// R(k, k) = 1 and zeros in the rest of row and column k: it only turns the plane (i, j) =
/// (k+1, k+2) mod 3. Where the recursions apply such an R (or R^T) to vectors and symmetric
/// 3x3 inertias, these skip the zeros: R v costs 4 multiplications instead of 9 and
/// \f$R A R^T\f$ 18 instead of 45. They read the plane entries from R itself (not from cos q,
/// sin q), so R v and R^T v give what the full products give (the skipped terms are products
/// with exact zeros); \f$R A R^T\f$ agrees to rounding. This is the fast path Pinocchio keeps in
/// its JointModelRX/RY/RZ types; here the revolute joint finds it at run time
/// (RevoluteJoint::calc sets RevoluteKinematics::coordinate_axis) and FramePlacement takes it
/// (spatial/frame_placement.hpp).

#include <type_traits>

#include <Eigen/Core>

namespace softrne {
namespace detail {

/// \brief The plane a rotation about axis K turns: I = (K+1) mod 3, J = (K+2) mod 3.
template <int K>
struct AxisPlane {
  static_assert(K >= 0 && K < 3, "softrne: a coordinate axis is 0, 1 or 2");
  static constexpr int I = (K + 1) % 3;  ///< first axis of the plane
  static constexpr int J = (K + 2) % 3;  ///< second axis of the plane
};

/// \brief \f$R v\f$ (or \f$R^T v\f$ with Transpose) for R a rotation about axis K (see the
/// file comment).
template <int K, bool Transpose = false, class Scalar, class V>
EIGEN_ALWAYS_INLINE Eigen::Matrix<Scalar, 3, 1> times_about_axis(
    const Eigen::Matrix<Scalar, 3, 3>& R, const Eigen::MatrixBase<V>& v) {
  constexpr int i = AxisPlane<K>::I, j = AxisPlane<K>::J;
  // The plane's off-diagonal entries: (i, j) and (j, i) of R, swapped for R^T.
  const Scalar& r_ij = Transpose ? R(j, i) : R(i, j);
  const Scalar& r_ji = Transpose ? R(i, j) : R(j, i);
  Eigen::Matrix<Scalar, 3, 1> out;
  out(K) = v(K);
  out(i) = R(i, i) * v(i) + r_ij * v(j);
  out(j) = r_ji * v(i) + R(j, j) * v(j);
  return out;
}

/// \brief \f$R A R^T\f$ for symmetric A and R a rotation about axis K: row/column K of A turned
/// in the plane, the plane's 2x2 block turned on both sides, A(K, K) kept (exactly symmetric,
/// like rotate_symmetric).
template <int K, class Scalar>
EIGEN_ALWAYS_INLINE Eigen::Matrix<Scalar, 3, 3> rotate_symmetric_about_axis(
    const Eigen::Matrix<Scalar, 3, 3>& R, const Eigen::Matrix<Scalar, 3, 3>& A) {
  constexpr int i = AxisPlane<K>::I, j = AxisPlane<K>::J;
  const Scalar c_ii = R(i, i), c_ij = R(i, j), c_ji = R(j, i), c_jj = R(j, j);
  // Q = R_p A_p on the plane block, then B_p = Q R_p^T (its upper entries).
  const Scalar q_ii = c_ii * A(i, i) + c_ij * A(j, i), q_ij = c_ii * A(i, j) + c_ij * A(j, j);
  const Scalar q_ji = c_ji * A(i, i) + c_jj * A(j, i), q_jj = c_ji * A(i, j) + c_jj * A(j, j);
  Eigen::Matrix<Scalar, 3, 3> B;
  B(i, i) = q_ii * c_ii + q_ij * c_ij;
  B(j, j) = q_ji * c_ji + q_jj * c_jj;
  B(i, j) = B(j, i) = q_ii * c_ji + q_ij * c_jj;
  B(i, K) = B(K, i) = c_ii * A(i, K) + c_ij * A(j, K);
  B(j, K) = B(K, j) = c_ji * A(i, K) + c_jj * A(j, K);
  B(K, K) = A(K, K);
  return B;
}

/// \brief Calls f(std::integral_constant<int, k>{}) for k = 0, 1, 2: the axis as a
/// compile-time constant, so that the products above see fixed indices.
/// \pre 0 <= k < 3.
template <class F>
EIGEN_ALWAYS_INLINE decltype(auto) with_axis(int k, F&& f) {
  if (k == 0) return f(std::integral_constant<int, 0>{});
  if (k == 1) return f(std::integral_constant<int, 1>{});
  return f(std::integral_constant<int, 2>{});
}

}  // namespace detail
}  // namespace softrne
