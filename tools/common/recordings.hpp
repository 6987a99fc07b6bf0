#pragma once
/// \file
/// \brief Data options that name several recordings (`--data a.csv --data b.csv`) and say how
/// each starts (`--initial-motion rest|estimated`), for softrne-fit and softrne-loop
/// (docs/formats.md section 6), and what the reports say about them (the tools' and the
/// Python package's).

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/cli.hpp"
#include "common/outputs.hpp"
#include "softrne/fit/loop.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/recordings.hpp"
#include "softrne/signals/error_stats.hpp"

namespace softrne::cli {

/// \brief The help text of --initial-motion.
inline const char* const kInitialMotionHelp =
    "how each recording starts: 'rest' (the arm at rest at its first sample, as in the paper's "
    "experiments) or 'estimated' (at the angle rates of a quadratic through its first 9 "
    "samples: logs cut out of longer runs)";

/// \brief Adds a data option that may be repeated (`--data a.csv --data b.csv`).
inline CLI::Option* add_recordings_option(App& app, const std::string& name, std::vector<std::string>& paths,
                                          const std::string& help, const std::string& type_name) {
  return app.add_option(name, paths, help + "; repeat the option for several recordings")
      ->type_name(type_name)
      ->allow_extra_args(false);
}

/// \brief Adds --initial-motion rest|estimated (default rest).
inline CLI::Option* add_initial_motion_option(App& app, std::string& motion) {
  return app.add_option("--initial-motion", motion, kInitialMotionHelp)
      ->type_name("rest|estimated")
      ->check(CLI::IsMember({"rest", "estimated"}))
      ->capture_default_str();
}

/// \brief The files of a repeated option, each as a FileOption (for check_outputs_are_not_inputs).
inline void append_file_options(std::vector<FileOption>& to, const std::string& option,
                                const std::vector<std::string>& paths) {
  for (const auto& p : paths) to.push_back({option, p});
}

/// \brief Reads every file of `paths` for `spec` and stacks them (io::stack_recordings); with
/// `motion == "estimated"`, each recording's initial rates come from its first samples.
/// io::InputError for a bad file; UsageError if a file is named twice.
inline io::Dataset read_recordings(const std::vector<std::string>& paths, const io::RobotSpec& spec,
                                   bool require_angles, const std::string& motion, const std::string& option) {
  std::vector<io::Dataset> parts;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    for (std::size_t k = 0; k < i; ++k)
      if (paths[k] == paths[i]) throw UsageError(option + ": " + paths[i] + " is given twice");
    parts.push_back(io::read_dataset(paths[i], spec, require_angles));
  }
  io::Dataset data;
  try {
    data = io::stack_recordings(parts);
    if (motion == "estimated") io::estimate_initial_rates(data);
  } catch (const std::invalid_argument& e) {
    throw Failure(e.what());
  }
  return data;
}

/// \brief What the reports say about a data set's recordings: null for one file started at
/// rest (the reports stay as they were); else each recording's file, rows, time shift in the
/// stacked tables and initial rates (null at rest).
inline nlohmann::ordered_json recordings_json(const io::Dataset& data) {
  if (data.recordings.empty()) return nullptr;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const auto& r : data.recordings) {
    nlohmann::ordered_json rates = nullptr;
    if (r.initial_rates.size()) {
      rates = nlohmann::ordered_json::array();
      for (Eigen::Index k = 0; k < r.initial_rates.size(); ++k) rates.push_back(r.initial_rates(k));
    }
    list.push_back({{"source", r.source},
                    {"first_row", r.first_row},
                    {"rows", r.rows},
                    {"time_shift", r.time_shift},
                    {"initial_rates", rates}});
  }
  return list;
}

/// \brief Median absolute error of each recording of `data` for simulated angles `sim`
/// (stacked as data's rows); empty for a single recording.
inline std::vector<std::pair<std::string, double>> recording_medians(const io::Dataset& data,
                                                                     const Eigen::MatrixXd& sim,
                                                                     const std::vector<std::string>& names) {
  std::vector<std::pair<std::string, double>> out;
  if (data.recordings.size() < 2 || sim.rows() != data.angles.rows()) return out;
  for (const auto& r : data.recordings) {
    const auto s = signals::error_stats(sim.middleRows(r.first_row, r.rows),
                                        data.angles.middleRows(r.first_row, r.rows), names);
    out.emplace_back(r.source, s.total.median);
  }
  return out;
}

/// \brief Each test recording's median angle error with the loop's baseline and final models.
struct RecordingMedians {
  std::string source;
  double baseline = 0, final = 0;  ///< rad
};

/// \brief Each recording's median error of the loop's baseline and final models on `test` (from
/// their simulations that run_loop kept; several recordings, empty otherwise).
inline std::vector<RecordingMedians> loop_test_medians(const fit::LoopResult& r, const io::Dataset& test) {
  std::vector<RecordingMedians> out;
  const auto& names = r.final_fit.fitted.coordinate_names;
  const auto b = recording_medians(test, r.baseline_test_angles, names);
  const auto a = recording_medians(test, r.final_test_angles, names);
  for (std::size_t k = 0; k < b.size() && k < a.size(); ++k) out.push_back({b[k].first, b[k].second, a[k].second});
  return out;
}

/// \brief Adds the reports' `recordings` key (docs/formats.md section 6) where a data set has a
/// list of recordings (several files, or initial rates): `train` and `test` (recordings_json)
/// and, for the loop, `test_medians`. One file started at rest adds nothing.
inline void add_recordings(nlohmann::ordered_json& report, const io::Dataset& train, const io::Dataset* test,
                           const std::vector<RecordingMedians>* medians = nullptr) {
  if (train.recordings.empty() && (!test || test->recordings.empty())) return;
  nlohmann::ordered_json rec;
  rec["train"] = recordings_json(train);
  rec["test"] = test ? recordings_json(*test) : nlohmann::ordered_json(nullptr);
  if (medians) {
    nlohmann::ordered_json per = nlohmann::ordered_json::array();
    for (const auto& m : *medians)
      per.push_back({{"source", m.source}, {"baseline_median", m.baseline}, {"final_median", m.final}});
    rec["test_medians"] = per;
  }
  report["recordings"] = rec;
}

}  // namespace softrne::cli
