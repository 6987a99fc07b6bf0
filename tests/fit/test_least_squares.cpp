// Included first: the header must compile on its own.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <random>
#include <thread>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include <softrne/fit/least_squares.hpp>
#include "../gauss.hpp"

namespace {

using softrne::fit::FitOptions;
using softrne::fit::FitResult;
using softrne::fit::GlobalMethod;
using softrne::fit::LocalMethod;
using softrne::fit::ParameterSet;
using softrne::fit::ResidualFactory;
using softrne::fit::ResidualFn;

using softrne::test::Gauss;

void expect_no_nan(const FitResult& r) {
  EXPECT_FALSE(r.params.hasNaN());
  EXPECT_FALSE(std::isnan(r.cost));
  EXPECT_FALSE(std::isnan(r.rms));
  EXPECT_FALSE(r.covariance.hasNaN());
  EXPECT_FALSE(r.std_errors.hasNaN());
  EXPECT_FALSE(r.relative_std_errors.hasNaN());
  EXPECT_FALSE(r.correlation.hasNaN());
  EXPECT_FALSE(std::isnan(r.condition_number));
  EXPECT_EQ(r.identifiable.size(), static_cast<std::size_t>(r.params.size()));
}

void expect_same(const FitResult& a, const FitResult& b) {
  ASSERT_EQ(a.params.size(), b.params.size());
  for (Eigen::Index i = 0; i < a.params.size(); ++i) {
    EXPECT_EQ(a.params[i], b.params[i]);
    EXPECT_EQ(a.std_errors[i], b.std_errors[i]);
  }
  EXPECT_EQ(a.cost, b.cost);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_EQ(a.failed_evaluations, b.failed_evaluations);
  EXPECT_EQ(a.converged, b.converged);
}

// ---- damped sinusoid y = a exp(-b t) sin(w t + c) ---------------------------

struct Sinusoid {
  static constexpr double a = 1.5, b = 0.7, w = 4.0, c = 0.3, sigma = 0.01;
  Eigen::VectorXd t, y;
  explicit Sinusoid(std::uint64_t noise_seed, int n = 200) : t(n), y(n) {
    Gauss g(noise_seed);
    for (int k = 0; k < n; ++k) {
      t[k] = 0.015 * k;
      y[k] = model(Eigen::Vector4d(a, b, w, c), t[k]) + sigma * g();
    }
  }
  static double model(const Eigen::VectorXd& x, double tk) {
    return x[0] * std::exp(-x[1] * tk) * std::sin(x[2] * tk + x[3]);
  }
  ResidualFn residual() const {
    return [this](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
      for (Eigen::Index k = 0; k < t.size(); ++k) r[k] = model(x, t[k]) - y[k];
      return true;
    };
  }
  static ParameterSet parameters(double a0, double b0, double w0, double c0) {
    return ParameterSet({{"a", a0, 0.1, 10.0, true},
                         {"b", b0, 0.01, 10.0, true},
                         {"w", w0, 0.5, 20.0, true},
                         {"c", c0, -M_PI, M_PI, false}});
  }
  // Asymptotic std errors sigma^2 (J^T J)^{-1} at the truth, analytic J.
  Eigen::Vector4d analytic_std_errors() const {
    Eigen::MatrixXd J(t.size(), 4);
    for (Eigen::Index k = 0; k < t.size(); ++k) {
      const double e = std::exp(-b * t[k]), s = std::sin(w * t[k] + c), co = std::cos(w * t[k] + c);
      J.row(k) << e * s, -t[k] * a * e * s, t[k] * a * e * co, a * e * co;
    }
    const Eigen::MatrixXd cov = sigma * sigma * (J.transpose() * J).inverse();
    return cov.diagonal().cwiseSqrt();
  }
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TEST(FitLeastSquares, DampedSinusoidRecoversParameters) {
  const Sinusoid data(1);
  const Eigen::Vector4d truth(Sinusoid::a, Sinusoid::b, Sinusoid::w, Sinusoid::c);
  const Eigen::Vector4d se_true = data.analytic_std_errors();
  // Starting guesses off by 0.5x - 2x.
  const std::vector<Eigen::Vector4d> starts = {
      {3.0, 0.35, 6.0, 0.6}, {0.75, 1.4, 2.0, 0.15}, {3.0, 1.4, 8.0, 0.6}};
  for (const Eigen::Vector4d& x0 : starts) {
    const auto t0 = std::chrono::steady_clock::now();
    const FitResult res =
        softrne::fit::fit_least_squares(Sinusoid::parameters(x0[0], x0[1], x0[2], x0[3]),
                                        static_cast<int>(data.t.size()), data.residual());
    std::printf("start (%g %g %g %g): %d evaluations in %.2f ms, rms %.5f, %s\n", x0[0], x0[1],
                x0[2], x0[3], res.evaluations, 1e3 * seconds_since(t0), res.rms,
                res.message.c_str());
    expect_no_nan(res);
    EXPECT_TRUE(res.converged) << res.message;
    EXPECT_NEAR(res.rms, Sinusoid::sigma, 0.15 * Sinusoid::sigma);
    ASSERT_EQ(res.residual.size(), data.t.size());
    EXPECT_DOUBLE_EQ(0.5 * res.residual.squaredNorm(), res.cost);
    for (int i = 0; i < 4; ++i) {
      EXPECT_LT(std::abs(res.params[i] - truth[i]), 4.0 * se_true[i]) << "parameter " << i;
      EXPECT_NEAR(res.std_errors[i], se_true[i], 0.15 * se_true[i]) << "parameter " << i;
      EXPECT_TRUE(res.identifiable[static_cast<std::size_t>(i)]);
    }
  }
}

TEST(FitLeastSquares, StdErrorsMatchMonteCarloSpread) {
  const int runs = 30;
  Eigen::MatrixXd estimates(runs, 4), reported(runs, 4);
  const auto t0 = std::chrono::steady_clock::now();
  int evaluations = 0;
  for (int s = 0; s < runs; ++s) {
    const Sinusoid data(1000 + static_cast<std::uint64_t>(s));
    const FitResult res =
        softrne::fit::fit_least_squares(Sinusoid::parameters(3.0, 0.35, 6.0, 0.6),
                                        static_cast<int>(data.t.size()), data.residual());
    ASSERT_TRUE(res.converged) << res.message;
    estimates.row(s) = res.params.transpose();
    reported.row(s) = res.std_errors.transpose();
    evaluations += res.evaluations;
  }
  const Eigen::RowVectorXd mean = estimates.colwise().mean();
  const Eigen::RowVectorXd spread =
      ((estimates.rowwise() - mean).array().square().colwise().sum() / (runs - 1)).sqrt();
  const Eigen::RowVectorXd mean_reported = reported.colwise().mean();
  const Eigen::Vector4d se_true = Sinusoid(1).analytic_std_errors();
  std::printf("30 fits: %.1f ms, %d evaluations\n", 1e3 * seconds_since(t0), evaluations);
  for (int i = 0; i < 4; ++i) {
    std::printf(
        "  param %d: Monte-Carlo spread %.3e, mean reported std error %.3e, analytic %.3e, ratio "
        "%.2f\n",
        i, spread[i], mean_reported[i], se_true[i], spread[i] / mean_reported[i]);
    EXPECT_NEAR(spread[i] / mean_reported[i], 1.0, 0.3) << "parameter " << i;
  }
}

TEST(FitLeastSquares, DeterministicAndParallelEqualsSerial) {
  const Sinusoid data(3);
  const ParameterSet ps = Sinusoid::parameters(3.0, 0.35, 6.0, 0.6);
  const int m = static_cast<int>(data.t.size());
  for (const GlobalMethod method : {GlobalMethod::multistart, GlobalMethod::crs2_lm}) {
    FitOptions opt;
    opt.seed = 17;
    opt.global_method = method;
    const FitResult first = softrne::fit::fit_least_squares(ps, m, data.residual(), opt);
    const FitResult second = softrne::fit::fit_least_squares(ps, m, data.residual(), opt);
    expect_same(first, second);

    // One functor per thread from the factory.
    std::atomic<int> made{0};
    const ResidualFactory factory = [&] {
      ++made;
      return data.residual();
    };
    FitOptions parallel = opt;
    parallel.threads = 2;
    const auto t0 = std::chrono::steady_clock::now();
    const FitResult par = softrne::fit::fit_least_squares(ps, m, factory, parallel);
    std::printf("threads=2: %.2f ms, %d evaluations\n", 1e3 * seconds_since(t0), par.evaluations);
    EXPECT_EQ(made.load(), 2);
    expect_same(first, par);
  }
  // Different seeds take different paths to the same optimum.
  FitOptions other;
  other.seed = 99;
  const FitResult a = softrne::fit::fit_least_squares(ps, m, data.residual());
  const FitResult b = softrne::fit::fit_least_squares(ps, m, data.residual(), other);
  EXPECT_LT((a.params - b.params).cwiseQuotient(a.std_errors).cwiseAbs().maxCoeff(), 1e-2);
}

TEST(FitLeastSquares, ParallelFactoryRunsOnSeveralThreads) {
  // Each functor records its thread; a slow residual makes the overlap visible.
  const Sinusoid data(5);
  std::mutex mutex;
  std::vector<std::thread::id> ids;
  const ResidualFactory factory = [&]() -> ResidualFn {
    return [&, base = data.residual()](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (std::find(ids.begin(), ids.end(), std::this_thread::get_id()) == ids.end())
          ids.push_back(std::this_thread::get_id());
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      return base(x, r);
    };
  };
  FitOptions opt;
  opt.threads = 2;
  opt.global_evals = 60;
  const FitResult res = softrne::fit::fit_least_squares(
      Sinusoid::parameters(3.0, 0.35, 6.0, 0.6), static_cast<int>(data.t.size()), factory, opt);
  EXPECT_TRUE(res.converged);
  EXPECT_GE(ids.size(), 2u);
}

TEST(FitLeastSquares, UnidentifiableProduct) {
  // y = (a b) t + c t^2: only a*b is determined, c is fine.
  Gauss g(11);
  const int n = 50;
  Eigen::VectorXd t(n), y(n);
  for (int k = 0; k < n; ++k) {
    t[k] = k / 49.0;
    y[k] = 2.0 * 1.5 * t[k] + 0.8 * t[k] * t[k] + 0.01 * g();
  }
  const ParameterSet ps(
      {{"a", 1.0, 0.1, 10.0, true}, {"b", 1.0, 0.1, 10.0, true}, {"c", 0.0, -5.0, 5.0, false}});
  const ResidualFn residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    r = (x[0] * x[1]) * t + x[2] * t.cwiseProduct(t) - y;
    return true;
  };
  const FitResult res = softrne::fit::fit_least_squares(ps, n, residual);
  std::printf("%s", res.identifiability_report.c_str());
  expect_no_nan(res);
  EXPECT_NEAR(res.params[0] * res.params[1], 3.0, 0.05);
  EXPECT_NEAR(res.params[2], 0.8, 0.1);
  EXPECT_FALSE(res.identifiable[0]);
  EXPECT_FALSE(res.identifiable[1]);
  EXPECT_TRUE(res.identifiable[2]);
  EXPECT_TRUE(std::isinf(res.std_errors[0]));
  EXPECT_TRUE(std::isfinite(res.std_errors[2]));
  EXPECT_GT(res.condition_number, 1e6);
  EXPECT_GT(std::abs(res.correlation(0, 1)), 0.95);
  EXPECT_NE(res.identifiability_report.find("correlated: a and b"), std::string::npos);
  EXPECT_NE(res.identifiability_report.find("null direction"), std::string::npos);
}

TEST(FitLeastSquares, LinearModelCovarianceIsClosedForm) {
  // y = a + b t: the fit is linear least squares, covariance s^2 (X^T X)^{-1}.
  Gauss g(5);
  const int n = 20;
  Eigen::MatrixXd X(n, 2);
  Eigen::VectorXd y(n);
  for (int k = 0; k < n; ++k) {
    X.row(k) << 1.0, 0.5 * k;
    y[k] = 0.7 - 0.3 * X(k, 1) + 0.05 * g();
  }
  const ParameterSet ps({{"a", 0.0, -10.0, 10.0, false}, {"b", 1.0, -10.0, 10.0, false}});
  const ResidualFn residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    r = X * x - y;
    return true;
  };
  const FitResult res = softrne::fit::fit_least_squares(ps, n, residual);
  const Eigen::Vector2d x_ls = (X.transpose() * X).ldlt().solve(X.transpose() * y);
  const double s2 = (X * x_ls - y).squaredNorm() / (n - 2);
  const Eigen::Matrix2d cov = s2 * (X.transpose() * X).inverse();
  EXPECT_LT((res.params - x_ls).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((res.covariance - cov).cwiseAbs().maxCoeff(), 1e-6 * cov.cwiseAbs().maxCoeff());
  EXPECT_NEAR(res.correlation(0, 1), cov(0, 1) / std::sqrt(cov(0, 0) * cov(1, 1)), 1e-6);
  // The analysis alone, at a given point, agrees.
  FitResult at_ls;
  at_ls.params = x_ls;
  softrne::fit::analyse_identifiability(ps, n, residual, at_ls);
  EXPECT_LT((at_ls.covariance - cov).cwiseAbs().maxCoeff(), 1e-6 * cov.cwiseAbs().maxCoeff());
  EXPECT_NEAR(at_ls.cost, 0.5 * (X * x_ls - y).squaredNorm(), 1e-14);
  EXPECT_TRUE(at_ls.identifiable[0] && at_ls.identifiable[1]);
}

TEST(FitLeastSquares, FailingResidualRegions) {
  // y = a exp(-b t); the model "diverges" (false) when a + b > 3.05, gives NaN
  // when b < 0.3 and throws when a > 8. Optimum (2, 1) sits next to the edge.
  Gauss g(21);
  const int n = 40;
  Eigen::VectorXd t(n), y(n);
  for (int k = 0; k < n; ++k) {
    t[k] = 0.05 * k;
    y[k] = 2.0 * std::exp(-1.0 * t[k]) + 0.01 * g();
  }
  const ResidualFn residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    if (x[0] > 8.0) throw std::runtime_error("blew up");
    if (x[0] + x[1] > 3.05) return false;
    for (int k = 0; k < n; ++k) r[k] = x[1] < 0.3 ? NAN : x[0] * std::exp(-x[1] * t[k]) - y[k];
    return true;
  };
  const ParameterSet ps({{"a", 1.0, 0.1, 10.0, true}, {"b", 1.9, 0.05, 5.0, true}});
  for (const GlobalMethod method :
       {GlobalMethod::multistart, GlobalMethod::crs2_lm, GlobalMethod::direct_l}) {
    FitOptions opt;
    opt.global_method = method;
    const FitResult res = softrne::fit::fit_least_squares(ps, n, residual, opt);
    expect_no_nan(res);
    EXPECT_TRUE(res.converged) << res.message;
    EXPECT_GT(res.failed_evaluations, 0);
    EXPECT_NEAR(res.params[0], 2.0, 0.03) << res.message;
    EXPECT_NEAR(res.params[1], 1.0, 0.03) << res.message;
    EXPECT_NEAR(res.rms, 0.01, 0.003);
    EXPECT_TRUE(res.std_errors.allFinite());
  }
  // Starting in the failing region with no global stage: LM cannot start.
  FitOptions local_only;
  local_only.global_evals = 0;
  const FitResult stuck = softrne::fit::fit_least_squares(
      ParameterSet({{"a", 5.0, 0.1, 10.0, true}, {"b", 1.9, 0.05, 5.0, true}}), n, residual,
      local_only);
  expect_no_nan(stuck);
  EXPECT_FALSE(stuck.converged);
  EXPECT_TRUE(std::isinf(stuck.cost));
  EXPECT_EQ(stuck.residual.size(), 0);
  EXPECT_NE(stuck.message.find("fails at the starting point"), std::string::npos);
  // ... but the global stage finds the valid region from there.
  const FitResult found = softrne::fit::fit_least_squares(
      ParameterSet({{"a", 5.0, 0.1, 10.0, true}, {"b", 1.9, 0.05, 5.0, true}}), n, residual);
  EXPECT_TRUE(found.converged);
  EXPECT_NEAR(found.params[0], 2.0, 0.03);
}

