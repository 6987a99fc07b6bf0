// softrne-make-case: one random test case for the closed loop (tools/common/random_arm.hpp):
// a random arm with injected effects, its declared (wrong) description, and train and test
// data simulated through the true description, in the formats of docs/formats.md.

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/cli.hpp"
#include "common/random_arm.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"

namespace {

constexpr const char* kTool = "softrne-make-case";
using softrne::cli::Failure;
using softrne::cli::UsageError;
namespace gen = softrne::gen;

std::vector<gen::EffectRequest> parse_effects(const std::string& text) {
  std::vector<gen::EffectRequest> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty())
      throw UsageError("--effects: empty item in " + softrne::io::detail::quoted(text));
    gen::EffectRequest r;
    const auto colon = item.find(':');
    r.name = item.substr(0, colon);
    if (colon != std::string::npos) r.scope = item.substr(colon + 1);
    const gen::EffectInfo* info = gen::find_effect(r.name);
    if (!info) {
      std::string list;
      for (const auto& e : gen::effect_table()) list += (list.empty() ? "" : ", ") + e.name;
      throw UsageError("--effects: unknown effect " + softrne::io::detail::quoted(r.name) +
                       " (one of " + list + ")");
    }
    if (!r.scope.empty()) {
      bool ok = false;
      std::string list;
      for (const auto& s : info->scopes) {
        ok = ok || s == r.scope;
        list += (list.empty() ? "" : ", ") + s;
      }
      if (!ok)
        throw UsageError("--effects: effect '" + r.name + "' has no scope " +
                         softrne::io::detail::quoted(r.scope) + " (one of " + list + ")");
    }
    for (const auto& o : out)
      if (o.name == r.name) throw UsageError("--effects: effect '" + r.name + "' given twice");
    out.push_back(r);
  }
  if (out.empty()) throw UsageError("--effects: no effect given");
  return out;
}

void write_dataset(const std::string& path, const softrne::io::Dataset& d,
                   const std::vector<std::string>& comments) {
  softrne::io::Table t;
  t.header.push_back("t");
  t.header.insert(t.header.end(), d.pressure_names.begin(), d.pressure_names.end());
  t.header.insert(t.header.end(), d.angle_names.begin(), d.angle_names.end());
  t.values.resize(d.t.size(), static_cast<Eigen::Index>(t.header.size()));
  t.values.col(0) = d.t;
  t.values.block(0, 1, d.t.size(), d.pressures.cols()) = d.pressures;
  t.values.rightCols(d.angles.cols()) = d.angles;
  softrne::io::write_csv(path, t, comments);
}

nlohmann::ordered_json case_json(const gen::Case& c) {
  nlohmann::ordered_json j;
  j["format"] = "softrne-case/1";
  j["seed"] = c.seed;
  j["attempt"] = c.attempt;
  j["arm"] = c.design.summary;
  j["mounting"] = c.design.mounting;
  j["gravity"] = {c.truth.gravity.x(), c.truth.gravity.y(), c.truth.gravity.z()};
  j["cc_joints"] = c.design.cc.size();
  j["noise"] = {{"angle_rad", c.angle_noise}, {"pressure_pa", c.pressure_noise}};
  auto effs = nlohmann::ordered_json::array();
  for (const auto& e : c.effects) {
    nlohmann::ordered_json x;
    x["name"] = e.name;
    x["scope"] = e.scope;
    x["joints"] = e.joints;
    if (!e.target.empty()) x["target"] = e.target;
    x["params"] = e.params;
    x["severity"] = e.severity;
    x["impact_rad"] = e.impact;
    x["calibration_steps"] = e.calibration_steps;
    if (!e.note.empty()) x["note"] = e.note;
    effs.push_back(x);
  }
  j["effects"] = effs;
  auto joints = nlohmann::ordered_json::array();
  for (const auto& jd : c.design.cc) {
    nlohmann::ordered_json x;
    x["name"] = jd.name;
    x["pmax_pa"] = jd.pmax;
    x["design_angle_rad"] = jd.theta;
    x["damping_ratio"] = jd.zeta;
    x["v90_rad_s"] = jd.v90;
    joints.push_back(x);
  }
  j["joints"] = joints;
  auto fac = nlohmann::ordered_json::object();
  for (const auto& [name, f] : c.declared_factors)
    fac[name] = {{"stiffness", {f.first(0), f.first(1)}}, {"damping", {f.second(0), f.second(1)}}};
  j["declared_factors"] = fac;
  j["tip_mass_kg"] = c.design.tip_mass;
  j["stability_margin"] = c.design.stability_margin;
  j["stiffness_raises"] = c.design.stiffness_raises;
  std::vector<double> q(c.q_rest.data(), c.q_rest.data() + c.q_rest.size());
  j["q_rest"] = q;
  j["hold_drift_rad"] = c.hold_drift;
  j["max_angle_rad"] = c.max_angle;
  j["train_samples"] = c.train.t.size();
  j["test_samples"] = c.test.t.size();
  return j;
}

int list_effects() {
  std::printf("# effect\tscope\tbuilds\tparameters (example)\trule\n");
  for (const auto& e : gen::effect_table())
    for (const auto& s : e.scopes) {
      std::string why;
      const bool ok = gen::effect_builds(e.name, s, &why);
      std::string kinds;
      for (const auto& k : e.kinds) kinds += (kinds.empty() ? "" : ",") + k;
      std::printf("%s\t%s\t%s\t%s\t%s%s\n", e.name.c_str(), s.c_str(), ok ? "yes" : "no", kinds.c_str(),
                  e.rule.c_str(), ok ? "" : ("  [this build: " + softrne::io::detail::one_line(why) + "]").c_str());
    }
  return softrne::cli::kExitOk;
}

