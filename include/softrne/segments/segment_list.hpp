#pragma once
/// \file
/// \brief The one place that lists every segment type (for the runtime chain's variant).

#include <variant>

#include "softrne/segments/constant_curvature_joint.hpp"
#include "softrne/segments/revolute_joint.hpp"
#include "softrne/segments/rigid_link.hpp"

namespace softrne {

/// \brief The distributed-inertia CC joint of the runtime chain (default number of points).
template <class Scalar>
using DistributedCCJoint = ConstantCurvatureJoint<Scalar, DistributedInertia<>>;

/// \brief Any segment, for chains read at run time.
template <class Scalar>
using AnySegment = std::variant<ConstantCurvatureJoint<Scalar>, RigidLink<Scalar>,
                                RevoluteJoint<Scalar>, DistributedCCJoint<Scalar>>;

/// \brief The matching kinematics record.
template <class Scalar>
using AnySegmentKinematics =
    std::variant<typename ConstantCurvatureJoint<Scalar>::Kinematics,
                 typename RigidLink<Scalar>::Kinematics, typename RevoluteJoint<Scalar>::Kinematics,
                 typename DistributedCCJoint<Scalar>::Kinematics>;

}  // namespace softrne
