#pragma once
/// \file
/// \brief Bounded nonlinear least squares over a residual vector: a seeded
///        global stage, a projected Levenberg-Marquardt local stage, and an
///        identifiability analysis at the optimum.
///
/// Generic: nothing here knows about robots. The model is a function that
/// fills a residual vector of fixed length \f$m\f$ for a parameter vector of
/// length \f$p\f$, and may fail (return false, throw, or produce non-finite
/// values) for part of the parameter space.
///
/// Cost: \f$c(x) = \tfrac12 \sum_k r_k(x)^2\f$. The optimisers work in the
/// normalised coordinates \f$u \in [0,1]^p\f$ of ParameterSet.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SVD>
#include <nlopt.h>

#include "softrne/config.hpp"
#include "softrne/fit/parallel_for.hpp"
#include "softrne/fit/least_squares_types.hpp"
#include "softrne/fit/residual_evaluation.hpp"
#include "softrne/fit/halton.hpp"
#include "softrne/fit/levenberg_marquardt.hpp"
#include "softrne/fit/finite_difference_jacobian.hpp"

#include <softrne/fit/parameters.hpp>

namespace softrne::fit {

namespace detail {

/// Objective adaptor for NLopt's derivative-free algorithms (serial).
struct NloptObjective {
  Evaluator* evaluator = nullptr;
  const std::function<void(double)>* report = nullptr;  // progress, main thread
  double worst_valid = 0.0;
  double best = kInf;
  Eigen::VectorXd best_u;

  static double call(unsigned n, const double* x, double* grad, void* data) {
    auto* self = static_cast<NloptObjective*>(data);
    if (grad)
      for (unsigned i = 0; i < n; ++i) grad[i] = 0.0;
    const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(x, n);
    Eigen::VectorXd r;
    double value;
    if (self->evaluator->normalised(u, r)) {
      value = half_squared_norm(r);
      self->worst_valid = std::max(self->worst_valid, value);
      if (value < self->best) {
        self->best = value;
        self->best_u = u;
      }
    } else {
      // Large but finite, and scaled to the problem so model-based methods
      // are not wrecked: worse than every valid point seen so far.
      value = 10.0 * std::max(1.0, self->worst_valid);
    }
    if (self->report && self->evaluator->evaluations % 10 == 0) (*self->report)(self->best);
    return value;
  }
};

/// Runs one NLopt algorithm on the cost in [0,1]^p from `u0`; returns the
/// best valid point it saw (or u0) and appends a summary to `msg`.
SOFTRNE_FIT_INLINE Eigen::VectorXd run_nlopt(nlopt_algorithm algorithm, Runner& runner,
                                             const Eigen::VectorXd& u0, int max_evals, double xtol_rel,
                                             double ftol_rel, unsigned seed, const Deadline& deadline,
                                             const std::function<void(double)>& report, double& best_cost,
                                             std::ostringstream& msg)
#if SOFTRNE_FIT_BODIES
{
  const unsigned p = static_cast<unsigned>(u0.size());
  NloptObjective objective;
  objective.evaluator = &runner.main();
  objective.report = &report;
  nlopt_opt opt = nlopt_create(algorithm, p);
  if (!opt) throw std::runtime_error("softrne::fit: nlopt_create failed");
  nlopt_set_lower_bounds1(opt, 0.0);
  nlopt_set_upper_bounds1(opt, 1.0);
  nlopt_set_min_objective(opt, &NloptObjective::call, &objective);
  nlopt_set_maxeval(opt, std::max(1, max_evals));
  if (xtol_rel > 0) nlopt_set_xtol_rel(opt, xtol_rel);
  if (ftol_rel > 0) nlopt_set_ftol_rel(opt, ftol_rel);
  if (deadline.active) nlopt_set_maxtime(opt, std::max(1e-3, deadline.remaining_seconds()));
  nlopt_srand(seed);  // CRS2 and friends draw from NLopt's (thread-local) RNG
  std::vector<double> x(u0.data(), u0.data() + u0.size());
  double f = 0.0;
  const nlopt_result status = nlopt_optimize(opt, x.data(), &f);
  const int evals = nlopt_get_numevals(opt);
  nlopt_destroy(opt);
  msg << nlopt_algorithm_to_string(algorithm) << ": " << evals << " evaluations, "
      << nlopt_result_to_string(status);
  if (objective.best_u.size() == p) {
    best_cost = objective.best;
    msg << ", best cost " << objective.best;
    return objective.best_u;
  }
  msg << ", no valid point";
  return u0;
}
#else
;
#endif

/// Seeded multistart: screen `global_evals/2` points (the initial guess and
/// a shifted Halton set), then refine the best distinct ones with short LM
/// runs in parallel; returns the best refined point.
SOFTRNE_FIT_INLINE Eigen::VectorXd multistart(Runner& runner, const Eigen::VectorXd& u0, const FitOptions& opt,
                                              double fd_step, const Deadline& deadline, double& best_cost,
                                              std::ostringstream& msg)
#if SOFTRNE_FIT_BODIES
{
  const int p = static_cast<int>(u0.size());
  const int n_screen = std::max(1, opt.global_evals / 2);
  std::vector<Eigen::VectorXd> points = shifted_halton(p, n_screen - 1, opt.seed);
  points.insert(points.begin(), u0);
  std::vector<double> costs(points.size(), kInf);
  runner.run(static_cast<int>(points.size()), [&](int k, Evaluator& ev) {
    if (deadline.passed()) return;  // unevaluated points keep an infinite cost
    Eigen::VectorXd r;
    if (ev.normalised(points[k], r)) costs[k] = half_squared_norm(r);
  });
  int n_valid = 0;
  for (const double c : costs) n_valid += std::isfinite(c) ? 1 : 0;
  msg << "multistart: screened " << points.size() << " points ("
      << (static_cast<int>(points.size()) - n_valid) << " failed)";

  // Order: the initial guess first (if valid), then by cost; stable in index.
  std::vector<int> order;
  for (int k = 1; k < static_cast<int>(points.size()); ++k)
    if (std::isfinite(costs[k])) order.push_back(k);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return costs[a] < costs[b]; });
  if (std::isfinite(costs[0])) order.insert(order.begin(), 0);
  if (order.empty()) {
    msg << ", no valid point";
    return u0;
  }
  int best_screened = order.front();
  for (const int k : order)
    if (costs[k] < costs[best_screened]) best_screened = k;

