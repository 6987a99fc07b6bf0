#pragma once
/// \file
/// \brief The white-noise level of sampled signals, estimated from the data alone (no model).
///
/// Moved from fit/noise_floor.hpp, where the closed loop turns it into its noise floor;
/// softrne::fit::estimate_noise_sigma stays available there as a using-declaration.

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace softrne::signals {

/// \brief Noise standard deviation of each column of `y` (N x n, uniformly or nearly
/// uniformly sampled), from third differences.
///
/// For white noise of standard deviation sigma, d3_i = y_{i+1} - 3 y_i + 3 y_{i-1} - y_{i-2}
/// has standard deviation sigma sqrt(1 + 9 + 9 + 1) = sigma sqrt(20), while a smooth signal
/// contributes only y''' dt^3 (1e-4 rad at 100 Hz for y''' = 100 rad/s^3). The median
/// absolute value (robust to the few samples at pressure steps where y''' is large) gives
/// sigma = median|d3| / (0.6745 sqrt(20)). Independent of any model.
/// \param[in] y N x n samples, one column per signal.
/// \return One sigma per column (zero with fewer than 8 samples).
inline Eigen::VectorXd estimate_noise_sigma(const Eigen::MatrixXd& y) {
  Eigen::VectorXd sigma = Eigen::VectorXd::Zero(y.cols());
  const Eigen::Index n = y.rows();
  if (n < 8) return sigma;
  for (Eigen::Index c = 0; c < y.cols(); ++c) {
    std::vector<double> d;
    d.reserve(static_cast<std::size_t>(n - 3));
    for (Eigen::Index i = 2; i + 1 < n; ++i)
      d.push_back(std::abs(y(i + 1, c) - 3 * y(i, c) + 3 * y(i - 1, c) - y(i - 2, c)));
    std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
    sigma(c) = d[d.size() / 2] / (0.6744897501960817 * std::sqrt(20.0));
  }
  return sigma;
}

}  // namespace softrne::signals
