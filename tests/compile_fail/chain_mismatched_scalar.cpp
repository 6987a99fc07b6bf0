// Must NOT compile: a compile-time softrne::Chain whose segments use different Scalar
// types. The build of this file is expected to fail with the static_assert message of
// include/softrne/chain/static_chain.hpp ("all segments must use the same Scalar type");
// ctest checks that message (tests/compile_fail/CMakeLists.txt). Built with
// SOFTRNE_COMPILE_FAIL_CONTROL, the same file with matching types must compile (so the
// failure is the static_assert, not a missing include or a typo).
#include "softrne/softrne.hpp"

#ifdef SOFTRNE_COMPILE_FAIL_CONTROL
using Tip = softrne::RigidLink<double>;
#else
using Tip = softrne::RigidLink<long double>;
#endif

int main() {
  softrne::Chain<softrne::ConstantCurvatureJoint<double>, Tip> arm;
  auto data = arm.make_data();
  (void)data;
  return arm.num_coordinates() == 2 ? 0 : 1;
}