  const int per_iteration = (opt.central_differences ? 2 * p : p) + 1;
  const int budget_left = opt.global_evals - static_cast<int>(points.size());
  int n_starts = std::max(0, std::min(opt.multistart_starts, static_cast<int>(order.size())));
  while (n_starts > 0 && budget_left / n_starts < 2 * per_iteration + 1) --n_starts;
  std::vector<int> starts;
  for (const int k : order) {
    if (static_cast<int>(starts.size()) >= n_starts) break;
    bool distinct = true;
    for (const int s : starts)
      if ((points[k] - points[s]).lpNorm<Eigen::Infinity>() < 0.05) distinct = false;
    if (distinct) starts.push_back(k);
  }
  if (starts.empty()) {
    best_cost = costs[best_screened];
    msg << ", best cost " << best_cost << " (no budget to refine)";
    return points[best_screened];
  }

  LmSettings settings;
  settings.max_evals = budget_left / static_cast<int>(starts.size());
  settings.xtol_rel = std::max(opt.xtol_rel, 1e-4);
  settings.ftol_rel = std::max(opt.ftol_rel, 1e-6);
  settings.central = opt.central_differences;
  settings.fd_step = fd_step;
  settings.deadline = &deadline;
  std::vector<LmOutcome> refined(starts.size());
  runner.run(static_cast<int>(starts.size()), [&](int k, Evaluator& ev) {
    Runner serial({&ev});
    refined[k] = levenberg_marquardt(serial, points[starts[k]], settings);
  });
  int best = -1;
  for (int k = 0; k < static_cast<int>(refined.size()); ++k)
    if (refined[k].valid && (best < 0 || refined[k].cost < refined[best].cost)) best = k;
  msg << ", refined " << starts.size() << " starts";
  if (best < 0 || refined[best].cost > costs[best_screened]) {
    best_cost = costs[best_screened];
    msg << ", best cost " << best_cost;
    return points[best_screened];
  }
  best_cost = refined[best].cost;
  msg << ", best cost " << best_cost;
  return refined[best].u;
}
#else
;
#endif

