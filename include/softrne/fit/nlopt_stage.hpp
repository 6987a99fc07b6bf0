#pragma once
/// \file
/// \brief One NLopt derivative-free algorithm on the cost in the normalised box: the
///        CRS2-LM and DIRECT-L global stages and the BOBYQA local stage.

#include <algorithm>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <nlopt.h>

#include "softrne/config.hpp"
#include "softrne/fit/residual_evaluation.hpp"

namespace softrne::fit::detail {

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

}  // namespace softrne::fit::detail
