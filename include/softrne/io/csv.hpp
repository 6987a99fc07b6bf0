#pragma once
/// \file
/// \brief CSV tables of measured, commanded and simulated data
/// (docs/formats.md sections 2 and 3): the data set of a robot (its time,
/// pressure and angle columns, checked against the robot) and the trajectory writer.
/// The strict reader and the full-precision writer of the tables themselves, and
/// what they accept, are csv_table.hpp's.

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "softrne/io/csv_table.hpp"
#include "softrne/io/errors.hpp"
#include "softrne/io/robot_spec.hpp"

namespace softrne::io {

/// \brief The data a robot needs from a measured or commanded CSV file.
struct Dataset {
  Eigen::VectorXd t;          ///< N, strictly increasing (s)
  Eigen::MatrixXd pressures;  ///< N x P, columns in robot order p1_0..p1_{K-1}, p2_0.. (Pa)
  Eigen::MatrixXd angles;     ///< N x nq in chain coordinate order (rad); N x 0 if absent
  bool has_angles = false;  ///< the file has the angle columns (all of them)
  std::vector<std::string> pressure_names;  ///< the P pressure column names, in order
  std::vector<std::string> angle_names;     ///< the nq coordinate names (even when absent)
  /// N x 3M measured marker positions (m, motion-capture frame), columns `<name>_x, _y, _z`
  /// of the robot's M markers in its order (marker_column_names()); N x 0 if absent.
  Eigen::MatrixXd markers;
  bool has_markers = false;  ///< the file has the marker columns (all of them)
  std::string source;  ///< the file, for messages

  /// \brief One recording of a data set that stacks several (io::stack_recordings()).
  struct Recording {
    Eigen::Index first_row = 0;  ///< its first row in t, pressures and angles
    Eigen::Index rows = 0;       ///< its number of rows
    /// Added to the recording's own times so that the stacked t increases strictly: t of
    /// its first row minus its file's first time.
    double time_shift = 0;
    std::string source;  ///< its file, for messages
    /// Measured angle rates at its first sample (rad/s, size nq; estimate_initial_rates()):
    /// the simulation starts with them. Empty: at rest, as the paper's experiments start.
    Eigen::VectorXd initial_rates;
  };
  /// The recordings, in row order, each simulated from its own first sample. Empty: the data
  /// set is one recording that starts at rest (every data set read from one file).
  std::vector<Recording> recordings;
};

namespace detail {

/// \brief True if `s` is `<c><digits>` or `<c><digits>_<digits>` (when `underscore`).
inline bool is_indexed_name(const std::string& s, char c, bool underscore) {
  if (s.size() < 2 || s[0] != c) return false;
  std::size_t i = 1;
  const auto digits = [&] {
    const std::size_t b = i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
    return i > b;
  };
  if (!digits()) return false;
  if (underscore) {
    if (i >= s.size() || s[i] != '_') return false;
    ++i;
    if (!digits()) return false;
  }
  return i == s.size();
}

}  // namespace detail

/// \brief The data columns of the robot's markers: `<name>_x, <name>_y, <name>_z` each.
/// \param[in] robot The robot.
/// \return 3 names per marker, in the robot's order.
inline std::vector<std::string> marker_column_names(const RobotSpec& robot) {
  std::vector<std::string> out;
  for (const auto& m : robot.markers)
    for (const char* axis : {"_x", "_y", "_z"}) out.push_back(m.name + axis);
  return out;
}

/// \brief Parse the CSV text of a data set for `robot`: columns `t`, every
/// `p{j}_{k}` of the robot, the angle columns (all of them or none; all if
/// `require_angles`, unless the robot's marker columns are all there) and the marker columns
/// (marker_column_names(): all of them or none). Other columns are ignored (not even parsed), except
/// `p{j}_{k}`, `u{j}`, `v{j}` columns the robot does not have, which mean robot
/// and data disagree (UnexpectedColumn). `t` must increase strictly; 2 rows at least.
/// \param[in] text The file's content.
/// \param[in] source The file's name, for messages.
/// \param[in] robot The robot the data belong to (its pressure and angle columns).
/// \param[in] require_angles Measurements must be present: the angle columns, or for a robot
///   with markers the angle or the marker columns.
/// \return Times, pressures and (if present) angles, in the robot's column order.
/// \throws InputError (MissingColumn, UnexpectedColumn, NonIncreasingTime, TooFewRows, or
///   as parse_csv()) naming source, line and column.
inline Dataset parse_dataset(const std::string& text, const std::string& source,
                             const RobotSpec& robot, bool require_angles) {
  detail::CsvScanner scan(text, source);
  const auto& header = scan.header();
  std::unordered_map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < header.size(); ++i)
    if (!header[i].empty()) index.emplace(header[i], i);
  const std::string robot_desc =
      robot.name.empty() ? std::string("the robot") : "robot " + detail::quoted(robot.name, 60);

