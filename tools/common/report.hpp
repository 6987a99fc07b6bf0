#pragma once
/// \file
/// \brief JSON of error statistics, of a fit and of the closed-loop report (formats.md
/// section 5), and the fit as softrne-fit runs it. Shared by the tools and the Python module
/// (python/src/module.cpp), which return the same reports.

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "common/cli.hpp"
#include "softrne/fit/arm_fit.hpp"
#include "softrne/fit/loop.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/signals/error_stats.hpp"

namespace softrne::cli {

/// \brief `STATS` of formats.md section 5.
inline nlohmann::ordered_json stats_json(const signals::ErrorStats& s) {
  nlohmann::ordered_json j;
  j["mean"] = s.total.mean;
  j["median"] = s.total.median;
  j["max"] = s.total.max;
  nlohmann::ordered_json per = nlohmann::ordered_json::object();
  for (std::size_t i = 0; i < s.per_angle.size(); ++i)
    per[s.names[i]] = {{"mean", s.per_angle[i].mean}, {"median", s.per_angle[i].median},
                       {"max", s.per_angle[i].max}};
  j["per_angle"] = per;
  return j;
}

/// \brief The fitted parameters with their standard errors, one line each.
inline std::string parameter_table(const fit::ArmFitResult& r) {
  std::string out;
  char line[256];
  for (int i = 0; i < r.parameters.size(); ++i) {
    const double v = r.fit.params(i), se = r.fit.std_errors.size() > i ? r.fit.std_errors(i) : NAN;
    std::snprintf(line, sizeof line, "  %-34s %12.6g  +- %-10.3g (%5.1f %%)%s\n",
                  r.parameters[i].name.c_str(), v, se, 100 * se / std::max(std::abs(v), 1e-300),
                  (r.fit.identifiable.size() > static_cast<std::size_t>(i) && !r.fit.identifiable[static_cast<std::size_t>(i)])
                      ? "  poorly determined by the data"
                      : "");
    out += line;
  }
  return out;
}

/// \brief Standard error of each named parameter of a fit (inf where not determined).
inline double std_error_of(const fit::ArmFitResult& r, const std::string& name) {
  for (int i = 0; i < r.parameters.size(); ++i)
    if (r.parameters[i].name == name && r.fit.std_errors.size() > i) return r.fit.std_errors(i);
  return INFINITY;
}

/// \brief JSON number, or null where it is not finite (JSON has no inf/NaN).
inline nlohmann::ordered_json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(nullptr);
}

inline nlohmann::ordered_json unexplained_json(const fit::UnexplainedResidual& u) {
  nlohmann::ordered_json j;
  j["above_floor"] = u.above_floor;
  j["threshold"] = u.threshold;
  j["statement"] = u.statement;
  nlohmann::ordered_json per = nlohmann::ordered_json::object();
  for (const auto& c : u.coordinates)
    per[c.name] = {{"median", c.median},
                   {"floor", c.floor},
                   {"ratio", finite_or_null(c.ratio)},
                   {"correlation", {{"q", c.corr_q}, {"qdot", c.corr_qdot}, {"drive", c.corr_drive},
                                    {"drive_rate", c.corr_drive_rate}}},
                   {"band_power", {{"below_0.5Hz", c.band_power.size() > 0 ? c.band_power[0] : 0.0},
                                   {"0.5_2Hz", c.band_power.size() > 1 ? c.band_power[1] : 0.0},
                                   {"2_10Hz", c.band_power.size() > 2 ? c.band_power[2] : 0.0},
                                   {"above_10Hz", c.band_power.size() > 3 ? c.band_power[3] : 0.0}}}};
  j["per_angle"] = per;
  return j;
}

