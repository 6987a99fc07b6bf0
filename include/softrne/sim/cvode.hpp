#pragma once
/// \file
/// \brief softrne::sim::integrate: a generic ODE system \f$\dot x = f(t, x)\f$
/// integrated by SUNDIALS CVODE (variable-order BDF, Newton with a dense direct
/// linear solver), stopping and restarting at input discontinuities.
///
/// Knows nothing about robots. The System concept (duck-typed):
/// \code
///   int size() const;                                       // state dimension n
///   void rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
///            Eigen::Ref<Eigen::VectorXd> xdot);             // or return bool:
///                                                           // false = recoverable
///   // optional, detected: analytic Jacobian df/dx (J is zeroed before the call)
///   bool jacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
///                 const Eigen::Ref<const Eigen::VectorXd>& f,
///                 Eigen::Ref<Eigen::MatrixXd> J);           // or void
///   // optional, detected: called before integrating each segment between
///   // breakpoints, segment k spanning [t_begin, t_end] (one of the forms; the
///   // first receives the state at t_begin: a controller sampled at the
///   // breakpoints, sim/closed_loop.hpp)
///   void set_segment(std::size_t k, double t_begin, double t_end,
///                    const Eigen::Ref<const Eigen::VectorXd>& x);
///   void set_segment(std::size_t k, double t_begin, double t_end);
///   void set_segment(std::size_t k);
/// \endcode
///
/// Discontinuous inputs. CVODE is told to stop exactly at each breakpoint and
/// is re-initialised there, so no step straddles a jump. The last step of a
/// segment evaluates f at \f$t_{end}\f$ itself: a zero-order-hold input must
/// give there the value held *before* the jump, or the error test sees the
/// jump and shrinks the step to ~tolerance/jump. Use set_segment and e.g.
/// `u.value(t, out, t >= t_end ? Side::left : Side::right)` (signals::InputSignal).
///
/// Callbacks receive Eigen::Map views of CVODE's own vectors: declare their
/// parameters as `Eigen::Ref` (or templates), not `const Eigen::VectorXd&`,
/// which would copy the state into a new heap vector on every call.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_types.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "softrne/sim/eigen_linear_solver.hpp"
#include "softrne/sim/serial_vector_ops.hpp"

namespace softrne::sim {

/// \brief Settings of one integrate() call.
struct CvodeOptions {
  double rtol = 1e-6;           ///< relative tolerance
  double atol = 1e-8;           ///< absolute tolerance (all components)
  long max_steps = 100000;      ///< internal steps in total over the run
  double max_wall_seconds = 0;  ///< wall-clock limit; 0 = none

  /// Cancellation: when `*stop` becomes true (a tool's SIGINT handler sets it), the run
  /// fails at the next right-hand-side evaluation with "stopped on request". Null: never.
  /// A fit or the closed loop built on these runs then ends within one simulation step.
  const std::atomic<bool>* stop = nullptr;
  double max_step = 0;          ///< largest step size; 0 = CVODE default (none)

  /// Smallest step size; 0 = a roundoff floor, 256 eps max(1, |t0|, |t_end|).
  /// Without a floor, an rhs that fails for all t > t* makes CVODE creep up to
  /// t* until t + h == t and then spin there until max_steps is exhausted.
  double min_step = 0;
  int max_order = 5;                  ///< BDF order limit, 1..5

