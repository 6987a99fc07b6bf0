// clang-format off
// The malloc guard only defines macros and must precede every Eigen include; the
// header under test is then the first real include (it must compile on its own).
#include "../eigen_malloc_guard.hpp"
#include "softrne/sim/cvode.hpp"
// clang-format on

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "oscillator.hpp"
#include "softrne/signals/input_signal.hpp"

namespace sim_test_cvode {

using Eigen::Ref;
using Eigen::VectorXd;
using softrne::sim::CvodeOptions;
using softrne::sim::integrate;
using softrne::sim::SimulationResult;
using softrne_test::Oscillator;
using softrne_test::StepForce;

// ---- systems ----------------------------------------------------------------------

// x'' + 2 zeta w x' + w^2 x = F(t), F a zero-order-hold InputSignal, evaluated
// from the right at every t (as a naive system would).
struct ForcedOscillator {
  Oscillator osc;
  softrne::signals::InputSignal force;
  double segment_end = std::numeric_limits<double>::infinity();
  long calls = 0;
  bool forbid_malloc = false;  // forbid Eigen heap allocation from the first rhs call on

  int size() const { return 2; }
  void rhs(double t, const Ref<const VectorXd>& x, Ref<VectorXd> xdot) {
    if (forbid_malloc) Eigen::internal::set_is_malloc_allowed(false);
    ++calls;
    Eigen::Matrix<double, 1, 1> F;
    // At the end of a segment, the value held before the jump (see cvode.hpp).
    using softrne::signals::Side;
    force.value(t, F, t >= segment_end ? Side::left : Side::right);
    xdot[0] = x[1];
    xdot[1] = F[0] - 2.0 * osc.zeta * osc.w * x[1] - osc.w * osc.w * x[0];
  }
  bool jacobian(double, const Ref<const VectorXd>&, const Ref<const VectorXd>&,
                Ref<Eigen::MatrixXd> J) {
    J(0, 1) = 1.0;  // J arrives zeroed
    J(1, 0) = -osc.w * osc.w;
    J(1, 1) = -2.0 * osc.zeta * osc.w;
    return true;
  }
};

// The same, told each segment's window, so the last step of a segment sees the
// force held before the breakpoint.
struct SegmentAwareOscillator : ForcedOscillator {
  std::size_t segments_seen = 0;
  void set_segment(std::size_t k, double, double t_end) {
    segments_seen = k + 1;
    segment_end = t_end;
  }
};

// Same dynamics, no jacobian(): CVODE must use difference quotients.
struct OscillatorWithoutJacobian {
  SegmentAwareOscillator inner;
  long calls = 0;
  int size() const { return 2; }
  void rhs(double t, const Ref<const VectorXd>& x, Ref<VectorXd> xdot) {
    ++calls;
    inner.rhs(t, x, xdot);
  }
  void set_segment(std::size_t k, double t_begin, double t_end) {
    inner.set_segment(k, t_begin, t_end);
  }
};

const StepForce k_force{{0.5, 1.2345, 2.0, 3.0}, {0.0, 20.0, -10.0, 35.0, 0.0}};

template <class System>
void setup_oscillator(System& sys) {
  VectorXd t(5);
  t << 0.0, 0.5, 1.2345, 2.0, 3.0;
  VectorXd F(5);
  F << 0.0, 20.0, -10.0, 35.0, 0.0;
  using softrne::signals::Interpolation;
  sys.force = softrne::signals::InputSignal(t, F, Interpolation::zero_order_hold);
}

VectorXd oscillator_output_times() {
  VectorXd t(501);
  for (int i = 0; i <= 500; ++i) t[i] = i / 100.0;  // includes 0.5, 2.0, 3.0 exactly; not 1.2345
  return t;
}

const Eigen::Vector2d k_x0(0.01, 0.2);

struct ErrorNorms {
  double position = 0, velocity = 0;
};
ErrorNorms oscillator_errors(const SimulationResult& r, const VectorXd& times) {
  ErrorNorms e;
  const Oscillator osc;
  for (Eigen::Index i = 0; i < r.x.rows(); ++i) {
    const Eigen::Vector2d exact = k_force.exact(osc, k_x0, 0.0, times[i]);
    e.position = std::max(e.position, std::abs(r.x(i, 0) - exact[0]));
    e.velocity = std::max(e.velocity, std::abs(r.x(i, 1) - exact[1]));
  }
  return e;
}

void print_stats(const char* label, const SimulationResult& r, const ErrorNorms& e) {
  const auto& s = r.stats;
  std::printf(
      "[stats] %-38s steps %5ld  rhs %6ld  jac %4ld  rhs_fd %5ld  etf %4ld  ncf %3ld  restarts "
      "%2ld  "
      "err_x %.2e  err_v %.2e  %.2f ms\n",
      label, s.steps, s.rhs_evals, s.jac_evals, s.rhs_evals_for_jacobian_fd, s.error_test_failures,
      s.nonlinear_convergence_failures, s.restarts, e.position, e.velocity, 1e3 * s.wall_seconds);
}

CvodeOptions tight() {
  CvodeOptions opt;
  opt.rtol = 1e-10;
  opt.atol = 1e-12;
  return opt;
}

// ---- damped oscillator with step inputs -------------------------------------------------

TEST(Cvode, StepForcedOscillatorAnalyticJacobian) {
  SegmentAwareOscillator sys;
  setup_oscillator(sys);
  const VectorXd times = oscillator_output_times();
  const SimulationResult r = integrate(sys, k_x0, times, k_force.breaks, tight());
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.message, "");
  EXPECT_EQ(r.x.rows(), times.size());
  EXPECT_EQ(r.t_reached, 5.0);
  const ErrorNorms e = oscillator_errors(r, times);
  print_stats("breakpoints + set_segment, analytic J", r, e);
  EXPECT_LT(e.position, 1e-8);
  EXPECT_LT(e.velocity, 1e-8 * sys.osc.w);
  EXPECT_EQ(r.stats.restarts, 4);
  EXPECT_EQ(sys.segments_seen, 5u);
  EXPECT_GT(r.stats.jac_evals, 0);
  EXPECT_EQ(r.stats.rhs_evals_for_jacobian_fd, 0);
  // Every rhs call is accounted for, across the restarts.
  EXPECT_EQ(sys.calls, r.stats.rhs_evals + r.stats.rhs_evals_for_jacobian_fd);
}

