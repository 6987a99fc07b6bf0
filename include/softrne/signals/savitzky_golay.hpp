#pragma once
/// \file
/// \brief Savitzky-Golay smoothing differentiator for noisy, possibly
///        irregularly sampled signals (Eigen only).
///
/// At every sample \f$t_i\f$ a polynomial of order \f$p\f$ is fitted by least
/// squares to the \f$2k+1\f$ samples around it, in the actual time stamps:
/// \f$y(t) \approx \sum_{q=0}^{p} c_q \tau^q\f$, \f$\tau = (t - t_i)/s\f$.
/// Then \f$\hat y_i = c_0\f$, \f$\dot y_i = c_1/s\f$, \f$\ddot y_i = 2c_2/s^2\f$
/// (Savitzky & Golay 1964; Gorry 1990 for the end points).
/// Near the ends the window keeps its length and order but is shifted, so
/// the fit is asymmetric rather than truncated. For uniform sampling and an
/// interior point this reproduces the classical convolution weights.
///
/// It lived in fit/ (the fit's residual analysis differentiates measured angles with it) and
/// keeps fit/'s compiled mode: SOFTRNE_FIT_INLINE, so a target linking softrne::fit_compiled
/// gets its one definition from src/fit.cpp. Its error messages still name
/// softrne::fit::savgol, the name callers had when they were written.

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Core>
#include <Eigen/QR>

#include "softrne/config.hpp"

namespace softrne::signals {

/// \brief Window and order of the smoothing differentiator.
struct SgOptions {
  /// Samples on each side of the centre, \f$k\f$ (window of \f$2k+1\f$).
  int half_window = 7;
  /// Polynomial order \f$p\f$ (needs \f$2k+1 \ge p+1\f$ samples).
  int order = 3;
};

/// \brief Weights that map the samples of one window to the value, first and
///        second derivative of the local least-squares polynomial at `t_eval`.
///
/// \param t_window distinct time stamps of the window (any order).
/// \param t_eval   where to evaluate (usually one of `t_window`).
/// \param order    polynomial order \f$p\f$, with `t_window.size() >= p+1`.
/// \return a \f$3 \times w\f$ matrix `W`: `W.row(d).dot(y_window)` is the
///         d-th derivative. Rows above `order` are zero.
SOFTRNE_FIT_INLINE Eigen::Matrix<double, 3, Eigen::Dynamic> savgol_weights(const Eigen::VectorXd& t_window,
                                                                           double t_eval, int order)
#if SOFTRNE_FIT_BODIES
{
  const Eigen::Index w = t_window.size();
  if (order < 0) throw std::invalid_argument("softrne::fit::savgol_weights: order < 0");
  if (w < order + 1)
    throw std::invalid_argument("softrne::fit::savgol_weights: window shorter than order + 1");
  // Scale tau into [-1, 1] so the Vandermonde matrix stays well conditioned.
  const Eigen::ArrayXd dt = t_window.array() - t_eval;
  double scale = dt.abs().maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) scale = 1.0;
  const Eigen::Index nc = order + 1;
  Eigen::MatrixXd V(w, nc);
  for (Eigen::Index j = 0; j < w; ++j) {
    const double tau = dt[j] / scale;
    double power = 1.0;
    for (Eigen::Index q = 0; q < nc; ++q) {
      V(j, q) = power;
      power *= tau;
    }
  }
  // pinv(V) = R^{-1} Q1^T from a Householder QR, V = Q1 R.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(V);
  const Eigen::MatrixXd Q1 = qr.householderQ() * Eigen::MatrixXd::Identity(w, nc);
  const Eigen::MatrixXd R = qr.matrixQR().topLeftCorner(nc, nc);
  const Eigen::MatrixXd P =
      R.triangularView<Eigen::Upper>().solve(Q1.transpose());  // nc x w: coefficients c_q
  Eigen::Matrix<double, 3, Eigen::Dynamic> W = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, w);
  W.row(0) = P.row(0);
  if (order >= 1) W.row(1) = P.row(1) / scale;
  if (order >= 2) W.row(2) = 2.0 * P.row(2) / (scale * scale);
  return W;
}
#else
;
#endif

/// \brief Column-wise Savitzky-Golay smoothing and differentiation.
///
/// \param t   strictly increasing, finite time stamps (\f$n\f$ of them; need not be uniform).
/// \param y   \f$n \times c\f$ samples, one signal per column.
/// \param opt window and order; the window is shortened to \f$n\f$ samples
///            when the signal is shorter than \f$2k+1\f$.
/// \param y_s smoothed values (\f$n \times c\f$).
/// \param dy  first derivatives w.r.t. t.
/// \param ddy second derivatives w.r.t. t (zero when `order < 2`).
/// \throws std::invalid_argument on mismatched sizes, non-increasing t, or
///         fewer than `order + 1` samples.
SOFTRNE_FIT_INLINE void savgol(const Eigen::VectorXd& t, const Eigen::MatrixXd& y, const SgOptions& opt,
                               Eigen::MatrixXd& y_s, Eigen::MatrixXd& dy, Eigen::MatrixXd& ddy)
#if SOFTRNE_FIT_BODIES
{
  const Eigen::Index n = t.size();
  if (y.rows() != n) throw std::invalid_argument("softrne::fit::savgol: y.rows() != t.size()");
  if (opt.half_window < 0 || opt.order < 0)
    throw std::invalid_argument("softrne::fit::savgol: negative half_window or order");
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(t[i])) throw std::invalid_argument("softrne::fit::savgol: non-finite t");
    if (i > 0 && !(t[i] > t[i - 1]))
      throw std::invalid_argument("softrne::fit::savgol: t must be strictly increasing");
  }
  const Eigen::Index w = std::min<Eigen::Index>(2 * Eigen::Index{opt.half_window} + 1, n);
  if (w < opt.order + 1)
    throw std::invalid_argument("softrne::fit::savgol: fewer samples than order + 1");
  y_s.resize(n, y.cols());
  dy.resize(n, y.cols());
  ddy.resize(n, y.cols());
  for (Eigen::Index i = 0; i < n; ++i) {
    // Centred window, shifted (same length and order) at the ends.
    const Eigen::Index a = std::clamp<Eigen::Index>(i - opt.half_window, 0, n - w);
    const auto W = savgol_weights(t.segment(a, w), t[i], opt.order);
    const auto block = y.middleRows(a, w);
    y_s.row(i).noalias() = W.row(0) * block;
    dy.row(i).noalias() = W.row(1) * block;
    ddy.row(i).noalias() = W.row(2) * block;
  }
}
#else
;
#endif

}  // namespace softrne::signals
