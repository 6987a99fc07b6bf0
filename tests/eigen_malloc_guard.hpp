#pragma once
// Include FIRST in a test translation unit, before anything that includes Eigen (the
// generated translation unit of a test folder does so when one of its files includes it:
// tests/CMakeLists.txt).
// Turns Eigen's runtime no-malloc check on (also in Release builds, where
// NDEBUG would compile eigen_assert out) and counts failed Eigen assertions
// instead of aborting, so a test can EXPECT_EQ(count, 0) and the process keeps
// running when a C library (CVODE) is on the stack.
//
// Use:
//   const long before = softrne_test::eigen_assert_failures;
//   Eigen::internal::set_is_malloc_allowed(false);
//   ... code that must not allocate ...
//   Eigen::internal::set_is_malloc_allowed(true);
//   EXPECT_EQ(softrne_test::eigen_assert_failures, before);
// The test EigenMallocGuard.CountsAnAllocationWhereForbidden, defined here once per
// translation unit (so once per test executable), proves that the check is live in the
// build that runs it. A failure counted anywhere else (an Eigen
// assertion that would have aborted) fails the process at exit, so none goes unseen.

#define EIGEN_RUNTIME_NO_MALLOC

#include <cstdio>
#include <cstdlib>

namespace softrne_test {
inline long eigen_assert_failures = 0;

struct EigenAssertionsAtExit {
  ~EigenAssertionsAtExit() {
    if (eigen_assert_failures != 0) {
      std::fprintf(stderr, "eigen_malloc_guard: %ld Eigen assertion(s) failed (an allocation where "
                   "forbidden, or another Eigen check)\n", eigen_assert_failures);
      std::_Exit(1);
    }
  }
};
inline EigenAssertionsAtExit eigen_assertions_at_exit;
}  // namespace softrne_test

#define eigen_assert(x)                                \
  do {                                                 \
    if (!(x)) ++::softrne_test::eigen_assert_failures; \
  } while (false)

#include <Eigen/Core>
#include <gtest/gtest.h>

/// A test that allocates where it is forbidden and expects the guard to count it (then
/// forgets the count): without it, a "does not allocate" test could pass in a build where the
/// check is compiled out.
TEST(EigenMallocGuard, CountsAnAllocationWhereForbidden) {
  const long before = ::softrne_test::eigen_assert_failures;
  Eigen::internal::set_is_malloc_allowed(false);
  Eigen::VectorXd v(64);
  Eigen::internal::set_is_malloc_allowed(true);
  v.setOnes();
  EXPECT_GT(::softrne_test::eigen_assert_failures, before) << v.sum();
  ::softrne_test::eigen_assert_failures = before;
}