/// Fills the identifiability fields of `res` at `res.params` (r = residual there).
SOFTRNE_FIT_INLINE void identifiability(const ParameterSet& ps, Runner& runner, const Eigen::VectorXd& r,
                                        const IdentifiabilityOptions& io, FitResult& res)
#if SOFTRNE_FIT_BODIES
{
  const int p = ps.size();
  const Eigen::Index m = r.size();
  const Eigen::VectorXd x = res.params;
  const Eigen::VectorXd lo = ps.lower(), hi = ps.upper();
  const double h_rel =
      io.fd_step > 0.0 ? io.fd_step : std::cbrt(std::numeric_limits<double>::epsilon());

  // "Parameter magnitude": |x|, floored for values near zero.
  Eigen::VectorXd magnitude(p);
  for (int i = 0; i < p; ++i) magnitude[i] = std::max(std::abs(x[i]), 1e-3 * (hi[i] - lo[i]));

  // Central differences w.r.t. physical parameters, one-sided at bounds/failures.
  Eigen::MatrixXd J(m, p);
  std::vector<char> column_ok(static_cast<std::size_t>(p), 0);
  runner.run(p, [&](int k, Evaluator& ev) {
    const double h = h_rel * magnitude[k];
    Eigen::VectorXd v = x, r_plus, r_minus;
    const double up = x[k] + h, down = x[k] - h;
    bool a = false, b = false;
    if (up <= hi[k]) {
      v[k] = up;
      a = ev.physical(v, r_plus);
    }
    if (down >= lo[k]) {
      v[k] = down;
      b = ev.physical(v, r_minus);
    }
    bool ok = true;
    if (a && b)
      J.col(k) = (r_plus - r_minus) / (up - down);
    else if (a)
      J.col(k) = (r_plus - r) / (up - x[k]);
    else if (b)
      J.col(k) = (r - r_minus) / (x[k] - down);
    else
      ok = false;
    if (!ok) J.col(k).setZero();
    column_ok[k] = ok ? 1 : 0;
  });

  // SVD of J scaled by parameter magnitude (derivatives w.r.t. relative changes).
  const Eigen::MatrixXd J_scaled = J * magnitude.asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J_scaled, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  const Eigen::MatrixXd& V = svd.matrixV();
  res.singular_values = sv;
  const double s_max = sv.size() ? sv.maxCoeff() : 0.0;
  const double s_min = sv.size() ? sv.minCoeff() : 0.0;
  res.condition_number = s_min > 0.0 ? s_max / s_min : kInf;
  int rank = 0;
  for (Eigen::Index k = 0; k < sv.size(); ++k)
    if (sv[k] > io.null_space_rtol * s_max && sv[k] > 0.0) ++rank;

  // A parameter with more than 1% of its unit vector in the null space is
  // undetermined: moving along the null direction leaves the residual unchanged.
  constexpr double kNullComponent = 1e-2;
  std::vector<bool> in_null(static_cast<std::size_t>(p), false);
  for (int i = 0; i < p; ++i) {
    double w2 = 0.0;
    for (Eigen::Index k = rank; k < V.cols(); ++k) w2 += V(i, k) * V(i, k);
    in_null[i] = std::sqrt(w2) > kNullComponent;
  }

  // Pseudo-inverse of the scaled Gauss-Newton Hessian, V_r S_r^{-2} V_r^T.
  Eigen::MatrixXd H_scaled_pinv = Eigen::MatrixXd::Zero(p, p);
  for (int k = 0; k < rank; ++k) H_scaled_pinv += V.col(k) * V.col(k).transpose() / (sv[k] * sv[k]);
  const Eigen::MatrixXd unscaled_cov =
      magnitude.asDiagonal() * H_scaled_pinv * magnitude.asDiagonal();

  const int dof = static_cast<int>(m) - p;
  const double s2 = dof > 0 ? 2.0 * res.cost / dof : kInf;
  res.covariance.resize(p, p);
  for (int i = 0; i < p; ++i)
    for (int j = 0; j < p; ++j)
      res.covariance(i, j) = std::isfinite(s2) ? s2 * unscaled_cov(i, j) : kInf;
  res.correlation = Eigen::MatrixXd::Identity(p, p);
  for (int i = 0; i < p; ++i)
    for (int j = 0; j < p; ++j) {
      const double d = unscaled_cov(i, i) * unscaled_cov(j, j);
      if (i != j) res.correlation(i, j) = d > 0.0 ? unscaled_cov(i, j) / std::sqrt(d) : 0.0;
    }
  res.std_errors.resize(p);
  res.relative_std_errors.resize(p);
  res.identifiable.assign(static_cast<std::size_t>(p), false);
  for (int i = 0; i < p; ++i) {
    const bool undetermined = in_null[i] || !column_ok[i];
    const double se = (undetermined || !std::isfinite(s2))
                          ? kInf
                          : std::sqrt(std::max(0.0, s2 * unscaled_cov(i, i)));
    res.std_errors[i] = se;
    res.relative_std_errors[i] = se / magnitude[i];
    res.identifiable[i] = !undetermined && res.relative_std_errors[i] < io.max_relative_std_error;
  }

  // Report.
  std::ostringstream rep;
  rep << std::setprecision(4);
  rep << "identifiability at the optimum: m = " << m << " residuals, p = " << p
      << " parameters, rms residual = " << res.rms;
  if (dof > 0) rep << ", noise estimate s = " << std::sqrt(s2);
  rep << "\n";
  rep << "condition number of J scaled by parameter magnitude: " << res.condition_number
      << " (rank " << rank << " of " << p << ")\n";
  if (dof <= 0) rep << "m <= p: the noise variance cannot be estimated; std errors are infinite\n";
  std::size_t width = 4;
  for (const Parameter& q : ps.parameters()) width = std::max(width, q.name.size());
  for (int i = 0; i < p; ++i) {
    const std::size_t ui = static_cast<std::size_t>(i);
    rep << "  " << std::left << std::setw(static_cast<int>(width)) << ps[i].name << std::right
        << " = " << std::setw(11) << x[i] << " +- " << std::setw(10) << res.std_errors[i] << " ("
        << std::setw(9) << 100.0 * res.relative_std_errors[i] << " %)  ";
    if (res.identifiable[ui])
      rep << "identifiable";
    else if (!column_ok[ui])
      rep << "NOT IDENTIFIABLE: residual failed on both sides, no derivative";
    else if (in_null[ui])
      rep << "NOT IDENTIFIABLE: in the null space of J (see below)";
    else
      rep << "POORLY DETERMINED: relative std error above " << 100.0 * io.max_relative_std_error
          << " %";
    if (x[i] <= lo[i] || x[i] >= hi[i]) rep << " [at a bound: std error unreliable]";
    rep << "\n";
  }
  for (Eigen::Index k = rank; k < V.cols(); ++k) {
    rep << "null direction (singular value " << sv[k] << " of " << s_max
        << "): the residual does not change along ";
    bool first = true;
    for (int i = 0; i < p; ++i) {
      if (std::abs(V(i, k)) <= kNullComponent) continue;
      rep << (first ? "" : " ") << (V(i, k) < 0 ? "- " : (first ? "" : "+ ")) << std::abs(V(i, k))
          << " d" << ps[i].name << "/|" << ps[i].name << "|";
      first = false;
    }
    rep << "\n";
  }
  for (int i = 0; i < p; ++i)
    for (int j = i + 1; j < p; ++j)
      if (std::abs(res.correlation(i, j)) > io.correlation_threshold)
        rep << "correlated: " << ps[i].name << " and " << ps[j].name << " (corr = " << std::showpos
            << res.correlation(i, j) << std::noshowpos << ")\n";
  res.identifiability_report = rep.str();
}
#else
;
#endif

