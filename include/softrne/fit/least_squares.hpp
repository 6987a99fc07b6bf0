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
///
/// This header is the entry point (fit_least_squares(), analyse_identifiability()) and
/// includes the pieces, one idea each: least_squares_types.hpp (FitOptions, FitResult),
/// residual_evaluation.hpp (ResidualFn, ResidualFactory, evaluating them),
/// finite_difference_jacobian.hpp, levenberg_marquardt.hpp, halton.hpp, multistart.hpp,
/// nlopt_stage.hpp and identifiability.hpp.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <functional>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlopt.h>

#include "softrne/config.hpp"
#include "softrne/fit/identifiability.hpp"
#include "softrne/fit/least_squares_types.hpp"
#include "softrne/fit/levenberg_marquardt.hpp"
#include "softrne/fit/multistart.hpp"
#include "softrne/fit/nlopt_stage.hpp"
#include "softrne/fit/parameters.hpp"
#include "softrne/fit/residual_evaluation.hpp"

namespace softrne::fit {
namespace detail {

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