  /// Steps between Jacobian evaluations, at most (CVodeSetJacEvalFrequency; 0 = CVODE's 51).
  /// CVODE evaluates the Jacobian anew whenever Newton's iteration fails to converge with the
  /// one it holds, so an old Jacobian costs iterations, never accuracy. The arms' Jacobians
  /// change slowly: 1000 evaluated about 13 times fewer of them than 51 on the bundled and
  /// eight random arms, with the same number of steps and fewer right-hand sides
  /// (docs/performance.md).
  long jacobian_max_age = 1000;
  /// Steps between updates of the Newton matrix \f$I - \gamma J\f$ (its LU factors), at most
  /// (CVodeSetLSetupFrequency; 0 = CVODE's 20). CVODE also updates it when \f$\gamma\f$ has
  /// changed by more than 30 % and after a convergence failure.
  long newton_matrix_max_age = 100;
  bool use_analytic_jacobian = true;  ///< use System::jacobian when present
  bool verbose = false;               ///< also print CVODE's messages to stderr
};

/// \brief Solver counters summed over every restart.
struct SimulationStats {
  long steps = 0;                           ///< accepted internal steps
  long rhs_evals = 0;                       ///< f evaluations by the integrator
  long jac_evals = 0;                       ///< Jacobian evaluations (analytic or by differences)
  long rhs_evals_for_jacobian_fd = 0;       ///< extra f evaluations for difference Jacobians
  long error_test_failures = 0;             ///< steps rejected by the local error test
  long nonlinear_convergence_failures = 0;  ///< Newton convergence failures
  long restarts = 0;                        ///< re-initialisations at breakpoints
  double wall_seconds = 0;                  ///< wall-clock time of the whole call

  /// \brief Adds another run's counters (several integrations reported as one).
  /// \param[in] o The other run's statistics.
  /// \return This.
  SimulationStats& operator+=(const SimulationStats& o) {
    steps += o.steps;
    rhs_evals += o.rhs_evals;
    jac_evals += o.jac_evals;
    rhs_evals_for_jacobian_fd += o.rhs_evals_for_jacobian_fd;
    error_test_failures += o.error_test_failures;
    nonlinear_convergence_failures += o.nonlinear_convergence_failures;
    restarts += o.restarts;
    wall_seconds += o.wall_seconds;
    return *this;
  }
};

/// \brief Output of integrate().
struct SimulationResult {
  bool ok = false;  ///< the integration reached the last output time

  /// "" when ok; else one line: the reason and the time reached, e.g.
  /// "CVODE failed at t = 3.217 s: too many steps (100000)".
  std::string message;
  double t_reached = 0;  ///< last time the solution is known at