/// \brief A fit as softrne-fit runs it: the error statistics of the starting model, the fit,
/// and where a held-out data set is given the errors of both models on it.
struct FitRun {
  fit::ArmFitResult result;
  /// What the objective held: "all" the data's measurements, "angles" or "markers" only.
  std::string fit_to = "all";
  bool has_angles = true;  ///< the data have angles (else only the marker errors mean anything)
  signals::ErrorStats train_before, train_after;  ///< angles, rad
  bool has_test = false;
  signals::ErrorStats test_before, test_after;
  /// Data with markers: their errors (mm) before and after, whether or not the objective held
  /// them. The starting model is measured in the frame fitted in closed form to its own
  /// training simulation, the fitted model in its fitted frame (`frame`: the fit's own when
  /// the objective held the markers, with standard errors; else fitted in closed form to the
  /// fitted model's training simulation), the test data in the training frame.
  bool has_markers = false;
  signals::ErrorStats markers_train_before, markers_train_after, markers_test_before, markers_test_after;
  bool frame_per_recording = false;  ///< one capture frame per training recording
  std::vector<CaptureFrame> frames;  ///< one, or one per training recording
  std::vector<Eigen::VectorXd> frame_std_errors;  ///< empty where the objective did not hold the markers
};

/// \brief Model `d` on `data`, simulated once: its angle errors (rad) if `angles` is asked for,
/// its marker errors (mm, fit::marker_errors: in `frames`, or in frames fitted in closed form
/// and returned in `fitted`) if `markers` is asked for.
struct Measured {
  signals::ErrorStats angles, markers;
};
/// \brief Measures `d` on `data` (Measured); cli::Failure naming the data set if the angles are
/// asked for and it does not simulate (`which`: "starting", "fitted"). Nothing asked: no
/// simulation.
inline Measured measure(const ArmDescription& d, const io::Dataset& data, const sim::ArmSimulationOptions& opt,
                        const std::string& which, bool angles, bool markers, bool per_recording = false,
                        const std::vector<CaptureFrame>* frames = nullptr,
                        std::vector<CaptureFrame>* fitted = nullptr) {
  Measured m;
  if (!angles && !markers) return m;
  const auto s = fit::simulate_dataset(d, data, opt);
  if (angles) {
    if (!s.ok())
      throw Failure(data.source + ": the " + which + " model fails to simulate: " + s.result.message);
    m.angles = signals::error_stats(s.angles, data.angles, d.coordinate_names);
  }
  if (markers) m.markers = fit::marker_errors(d, data, s, per_recording, frames, fitted);
  return m;
}

