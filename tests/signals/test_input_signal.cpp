// Self-containment of the header is checked by tests/headers.
#include <algorithm>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "softrne/signals/input_signal.hpp"

namespace signals_test_input_signal {

using softrne::signals::InputSignal;
using softrne::signals::Interpolation;
using softrne::signals::Side;
using softrne::signals::SignalCursor;

// Irregular times, two channels: channel 0 = 10 * i, channel 1 = a ramp with a repeat.
InputSignal make_signal(Interpolation interp) {
  Eigen::VectorXd t(5);
  t << 0.0, 0.1, 0.35, 0.4, 1.0;
  Eigen::MatrixXd u(5, 2);
  u << 0, 5,  //
      10, 5,  //
      20, 7,  //
      30, 7,  //
      40, 9;
  return InputSignal(t, u, interp);
}

// PCHIP written independently of the library (polynomial form on each interval, slopes by
// the Fritsch-Butland mean in the form 3 (h0 + h1) / ((2 h1 + h0) / d0 + (h1 + 2 h0) / d1)).
double pchip_reference(const Eigen::VectorXd& ts, const Eigen::VectorXd& ys, double t) {
  const Eigen::Index n = ts.size();
  if (t <= ts[0]) return ys[0];
  if (t >= ts[n - 1]) return ys[n - 1];
  auto d = [&](Eigen::Index i) { return (ys[i + 1] - ys[i]) / (ts[i + 1] - ts[i]); };
  auto slope = [&](Eigen::Index i) {
    if (i == 0) return d(0);
    if (i == n - 1) return d(n - 2);
    const double d0 = d(i - 1), d1 = d(i);
    if (d0 == 0 || d1 == 0 || (d0 > 0) != (d1 > 0)) return 0.0;
    const double h0 = ts[i] - ts[i - 1], h1 = ts[i + 1] - ts[i];
    return 3 * (h0 + h1) / ((2 * h1 + h0) / d0 + (h1 + 2 * h0) / d1);
  };
  Eigen::Index i = 0;
  while (ts[i + 1] <= t) ++i;
  const double h = ts[i + 1] - ts[i], x = t - ts[i], di = d(i);
  const double m0 = slope(i), m1 = slope(i + 1);
  const double c2 = (3 * di - 2 * m0 - m1) / h, c3 = (m0 + m1 - 2 * di) / (h * h);
  return ys[i] + x * (m0 + x * (c2 + x * c3));
}

// Reference: straightforward linear scan.
Eigen::Vector2d reference(const InputSignal& s, double t, Side side) {
  const Eigen::VectorXd& ts = s.times();
  const Eigen::Index n = ts.size();
  if (s.interpolation() == Interpolation::zero_order_hold) {
    Eigen::Index i = 0;
    for (Eigen::Index k = 0; k < n; ++k)
      if (side == Side::right ? ts[k] <= t : ts[k] < t) i = k;
    return s.sample(i);
  }
  if (s.interpolation() == Interpolation::pchip) {
    Eigen::MatrixXd ys(n, 2);
    for (Eigen::Index k = 0; k < n; ++k) ys.row(k) = s.sample(k).transpose();
    return {pchip_reference(ts, ys.col(0), t), pchip_reference(ts, ys.col(1), t)};
  }
  if (t <= ts[0]) return s.sample(0);
  if (t >= ts[n - 1]) return s.sample(n - 1);
  Eigen::Index i = 0;
  while (ts[i + 1] <= t) ++i;
  const double a = (t - ts[i]) / (ts[i + 1] - ts[i]);
  return (1 - a) * s.sample(i) + a * s.sample(i + 1);
}

TEST(InputSignal, ZeroOrderHoldValuesAndClamping) {
  InputSignal s = make_signal(Interpolation::zero_order_hold);
  ASSERT_EQ(s.size(), 2);
  ASSERT_EQ(s.num_samples(), 5);
  Eigen::Vector2d u;
  s.value(-3.0, u);
  EXPECT_EQ(u, Eigen::Vector2d(0, 5));
  s.value(0.0, u);
  EXPECT_EQ(u, Eigen::Vector2d(0, 5));
  s.value(0.0999, u);
  EXPECT_EQ(u, Eigen::Vector2d(0, 5));
  s.value(0.1, u);  // right-continuous
  EXPECT_EQ(u, Eigen::Vector2d(10, 5));
  s.value(0.1, u, Side::left);  // left limit at a jump
  EXPECT_EQ(u, Eigen::Vector2d(0, 5));
  s.value(0.37, u, Side::left);  // off a sample time both sides agree
  EXPECT_EQ(u, Eigen::Vector2d(20, 7));
  s.value(1.0, u);
  EXPECT_EQ(u, Eigen::Vector2d(40, 9));
  s.value(1.0, u, Side::left);
  EXPECT_EQ(u, Eigen::Vector2d(30, 7));
  s.value(7.0, u);
  EXPECT_EQ(u, Eigen::Vector2d(40, 9));
}

TEST(InputSignal, LinearValuesAndClamping) {
  InputSignal s = make_signal(Interpolation::linear);
  Eigen::Vector2d u;
  s.value(-1.0, u);
  EXPECT_EQ(u, Eigen::Vector2d(0, 5));
  s.value(0.05, u);
  EXPECT_NEAR(u[0], 5.0, 1e-14);
  EXPECT_NEAR(u[1], 5.0, 1e-14);
  s.value(0.225, u);  // halfway between 0.1 and 0.35
  EXPECT_NEAR(u[0], 15.0, 1e-13);
  EXPECT_NEAR(u[1], 6.0, 1e-13);
  s.value(0.7, u);
  EXPECT_NEAR(u[0], 35.0, 1e-13);
  EXPECT_NEAR(u[1], 8.0, 1e-13);
  s.value(0.35, u, Side::left);  // continuous: the side is irrelevant
  EXPECT_NEAR(u[0], 20.0, 1e-13);
  s.value(2.0, u);
  EXPECT_EQ(u, Eigen::Vector2d(40, 9));
}

TEST(InputSignal, WritesIntoBlocksOfLargerVectors) {
  InputSignal s = make_signal(Interpolation::zero_order_hold);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(6, -1.0);
  s.value(0.36, x.segment(2, 2));
  EXPECT_EQ(x, (Eigen::VectorXd(6) << -1, -1, 20, 7, -1, -1).finished());
}

TEST(InputSignal, Breakpoints) {
  const InputSignal zoh = make_signal(Interpolation::zero_order_hold);
  // Every sample after the first changes channel 0.
  EXPECT_EQ(zoh.breakpoints(), (std::vector<double>{0.1, 0.35, 0.4, 1.0}));
  // Only channel 1 would not jump at 0.1 and 0.4: a tolerance above 10 keeps none.
  EXPECT_TRUE(zoh.breakpoints(10.5).empty());

  Eigen::VectorXd t(4);
  t << 0, 1, 2, 3;
  Eigen::MatrixXd u(4, 1);
  u << 0, 1, 2, 2;  // slope 1, 1, 0 ; zero outside
  const InputSignal lin(t, u, Interpolation::linear);
  EXPECT_EQ(lin.breakpoints(), (std::vector<double>{0.0, 2.0}));
  const InputSignal zoh2(t, u, Interpolation::zero_order_hold);
  EXPECT_EQ(zoh2.breakpoints(), (std::vector<double>{1.0, 2.0}));
}

TEST(InputSignal, RejectsBadData) {
  Eigen::VectorXd t(3);
  t << 0, 1, 1;
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(3, 1);
  EXPECT_THROW(InputSignal(t, u), std::invalid_argument);
  t << 0, 1, 2;
  EXPECT_THROW(InputSignal(t, Eigen::MatrixXd::Zero(2, 1)), std::invalid_argument);
  EXPECT_THROW(InputSignal(Eigen::VectorXd(), Eigen::MatrixXd()), std::invalid_argument);
  u(1, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(InputSignal(t, u), std::invalid_argument);
}

TEST(InputSignal, SingleSampleIsConstant) {
  InputSignal s(Eigen::VectorXd::Constant(1, 2.0), Eigen::MatrixXd::Constant(1, 3, 4.0),
                Interpolation::linear);
  Eigen::Vector3d u;
  for (double t : {-1.0, 2.0, 5.0}) {
    s.value(t, u);
    EXPECT_EQ(u, Eigen::Vector3d::Constant(4.0));
  }
}

// Cursor correctness: monotone sweeps (dense and sparse), random jumps, exact
// sample times, both sides, every interpolation, against a linear scan (and, for PCHIP, an
// interpolant written here).
TEST(InputSignal, CursorMatchesLinearScanOnRandomQueries) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> dt(0.001, 0.1);
  const int n = 500;
  Eigen::VectorXd t(n);
  t[0] = -0.3;
  for (int i = 1; i < n; ++i) t[i] = t[i - 1] + dt(rng);
  Eigen::MatrixXd u = Eigen::MatrixXd::Random(n, 2);

  for (Interpolation interp :
       {Interpolation::zero_order_hold, Interpolation::linear, Interpolation::pchip}) {
    InputSignal s(t, u, interp);
    std::uniform_real_distribution<double> any(t[0] - 1.0, t[n - 1] + 1.0);
    std::uniform_int_distribution<int> any_sample(0, n - 1);
    std::vector<double> queries;
    // Monotone dense sweep, including every sample time exactly.
    for (int i = 0; i < n; ++i) {
      queries.push_back(t[i]);
      if (i + 1 < n) queries.push_back(0.5 * (t[i] + t[i + 1]));
    }
    // Monotone sparse sweep (jumps of many samples).
    for (double q = t[0] - 0.5; q < t[n - 1] + 0.5; q += 0.37) queries.push_back(q);
    // Backwards sweep.
    for (int i = n - 1; i >= 0; i -= 3) queries.push_back(t[i] - 1e-9);
    // Random, non-monotone, half of them exact sample times.
    for (int k = 0; k < 4000; ++k) queries.push_back(k % 2 ? any(rng) : t[any_sample(rng)]);

    SignalCursor cursor;
    Eigen::Vector2d value, value_const;
    int mismatches = 0;
    for (double q : queries)
      for (Side side : {Side::right, Side::left}) {
        s.value(q, value, side);
        s.value(q, value_const, cursor, side);
        const Eigen::Vector2d expected = reference(s, q, side);
        // PCHIP's reference evaluates another form of the same cubic: rounding differs.
        const double tol = interp == Interpolation::pchip ? 1e-12 : 1e-14;
        if ((value - expected).cwiseAbs().maxCoeff() > tol ||
            (value_const - expected).cwiseAbs().maxCoeff() > tol)
          ++mismatches;
      }
    EXPECT_EQ(mismatches, 0) << "interpolation " << static_cast<int>(interp);
  }
}

// PCHIP by hand on three samples: t = 0, 1, 2 and u = 0, 1, 3 (secants 1 and 2, so the
// interior slope is their harmonic mean 4/3; the ends take the secants), and on data with an
// extremum (interior slope 0). At s = 1/2 the Hermite basis is (1/2, 1/8, 1/2, -1/8).
TEST(InputSignal, PchipClosedForms) {
  Eigen::VectorXd t(3);
  t << 0.0, 1.0, 2.0;
  Eigen::MatrixXd u(3, 2);
  u << 0, 0,  //
      1, 1,   //
      3, 1;
  InputSignal s(t, u, Interpolation::pchip);
  Eigen::Vector2d v;
  s.value(1.5, v);
  EXPECT_NEAR(v[0], 0.5 * 1 + 0.125 * (4.0 / 3.0) + 0.5 * 3 - 0.125 * 2, 1e-15);  // 23/12
  EXPECT_NEAR(v[1], 1.0, 1e-15);  // flat at the extremum and, with a zero secant, after it
  s.value(0.5, v);
  EXPECT_NEAR(v[0], 0.125 * 1 + 0.5 * 1 - 0.125 * (4.0 / 3.0), 1e-15);
  EXPECT_NEAR(v[1], 0.125 * 1 + 0.5 * 1, 1e-15);  // 0.625: slopes 1 and 0
  EXPECT_TRUE(s.breakpoints().empty());           // C1 inside its range
}

// PCHIP is exact on linear data, C1 at every sample (its one-sided difference quotients agree
// with each other), and does not overshoot monotone data, on random irregular samples.
TEST(InputSignal, PchipIsExactOnLinesC1AndMonotone) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> dt(0.005, 0.05), du(0.0, 1.0);
  const int n = 200;
  Eigen::VectorXd t(n);
  Eigen::MatrixXd u(n, 2);
  t[0] = 0.0;
  u(0, 1) = 0.0;
  for (int i = 1; i < n; ++i) {
    t[i] = t[i - 1] + dt(rng);
    u(i, 1) = u(i - 1, 1) + (i % 7 == 0 ? 0.0 : du(rng));  // non-decreasing, with flat parts
  }
  u.col(0) = (3.0 - 2.0 * t.array()).matrix();  // a line
  InputSignal s(t, u, Interpolation::pchip);
  Eigen::Vector2d v;
  double worst_line = 0, worst_kink = 0, worst_overshoot = 0;
  for (int i = 0; i + 1 < n; ++i) {
    for (double f : {0.1, 0.37, 0.5, 0.9}) {
      const double tq = t[i] + f * (t[i + 1] - t[i]);
      s.value(tq, v);
      worst_line = std::max(worst_line, std::abs(v[0] - (3.0 - 2.0 * tq)));
      worst_overshoot = std::max({worst_overshoot, u(i, 1) - v[1], v[1] - u(i + 1, 1)});
    }
    if (i > 0) {  // left and right derivatives at t_i, one-sided quotients with Richardson
      auto at = [&](double tq) {
        s.value(tq, v);
        return v[1];
      };
      const double e = 1e-6, c = at(t[i]);
      auto left = [&](double h) { return (c - at(t[i] - h)) / h; };
      auto right = [&](double h) { return (at(t[i] + h) - c) / h; };
      const double dl = 2 * left(e / 2) - left(e), dr = 2 * right(e / 2) - right(e);
      worst_kink = std::max(worst_kink, std::abs(dr - dl) / std::max(1.0, std::abs(dl)));
    }
  }
  EXPECT_LT(worst_line, 1e-14);
  EXPECT_LT(worst_overshoot, 1e-12);  // rounding only (h00 + h01 = 1 up to an ulp)
  // A kink jumps the slope by O(1) of itself; C1 leaves O(e^2 u''') and rounding, ~1e-7.
  EXPECT_LT(worst_kink, 1e-5);
}

}  // namespace signals_test_input_signal
