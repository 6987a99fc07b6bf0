#pragma once
/// \file
/// \brief JSON of error statistics and of the closed-loop report (formats.md section 5).

#include <nlohmann/json.hpp>

#include "softrne/fit/loop.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/model/error_stats.hpp"

namespace softrne::cli {

/// \brief `STATS` of formats.md section 5.
inline nlohmann::ordered_json stats_json(const ErrorStats& s) {
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

/// \brief The closed-loop report (format softrne-loop-report/1).
inline nlohmann::ordered_json loop_report_json(const fit::LoopResult& r, bool has_test) {
  nlohmann::ordered_json j;
  j["format"] = "softrne-loop-report/1";
  nlohmann::ordered_json base;
  base["train"] = stats_json(r.baseline.stats);
  if (has_test) base["test"] = stats_json(r.baseline_test);
  j["baseline"] = base;
  nlohmann::ordered_json effects = nlohmann::ordered_json::array();
  const auto& d = r.final_fit.fitted;
  for (std::size_t k = 0; k < r.added.size(); ++k) {
    // The refitted parameters of the k-th added effect live in the final description.
    const AnyEffect& e = d.effects.size() > k ? d.effects[k] : r.added[k].effect;
    nlohmann::ordered_json x;
    x["name"] = effect_name(e);
    nlohmann::ordered_json joints = nlohmann::ordered_json::array();
    for (int ji : effect_base(e).joints) joints.push_back(d.joints[static_cast<std::size_t>(ji)].name);
    x["joints"] = joints;
    nlohmann::ordered_json params = nlohmann::ordered_json::object();
    const auto names = effect_param_names(e, d.joints, d.coordinate_names);
    for (std::size_t i = 0; i < names.size(); ++i) params[names[i]] = effect_base(e).params(static_cast<Eigen::Index>(i));
    x["params"] = params;
    x["evidence"] = r.added[k].evidence;
    x["selection_gain"] = r.added[k].selection_gain;
    effects.push_back(x);
  }
  j["effects"] = effects;
  nlohmann::ordered_json fin;
  fin["train"] = stats_json(r.final_train);
  if (has_test) fin["test"] = stats_json(r.final_test);
  j["final"] = fin;
  nlohmann::ordered_json candidates = nlohmann::ordered_json::array();
  for (const auto& round : r.rounds) {
    nlohmann::ordered_json rj = nlohmann::ordered_json::array();
    for (const auto& c : round)
      rj.push_back({{"name", c.name},
                    {"residual_explained", c.residual_explained},
                    {"confirmed", c.confirmed},
                    {"cv_gain", c.cv_gain},
                    {"fold_gains", c.fold_gains}});
    candidates.push_back(rj);
  }
  j["candidates"] = candidates;
  io::RobotSpec fitted = to_robot_spec(d);
  for (std::size_t k = 0; k < fitted.effects.size() && k < r.added.size(); ++k)
    fitted.effects[k].evidence = r.added[k].evidence;
  j["fitted_robot"] = io::to_ordered_json(fitted);
  return j;
}

}  // namespace softrne::cli
