#pragma once
// Include FIRST in a test translation unit, before anything that includes Eigen.
// Turns Eigen's runtime no-malloc check on (also in Release builds, where
// NDEBUG would compile eigen_assert out) and counts failed Eigen assertions
// instead of aborting, so a test can EXPECT_EQ(count, 0) and the process keeps
// running when a C library (CVODE) is on the stack.

#define EIGEN_RUNTIME_NO_MALLOC

namespace softrne_test {
inline long eigen_assert_failures = 0;
}  // namespace softrne_test

#define eigen_assert(x)                                \
  do {                                                 \
    if (!(x)) ++::softrne_test::eigen_assert_failures; \
  } while (false)
