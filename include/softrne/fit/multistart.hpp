#pragma once
/// \file
/// \brief Seeded multistart, the default global stage: screen a shifted Halton set and the
///        initial guess, then refine the best distinct points with short
///        Levenberg-Marquardt runs in parallel.

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/fit/halton.hpp"
#include "softrne/fit/least_squares_types.hpp"
#include "softrne/fit/levenberg_marquardt.hpp"
#include "softrne/fit/residual_evaluation.hpp"

namespace softrne::fit::detail {

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

}  // namespace softrne::fit::detail