  /// One row per output time reached (all of them when ok), one column per state.
  Eigen::MatrixXd x;
  SimulationStats stats;  ///< solver statistics (steps, evaluations, time)
};

namespace detail {

// ---- System concept detection -------------------------------------------------

using ConstVectorMap = Eigen::Map<const Eigen::VectorXd>;
using VectorMap = Eigen::Map<Eigen::VectorXd>;
using MatrixMap = Eigen::Map<Eigen::MatrixXd>;

template <class S, class = void>
struct has_size : std::false_type {};
template <class S>
struct has_size<S, std::enable_if_t<std::is_integral_v<decltype(std::declval<const S&>().size())>>>
    : std::true_type {};

template <class S, class = void>
struct has_rhs : std::false_type {};
template <class S>
struct has_rhs<S, std::void_t<decltype(std::declval<S&>().rhs(
                      0.0, std::declval<const ConstVectorMap&>(), std::declval<VectorMap&>()))>>
    : std::bool_constant<
          std::is_void_v<decltype(std::declval<S&>().rhs(0.0, std::declval<const ConstVectorMap&>(),
                                                         std::declval<VectorMap&>()))> ||
          std::is_convertible_v<decltype(std::declval<S&>().rhs(
                                    0.0, std::declval<const ConstVectorMap&>(),
                                    std::declval<VectorMap&>())),
                                bool>> {};

template <class S, class = void>
struct has_jacobian : std::false_type {};
template <class S>
struct has_jacobian<S, std::void_t<decltype(std::declval<S&>().jacobian(
                           0.0, std::declval<const ConstVectorMap&>(),
                           std::declval<const ConstVectorMap&>(), std::declval<MatrixMap&>()))>>
    : std::true_type {};

template <class S, class = void>
struct has_set_segment_state : std::false_type {};
template <class S>
struct has_set_segment_state<
    S, std::void_t<decltype(std::declval<S&>().set_segment(std::size_t{0}, 0.0, 0.0,
                                                           std::declval<const ConstVectorMap&>()))>>
    : std::true_type {};

template <class S, class = void>
struct has_set_segment_window : std::false_type {};
template <class S>
struct has_set_segment_window<
    S, std::void_t<decltype(std::declval<S&>().set_segment(std::size_t{0}, 0.0, 0.0))>>
    : std::true_type {};

template <class S, class = void>
struct has_set_segment_index : std::false_type {};
template <class S>
struct has_set_segment_index<S,
                             std::void_t<decltype(std::declval<S&>().set_segment(std::size_t{0}))>>
    : std::true_type {};

/// Calls a nullary callable; its bool result, or true when it returns void.
template <class F>
bool invoke_ok(F&& f) {
  if constexpr (std::is_void_v<decltype(f())>) {
    f();
    return true;
  } else {
    return static_cast<bool>(f());
  }
}

// ---- RAII handles on SUNDIALS objects -----------------------------------------

struct ContextDeleter {
  void operator()(SUNContext ctx) const { SUNContext_Free(&ctx); }
};
struct VectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct MatrixDeleter {
  void operator()(SUNMatrix m) const { SUNMatDestroy(m); }
};
struct LinearSolverDeleter {
  void operator()(SUNLinearSolver ls) const { SUNLinSolFree(ls); }
};
struct CvodeMemDeleter {
  void operator()(void* mem) const { CVodeFree(&mem); }
};
using ContextPtr = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;
using VectorPtr = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter>;
using MatrixPtr = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter>;
using LinearSolverPtr =
    std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinearSolverDeleter>;
using CvodeMemPtr = std::unique_ptr<void, CvodeMemDeleter>;

using Clock = std::chrono::steady_clock;

/// What the callbacks share with integrate(); no allocation on the hot path.
template <class System>
struct CallbackData {
  System* sys = nullptr;
  Eigen::Index n = 0;
  Clock::time_point start;
  double max_wall_seconds = 0;
  const std::atomic<bool>* stop = nullptr;
  bool verbose = false;
  // Failure bookkeeping, read after CVode returns.
  bool wall_exceeded = false;
  bool stopped = false;
  bool rhs_nonfinite = false;  // the rhs produced NaN/Inf at least once
  double t_rhs_nonfinite = 0;  // first such time
  bool rhs_refused = false;    // the rhs returned false at least once
  double t_rhs_refused = 0;
  std::exception_ptr exception;
  std::string last_error;  // CVODE's last error message (error path only)