/// \brief Fits `desc` to `train` (fit::fit_arm) and measures it before and after, on `train`
/// and on `test` if given: angle errors where the data have angles, marker errors where they
/// have markers, whatever the objective held. `fit_to`: "all" (every measurement the data
/// have), "angles" or "markers" (the other columns are set aside for the fit, and a recording
/// fitted without its angles starts at rest in the equilibrium of its first pressures: a fit
/// that never sees an angle). cli::Failure when a model does not simulate, the fit finds no
/// parameters that do, or the data lack what fit_to asks for.
inline FitRun run_fit(const ArmDescription& desc, const io::Dataset& train, const io::Dataset* test,
                      const fit::ArmFitOptions& opt, const std::string& fit_to = "all") {
  FitRun run;
  run.fit_to = fit_to;
  run.has_angles = train.has_angles;
  run.has_markers = train.has_markers && !desc.spec.markers.empty();
  io::Dataset objective = train;
  if (fit_to == "angles") {
    if (!train.has_angles) throw Failure(train.source + ": --fit-to angles, but the data have no angle columns");
    objective.has_markers = false;
    objective.markers.resize(train.t.size(), 0);
  } else if (fit_to == "markers") {
    if (!run.has_markers) throw Failure(train.source + ": --fit-to markers, but the data have no marker columns of the robot's markers");
    objective.has_angles = false;
    objective.angles.resize(train.t.size(), 0);
    objective.recordings = {};  // initial rates come from angles: without them, from rest
    for (auto r : train.recordings) {
      r.initial_rates.resize(0);
      objective.recordings.push_back(r);
    }
  }
  // Each model on each data set is simulated once, for its angle and its marker errors.
  const bool per = run.frame_per_recording = run.has_markers && opt.capture_frame_per_recording;
  std::vector<CaptureFrame> start_frames;
  const Measured train_before = measure(desc, train, opt.simulation, "starting", run.has_angles, run.has_markers,
                                        per, nullptr, &start_frames);
  run.train_before = train_before.angles;
  run.markers_train_before = train_before.markers;
  try {
    run.result = fit::fit_arm(desc, objective, opt);
  } catch (const std::invalid_argument& e) {
    throw Failure(e.what());
  }
  if (!std::isfinite(run.result.fit.cost))
    throw Failure(train.source + ": the fit found no parameters that simulate: " + run.result.fit.message);
  const ArmDescription& fitted = run.result.fitted;
  // What the objective held is measured already (the fit's own statistics and frames).
  const bool fitted_markers = run.has_markers && objective.has_markers;
  const Measured train_after = measure(fitted, train, opt.simulation, "fitted", run.has_angles && !objective.has_angles,
                                       run.has_markers && !fitted_markers, per, nullptr, &run.frames);
  if (run.has_angles) run.train_after = objective.has_angles ? run.result.stats : train_after.angles;
  if (fitted_markers) {
    run.frames = run.result.capture_frames;
    run.frame_std_errors = run.result.capture_frame_std_errors;
    run.markers_train_after = run.result.marker_stats;
  } else if (run.has_markers) {
    run.markers_train_after = train_after.markers;
  }
  if (test) {
    run.has_test = true;
    const bool markers = run.has_markers && test->has_markers;
    const Measured before = measure(desc, *test, opt.simulation, "starting", test->has_angles, markers, per, &start_frames);
    const Measured after = measure(fitted, *test, opt.simulation, "fitted", test->has_angles, markers, per, &run.frames);
    run.test_before = before.angles;
    run.test_after = after.angles;
    run.markers_test_before = before.markers;
    run.markers_test_after = after.markers;
  }
  return run;
}

