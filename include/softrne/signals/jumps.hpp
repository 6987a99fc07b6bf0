#pragma once
/// \file
/// \brief Where sampled pressures step: the times an ODE integrator should restart at.
///
/// Moved from sim/arm_simulation.hpp (signal processing has its own folder, signals/);
/// softrne::sim::pressure_jumps stays available there as a using-declaration.

#include <algorithm>
#include <limits>
#include <vector>

#include <Eigen/Core>

namespace softrne::signals {

/// \brief Times where the recorded pressures jump (a pressure step): the integrator restarts
/// there. A jump is a sample-to-sample change larger than both 10x the channel's median change
/// (noise) and 5% of its range; relative, so it does not depend on units or the robot.
/// \param[in] t The N sample times, s.
/// \param[in] p N x P recorded pressures.
/// \return The sample times where a step starts, increasing.
inline std::vector<double> pressure_jumps(const Eigen::VectorXd& t, const Eigen::MatrixXd& p) {
  std::vector<double> out;
  const Eigen::Index n = t.size();
  if (n < 3 || p.cols() == 0) return out;
  const Eigen::MatrixXd d = (p.bottomRows(n - 1) - p.topRows(n - 1)).cwiseAbs();
  Eigen::VectorXd thr(p.cols());
  for (Eigen::Index c = 0; c < p.cols(); ++c) {
    std::vector<double> col(d.col(c).data(), d.col(c).data() + d.rows());
    std::nth_element(col.begin(), col.begin() + static_cast<long>(col.size() / 2), col.end());
    const double med = col[col.size() / 2];
    const double range = p.col(c).maxCoeff() - p.col(c).minCoeff();
    thr(c) = std::max(10 * med, 0.05 * range);
    if (!(thr(c) > 0)) thr(c) = std::numeric_limits<double>::infinity();
  }
  for (Eigen::Index i = 0; i + 1 < n; ++i)
    for (Eigen::Index c = 0; c < p.cols(); ++c)
      if (d(i, c) > thr(c)) {
        out.push_back(t(i));  // the ramp of a step starts at sample i
        break;
      }
  return out;
}

}  // namespace softrne::signals