TEST(Cvode, StepForcedOscillatorFiniteDifferenceJacobian) {
  const VectorXd times = oscillator_output_times();
  // Disabled by option ...
  SegmentAwareOscillator sys;
  setup_oscillator(sys);
  CvodeOptions opt = tight();
  opt.use_analytic_jacobian = false;
  const SimulationResult r = integrate(sys, k_x0, times, k_force.breaks, opt);
  ASSERT_TRUE(r.ok) << r.message;
  const ErrorNorms e = oscillator_errors(r, times);
  print_stats("breakpoints + set_segment, FD J (option)", r, e);
  EXPECT_LT(e.position, 1e-8);
  EXPECT_LT(e.velocity, 1e-8 * sys.osc.w);
  EXPECT_GT(r.stats.rhs_evals_for_jacobian_fd, 0);
  EXPECT_EQ(sys.calls, r.stats.rhs_evals + r.stats.rhs_evals_for_jacobian_fd);

  // ... or absent from the system.
  OscillatorWithoutJacobian sys2;
  setup_oscillator(sys2.inner);
  const SimulationResult r2 = integrate(sys2, k_x0, times, k_force.breaks, tight());
  ASSERT_TRUE(r2.ok) << r2.message;
  EXPECT_LT(oscillator_errors(r2, times).position, 1e-8);
  EXPECT_GT(r2.stats.rhs_evals_for_jacobian_fd, 0);
  EXPECT_EQ(sys2.calls, r2.stats.rhs_evals + r2.stats.rhs_evals_for_jacobian_fd);
  EXPECT_EQ(r2.stats.steps, r.stats.steps);  // same method, same decisions
}