SOFTRNE_FIT_INLINE FitResult fit_impl(const ParameterSet& ps, int m, std::vector<ResidualFn> functors,
                                      const FitOptions& opt, const std::string& note)
#if SOFTRNE_FIT_BODIES
{
  const int p = ps.size();
  if (p < 1) throw std::invalid_argument("softrne::fit::fit_least_squares: no parameters");
  if (m < 1) throw std::invalid_argument("softrne::fit::fit_least_squares: residual_size < 1");
  std::vector<Evaluator> evaluators;
  evaluators.reserve(functors.size());
  for (ResidualFn& f : functors) evaluators.emplace_back(ps, m, std::move(f));
  std::vector<Evaluator*> pointers;
  for (Evaluator& e : evaluators) pointers.push_back(&e);
  Runner runner(pointers);

  Deadline deadline;
  if (opt.max_wall_seconds > 0.0) {
    deadline.active = true;
    deadline.end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(opt.max_wall_seconds));
  }
  const double fd_step = opt.fd_step > 0.0 ? opt.fd_step : (opt.central_differences ? 1e-5 : 1e-6);
  double best_cost = kInf;
  const std::function<void(double)> report = [&](double c) {
    best_cost = std::min(best_cost, c);
    if (opt.progress) opt.progress(runner.evaluations(), best_cost);
  };
  std::ostringstream msg;
  msg << std::setprecision(6);

  // Global stage.
  Eigen::VectorXd u = ps.to_normalised(ps.initial());
  if (opt.global_evals > 0) {
    double c = kInf;
    switch (opt.global_method) {
      case GlobalMethod::multistart:
        u = multistart(runner, u, opt, fd_step, deadline, c, msg);
        break;
      case GlobalMethod::crs2_lm:
        u = run_nlopt(NLOPT_GN_CRS2_LM, runner, u, opt.global_evals, 0.0, 0.0, opt.seed, deadline,
                      report, c, msg);
        break;
      case GlobalMethod::direct_l:
        u = run_nlopt(NLOPT_GN_DIRECT_L, runner, u, opt.global_evals, 0.0, 0.0, opt.seed, deadline,
                      report, c, msg);
        break;
    }
    report(c);
    msg << "; ";
  }

  // Local stage.
  int local_budget = opt.local_evals;
  if (opt.local_method == LocalMethod::bobyqa_then_lm) {
    const int start = runner.evaluations();
    double c = kInf;
    u = run_nlopt(NLOPT_LN_BOBYQA, runner, u, opt.local_evals / 2, opt.xtol_rel, opt.ftol_rel,
                  opt.seed, deadline, report, c, msg);
    report(c);
    msg << "; ";
    local_budget -= runner.evaluations() - start;
  }
  LmSettings settings;
  settings.max_evals = std::max(1, local_budget);
  settings.xtol_rel = opt.xtol_rel;
  settings.ftol_rel = opt.ftol_rel;
  settings.central = opt.central_differences;
  settings.fd_step = fd_step;
  settings.deadline = &deadline;
  settings.on_accept = report;
  const LmOutcome lm = levenberg_marquardt(runner, u, settings);
  msg << "Levenberg-Marquardt: " << lm.iterations << " iterations, " << lm.message;

  FitResult res;
  res.converged = lm.valid && lm.converged;
  if (lm.valid) {
    res.params = ps.to_physical(lm.u);
    res.residual = lm.r;
    res.cost = lm.cost;
    res.rms = std::sqrt(2.0 * lm.cost / m);
    if (opt.compute_identifiability) identifiability(ps, runner, lm.r, opt.identifiability, res);
  } else {
    res.params = ps.initial();
    msg << "; no point where the residual succeeds was found";
  }
  if (!res.identifiable.size()) {
    res.covariance = Eigen::MatrixXd::Constant(p, p, kInf);
    res.std_errors = Eigen::VectorXd::Constant(p, kInf);
    res.relative_std_errors = Eigen::VectorXd::Constant(p, kInf);
    res.correlation = Eigen::MatrixXd::Identity(p, p);
    res.singular_values = Eigen::VectorXd::Zero(p);
    res.identifiable.assign(static_cast<std::size_t>(p), false);
    if (res.identifiability_report.empty())
      res.identifiability_report = "identifiability not computed\n";
  }
  res.evaluations = runner.evaluations();
  res.failed_evaluations = runner.failures();
  for (const std::string& n : ps.notes()) msg << "; " << n;
  if (!note.empty()) msg << "; " << note;
  res.message = msg.str();
  if (opt.progress && lm.valid) opt.progress(res.evaluations, res.cost);
  return res;
}
#else
;
#endif

}  // namespace detail