TEST(FitLeastSquares, AlwaysFailingResidual) {
  const ResidualFn residual = [](const Eigen::VectorXd&, Eigen::VectorXd&) { return false; };
  const ParameterSet ps({{"a", 1.0, 0.1, 10.0, true}});
  const FitResult res = softrne::fit::fit_least_squares(ps, 5, residual);
  expect_no_nan(res);
  EXPECT_FALSE(res.converged);
  EXPECT_EQ(res.params[0], 1.0);
  EXPECT_EQ(res.failed_evaluations, res.evaluations);
  EXPECT_NE(res.message.find("no point"), std::string::npos);
}

TEST(FitLeastSquares, RosenbrockFromBadStarts) {
  const ResidualFn rosenbrock = [](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    r << 10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0];
    return true;
  };
  for (const Eigen::Vector2d& x0 :
       {Eigen::Vector2d(-1.2, 1.0), Eigen::Vector2d(-4.0, -4.0), Eigen::Vector2d(4.5, -3.0)}) {
    const ParameterSet ps({{"x", x0[0], -5.0, 5.0, false}, {"y", x0[1], -5.0, 5.0, false}});
    FitOptions local_only;
    local_only.global_evals = 0;
    FitOptions crs;
    crs.global_method = GlobalMethod::crs2_lm;
    FitOptions bobyqa;
    bobyqa.local_method = LocalMethod::bobyqa_then_lm;
    FitOptions central;
    central.central_differences = true;
    central.global_evals = 0;
    for (const FitOptions& opt : {FitOptions{}, local_only, crs, bobyqa, central}) {
      const FitResult res = softrne::fit::fit_least_squares(ps, 2, rosenbrock, opt);
      expect_no_nan(res);
      EXPECT_TRUE(res.converged) << res.message;
      EXPECT_LT(std::abs(res.params[0] - 1.0), 1e-6) << res.message;
      EXPECT_LT(std::abs(res.params[1] - 1.0), 1e-6) << res.message;
    }
  }
}