TEST(Cvode, StepForcedOscillatorWithoutSegmentHintOrBreakpoints) {
  const VectorXd times = oscillator_output_times();
  SegmentAwareOscillator reference_sys;
  setup_oscillator(reference_sys);
  const SimulationResult reference = integrate(reference_sys, k_x0, times, k_force.breaks, tight());
  ASSERT_TRUE(reference.ok);

  // Breakpoints, but the rhs sees the new force at the end of each segment.
  ForcedOscillator naive;
  setup_oscillator(naive);
  const SimulationResult r1 = integrate(naive, k_x0, times, k_force.breaks, tight());
  ASSERT_TRUE(r1.ok) << r1.message;
  const ErrorNorms e1 = oscillator_errors(r1, times);
  print_stats("breakpoints, no set_segment", r1, e1);
  EXPECT_LT(e1.position, 1e-8);
  EXPECT_EQ(r1.stats.restarts, 4);
  EXPECT_GT(r1.stats.error_test_failures, reference.stats.error_test_failures);

  // No breakpoints: CVODE steps across the jumps and finds them by error test failures.
  ForcedOscillator blind;
  setup_oscillator(blind);
  const SimulationResult r2 = integrate(blind, k_x0, times, {}, tight());
  ASSERT_TRUE(r2.ok) << r2.message;
  const ErrorNorms e2 = oscillator_errors(r2, times);
  print_stats("no breakpoints", r2, e2);
  EXPECT_EQ(r2.stats.restarts, 0);
  EXPECT_LT(e2.position, 1e-6);
  EXPECT_GT(r2.stats.rhs_evals, reference.stats.rhs_evals);
  EXPECT_EQ(blind.calls, r2.stats.rhs_evals + r2.stats.rhs_evals_for_jacobian_fd);
}

TEST(Cvode, BreakpointsPayOffAtDefaultTolerances) {
  const VectorXd times = oscillator_output_times();
  const CvodeOptions opt;  // rtol 1e-6, atol 1e-8
  SegmentAwareOscillator aware;
  setup_oscillator(aware);
  const SimulationResult r1 = integrate(aware, k_x0, times, k_force.breaks, opt);
  ForcedOscillator naive;
  setup_oscillator(naive);
  const SimulationResult r2 = integrate(naive, k_x0, times, k_force.breaks, opt);
  ForcedOscillator blind;
  setup_oscillator(blind);
  const SimulationResult r3 = integrate(blind, k_x0, times, {}, opt);
  ASSERT_TRUE(r1.ok && r2.ok && r3.ok);
  const ErrorNorms e1 = oscillator_errors(r1, times), e2 = oscillator_errors(r2, times),
                   e3 = oscillator_errors(r3, times);
  print_stats("default tol: breakpoints + set_segment", r1, e1);
  print_stats("default tol: breakpoints, no set_segment", r2, e2);
  print_stats("default tol: no breakpoints", r3, e3);
  EXPECT_LT(e1.position, 1e-5);
  EXPECT_LT(r1.stats.rhs_evals, r2.stats.rhs_evals);
  EXPECT_LT(r1.stats.rhs_evals, r3.stats.rhs_evals);
  EXPECT_LT(r1.stats.error_test_failures, r3.stats.error_test_failures);
}

TEST(Cvode, CallbacksDoNotAllocate) {
  const VectorXd times = oscillator_output_times();
  for (bool analytic : {true, false}) {
    SegmentAwareOscillator sys;
    setup_oscillator(sys);
    sys.forbid_malloc = true;
    CvodeOptions opt = tight();
    opt.use_analytic_jacobian = analytic;
    const long before = softrne_test::eigen_assert_failures;
    const SimulationResult r = integrate(sys, k_x0, times, k_force.breaks, opt);
    Eigen::internal::set_is_malloc_allowed(true);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_EQ(softrne_test::eigen_assert_failures, before) << "analytic Jacobian: " << analytic;
  }
}

// ---- stiff linear system ---------------------------------------------------------------

// xdot = A x with A = V diag(-1, -1e4) V^-1.
struct StiffLinear {
  Eigen::Matrix2d V, A;
  StiffLinear() {
    V << 1.0, 1.0, 0.5, -1.0;
    A = V * Eigen::Vector2d(-1.0, -1e4).asDiagonal() * V.inverse();
  }
  Eigen::Vector2d exact(const Eigen::Vector2d& x0, double t) const {
    return V * Eigen::Vector2d(std::exp(-t), std::exp(-1e4 * t)).asDiagonal() * V.inverse() * x0;
  }
  int size() const { return 2; }
  void rhs(double, const Ref<const VectorXd>& x, Ref<VectorXd> xdot) { xdot.noalias() = A * x; }
  void jacobian(double, const Ref<const VectorXd>&, const Ref<const VectorXd>&,
                Ref<Eigen::MatrixXd> J) {
    J = A;
  }
};