int run(int argc, char** argv) {
  using softrne::cli::FiniteNumber;
  softrne::cli::App app(
      kTool, "--seed N (--effects NAME[:SCOPE],... | --none) --out DIR [options]",
      "Draws a random soft arm (1-4 CC joints, links, maybe a revolute joint; hanging, "
      "wall-mounted or upright) from the seed, injects the effects asked for at random "
      "strengths that are clearly present, and writes DIR/robot.json (the declared model: "
      "lumped inertia, no effects, stiffness and damping off by up to 1.5x), DIR/truth.json "
      "(the true model: distributed inertia, the effects), DIR/case.json (what was injected, "
      "noise, mounting) and DIR/train.csv (random pressure steps) and DIR/test.csv (smooth "
      "inputs), 100 Hz, simulated through the truth (rtol 1e-8, atol 1e-9) plus sensor noise. "
      "The same seed gives the same arm whatever the effects. See tools/common/random_arm.hpp "
      "for the distributions and strength rules.",
      "  softrne-make-case --seed 7 --effects stiffening:joint,actuator_lag --out case7\n"
      "  softrne-loop --robot case7/robot.json --train case7/train.csv --test case7/test.csv \\\n"
      "               --out case7/report.json");
  gen::CaseOptions opt;
  std::string effects, out;
  bool none = false, no_calibrate = false, quiet = false, list = false;
  app.add_integer("--seed", opt.seed, "case seed", 0L, 2147483647L)->required();
  CLI::App* inject = app.add_option_group("injection", "what to inject");
  inject
      ->add_option(
          "--effects", effects,
          "effects to inject, comma separated, each NAME or NAME:SCOPE (scope: shared, joint, "
          "coordinate, chamber; drawn at random when absent); see --list-effects")
      ->type_name("LIST");
  inject->add_flag("--none", none, "inject nothing: an effect-free control case");
  inject->require_option(1);
  app.add_option("--out", out, "output folder (created if needed)")->type_name("DIR")->required();
  app.add_option("--train-seconds", opt.train_seconds, "length of the train record")
      ->type_name("S")
      ->capture_default_str()
      ->check(FiniteNumber(3, 600));
  app.add_option("--test-seconds", opt.test_seconds, "length of the test record")
      ->type_name("S")
      ->capture_default_str()
      ->check(FiniteNumber(3, 600));
  app.add_option("--angle-noise", opt.angle_noise, "standard deviation of the angle sensor noise")
      ->type_name("RAD")
      ->capture_default_str()
      ->check(FiniteNumber(0, 1));
  app.add_option("--pressure-noise", opt.pressure_noise,
                 "standard deviation of the pressure sensor noise")
      ->type_name("PA")
      ->capture_default_str()
      ->check(FiniteNumber(0, 1e5));
  app.add_flag("--no-calibrate", no_calibrate,
               "keep the drawn effect strengths (no adjustment to the impact band)");
  app.add_flag_callback(
         "--list-effects",
         [&list] {
           list = true;
           throw CLI::Success();
         },
         "print the effect table (name, scope, whether this build of the library accepts it, "
         "parameters, strength rule) as tab-separated lines and exit (whatever else is given)")
      ->trigger_on_parse();
  app.add_flag("--quiet", quiet, "print nothing on success");
  if (!app.parse_command_line(argc, argv)) return list ? list_effects() : softrne::cli::kExitOk;
  if (!effects.empty()) opt.effects = parse_effects(effects);
  opt.calibrate = !no_calibrate;

  gen::Case c;
  try {
    c = gen::make_case(opt);
  } catch (const gen::EffectBuildError& e) {
    throw Failure("effect '" + e.effect + "' is not accepted by this build of softrne (build_arm: " +
                  e.what() + "); softrne-make-case --list-effects shows what builds");
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--effects: ") + e.what());
  } catch (const std::runtime_error& e) {
    throw Failure(e.what());
  }

  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec || !std::filesystem::is_directory(out))
    throw softrne::io::InputError(softrne::io::Category::WriteFailed, out, "",
                                  "cannot create the output folder" + (ec ? ": " + ec.message() : std::string()));
  softrne::io::write_robot_json(c.declared, out + "/robot.json");
  softrne::io::write_robot_json(c.truth, out + "/truth.json");
  const std::vector<std::string> comments = {
      "softrne-make-case --seed " + std::to_string(c.seed) + ": " + c.design.summary,
      "simulated through truth.json (rtol 1e-8, atol 1e-9); noise N(0, " +
          softrne::io::detail::format_double(c.angle_noise) + " rad) on angles, N(0, " +
          softrne::io::detail::format_double(c.pressure_noise) + " Pa) on pressures",
      "at rest at the first sample (zero pressure held for the first second)"};
  write_dataset(out + "/train.csv", c.train, comments);
  write_dataset(out + "/test.csv", c.test, comments);
  softrne::io::detail::write_text_file(out + "/case.json", case_json(c).dump(2) + "\n");
  if (!quiet) {
    std::string effs;
    for (const auto& e : c.effects) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s%s:%s (impact %.3f rad)", effs.empty() ? "" : ", ", e.name.c_str(),
                    e.scope.c_str(), e.impact);
      effs += buf;
    }
    std::printf("%s: %s; effects: %s; max angle %.2f rad; wrote %s/{robot,truth,case}.json, train.csv, test.csv\n",
                kTool, c.design.summary.c_str(), effs.empty() ? "none" : effs.c_str(), c.max_angle, out.c_str());
  }
  return softrne::cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return softrne::cli::run(kTool, [&] { return run(argc, argv); });
}