TEST(FitLeastSquares, OptimumOnABound) {
  // y = a t with a_true = 2 but a <= 1: the fit stops at the bound.
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(10, 0.0, 1.0);
  const ResidualFn residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    r = x[0] * t - 2.0 * t;
    return true;
  };
  const FitResult res =
      softrne::fit::fit_least_squares(ParameterSet({{"a", 0.5, 0.0, 1.0, false}}), 10, residual);
  expect_no_nan(res);
  EXPECT_TRUE(res.converged) << res.message;
  EXPECT_EQ(res.params[0], 1.0);
  EXPECT_NE(res.identifiability_report.find("at a bound"), std::string::npos);
}

TEST(FitLeastSquares, ProgressAndWallClockLimit) {
  const Sinusoid data(9);
  std::vector<std::pair<int, double>> calls;
  FitOptions opt;
  opt.progress = [&](int evals, double best) { calls.emplace_back(evals, best); };
  const FitResult res =
      softrne::fit::fit_least_squares(Sinusoid::parameters(3.0, 0.35, 6.0, 0.6),
                                      static_cast<int>(data.t.size()), data.residual(), opt);
  ASSERT_GE(calls.size(), 3u);
  for (std::size_t k = 1; k < calls.size(); ++k) {
    EXPECT_GE(calls[k].first, calls[k - 1].first);
    EXPECT_LE(calls[k].second, calls[k - 1].second);
  }
  EXPECT_EQ(calls.back().second, res.cost);

  // A slow residual (2 ms) with a 0.1 s limit stops early and says so.
  const ResidualFn slow = [base = data.residual()](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    return base(x, r);
  };
  FitOptions limited;
  limited.max_wall_seconds = 0.1;
  const auto t0 = std::chrono::steady_clock::now();
  const FitResult cut = softrne::fit::fit_least_squares(
      Sinusoid::parameters(3.0, 0.35, 6.0, 0.6), static_cast<int>(data.t.size()), slow, limited);
  const double elapsed = seconds_since(t0);
  expect_no_nan(cut);
  EXPECT_LT(elapsed, 0.5);
  EXPECT_FALSE(cut.converged);
  EXPECT_NE(cut.message.find("wall-clock"), std::string::npos) << cut.message;
}