TEST(Cvode, StiffLinearSystemMatchesMatrixExponential) {
  StiffLinear sys;
  const Eigen::Vector2d x0(1.0, 2.0);
  VectorXd times(15);
  times << 0, 1e-5, 1e-4, 3e-4, 1e-3, 1e-2, 0.1, 0.5, 1, 2, 3, 5, 7, 9, 10;
  for (bool analytic : {true, false}) {
    CvodeOptions opt = tight();
    opt.use_analytic_jacobian = analytic;
    const SimulationResult r = integrate(sys, x0, times, {}, opt);
    ASSERT_TRUE(r.ok) << r.message;
    double err = 0;
    for (Eigen::Index i = 0; i < times.size(); ++i)
      err = std::max(err, (r.x.row(i).transpose() - sys.exact(x0, times[i])).cwiseAbs().maxCoeff());
    std::printf("[stats] stiff, %s J: steps %ld rhs %ld jac %ld rhs_fd %ld err %.2e\n",
                analytic ? "analytic" : "FD", r.stats.steps, r.stats.rhs_evals, r.stats.jac_evals,
                r.stats.rhs_evals_for_jacobian_fd, err);
    EXPECT_LT(err, 1e-8);
    // An explicit method would need ~1e5 steps (|lambda| dt < ~2.8) for the 10 s.
    EXPECT_LT(r.stats.steps, 3000);
  }
}

// ---- failure modes ----------------------------------------------------------------------

struct Decay {
  double nan_after = std::numeric_limits<double>::infinity();
  std::chrono::microseconds sleep{0};
  int size() const { return 1; }
  void rhs(double t, const Ref<const VectorXd>& x, Ref<VectorXd> xdot) {
    if (sleep.count() > 0) std::this_thread::sleep_for(sleep);
    xdot[0] = t > nan_after ? std::numeric_limits<double>::quiet_NaN() : -x[0];
  }
};

VectorXd linspace(double a, double b, int n) {
  return VectorXd::LinSpaced(n, a, b);
}

// The number after the first "t = " in a message.
double time_in_message(const std::string& message) {
  const auto pos = message.find("t = ");
  return pos == std::string::npos ? std::numeric_limits<double>::quiet_NaN()
                                  : std::stod(message.substr(pos + 4));
}

TEST(Cvode, NonFiniteRhsStopsWithTimeInMessage) {
  Decay sys;
  sys.nan_after = 1.0;
  const VectorXd times = linspace(0.0, 3.0, 31);
  testing::internal::CaptureStderr();
  const SimulationResult r = integrate(sys, VectorXd::Ones(1), times, {}, tight());
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "");  // silent
  ASSERT_FALSE(r.ok);
  std::printf("[message] %s\n", r.message.c_str());
  EXPECT_EQ(r.message.find('\n'), std::string::npos);
  EXPECT_NE(r.message.find("non-finite"), std::string::npos) << r.message;
  EXPECT_GT(r.t_reached, 0.9);
  EXPECT_LE(r.t_reached, 1.0 + 1e-9);
  EXPECT_NEAR(time_in_message(r.message), r.t_reached, 1e-8);
  // Rows for the outputs reached (0, 0.1, ..., up to t_reached), all finite.
  EXPECT_GE(r.x.rows(), 10);
  EXPECT_LE(r.x.rows(), 11);
  EXPECT_TRUE(r.x.allFinite());
  for (Eigen::Index i = 0; i < r.x.rows(); ++i) EXPECT_NEAR(r.x(i, 0), std::exp(-times[i]), 1e-8);
}