  /// The wall-clock limit, or a stop request (reported as such).
  bool wall_clock_exceeded() {
    if (stop && stop->load(std::memory_order_relaxed)) {
      stopped = true;
      wall_exceeded = true;
    }
    if (max_wall_seconds > 0 &&
        std::chrono::duration<double>(Clock::now() - start).count() > max_wall_seconds)
      wall_exceeded = true;
    return wall_exceeded;
  }
};

template <class System>
int rhs_callback(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto& d = *static_cast<CallbackData<System>*>(user_data);
  if (d.wall_clock_exceeded()) return -1;  // unrecoverable: stop now
  const ConstVectorMap x(N_VGetArrayPointer(y), d.n);
  VectorMap xdot(N_VGetArrayPointer(ydot), d.n);
  bool ok = false;
  try {
    ok = invoke_ok([&] { return d.sys->rhs(static_cast<double>(t), x, xdot); });
  } catch (...) {
    d.exception = std::current_exception();
    return -1;
  }
  if (!ok) {
    if (!d.rhs_refused) d.t_rhs_refused = t;
    d.rhs_refused = true;
    return 1;  // recoverable: CVODE retries with a smaller step
  }
  if (!xdot.allFinite()) {
    if (!d.rhs_nonfinite) d.t_rhs_nonfinite = t;
    d.rhs_nonfinite = true;
    return 1;
  }
  return 0;
}

template <class System>
int jacobian_callback(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix jac, void* user_data,
                      N_Vector, N_Vector, N_Vector) {
  auto& d = *static_cast<CallbackData<System>*>(user_data);
  if (d.wall_clock_exceeded()) return -1;
  const ConstVectorMap x(N_VGetArrayPointer(y), d.n);
  const ConstVectorMap f(N_VGetArrayPointer(fy), d.n);
  // Dense SUNMatrix: column-major, leading dimension = rows.
  MatrixMap J(SUNDenseMatrix_Data(jac), SUNDenseMatrix_Rows(jac), SUNDenseMatrix_Columns(jac));
  J.setZero();
  bool ok = false;
  try {
    ok = invoke_ok([&] { return d.sys->jacobian(static_cast<double>(t), x, f, J); });
  } catch (...) {
    d.exception = std::current_exception();
    return -1;
  }
  if (!ok || !J.allFinite()) return 1;  // recoverable
  return 0;
}

template <class System>
void error_callback(int error_code, const char* module, const char* function, char* msg,
                    void* user_data) {
  auto& d = *static_cast<CallbackData<System>*>(user_data);
  if (d.verbose)
    std::cerr << "[" << (module ? module : "CVODE") << (error_code < 0 ? " ERROR" : " WARNING")
              << "] " << (function ? function : "") << ": " << (msg ? msg : "") << '\n';
  if (error_code < 0 && msg) {
    d.last_error = msg;
    std::replace(d.last_error.begin(), d.last_error.end(), '\n', ' ');
  }
}

inline std::string format_time(double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", t);
  return buf;
}

/// Adds CVODE's counters (reset by CVodeReInit) to `total`.
inline void harvest_stats(void* mem, SimulationStats& total) {
  SimulationStats run;
  CVodeGetNumSteps(mem, &run.steps);
  CVodeGetNumRhsEvals(mem, &run.rhs_evals);
  CVodeGetNumJacEvals(mem, &run.jac_evals);
  CVodeGetNumLinRhsEvals(mem, &run.rhs_evals_for_jacobian_fd);
  CVodeGetNumErrTestFails(mem, &run.error_test_failures);
  CVodeGetNumNonlinSolvConvFails(mem, &run.nonlinear_convergence_failures);
  total += run;
}

inline long current_steps(void* mem) {
  long steps = 0;
  CVodeGetNumSteps(mem, &steps);
  return steps;
}

/// One line for a failed CVode() return.
inline std::string describe_flag(int flag, long max_steps) {
  switch (flag) {
    case CV_TOO_MUCH_WORK:
      return "too many steps (" + std::to_string(max_steps) + ")";
    case CV_TOO_MUCH_ACC:
      return "tolerances too tight for machine precision";
    case CV_ERR_FAILURE:
      return "repeated error test failures (step size underflow, possibly a singularity)";
    case CV_CONV_FAILURE:
      return "repeated Newton convergence failures";
    case CV_LSETUP_FAIL:
      return "linear solver setup failed (singular iteration matrix or Jacobian failure)";
    case CV_LSOLVE_FAIL:
      return "linear solve failed";
    case CV_RHSFUNC_FAIL:
      return "the right-hand side failed unrecoverably";
    case CV_FIRST_RHSFUNC_ERR:
      return "the right-hand side failed at the initial state";
    case CV_REPTD_RHSFUNC_ERR:
      return "the right-hand side failed repeatedly";
    case CV_UNREC_RHSFUNC_ERR:
      return "the right-hand side failed and CVODE could not recover";
    default: {
      char* name = CVodeGetReturnFlagName(flag);  // malloc'ed by SUNDIALS
      std::string s = name ? name : "unknown error";
      std::free(name);
      return "CVODE error " + s;
    }
  }
}

}  // namespace detail

/// \brief Integrates \f$\dot x = f(t, x)\f$ from `output_times[0]` (state `x0`)
/// to `output_times.back()`, recording the state at each output time.
///
/// \param sys           the ODE system (see the file comment for the concept)
/// \param x0            state at output_times[0], size sys.size()
/// \param output_times  strictly increasing, at least one
/// \param breakpoints   times where f is discontinuous in t (input steps), any
///                      order; those outside (t0, t_end) are ignored. CVODE
///                      stops exactly at each and restarts there.
/// \param opt           tolerances and limits
/// \return ok = false, with a one-line message naming the time reached, on a
///         CVODE failure, a non-finite state, max_steps exhausted, the
///         wall-clock limit or invalid arguments; x then holds the rows
///         computed so far. Exceptions thrown by the system's callbacks are
///         rethrown after CVODE's memory is released. Nothing is printed
///         unless opt.verbose.
///
/// One CVODE instance per call; callbacks run on views of CVODE's vectors
/// and allocate nothing.
template <class System>
SimulationResult integrate(System& sys, const Eigen::VectorXd& x0,
                           const Eigen::VectorXd& output_times,
                           const std::vector<double>& breakpoints, const CvodeOptions& opt = {}) {
  static_assert(
      detail::has_size<System>::value,
      "softrne::sim::integrate: System must provide `int size() const` (the state dimension)");
  static_assert(
      detail::has_rhs<System>::value,
      "softrne::sim::integrate: System must provide `rhs(double t, const Eigen::Ref<const "
      "Eigen::VectorXd>& x, Eigen::Ref<Eigen::VectorXd> xdot)` returning void or bool");

  using detail::format_time;
  const auto start = detail::Clock::now();
  SimulationResult result;
  auto elapsed = [&] {
    return std::chrono::duration<double>(detail::Clock::now() - start).count();
  };
  auto fail = [&](std::string message) {
    result.ok = false;
    result.message = std::move(message);
    result.stats.wall_seconds = elapsed();
    return result;
  };

  // ---- arguments --------------------------------------------------------------
  const Eigen::Index n = static_cast<Eigen::Index>(sys.size());
  const Eigen::Index n_out = output_times.size();
  if (n_out < 1) return fail("invalid arguments: no output times");
  result.t_reached = output_times[0];
  if (x0.size() != n)
    return fail("invalid arguments: x0 has size " + std::to_string(x0.size()) +
                " but the system has " + std::to_string(n) + " states");
  if (!output_times.allFinite()) return fail("invalid arguments: non-finite output time");
  for (Eigen::Index i = 1; i < n_out; ++i)
    if (!(output_times[i] > output_times[i - 1]))
      return fail("invalid arguments: output times not strictly increasing at index " +
                  std::to_string(i));
  if (!x0.allFinite())
    return fail("non-finite initial state at t = " + format_time(output_times[0]) + " s");
  if (!(opt.rtol >= 0) || !(opt.atol >= 0) || (opt.rtol == 0 && opt.atol == 0))
    return fail("invalid arguments: tolerances must be non-negative and not both zero");

  const double t0 = output_times[0];
  const double t_end = output_times[n_out - 1];
  result.x.resize(n_out, n);  // allocated once; rows filled as outputs are reached
  result.x.row(0) = x0.transpose();
  if (n_out == 1 || n == 0) {
    if (n == 0) result.x.resize(n_out, 0);
    result.ok = true;
    result.t_reached = t_end;
    result.stats.wall_seconds = elapsed();
    return result;
  }

  // Breakpoints strictly inside (t0, t_end), sorted, merged when closer than roundoff.
  const double t_fuzz = 64.0 * std::numeric_limits<double>::epsilon() *
                        std::max({1.0, std::abs(t0), std::abs(t_end)});
  std::vector<double> stops;
  stops.reserve(breakpoints.size() + 1);
  for (double b : breakpoints)
    if (std::isfinite(b) && b > t0 + t_fuzz && b < t_end - t_fuzz) stops.push_back(b);
  std::sort(stops.begin(), stops.end());
  stops.erase(
      std::unique(stops.begin(), stops.end(), [&](double a, double b) { return b - a <= t_fuzz; }),
      stops.end());
  const std::size_t n_breaks = stops.size();
  stops.push_back(t_end);  // CVODE never steps past the last output either

  // ---- CVODE setup ------------------------------------------------------------
  detail::CallbackData<System> data;
  data.sys = &sys;
  data.n = n;
  data.start = start;
  data.max_wall_seconds = opt.max_wall_seconds;
  data.stop = opt.stop;
  data.verbose = opt.verbose;

  auto setup_error = [&](const char* what) {
    return fail(std::string("CVODE setup failed (") + what + ")" +
                (data.last_error.empty() ? "" : ": " + data.last_error));
  };

  SUNContext ctx_raw = nullptr;
  if (SUNContext_Create(nullptr, &ctx_raw) != 0 || !ctx_raw)
    return setup_error("SUNContext_Create");
  detail::ContextPtr ctx(ctx_raw);
  detail::VectorPtr y(N_VNew_Serial(static_cast<sunindextype>(n), ctx.get()));
  if (!y) return setup_error("N_VNew_Serial");
  detail::use_softrne_vector_ops(y.get());  // before CVodeInit clones it (serial_vector_ops.hpp)
  detail::VectorMap y_map(N_VGetArrayPointer(y.get()), n);
  y_map = x0;
  detail::MatrixPtr A(
      SUNDenseMatrix(static_cast<sunindextype>(n), static_cast<sunindextype>(n), ctx.get()));
  if (!A) return setup_error("SUNDenseMatrix");
  // Newton systems by Eigen's LU (eigen_linear_solver.hpp says why not SUNLinSol_Dense).
  detail::LinearSolverPtr LS(
      detail::make_eigen_dense_solver(static_cast<sunindextype>(n), ctx.get()));
  if (!LS) return setup_error("make_eigen_dense_solver");
  detail::CvodeMemPtr mem_owner(CVodeCreate(CV_BDF, ctx.get()));
  void* mem = mem_owner.get();
  if (!mem) return setup_error("CVodeCreate");
  // Silence CVODE first, so that every later message is captured.
  if (CVodeSetErrHandlerFn(mem, &detail::error_callback<System>, &data) != CV_SUCCESS)
    return setup_error("CVodeSetErrHandlerFn");
  if (CVodeInit(mem, &detail::rhs_callback<System>, t0, y.get()) != CV_SUCCESS)
    return setup_error("CVodeInit");
  if (CVodeSetUserData(mem, &data) != CV_SUCCESS) return setup_error("CVodeSetUserData");
  if (CVodeSStolerances(mem, opt.rtol, opt.atol) != CV_SUCCESS)
    return setup_error("CVodeSStolerances");
  if (CVodeSetLinearSolver(mem, LS.get(), A.get()) != CVLS_SUCCESS)
    return setup_error("CVodeSetLinearSolver");
  if constexpr (detail::has_jacobian<System>::value) {
    if (opt.use_analytic_jacobian &&
        CVodeSetJacFn(mem, &detail::jacobian_callback<System>) != CVLS_SUCCESS)
      return setup_error("CVodeSetJacFn");
  }
  if (opt.jacobian_max_age > 0 &&
      CVodeSetJacEvalFrequency(mem, opt.jacobian_max_age) != CVLS_SUCCESS)
    return setup_error("CVodeSetJacEvalFrequency");
  if (opt.newton_matrix_max_age > 0 &&
      CVodeSetLSetupFrequency(mem, opt.newton_matrix_max_age) != CV_SUCCESS)
    return setup_error("CVodeSetLSetupFrequency");
  if (CVodeSetMaxOrd(mem, std::clamp(opt.max_order, 1, 5)) != CV_SUCCESS)
    return setup_error("CVodeSetMaxOrd");
  if (opt.max_step > 0 && CVodeSetMaxStep(mem, opt.max_step) != CV_SUCCESS)
    return setup_error("CVodeSetMaxStep");
  const double min_step = opt.min_step > 0 ? opt.min_step : 4.0 * t_fuzz;
  if (CVodeSetMinStep(mem, min_step) != CV_SUCCESS) return setup_error("CVodeSetMinStep");
  if (CVodeSetStopTime(mem, stops[0]) != CV_SUCCESS) return setup_error("CVodeSetStopTime");

  std::size_t segment = 0;  // index into stops: the current segment ends at stops[segment]
  auto announce_segment = [&](double t_begin) {
    if constexpr (detail::has_set_segment_state<System>::value)
      sys.set_segment(segment, t_begin, stops[segment], detail::ConstVectorMap(y_map.data(), n));
    else if constexpr (detail::has_set_segment_window<System>::value)
      sys.set_segment(segment, t_begin, stops[segment]);
    else if constexpr (detail::has_set_segment_index<System>::value)
      sys.set_segment(segment);
    else
      (void)t_begin;
  };
  announce_segment(t0);

  // ---- time loop --------------------------------------------------------------
  SimulationStats& stats = result.stats;
  bool counters_harvested = false;  // CVODE's counters already added since the last restart
  auto finish_stats = [&] {
    if (!counters_harvested) detail::harvest_stats(mem, stats);
    counters_harvested = true;
    stats.wall_seconds = elapsed();
  };
  Eigen::Index rows_done = 1;
  auto failure = [&](const std::string& reason, double t) {
    finish_stats();
    result.x.conservativeResize(rows_done, n);
    result.ok = false;
    result.t_reached = t;
    result.message = "CVODE failed at t = " + format_time(t) + " s: " + reason;
    return result;
  };
  auto with_cvode_message = [&](std::string s) {
    return data.last_error.empty() ? s : s + " [" + data.last_error + "]";
  };

  double t_known = t0;  // y holds the solution at t_known
  for (Eigen::Index i = 1; i < n_out; ++i) {
    const double tout = output_times[i];
    // tout within roundoff of t_known (e.g. just after a breakpoint): y is the answer.
    while (tout - t_known > t_fuzz) {
      const long remaining =
          opt.max_steps - stats.steps - (counters_harvested ? 0 : detail::current_steps(mem));
      if (remaining <= 0)
        return failure(detail::describe_flag(CV_TOO_MUCH_WORK, opt.max_steps), t_known);
      CVodeSetMaxNumSteps(mem, remaining);
      sunrealtype tret = t_known;
      counters_harvested = false;
      const int flag = CVode(mem, tout, y.get(), &tret, CV_NORMAL);

      if (data.exception) {
        mem_owner.reset();  // release CVODE before unwinding
        std::rethrow_exception(data.exception);
      }
      if (flag < 0) {
        if (data.stopped) return failure("stopped on request", tret);
        if (data.wall_exceeded)
          return failure("wall-clock limit (" + format_time(opt.max_wall_seconds) + " s) exceeded",
                         tret);
        std::string reason = detail::describe_flag(flag, opt.max_steps);
        if (data.rhs_nonfinite)
          reason += "; the right-hand side returned non-finite values (first at t = " +
                    format_time(data.t_rhs_nonfinite) + " s)";
        if (data.rhs_refused)
          reason += "; the right-hand side reported a failure (first at t = " +
                    format_time(data.t_rhs_refused) + " s)";
        return failure(flag == CV_TOO_MUCH_WORK ? reason : with_cvode_message(reason), tret);
      }
      if (!y_map.allFinite()) return failure("non-finite state", t_known);
      t_known = tret;

      if (segment < n_breaks && (flag == CV_TSTOP_RETURN || tret >= stops[segment])) {
        // At a breakpoint: restart the multistep history on the new input.
        const double tb = stops[segment];
        detail::harvest_stats(mem, stats);
        counters_harvested = true;
        if (CVodeReInit(mem, tb, y.get()) != CV_SUCCESS)
          return failure(with_cvode_message("CVodeReInit failed"), tb);
        ++stats.restarts;
        ++segment;
        if (CVodeSetStopTime(mem, stops[segment]) != CV_SUCCESS)
          return failure(with_cvode_message("CVodeSetStopTime failed"), tb);
        announce_segment(tb);
        t_known = tb;
        continue;  // loop exits when tout - tb is within roundoff
      }
      break;  // y holds the state at tout (interpolated, or exactly at the final stop time)
    }
    result.x.row(i) = y_map.transpose();
    rows_done = i + 1;
    if (opt.max_wall_seconds > 0 && i + 1 < n_out && elapsed() > opt.max_wall_seconds)
      return failure("wall-clock limit (" + format_time(opt.max_wall_seconds) + " s) exceeded",
                     tout);
  }

  finish_stats();
  result.ok = true;
  result.t_reached = t_end;
  return result;
}

}  // namespace softrne::sim