  const std::size_t ncc = num_cc_joints(robot);
  const std::string cc_count = std::to_string(ncc) + (ncc == 1 ? " cc joint" : " cc joints");
  Dataset d;
  d.source = source;
  d.pressure_names = pressure_column_names(robot);
  d.angle_names = coordinate_names(robot);

  const auto it_t = index.find("t");
  if (it_t == index.end()) {
    std::string hint;
    if (header.size() == 1 && header[0].find_first_of(";\t") != std::string::npos)
      hint = "; the header has a single column: cells must be separated by ','";
    throw InputError(Category::MissingColumn, source, scan.header_where(),
                     "missing column 't' (time in s)" + hint);
  }
  std::vector<std::size_t> wanted{it_t->second};

  for (const auto& name : d.pressure_names) {
    const auto it = index.find(name);
    if (it == index.end())
      throw InputError(Category::MissingColumn, source, scan.header_where(),
                       "missing column '" + name + "' (" + robot_desc + " has " +
                           std::to_string(d.pressure_names.size()) + " pressure columns, " +
                           d.pressure_names.front() + ".." + d.pressure_names.back() + ")");
    wanted.push_back(it->second);
  }
  for (const auto& h : header) {
    const bool pressure_like = detail::is_indexed_name(h, 'p', true);
    const bool angle_like =
        detail::is_indexed_name(h, 'u', false) || detail::is_indexed_name(h, 'v', false);
    if (pressure_like &&
        std::find(d.pressure_names.begin(), d.pressure_names.end(), h) == d.pressure_names.end())
      throw InputError(Category::UnexpectedColumn, source, scan.header_where(),
                       "column '" + h + "' is not a pressure of " + robot_desc + " (" + cc_count +
                           ", pressure columns " +
                           (d.pressure_names.empty()
                                ? std::string("none")
                                : d.pressure_names.front() + ".." + d.pressure_names.back()) +
                           "): robot description and data disagree");
    if (angle_like &&
        std::find(d.angle_names.begin(), d.angle_names.end(), h) == d.angle_names.end())
      throw InputError(Category::UnexpectedColumn, source, scan.header_where(),
                       "column '" + h + "' is not an angle of " + robot_desc + " (" + cc_count +
                           "): robot description and data disagree");
  }

  // Marker columns: all of the robot's or none; where measurements are required, markers may
  // stand in for the angles (a fit from motion capture alone).
  const std::vector<std::string> marker_names = marker_column_names(robot);
  std::size_t markers_present = 0;
  for (const auto& name : marker_names) markers_present += index.count(name);
  d.has_markers = !marker_names.empty() && markers_present == marker_names.size();

