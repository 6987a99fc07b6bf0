// Included first: the header must compile on its own.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include <softrne/signals/savitzky_golay.hpp>
#include "../gauss.hpp"

namespace {

using softrne::signals::savgol;
using softrne::signals::savgol_weights;
using softrne::signals::SgOptions;

using softrne::test::Gauss;

// y = sum_q c_q t^q and its derivatives.
struct Poly {
  Eigen::VectorXd c;
  double f(double t) const {
    double s = 0, tp = 1;
    for (Eigen::Index q = 0; q < c.size(); ++q, tp *= t) s += c[q] * tp;
    return s;
  }
  double df(double t) const {
    double s = 0, tp = 1;
    for (Eigen::Index q = 1; q < c.size(); ++q, tp *= t) s += static_cast<double>(q) * c[q] * tp;
    return s;
  }
  double ddf(double t) const {
    double s = 0, tp = 1;
    for (Eigen::Index q = 2; q < c.size(); ++q, tp *= t)
      s += static_cast<double>(q * (q - 1)) * c[q] * tp;
    return s;
  }
};

void expect_exact(const Eigen::VectorXd& t, const Poly& poly, const SgOptions& opt) {
  Eigen::MatrixXd y(t.size(), 2);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    y(i, 0) = poly.f(t[i]);
    y(i, 1) = -3.0 * poly.f(t[i]) + 1.0;  // a second column, fitted independently
  }
  Eigen::MatrixXd ys, dy, ddy;
  savgol(t, y, opt, ys, dy, ddy);
  ASSERT_EQ(ys.rows(), t.size());
  ASSERT_EQ(ys.cols(), 2);
  for (Eigen::Index i = 0; i < t.size(); ++i) {  // every sample, ends included
    EXPECT_NEAR(ys(i, 0), poly.f(t[i]), 1e-9) << "i=" << i;
    EXPECT_NEAR(dy(i, 0), poly.df(t[i]), 1e-9) << "i=" << i;
    EXPECT_NEAR(ddy(i, 0), poly.ddf(t[i]), 1e-9) << "i=" << i;
    EXPECT_NEAR(ys(i, 1), -3.0 * poly.f(t[i]) + 1.0, 1e-9) << "i=" << i;
    EXPECT_NEAR(dy(i, 1), -3.0 * poly.df(t[i]), 1e-9) << "i=" << i;
    EXPECT_NEAR(ddy(i, 1), -3.0 * poly.ddf(t[i]), 1e-9) << "i=" << i;
  }
}

}  // namespace

