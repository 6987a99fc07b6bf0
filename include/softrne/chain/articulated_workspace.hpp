#pragma once
/// \file
/// \brief Per-segment scratch of the articulated-body forward dynamics (algorithms/
/// articulated_body.hpp), kept in the chains' Data so that `aba` allocates nothing.

#include <algorithm>
#include <variant>

#include <Eigen/Core>

namespace softrne {

/// \brief What the backward sweep of `aba` leaves for the forward sweep, for one segment with
/// n <= MaxNq coordinates (only the leading n rows/columns are used). All in the segment's
/// base frame, about its origin, (linear; angular) ordering.
template <class Scalar, int MaxNq>
struct ArticulatedSegment {
  static_assert(MaxNq >= 1, "ArticulatedSegment: MaxNq >= 1");
  /// U = coupling + I^A S_e: the wrench at the base per unit qddot of the segment
  Eigen::Matrix<Scalar, 6, MaxNq> U = Eigen::Matrix<Scalar, 6, MaxNq>::Zero();
  /// D^-1, D = joint + S_e^T I^A S_e: the segment's articulated joint-space inertia
  Eigen::Matrix<Scalar, MaxNq, MaxNq> D_inv = Eigen::Matrix<Scalar, MaxNq, MaxNq>::Zero();
  /// u = tau - b - S_e^T p^A: the generalised force left for the segment's coordinates
  Eigen::Matrix<Scalar, MaxNq, 1> u = Eigen::Matrix<Scalar, MaxNq, 1>::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

namespace detail {

/// \brief Largest nq among segment types (at least 1), for sizing ArticulatedSegment.
template <class... Segments>
constexpr int max_segment_nq() {
  return std::max({1, Segments::nq...});
}

template <class Variant>
struct variant_max_nq;
template <class... Segments>
struct variant_max_nq<std::variant<Segments...>> {
  static constexpr int value = max_segment_nq<Segments...>();
};

}  // namespace detail
}  // namespace softrne