TEST(Cvode, TooManyStepsStopsWithTimeInMessage) {
  SegmentAwareOscillator sys;
  setup_oscillator(sys);
  CvodeOptions opt = tight();
  opt.max_steps = 50;
  testing::internal::CaptureStderr();
  const SimulationResult r = integrate(sys, k_x0, oscillator_output_times(), k_force.breaks, opt);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  ASSERT_FALSE(r.ok);
  std::printf("[message] %s\n", r.message.c_str());
  EXPECT_EQ(r.message.rfind("CVODE failed at t = ", 0), 0u) << r.message;
  EXPECT_NE(r.message.find("too many steps (50)"), std::string::npos) << r.message;
  EXPECT_NEAR(time_in_message(r.message), r.t_reached, 1e-8 * (1 + r.t_reached));
  EXPECT_GT(r.t_reached, 0.0);
  EXPECT_LT(r.t_reached, 5.0);
  EXPECT_LE(r.stats.steps, 50);
  EXPECT_TRUE(r.x.allFinite());
}

TEST(Cvode, WallClockLimit) {
  Decay sys;
  sys.sleep = std::chrono::microseconds(500);
  CvodeOptions opt = tight();
  opt.max_wall_seconds = 0.05;
  const auto start = std::chrono::steady_clock::now();
  const SimulationResult r = integrate(sys, VectorXd::Ones(1), linspace(0.0, 100.0, 3), {}, opt);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(r.ok);
  std::printf("[message] %s\n", r.message.c_str());
  EXPECT_NE(r.message.find("wall-clock limit (0.05 s) exceeded"), std::string::npos) << r.message;
  EXPECT_NEAR(time_in_message(r.message), r.t_reached, 1e-8 * (1 + r.t_reached));
  EXPECT_LT(seconds, 0.5);
  EXPECT_GE(r.stats.wall_seconds, 0.05);
}

TEST(Cvode, RecoverableRhsFailureIsRetried) {
  struct Flaky {
    long calls = 0;
    int size() const { return 1; }
    bool rhs(double, const Ref<const VectorXd>& x, Ref<VectorXd> xdot) {
      xdot[0] = -x[0];
      return ++calls % 7 != 0;  // every 7th evaluation refuses
    }
  } sys;
  const VectorXd times = linspace(0.0, 2.0, 5);
  const SimulationResult r = integrate(sys, VectorXd::Ones(1), times, {}, tight());
  ASSERT_TRUE(r.ok) << r.message;
  for (Eigen::Index i = 0; i < times.size(); ++i) EXPECT_NEAR(r.x(i, 0), std::exp(-times[i]), 1e-8);
}

TEST(Cvode, ExceptionFromRhsPropagates) {
  struct Throws {
    int size() const { return 1; }
    void rhs(double t, const Ref<const VectorXd>& x, Ref<VectorXd> xdot) {
      if (t > 0.5) throw std::runtime_error("boom");
      xdot = -x;
    }
  } sys;
  EXPECT_THROW(integrate(sys, VectorXd::Ones(1), linspace(0.0, 1.0, 3), {}), std::runtime_error);
}

TEST(Cvode, InvalidArguments) {
  Decay sys;
  SimulationResult r = integrate(sys, VectorXd::Ones(2), linspace(0.0, 1.0, 3), {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("x0 has size 2"), std::string::npos) << r.message;
  VectorXd times(3);
  times << 0.0, 1.0, 1.0;
  r = integrate(sys, VectorXd::Ones(1), times, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("not strictly increasing"), std::string::npos) << r.message;
  r = integrate(sys, VectorXd::Ones(1), VectorXd(), {});
  EXPECT_FALSE(r.ok);
  r = integrate(sys, VectorXd::Constant(1, std::nan("")), linspace(0.0, 1.0, 3), {});
  EXPECT_FALSE(r.ok);
}

TEST(Cvode, SingleOutputTimeAndBreakpointsOutsideRange) {
  Decay sys;
  SimulationResult r = integrate(sys, VectorXd::Ones(1), VectorXd::Constant(1, 2.0), {1.0, 3.0});
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.x.rows(), 1);
  EXPECT_EQ(r.x(0, 0), 1.0);
  // Breakpoints at or outside the ends, duplicated, unsorted: ignored or merged.
  const VectorXd times = linspace(1.0, 2.0, 11);
  r = integrate(sys, VectorXd::Ones(1), times, {2.0, 1.5, -4.0, 1.0, 1.5, 7.0}, tight());
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.stats.restarts, 1);
  for (Eigen::Index i = 0; i < times.size(); ++i)
    EXPECT_NEAR(r.x(i, 0), std::exp(-(times[i] - 1.0)), 1e-8);
}

}  // namespace sim_test_cvode