/// \brief The fit report (format softrne-fit-report/1, formats.md section 5): softrne-fit
/// --report, softrne.fit() in Python.
inline nlohmann::ordered_json fit_report_json(const FitRun& run) {
  const fit::ArmFitResult& r = run.result;
  nlohmann::ordered_json j;
  j["format"] = "softrne-fit-report/1";
  nlohmann::ordered_json params = nlohmann::ordered_json::array();
  for (int i = 0; i < r.parameters.size(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    params.push_back(
        {{"name", r.parameters[i].name},
         {"value", r.fit.params.size() > i ? r.fit.params(i) : r.parameters[i].initial},
         {"std_error", finite_or_null(r.fit.std_errors.size() > i ? r.fit.std_errors(i) : INFINITY)},
         {"identifiable", r.fit.identifiable.size() > k ? static_cast<bool>(r.fit.identifiable[k]) : false}});
  }
  j["parameters"] = params;
  j["identifiability"] = r.fit.identifiability_report;
  // Angle errors (rad) where the data have angles: without them (markers only) null.
  const auto angle_stats = [&](const signals::ErrorStats& e) -> nlohmann::ordered_json {
    return run.has_angles ? stats_json(e) : nlohmann::ordered_json(nullptr);
  };
  j["train"] = {{"before", angle_stats(run.train_before)}, {"after", angle_stats(run.train_after)}};
  if (run.has_test) j["test"] = {{"before", angle_stats(run.test_before)}, {"after", angle_stats(run.test_after)}};
  if (run.fit_to != "all") j["fit_to"] = run.fit_to;
  if (run.has_markers) {
    // Marker errors in mm (per marker the distance between simulated and measured positions)
    // and the capture frame: y_capture = R x_base + t.
    nlohmann::ordered_json m;
    m["unit"] = "mm";
    m["train"] = {{"before", stats_json(run.markers_train_before)}, {"after", stats_json(run.markers_train_after)}};
    if (run.has_test)
      m["test"] = {{"before", stats_json(run.markers_test_before)}, {"after", stats_json(run.markers_test_after)}};
    j["markers"] = m;
    // One frame (shared by all training recordings) or one per training recording.
    nlohmann::ordered_json frames = nlohmann::ordered_json::array();
    for (std::size_t g = 0; g < run.frames.size(); ++g) {
      const CaptureFrame& f = run.frames[g];
      nlohmann::ordered_json R = nlohmann::ordered_json::array();
      for (int i = 0; i < 3; ++i) R.push_back({f.R(i, 0), f.R(i, 1), f.R(i, 2)});
      nlohmann::ordered_json se = nullptr;
      if (g < run.frame_std_errors.size() && run.frame_std_errors[g].size() == 6) {
        se = nlohmann::ordered_json::array();
        for (Eigen::Index i = 0; i < 6; ++i) se.push_back(finite_or_null(run.frame_std_errors[g](i)));
      }
      frames.push_back({{"rotation", R}, {"translation", {f.t(0), f.t(1), f.t(2)}}, {"std_errors", se}});
    }
    j["capture_frames"] = {{"per_recording", run.frame_per_recording},
                           {"frames", frames},
                           {"std_errors_meaning", "rotation about the capture x, y, z axes (rad), then translation "
                                                  "(m); null where the fit did not use the markers"}};
  }
  j["converged"] = r.fit.converged;
  j["message"] = r.fit.message;
  j["simulations"] = r.simulations;
  j["wall_seconds"] = r.wall_seconds;
  j["fitted_robot"] = io::to_ordered_json(to_robot_spec(r.fitted));
  return j;
}

/// \brief The closed-loop report (format softrne-loop-report/2, formats.md section 5).
inline nlohmann::ordered_json loop_report_json(const fit::LoopResult& r, bool has_test,
                                               const fit::LoopOptions& opt = {}) {
  nlohmann::ordered_json j;
  j["format"] = "softrne-loop-report/2";
  nlohmann::ordered_json base;
  base["train"] = stats_json(r.baseline.stats);
  if (has_test) base["test"] = stats_json(r.baseline_test);
  j["baseline"] = base;
  nlohmann::ordered_json effects = nlohmann::ordered_json::array();
  const auto& d = r.final_fit.fitted;
  // The added effects are the last r.added.size() effects of the final model, in order.
  const std::size_t first = d.effects.size() >= r.added.size() ? d.effects.size() - r.added.size() : 0;
  for (std::size_t k = 0; k < r.added.size(); ++k) {
    const AnyEffect& e = first + k < d.effects.size() ? d.effects[first + k] : r.added[k].effect;
    nlohmann::ordered_json x;
    x["name"] = effect_name(e);
    x["scope"] = scope_name(effect_base(e).scope);
    nlohmann::ordered_json joints = nlohmann::ordered_json::array();
    for (int ji : effect_base(e).joints) joints.push_back(d.joints[static_cast<std::size_t>(ji)].name);
    x["joints"] = joints;
    nlohmann::ordered_json params = nlohmann::ordered_json::object(), se = nlohmann::ordered_json::object();
    const auto names = effect_param_names(e, d.joints, d.coordinate_names, d.pressure_names);
    for (std::size_t i = 0; i < names.size(); ++i) {
      params[names[i]] = effect_base(e).params(static_cast<Eigen::Index>(i));
      se[names[i]] = finite_or_null(std_error_of(r.final_fit, effect_name(e) + "." + names[i]));
    }
    x["params"] = params;
    x["std_errors"] = se;
    x["fold_gains"] = r.added[k].fold_gains;
    x["selection_gain"] = r.added[k].selection_gain;
    x["evidence"] = r.added[k].evidence;
    x["equivalent"] = r.added[k].equivalent;
    effects.push_back(x);
  }
  j["effects"] = effects;
  // Added in a round, removed by the backward pass once later effects were in, or replaced by
  // its simpler limit at the end (run_loop).
  nlohmann::ordered_json removed = nlohmann::ordered_json::array();
  for (const auto& a : r.removed) {
    nlohmann::ordered_json fg = nlohmann::ordered_json::array();
    for (double g : a.fold_gains) fg.push_back(finite_or_null(g));
    removed.push_back({{"name", effect_name(a.effect)},
                       {"label", a.label},
                       {"scope", scope_name(effect_base(a.effect).scope)},
                       {"fold_gains", fg},
                       {"evidence", a.evidence}});
  }
  j["removed_effects"] = removed;
  // The CC joints' inertia model: a structure the loop may change (no parameters), not an effect.
  nlohmann::ordered_json inertia;
  inertia["tried"] = r.inertia.tried;
  inertia["chosen"] = r.inertia.adopted ? "distributed" : "as declared";
  nlohmann::ordered_json ig = nlohmann::ordered_json::array();
  for (double g : r.inertia.fold_gains) ig.push_back(finite_or_null(g));
  inertia["fold_gains"] = ig;
  inertia["round"] = r.inertia.round;
  inertia["min_gain"] = opt.inertia_min_gain;
  j["inertia_model"] = inertia;
  nlohmann::ordered_json fin;
  fin["train"] = stats_json(r.final_train);
  if (has_test) fin["test"] = stats_json(r.final_test);
  j["final"] = fin;
  nlohmann::ordered_json noise;
  nlohmann::ordered_json sigma = nlohmann::ordered_json::object();
  for (Eigen::Index k = 0; k < r.noise_sigma.size(); ++k)
    sigma[d.coordinate_names[static_cast<std::size_t>(k)]] = r.noise_sigma(k);
  noise["sigma"] = sigma;
  noise["floor_median"] = r.noise_floor;
  noise["method"] = "third differences of the measured training angles, median absolute value";
  j["noise"] = noise;
  nlohmann::ordered_json unexplained;
  unexplained["train"] = unexplained_json(r.unexplained_train);
  if (has_test) unexplained["test"] = unexplained_json(r.unexplained_test);
  j["unexplained"] = unexplained;
  j["selection"] = {{"rule", "an effect is added only if it lowers the held-out training error by at least "
                             "min_gain in every fold"},
                    {"min_gain", opt.min_gain},
                    {"folds", r.folds},
                    {"cv_blocks", opt.cv_blocks},
                    {"false_positive_rate", fit::kCalibratedFalsePositiveRate}};
  nlohmann::ordered_json candidates = nlohmann::ordered_json::array();
  for (const auto& round : r.rounds) {
    nlohmann::ordered_json rj = nlohmann::ordered_json::array();
    for (const auto& c : round) {
      nlohmann::ordered_json pg = nlohmann::ordered_json::array(), fg = nlohmann::ordered_json::array();
      for (double g : c.predicted_gains) pg.push_back(finite_or_null(g));
      for (double g : c.fold_gains) fg.push_back(finite_or_null(g));
      rj.push_back({{"name", c.name},
                    {"label", c.label},
                    {"scope", scope_name(c.scope)},
                    {"joints", c.joints},
                    {"predicted_gains", pg},
                    {"confirmed", c.confirmed},
                    {"fold_gains", fg},
                    {"cv_gain", finite_or_null(c.cv_gain)},
                    {"added", c.added}});
    }
    candidates.push_back(rj);
  }
  j["candidates"] = candidates;
  j["simulations"] = r.simulations;
  j["wall_seconds"] = r.wall_seconds;
  io::RobotSpec fitted = to_robot_spec(d);
  for (std::size_t k = 0; k < r.added.size() && first + k < fitted.effects.size(); ++k)
    fitted.effects[first + k].evidence = r.added[k].evidence;
  j["fitted_robot"] = io::to_ordered_json(fitted);
  return j;
}

}  // namespace softrne::cli
