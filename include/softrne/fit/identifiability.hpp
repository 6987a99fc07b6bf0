#pragma once
/// \file
/// \brief Identifiability analysis at a point: the central-difference Jacobian w.r.t. the
///        physical parameters, its SVD scaled by parameter magnitude, the covariance, std
///        errors, correlations, null directions and a human-readable report (the fields of
///        FitResult that analyse_identifiability() and fit_least_squares() fill).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SVD>

#include "softrne/config.hpp"
#include "softrne/fit/finite_difference_jacobian.hpp"
#include "softrne/fit/least_squares_types.hpp"
#include "softrne/fit/parameters.hpp"
#include "softrne/fit/residual_evaluation.hpp"

namespace softrne::fit::detail {

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
    Eigen::VectorXd v = x;
    const bool ok = central_difference_column(ev, Coordinates::physical, x, r, k,
                                              h_rel * magnitude[k], lo[k], hi[k], v, J.col(k));
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

}  // namespace softrne::fit::detail
