#pragma once
/// \file
/// \brief Absolute joint-angle error statistics (the paper's Tables I and II).
///
/// Statistics of |simulated - measured| for two sampled signals on one grid: they need no
/// model, and the simulator's tools and the fit both report them. Moved from model/ (which
/// held the arm layer); softrne::ErrorStats, ErrorSummary, error_stats and format_error_table
/// stay available through model/error_stats.hpp and fit/arm_fit.hpp.

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace softrne::signals {

/// \brief Mean, median and max of |simulated - measured| for one angle or all of them.
struct ErrorSummary {
  double mean = 0, median = 0, max = 0;
  /// \var mean
  /// \brief Mean absolute error, rad.
  /// \var median
  /// \brief Median absolute error, rad.
  /// \var max
  /// \brief Largest absolute error, rad.
};

/// \brief Per-angle and total error statistics (formats.md section 5, `STATS`).
struct ErrorStats {
  std::vector<std::string> names;       ///< the angles' names
  std::vector<ErrorSummary> per_angle;  ///< one summary per angle, in names' order
  ErrorSummary total;                   ///< over every sample of every angle
};

namespace detail {
inline ErrorSummary summarize(std::vector<double> v) {
  ErrorSummary s;
  if (v.empty()) return s;
  double sum = 0;
  for (double x : v) {
    sum += x;
    s.max = std::max(s.max, x);
  }
  s.mean = sum / static_cast<double>(v.size());
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + static_cast<long>(n / 2), v.end());
  double med = v[n / 2];
  if (n % 2 == 0) {
    const double lower = *std::max_element(v.begin(), v.begin() + static_cast<long>(n / 2));
    med = 0.5 * (med + lower);
  }
  s.median = med;
  return s;
}
}  // namespace detail

/// \brief Statistics of |simulated - measured| over all samples (rows) for each angle
/// (column) and in total. Rows beyond the shorter of the two are ignored.
/// \param[in] simulated N x nq simulated angles, rad.
/// \param[in] measured N x nq measured angles, rad.
/// \param[in] names The nq angle names.
/// \return The statistics (the paper's Tables I-II).
inline ErrorStats error_stats(const Eigen::MatrixXd& simulated, const Eigen::MatrixXd& measured,
                              const std::vector<std::string>& names) {
  ErrorStats out;
  out.names = names;
  const Eigen::Index rows = std::min(simulated.rows(), measured.rows());
  std::vector<double> all;
  all.reserve(static_cast<std::size_t>(rows * measured.cols()));
  for (Eigen::Index c = 0; c < measured.cols(); ++c) {
    std::vector<double> col(static_cast<std::size_t>(rows));
    for (Eigen::Index r = 0; r < rows; ++r)
      col[static_cast<std::size_t>(r)] = std::abs(simulated(r, c) - measured(r, c));
    all.insert(all.end(), col.begin(), col.end());
    out.per_angle.push_back(detail::summarize(std::move(col)));
  }
  out.total = detail::summarize(std::move(all));
  return out;
}

/// \brief The table as text, like the paper's Tables I-II (radians; or marker distances, mm).
/// \param[in] s The statistics.
/// \param[in] title The first line.
/// \param[in] what The first column's heading ("angle", "marker").
/// \param[in] unit The unit after the total line ("rad", "mm").
/// \return The table, one line per angle and a total line.
inline std::string format_error_table(const ErrorStats& s, const std::string& title,
                                      const std::string& what = "angle", const std::string& unit = "rad") {
  std::string out = title + "\n";
  char line[160];
  std::snprintf(line, sizeof line, "  %-10s %10s %10s %10s\n", what.c_str(), "mean", "median", "max");
  out += line;
  for (std::size_t i = 0; i < s.per_angle.size(); ++i) {
    std::snprintf(line, sizeof line, "  %-10s %10.4f %10.4f %10.4f\n", s.names[i].c_str(),
                  s.per_angle[i].mean, s.per_angle[i].median, s.per_angle[i].max);
    out += line;
  }
  std::snprintf(line, sizeof line, "  %-10s %10.4f %10.4f %10.4f   (%s)\n", "total", s.total.mean,
                s.total.median, s.total.max, unit.c_str());
  out += line;
  return out;
}

}  // namespace softrne::signals
