#pragma once
/// \file
/// \brief Several recordings as one data set (issue 19): stacked row after row, each keeping
/// its own first sample (the simulation restarts there) and, if it starts in motion, its
/// initial angle rates.
///
/// Why one stacked data set and not a list: the fit's objective, the loop's cross-validation
/// masks, the error statistics and the residual analysis all work on rows, and stay one code
/// path for one file or many; only the simulation (fit::simulate_dataset) and the choice of
/// held-out rows (whole recordings, fit/loop.hpp) look at the boundaries. The stacked times
/// run on (Dataset::Recording::time_shift), so every consumer of t sees it increase.

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "softrne/io/csv.hpp"
#include "softrne/signals/initial_rate.hpp"

namespace softrne::io {

/// \brief The recordings of a data set: its own list, or the whole data set as one recording
/// from rest when the list is empty (a data set read from one file).
/// \param[in] data The data set.
/// \return At least one recording (none for an empty data set).
inline std::vector<Dataset::Recording> recordings_of(const Dataset& data) {
  if (!data.recordings.empty()) return data.recordings;
  if (data.t.size() == 0) return {};
  Dataset::Recording r;
  r.rows = data.t.size();
  r.source = data.source;
  return {r};
}

/// \brief Recording `k` of a data set on its own, at its file's own times.
/// \param[in] data The data set.
/// \param[in] k The recording's index in recordings_of(data).
/// \return Its rows; its `recordings` holds it alone (with its initial rates) if data had a list.
inline Dataset recording(const Dataset& data, std::size_t k) {
  const std::vector<Dataset::Recording> list = recordings_of(data);
  if (k >= list.size()) throw std::out_of_range("recording: no recording " + std::to_string(k));
  const Dataset::Recording& r = list[k];
  Dataset out;
  out.t = data.t.segment(r.first_row, r.rows).array() - r.time_shift;
  out.pressures = data.pressures.middleRows(r.first_row, r.rows);
  out.angles = data.has_angles ? Eigen::MatrixXd(data.angles.middleRows(r.first_row, r.rows))
                               : Eigen::MatrixXd(r.rows, 0);
  out.has_angles = data.has_angles;
  out.markers = data.has_markers ? Eigen::MatrixXd(data.markers.middleRows(r.first_row, r.rows))
                                 : Eigen::MatrixXd(r.rows, 0);
  out.has_markers = data.has_markers;
  out.pressure_names = data.pressure_names;
  out.angle_names = data.angle_names;
  out.source = r.source;
  if (!data.recordings.empty()) {
    Dataset::Recording own = r;
    own.first_row = 0;
    own.time_shift = 0;
    out.recordings = {own};
  }
  return out;
}

/// \brief Stacks recordings of one robot into one data set: rows in the given order, times
/// shifted so that each recording starts one sampling interval (its predecessor's last) after
/// the previous one ends. A single recording comes back unchanged (no list: from rest).
/// \param[in] parts The recordings (same columns: read with the same robot); each may already
///   carry a one-entry `recordings` list with its initial rates.
/// \return The stacked data set; its source names every file ("a.csv + b.csv").
/// \throws std::invalid_argument if parts is empty or their columns differ.
inline Dataset stack_recordings(const std::vector<Dataset>& parts) {
  if (parts.empty()) throw std::invalid_argument("stack_recordings: no recordings");
  if (parts.size() == 1) return parts.front();
  Dataset out;
  const Dataset& first = parts.front();
  out.has_angles = first.has_angles;
  out.has_markers = first.has_markers;
  out.pressure_names = first.pressure_names;
  out.angle_names = first.angle_names;
  Eigen::Index rows = 0;
  for (const Dataset& p : parts) {
    if (p.pressure_names != first.pressure_names || p.has_angles != first.has_angles ||
        p.has_markers != first.has_markers || p.pressures.cols() != first.pressures.cols() ||
        p.pressures.rows() != p.t.size() || (p.has_angles && p.angles.cols() != first.angles.cols()) ||
        (p.has_angles && p.angles.rows() != p.t.size()) ||
        (p.has_markers && p.markers.cols() != first.markers.cols()) ||
        (p.has_markers && p.markers.rows() != p.t.size()))
      throw std::invalid_argument(p.source + ": its columns differ from " + first.source + "'s (or its "
                                  "tables' sizes disagree)");
    rows += p.t.size();
  }
  out.t.resize(rows);
  out.pressures.resize(rows, first.pressures.cols());
  // Angles and markers only where the data have them (N x 0 otherwise, whatever shape an
  // absent block was given).
  const Eigen::Index na = first.has_angles ? first.angles.cols() : 0;
  const Eigen::Index nm = first.has_markers ? first.markers.cols() : 0;
  out.angles.resize(rows, na);
  out.markers.resize(rows, nm);
  Eigen::Index row = 0;
  for (const Dataset& p : parts) {
    const Eigen::Index n = p.t.size();
    Dataset::Recording r;
    if (p.recordings.size() == 1) r = p.recordings.front();
    r.first_row = row;
    r.rows = n;
    r.source = p.source;
    if (row == 0) {
      r.time_shift = 0;
    } else {
      const double gap = out.t(row - 1) - out.t(row - 2 >= 0 ? row - 2 : row - 1);
      r.time_shift = out.t(row - 1) + (gap > 0 ? gap : 1.0) - p.t(0);
    }
    out.t.segment(row, n) = p.t.array() + r.time_shift;
    out.pressures.middleRows(row, n) = p.pressures;
    if (na > 0) out.angles.middleRows(row, n) = p.angles;
    if (nm > 0) out.markers.middleRows(row, n) = p.markers;
    out.recordings.push_back(r);
    out.source += (row == 0 ? "" : " + ") + p.source;
    row += n;
  }
  return out;
}

/// \brief Sets every recording's initial angle rates from its first samples
/// (signals::initial_rate(), a quadratic through the first `samples`): for recordings that
/// start in motion (`--initial-motion estimated`). A data set without a list gets one.
/// \param[in,out] data A data set with angles.
/// \param[in] samples Samples per estimate.
/// \throws std::invalid_argument if it has no angles or a recording has fewer than 3 rows.
inline void estimate_initial_rates(Dataset& data, int samples = 9) {
  if (!data.has_angles) throw std::invalid_argument(data.source + ": no measured angles to estimate initial rates from");
  data.recordings = recordings_of(data);
  for (Dataset::Recording& r : data.recordings) {
    if (r.rows < 3)
      throw std::invalid_argument(r.source + ": too short to estimate its initial rates (" +
                                  std::to_string(r.rows) + " rows; at least 3)");
    r.initial_rates = signals::initial_rate(data.t.segment(r.first_row, r.rows),
                                            data.angles.middleRows(r.first_row, r.rows), samples);
  }
}

}  // namespace softrne::io