/// \brief Fits `params` so that the residual is least-squares small.
///
/// Global stage (`opt.global_evals` evaluations, deterministic for a seed),
/// then projected Levenberg-Marquardt (`opt.local_evals`), then the
/// identifiability analysis at the optimum. `residual` is called from the
/// calling thread only, so `opt.threads` is ignored here (see the
/// ResidualFactory overload).
/// \param params the parameters, bounds and starting values
/// \param residual_size the fixed length \f$m\f$ of the residual.
/// \param residual the residual function r(params)
/// \param opt the stages' settings
/// \return The optimum, its residual and the identifiability analysis.
/// \throws std::invalid_argument if there are no parameters or residual_size < 1.
SOFTRNE_FIT_INLINE FitResult fit_least_squares(const ParameterSet& params, int residual_size,
                                               const ResidualFn& residual, const FitOptions& opt = {})
#if SOFTRNE_FIT_BODIES
{
  return detail::fit_impl(
      params, residual_size, {residual}, opt,
      opt.threads > 1 ? "threads > 1 ignored: pass a ResidualFactory to evaluate in parallel" : "");
}
#else
;
#endif

/// \brief As above, evaluating independent candidates (multistart points and
///        starts, Jacobian columns) on `opt.threads` threads, each with its
///        own functor from `make_residual` (called `max(1, opt.threads)`
///        times, on the calling thread). The result equals the serial one
///        bit for bit when the functors are deterministic.
/// \param params the parameters, bounds and starting values
/// \param residual_size the fixed length \f$m\f$ of the residual
/// \param make_residual makes one residual functor per thread
/// \param opt the stages' settings
/// \return The optimum, its residual and the identifiability analysis.
/// \throws std::invalid_argument if there are no parameters or residual_size < 1.
SOFTRNE_FIT_INLINE FitResult fit_least_squares(const ParameterSet& params, int residual_size,
                                               const ResidualFactory& make_residual,
                                               const FitOptions& opt = {})
