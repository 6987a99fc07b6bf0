// Must NOT compile: a fixed-size argument of another size than a compile-time chain's nq
// (here a 3-vector q for a chain with 2 coordinates). The build of this file is expected to
// fail with the static_assert message of include/softrne/algorithms/kinematics.hpp
// (detail::check_argument: "a fixed-size argument has another size than the chain's nq");
// ctest checks that message (tests/compile_fail/CMakeLists.txt). Built with
// SOFTRNE_COMPILE_FAIL_CONTROL, the same call with a 2-vector must compile (so the failure
// is the static_assert, not a missing include or a typo).
#include "softrne/softrne.hpp"

#ifdef SOFTRNE_COMPILE_FAIL_CONTROL
using Q = Eigen::Vector2d;
#else
using Q = Eigen::Vector3d;
#endif

int main() {
  softrne::Chain<softrne::ConstantCurvatureJoint<double>, softrne::RigidLink<double>> arm;
  auto data = arm.make_data();
  const Q q = Q::Zero();
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  const auto& tau = softrne::rnea(arm, data, q, zero, zero);
  return tau.allFinite() ? 0 : 1;
}