  std::size_t present = 0;
  for (const auto& name : d.angle_names) present += index.count(name);
  const std::size_t nq = d.angle_names.size();
  if ((present > 0 && present < nq) || (present == 0 && require_angles && nq > 0 && !d.has_markers)) {
    for (const auto& name : d.angle_names) {
      if (index.count(name) == 0)
        throw InputError(Category::MissingColumn, source, scan.header_where(),
                         "missing column '" + name + "'" +
                             (present == 0 ? std::string(" (measured angles are required here)")
                                           : " (angle columns must be all present or all absent)"));
    }
  }
  d.has_angles = present == nq;
  if (d.has_angles)
    for (const auto& name : d.angle_names) wanted.push_back(index.at(name));
  if (markers_present > 0 && markers_present < marker_names.size())
    for (const auto& name : marker_names)
      if (index.count(name) == 0)
        throw InputError(Category::MissingColumn, source, scan.header_where(),
                         "missing column '" + name + "' (marker columns must be all present or all absent)");
  if (d.has_markers)
    for (const auto& name : marker_names) wanted.push_back(index.at(name));

  std::vector<double> data;
  double t_prev = 0.0;
  std::size_t line_prev = 0;
  const std::size_t rows = scan.read_rows(wanted, data, [&](const double* row, std::size_t line) {
    if (line_prev != 0 && !(row[0] > t_prev))
      throw InputError(Category::NonIncreasingTime, source, detail::cell_where(line, "t"),
                       "time not strictly increasing (" + detail::format_double(row[0]) +
                           " after " + detail::format_double(t_prev) + " on line " +
                           std::to_string(line_prev) + ")");
    t_prev = row[0];
    line_prev = line;
  });
  if (rows < 2)
    throw InputError(
        Category::TooFewRows, source, "",
        std::to_string(rows) + " data row" + (rows == 1 ? "" : "s") + "; need at least 2");

  const auto N = static_cast<Eigen::Index>(rows);
  const auto W = static_cast<Eigen::Index>(wanted.size());
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
      all(data.data(), N, W);
  const auto P = static_cast<Eigen::Index>(d.pressure_names.size());
  d.t = all.col(0);
  d.pressures = all.middleCols(1, P);
  d.angles = d.has_angles ? Eigen::MatrixXd(all.middleCols(1 + P, static_cast<Eigen::Index>(nq)))
                          : Eigen::MatrixXd(N, 0);
  const Eigen::Index first_marker = 1 + P + (d.has_angles ? static_cast<Eigen::Index>(nq) : 0);
  d.markers = d.has_markers ? Eigen::MatrixXd(all.middleCols(first_marker, static_cast<Eigen::Index>(marker_names.size())))
                            : Eigen::MatrixXd(N, 0);
  return d;
}

/// \brief Read a data set for `robot` from a CSV file (see parse_dataset).
/// \param[in] path The file.
/// \param[in] robot The robot the data belong to.
/// \param[in] require_angles Measurements must be present (see parse_dataset()).
/// \return Times, pressures and (if present) angles.
/// \throws InputError (FileNotFound, ReadFailed, or as parse_dataset()).
inline Dataset read_dataset(const std::string& path, const RobotSpec& robot, bool require_angles) {
  return parse_dataset(detail::read_text_file(path), path, robot, require_angles);
}

/// \brief Write a trajectory `t,<names...>` (formats.md section 3) with full
/// precision (shortest round-trip). `q` is N x names.size(), `t` has N entries.
/// \param[in] path The output file.
/// \param[in] t The N sample times, s.
/// \param[in] q The N x names.size() samples.
/// \param[in] names The column names after `t`.
/// \throws std::invalid_argument if q and t disagree on N.
/// \throws InputError (WriteFailed) if the file cannot be written.
inline void write_trajectory_csv(const std::string& path, const Eigen::VectorXd& t,
                                 const Eigen::MatrixXd& q, const std::vector<std::string>& names) {
  if (q.rows() != t.size())
    throw std::invalid_argument("softrne::io::write_trajectory_csv: t has " +
                                std::to_string(t.size()) + " samples but q has " +
                                std::to_string(q.rows()) + " rows");
  std::vector<std::string> header{"t"};
  header.insert(header.end(), names.begin(), names.end());
  Eigen::MatrixXd values(t.size(), 1 + q.cols());
  values.col(0) = t;
  values.rightCols(q.cols()) = q;
  detail::write_text_file(path, format_csv(header, values));
}

}  // namespace softrne::io
