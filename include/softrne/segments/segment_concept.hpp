#pragma once
/// \file
/// \brief Compile-time check that a type can be a segment of a chain.

#include <type_traits>

#include <Eigen/Core>

#include "softrne/segments/segment_kinematics.hpp"

namespace softrne {
namespace detail {

template <class T, class = void>
struct is_segment : std::false_type {};

template <class T>
struct is_segment<T, std::void_t<typename T::Scalar, decltype(T::nq), decltype(T::has_body),
                                 typename T::Kinematics, decltype(std::declval<const T&>().mass),
                                 decltype(std::declval<const T&>().num_inputs())>>
    : std::bool_constant<std::is_base_of_v<SegmentKinematics<typename T::Scalar, T::nq>,
                                           typename T::Kinematics>> {};

}  // namespace detail

/// \brief Gives one readable error when a type does not model the segment interface:
/// `Scalar`, `nq`, `has_body`, `Kinematics` (SegmentKinematics<Scalar, nq> or derived from
/// it, e.g. MultiBodyKinematics), `mass`,
/// `num_inputs()`, `calc(q, qdot, kin)`, `passive_force(q, qdot)`, `cast<S>()`.
template <class T>
constexpr void check_segment() {
  static_assert(detail::is_segment<T>::value,
                "softrne: this type is not a segment: it needs Scalar, nq, has_body, "
                "Kinematics derived from SegmentKinematics<Scalar, nq>, mass and num_inputs() "
                "(see ConstantCurvatureJoint, RigidLink, RevoluteJoint)");
}

}  // namespace softrne