TEST(FitSavitzkyGolay, ClassicalFivePointQuadraticWeights) {
  Eigen::VectorXd t(5);
  t << -2, -1, 0, 1, 2;
  const auto W = savgol_weights(t, 0.0, 2);
  Eigen::VectorXd smooth(5), d1(5), d2(5);
  smooth << -3, 12, 17, 12, -3;
  d1 << -2, -1, 0, 1, 2;
  d2 << 2, -1, -2, -1, 2;
  EXPECT_LT((W.row(0).transpose() - smooth / 35.0).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((W.row(1).transpose() - d1 / 10.0).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((W.row(2).transpose() - d2 / 7.0).cwiseAbs().maxCoeff(), 1e-14);
  // Seven-point cubic smoothing: [-2, 3, 6, 7, 6, 3, -2] / 21.
  Eigen::VectorXd t7(7), s7(7);
  t7 << -3, -2, -1, 0, 1, 2, 3;
  s7 << -2, 3, 6, 7, 6, 3, -2;
  EXPECT_LT((savgol_weights(t7, 0.0, 3).row(0).transpose() - s7 / 21.0).cwiseAbs().maxCoeff(),
            1e-14);
  // Time scaling: spacing dt divides the first derivative by dt, the second by dt^2.
  const auto Wh = savgol_weights(0.01 * t, 0.0, 2);
  EXPECT_LT((Wh.row(1).transpose() - d1 / 10.0 / 0.01).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((Wh.row(2).transpose() - d2 / 7.0 / 1e-4).cwiseAbs().maxCoeff(), 1e-7);
}

TEST(FitSavitzkyGolay, ExactForPolynomialsUniformSampling) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(60, 0.0, 2.0);
  Poly cubic{Eigen::Vector4d(1.0, -2.0, 0.5, 0.3)};
  expect_exact(t, cubic, {7, 3});
  expect_exact(t, cubic, {3, 3});  // smallest useful window for p = 3
  Poly quadratic{Eigen::Vector3d(0.2, 1.0, -0.7)};
  expect_exact(t, quadratic, {2, 2});
  Poly quartic{(Eigen::VectorXd(5) << 1.0, -1.0, 0.5, 0.25, -0.1).finished()};
  expect_exact(t, quartic, {6, 4});
  // Signal shorter than the window: the window shrinks to the signal.
  expect_exact(Eigen::VectorXd::LinSpaced(9, -1.0, 1.0), cubic, {7, 3});
}

TEST(FitSavitzkyGolay, ExactForPolynomialsIrregularSampling) {
  Gauss g(7);
  Eigen::VectorXd t(80);
  double now = 0.0;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    t[i] = now;
    now += 0.01 * (0.3 + 1.4 * g.uniform());  // steps between 3 ms and 17 ms
  }
  Poly cubic{Eigen::Vector4d(1.0, -2.0, 0.5, 0.3)};
  expect_exact(t, cubic, {7, 3});
  expect_exact(t, cubic, {4, 3});
  Poly quartic{(Eigen::VectorXd(5) << 1.0, -1.0, 0.5, 0.25, -0.1).finished()};
  expect_exact(t, quartic, {5, 4});
}

TEST(FitSavitzkyGolay, NoisySineDerivative) {
  // sin(2 pi t) at 100 Hz for 2 s, noise sigma 0.003, default window (15 samples, cubic).
  const int n = 201;
  const double dt = 0.01, sigma = 0.003, w = 2.0 * M_PI;
  Gauss g(42);
  Eigen::VectorXd t(n);
  Eigen::MatrixXd y(n, 1);
  for (int i = 0; i < n; ++i) {
    t[i] = i * dt;
    y(i, 0) = std::sin(w * t[i]) + sigma * g();
  }
  Eigen::MatrixXd ys, dy, ddy;
  savgol(t, y, SgOptions{}, ys, dy, ddy);
  double e0 = 0, e1 = 0, e2 = 0, e1_interior = 0, e1_max = 0, e_naive = 0;
  int n_interior = 0;
  for (int i = 0; i < n; ++i) {
    const double d0 = ys(i, 0) - std::sin(w * t[i]);
    const double d1 = dy(i, 0) - w * std::cos(w * t[i]);
    const double d2 = ddy(i, 0) + w * w * std::sin(w * t[i]);
    e0 += d0 * d0;
    e1 += d1 * d1;
    e2 += d2 * d2;
    e1_max = std::max(e1_max, std::abs(d1));
    if (i >= 7 && i < n - 7) {
      e1_interior += d1 * d1;
      ++n_interior;
    }
    if (i > 0 && i < n - 1) {
      const double naive = (y(i + 1, 0) - y(i - 1, 0)) / (2 * dt) - w * std::cos(w * t[i]);
      e_naive += naive * naive;
    }
  }
  e0 = std::sqrt(e0 / n);
  e1 = std::sqrt(e1 / n);
  e2 = std::sqrt(e2 / n);
  e1_interior = std::sqrt(e1_interior / n_interior);
  e_naive = std::sqrt(e_naive / (n - 2));
  std::printf(
      "sin(2 pi t), 100 Hz, sigma 0.003, k=7 p=3: rms error value %.2e, first derivative %.3f "
      "(interior %.3f, max %.3f; amplitude %.2f), second derivative %.2f (amplitude %.1f); "
      "naive central difference %.3f\n",
      e0, e1, e1_interior, e1_max, w, e2, w * w, e_naive);
  EXPECT_LT(e0, sigma);              // smoothing reduces the noise
  EXPECT_LT(e1_interior, 0.02 * w);  // < 2 % of the derivative amplitude
  EXPECT_LT(e1, 0.03 * w);           // ends included
  EXPECT_LT(e1, 0.5 * e_naive);      // much better than a raw central difference
}

TEST(FitSavitzkyGolay, RejectsBadInput) {
  Eigen::MatrixXd ys, dy, ddy;
  Eigen::VectorXd t(4);
  t << 0, 1, 1, 2;  // repeated stamp
  EXPECT_THROW(savgol(t, Eigen::MatrixXd::Zero(4, 1), SgOptions{}, ys, dy, ddy),
               std::invalid_argument);
  t << 0, 1, 2, 3;
  EXPECT_THROW(savgol(t, Eigen::MatrixXd::Zero(3, 1), SgOptions{}, ys, dy, ddy),
               std::invalid_argument);
  EXPECT_THROW(savgol(t, Eigen::MatrixXd::Zero(4, 1), SgOptions{7, 4}, ys, dy, ddy),
               std::invalid_argument);  // 4 samples < order + 1
}