#if SOFTRNE_FIT_BODIES
{
  std::vector<ResidualFn> functors;
  for (int w = 0; w < std::max(1, opt.threads); ++w) functors.push_back(make_residual());
  return detail::fit_impl(params, residual_size, std::move(functors), opt, "");
}
#else
;
#endif

/// \brief Identifiability analysis alone at `result.params` (e.g. at a
///        hand-picked point): fills cost, rms and the identifiability fields.
/// \param params the parameters
/// \param residual_size the fixed length \f$m\f$ of the residual
/// \param residual the residual function
/// \param result in: params, the point; out: cost, rms, residual and identifiability
/// \param io the analysis's settings
/// \throws std::invalid_argument if the residual fails at result.params.
SOFTRNE_FIT_INLINE void analyse_identifiability(const ParameterSet& params, int residual_size,
                                                const ResidualFn& residual, FitResult& result,
                                                const IdentifiabilityOptions& io = {})
#if SOFTRNE_FIT_BODIES
{
  detail::Evaluator ev(params, residual_size, residual);
  detail::Runner runner({&ev});
  Eigen::VectorXd r;
  if (!ev.physical(result.params, r))
    throw std::invalid_argument(
        "softrne::fit::analyse_identifiability: the residual fails at result.params");
  result.cost = detail::half_squared_norm(r);
  result.residual = r;
  result.rms = std::sqrt(2.0 * result.cost / residual_size);
  detail::identifiability(params, runner, r, io, result);
}
#else
;
#endif

}  // namespace softrne::fit
