#pragma once
/// \file
/// \brief The rate of a sampled signal at its first sample, from the first samples alone: what
/// a recording that starts in motion needs as its initial velocity (issue 19).

#include <algorithm>
#include <stdexcept>

#include <Eigen/Core>
#include <Eigen/Cholesky>

namespace softrne::signals {

/// \brief Slope at t(0) of the least-squares quadratic through the first `samples` rows of
/// each column of `y`.
///
/// A quadratic, not a line: a recording that starts while the arm accelerates (the usual case
/// when a log is cut out of a longer run) has a curved start, and a line's slope is the rate
/// at the window's middle, off by acceleration x half the window. The price is noise: through
/// n samples of white noise sigma at spacing dt the slope's standard deviation is about
/// sqrt(192) sigma / (n^1.5 dt) for large n (n = 9: 0.14 rad/s for sigma 3e-3 rad at 100 Hz,
/// exactly), which the simulation's damping then forgets. Times are taken relative to t(0)
/// and scaled by the window, so the normal equations stay well conditioned at any rate.
/// \param[in] t N sample times, strictly increasing.
/// \param[in] y N x n samples.
/// \param[in] samples How many first samples (at least 3; fewer rows: all of them).
/// \return The n rates (units of y per s).
/// \throws std::invalid_argument with fewer than 3 rows or mismatched sizes.
inline Eigen::VectorXd initial_rate(const Eigen::VectorXd& t, const Eigen::MatrixXd& y, int samples = 9) {
  if (t.size() != y.rows()) throw std::invalid_argument("initial_rate: t and y have different row counts");
  const Eigen::Index n = std::min<Eigen::Index>(std::max(samples, 3), t.size());
  if (n < 3) throw std::invalid_argument("initial_rate: at least 3 samples are needed");
  const double span = t(n - 1) - t(0);
  if (!(span > 0)) throw std::invalid_argument("initial_rate: the first samples' times do not increase");
  // The 3 x 3 normal equations of the basis (1, s, s^2), s = (t - t0) / span in [0, 1]: on
  // that interval their condition number is small (228 to 505 for 3 to 100 evenly spaced
  // samples: about 1e-13 relative error), and a fixed-size LDLT costs the compiler a fraction
  // of what a dynamic-size QR does in every unit that includes this header (through
  // io/recordings.hpp: 3.6 -> 1.8 s of g++ front end for this header alone).
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd Aty = Eigen::MatrixXd::Zero(3, y.cols());
  for (Eigen::Index i = 0; i < n; ++i) {
    const double s = (t(i) - t(0)) / span;
    const Eigen::Vector3d a(1.0, s, s * s);
    AtA.noalias() += a * a.transpose();
    Aty.noalias() += a * y.row(i);
  }
  const Eigen::MatrixXd coef = AtA.ldlt().solve(Aty);  // 3 x cols
  return coef.row(1).transpose() / span;  // d/dt = d/ds / span at s = 0
}

}  // namespace softrne::signals
