#pragma once
/// \file
/// \brief The residual function that fit_least_squares() fits, and how the fitter's stages
///        call it: counted, with every failure caught, one functor per worker thread, within
///        an optional wall-clock deadline.

#include <chrono>
#include <cstddef>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "softrne/fit/parallel_for.hpp"
#include "softrne/fit/parameters.hpp"

namespace softrne::fit {

/// \brief Fills `r` (already sized to \f$m\f$) for physical parameters
///        `params`; returns false when the model fails (e.g. the simulation
///        diverged). Throwing, resizing `r`, or leaving non-finite entries
///        also counts as a failure.
using ResidualFn = std::function<bool(const Eigen::VectorXd& params, Eigen::VectorXd& r)>;

/// \brief Makes one independent ResidualFn per worker thread (the model's
///        workspace is not shared). Each functor must give the same result
///        for the same parameters whatever it computed before (no warm
///        starts), or parallel and serial fits differ.
using ResidualFactory = std::function<ResidualFn()>;

namespace detail {

using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Optional wall-clock deadline shared by all stages.
struct Deadline {
  bool active = false;
  Clock::time_point end{};
  bool passed() const { return active && Clock::now() >= end; }
  double remaining_seconds() const {
    return active ? std::chrono::duration<double>(end - Clock::now()).count() : kInf;
  }
};

/// One residual functor with its counters; used by one thread at a time.
class Evaluator {
 public:
  Evaluator(const ParameterSet& ps, int m, ResidualFn fn) : ps_(&ps), m_(m), fn_(std::move(fn)) {}

  /// Residual at physical `x`; false (and counted) on any failure.
  bool physical(const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    ++evaluations;
    bool ok = false;
    r.resize(m_);
    try {
      ok = fn_ && fn_(x, r);
    } catch (...) {
      ok = false;
    }
    if (ok && (r.size() != m_ || !r.allFinite())) ok = false;
    if (!ok) ++failures;
    return ok;
  }
  /// Residual at normalised `u`.
  bool normalised(const Eigen::VectorXd& u, Eigen::VectorXd& r) {
    return physical(ps_->to_physical(u), r);
  }
  const ParameterSet& parameters() const { return *ps_; }
  int residual_size() const { return m_; }

  int evaluations = 0;
  int failures = 0;

 private:
  const ParameterSet* ps_;
  int m_;
  ResidualFn fn_;
};

/// Runs batches of independent tasks, task k writing only its own outputs.
/// Worker w always uses evaluator w, so no functor is shared between threads.
class Runner {
 public:
  explicit Runner(std::vector<Evaluator*> evaluators) : evaluators_(std::move(evaluators)) {}

  Evaluator& main() { return *evaluators_.front(); }
  int evaluations() const {
    int n = 0;
    for (const Evaluator* e : evaluators_) n += e->evaluations;
    return n;
  }
  int failures() const {
    int n = 0;
    for (const Evaluator* e : evaluators_) n += e->failures;
    return n;
  }

  void run(int n, const std::function<void(int task, Evaluator& ev)>& task) {
    parallel_for_workers(n, static_cast<int>(evaluators_.size()),
                         [&](int k, int w) { task(k, *evaluators_[static_cast<std::size_t>(w)]); });
  }

 private:
  std::vector<Evaluator*> evaluators_;
};

inline double half_squared_norm(const Eigen::VectorXd& r) {
  return 0.5 * r.squaredNorm();
}

}  // namespace detail
}  // namespace softrne::fit
