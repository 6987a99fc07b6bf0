#pragma once
/// \file
/// \brief What is still unexplained after the closed loop: per coordinate, how far the
/// simulation error stays above the sensor noise floor, what it correlates with (q, qdot, the
/// pressure drive K_prs p and its rate), and in which frequency band its power lies. It names
/// no effect: only held-out evidence may do that (docs/closing-the-loop.md).

#include <cmath>
#include <complex>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/fit/noise_floor.hpp"
#include "softrne/signals/savitzky_golay.hpp"

namespace softrne::fit {

/// \brief One coordinate's unexplained residual.
struct CoordinateResidual {
  std::string name;  ///< the coordinate's name (u1, ...)
  double median = 0;       ///< median |measured - simulated| (rad)
  double floor = 0;        ///< what sensor noise alone gives (rad)
  double ratio = 0;        ///< median / floor
  double corr_q = 0, corr_qdot = 0, corr_drive = 0, corr_drive_rate = 0;  ///< Pearson r

  /// Fractions of the residual's power below 0.5 Hz, 0.5-2 Hz, 2-10 Hz, above 10 Hz.
  std::vector<double> band_power;
  /// \var corr_q
  /// \brief Pearson r of the residual with q.
  /// \var corr_qdot
  /// \brief Pearson r of the residual with qdot.
  /// \var corr_drive
  /// \brief Pearson r of the residual with the drive K_prs p (eq. 24).
};

/// \brief The statement of the report: which coordinates are clearly above the floor.
struct UnexplainedResidual {
  double threshold = 1.5;  ///< a coordinate is "clearly above" when ratio > threshold
  std::vector<CoordinateResidual> coordinates;  ///< one per coordinate
  bool above_floor = false;  ///< some coordinate is clearly above its noise floor
  std::string statement;     ///< the report's one-sentence conclusion
};

/// \brief Band edges (Hz) of CoordinateResidual::band_power.
/// \return {0.5, 2, 10}.
inline std::vector<double> residual_band_edges() { return {0.5, 2.0, 10.0}; }

namespace detail {

inline double pearson(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::ArrayXd x = a.array() - a.mean(), y = b.array() - b.mean();
  const double d = std::sqrt((x * x).sum() * (y * y).sum());
  return d > 0 ? (x * y).sum() / d : 0.0;
}

/// Power fractions per band of a demeaned signal on a (near) uniform grid, by a direct DFT
/// (O(N^2), N ~ 1e3..1e4 here).
SOFTRNE_FIT_INLINE std::vector<double> band_fractions(const Eigen::VectorXd& t, const Eigen::VectorXd& e)
#if SOFTRNE_FIT_BODIES
{
  const auto edges = residual_band_edges();
  std::vector<double> p(edges.size() + 1, 0.0);
  const Eigen::Index n = e.size();
  if (n < 4) return p;
  const double dt = (t(n - 1) - t(0)) / static_cast<double>(n - 1);
  const Eigen::VectorXd x = e.array() - e.mean();
  double total = 0;
  for (Eigen::Index k = 1; k <= n / 2; ++k) {
    std::complex<double> s = 0;
    const double w = -2 * M_PI * static_cast<double>(k) / static_cast<double>(n);
    for (Eigen::Index i = 0; i < n; ++i) s += x(i) * std::polar(1.0, w * static_cast<double>(i));
    const double pw = std::norm(s);
    const double f = static_cast<double>(k) / (static_cast<double>(n) * dt);
    std::size_t b = 0;
    while (b < edges.size() && f >= edges[b]) ++b;
    p[b] += pw;
    total += pw;
  }
  if (total > 0)
    for (double& v : p) v /= total;
  return p;
}
#else
;
#endif

}  // namespace detail

/// \brief Analyses measured - simulated angles of the final model on a data set.
/// \param desc      the final model (its pressure maps give the drive K_prs p)
/// \param t         sample times (N)
/// \param measured  measured angles (N x nq)
/// \param simulated simulated angles in measurement space (N x nq)
/// \param pressures recorded pressures (N x inputs)
/// \param sigma     sensor noise per coordinate (estimate_noise_sigma)
/// \param threshold a coordinate is clearly above its floor when median / floor exceeds it
/// \return The per-coordinate analysis and the statement.
SOFTRNE_FIT_INLINE UnexplainedResidual analyse_residual(const ArmDescription& desc, const Eigen::VectorXd& t,
                                                        const Eigen::MatrixXd& measured,
                                                        const Eigen::MatrixXd& simulated,
                                                        const Eigen::MatrixXd& pressures,
                                                        const Eigen::VectorXd& sigma, double threshold = 1.5)
#if SOFTRNE_FIT_BODIES
{
  UnexplainedResidual out;
  out.threshold = threshold;
  const Eigen::Index n = std::min(measured.rows(), simulated.rows());
  if (n < 16) return out;
  const Eigen::MatrixXd e = measured.topRows(n) - simulated.topRows(n);
  const Eigen::VectorXd tt = t.head(n);
  Eigen::MatrixXd q, qd, qdd, drive(n, desc.nq), drive_s, drive_d, drive_dd;
  signals::savgol(tt, measured.topRows(n), signals::SgOptions{}, q, qd, qdd);
  drive.setZero();
  for (const auto& j : desc.joints)
    for (int k = 0; k < j.nq; ++k)
      for (int c = 0; c < j.num_inputs; ++c)
        drive.col(j.q_offset + k) += j.pressure_to_torque(k, c) * pressures.col(j.input_offset + c).head(n);
  signals::savgol(tt, drive, signals::SgOptions{}, drive_s, drive_d, drive_dd);
  std::string above;
  for (int k = 0; k < desc.nq; ++k) {
    CoordinateResidual c;
    c.name = desc.coordinate_names[static_cast<std::size_t>(k)];
    std::vector<double> a(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) a[static_cast<std::size_t>(i)] = std::abs(e(i, k));
    std::nth_element(a.begin(), a.begin() + n / 2, a.end());
    c.median = a[static_cast<std::size_t>(n / 2)];
    c.floor = noise_floor_median(sigma(k));
    c.ratio = c.floor > 0 ? c.median / c.floor : INFINITY;
    const Eigen::VectorXd ek = e.col(k);
    c.corr_q = detail::pearson(ek, q.col(k));
    c.corr_qdot = detail::pearson(ek, qd.col(k));
    c.corr_drive = detail::pearson(ek, drive_s.col(k));
    c.corr_drive_rate = detail::pearson(ek, drive_d.col(k));
    c.band_power = detail::band_fractions(tt, ek);
    if (c.ratio > threshold) {
      out.above_floor = true;
      const char* feat[] = {"q", "qdot", "K_prs p", "d(K_prs p)/dt"};
      const double r[] = {c.corr_q, c.corr_qdot, c.corr_drive, c.corr_drive_rate};
      int best = 0;
      for (int f = 1; f < 4; ++f)
        if (std::abs(r[f]) > std::abs(r[best])) best = f;
      const char* band[] = {"< 0.5 Hz", "0.5-2 Hz", "2-10 Hz", "> 10 Hz"};
      std::size_t bb = 0;
      for (std::size_t b = 1; b < c.band_power.size(); ++b)
        if (c.band_power[b] > c.band_power[bb]) bb = b;
      char line[320];
      std::snprintf(line, sizeof line,
                    "%s%s: median error %.4f rad, %.1fx the noise floor %.4f; correlates most with "
                    "%s (r = %+.2f); %.0f %% of its power %s",
                    above.empty() ? "" : "; ", c.name.c_str(), c.median, c.ratio, c.floor,
                    feat[best], r[best], 100 * c.band_power[bb], band[bb]);
      above += line;
    }
    out.coordinates.push_back(c);
  }
  if (out.above_floor)
    out.statement = "unexplained residual above the sensor noise floor (no effect tried earned its "
                    "place for it): " + above;
  else
    out.statement = "every coordinate is within " + std::to_string(threshold).substr(0, 4) +
                    "x of the sensor noise floor: nothing systematic is left to explain";
  return out;
}
#else
;
#endif

}  // namespace softrne::fit
