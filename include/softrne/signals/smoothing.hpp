#pragma once
/// \file
/// \brief Zero-phase Gaussian smoothing of sampled signals on irregular grids.
///
/// Moved from sim/arm_simulation.hpp (signal processing has its own folder, signals/);
/// softrne::sim::smooth_pressures stays available there as a using-declaration.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace softrne::signals {

/// \brief Zero-phase Gaussian smoothing of sampled signals (one column per channel), for
/// sim::ArmSimulationOptions::pressure_smoothing: row i becomes the weighted mean of the rows j
/// with weights exp(-(t_j - t_i)^2 / (2 sigma^2)) - exp(-8), cut off at |t_j - t_i| = 4 sigma
/// where they reach zero (so that rounding in the window bounds cannot matter), renormalised at
/// the ends. Works on irregular grids; non-negative weights, so no overshoot at pressure steps.
/// sigma <= 0 returns the input. Cost O(N * window).
/// \param[in] t The N sample times, s (irregular allowed).
/// \param[in] p N x P samples.
/// \param[in] sigma The kernel's standard deviation, s.
/// \return The smoothed N x P samples.
inline Eigen::MatrixXd smooth_pressures(const Eigen::VectorXd& t, const Eigen::MatrixXd& p,
                                        double sigma) {
  if (!(sigma > 0) || t.size() < 2) return p;
  const Eigen::Index n = t.size();
  Eigen::MatrixXd out(p.rows(), p.cols());
  const double reach = 4 * sigma, inv2s2 = 1.0 / (2 * sigma * sigma), floor = std::exp(-8.0);
  Eigen::Index lo = 0, hi = 0;  // window [lo, hi) around sample i
  for (Eigen::Index i = 0; i < n; ++i) {
    while (t(lo) < t(i) - reach) ++lo;
    while (hi < n && t(hi) <= t(i) + reach) ++hi;
    double wsum = 0;
    out.row(i).setZero();
    for (Eigen::Index j = lo; j < hi; ++j) {
      const double dt = t(j) - t(i);
      const double w = std::max(0.0, std::exp(-dt * dt * inv2s2) - floor);
      out.row(i) += w * p.row(j);
      wsum += w;
    }
    out.row(i) /= wsum;  // >= the weight of j = i, 1 - exp(-8)
  }
  return out;
}

}  // namespace softrne::signals
