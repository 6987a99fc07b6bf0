// smooth_pressures (ArmSimulationOptions::pressure_smoothing): off at sigma 0, zero phase, no
// overshoot at a step. Self-containment of the header is checked by tests/headers.
#include <gtest/gtest.h>

#include "softrne/signals/smoothing.hpp"

namespace signals_test_smoothing {

using Eigen::MatrixXd;
using Eigen::VectorXd;

TEST(Smoothing, IsOptionalZeroPhaseAndMonotone) {
  const VectorXd t = VectorXd::LinSpaced(201, 0.0, 2.0);
  MatrixXd P(t.size(), 2);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    P(i, 0) = 5e4;                          // constant
    P(i, 1) = t(i) < 1.0 - 1e-9 ? 0 : 1e5;  // a step at t = 1
  }
  EXPECT_EQ(softrne::signals::smooth_pressures(t, P, 0.0), P);  // off
  const MatrixXd S = softrne::signals::smooth_pressures(t, P, 0.02);
  EXPECT_LT((S.col(0).array() - 5e4).abs().maxCoeff(), 1e-9);
  for (Eigen::Index i = 1; i < t.size(); ++i) EXPECT_GE(S(i, 1), S(i - 1, 1) - 1e-9);  // monotone
  EXPECT_GE(S.col(1).minCoeff(), 0.0);
  EXPECT_LE(S.col(1).maxCoeff(), 1e5 * (1 + 1e-14));
  // Zero phase: symmetric about the step (between samples 99 and 100).
  for (int k = 0; k < 10; ++k) EXPECT_NEAR(S(99 - k, 1) + S(100 + k, 1), 1e5, 1e-6);
  EXPECT_EQ(S(0, 1), 0.0);
}

}  // namespace signals_test_smoothing
