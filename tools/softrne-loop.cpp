// softrne-loop: the closed loop (formats.md section 6): baseline fit, residual, effect
// discovery, refit, report.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/cli.hpp"
#include "common/outputs.hpp"
#include "common/robot_file.hpp"
#include "common/recordings.hpp"
#include "common/report.hpp"
#include "softrne/fit/loop.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"

namespace {

// Writes what tools/plot_loop.py draws: simulated angles before and after on both data sets,
// and the simulation residual (measured - simulated) on train before and after; then runs it.
// The simulations are the loop's own (LoopResult keeps them; a model that did not simulate
// leaves its file out), so the plots show exactly what the report's numbers measured.
void write_plot_data(const std::string& dir, const softrne::fit::LoopResult& r, const softrne::io::Dataset& train,
                     const softrne::io::Dataset& test) {
  using namespace softrne;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw io::InputError(io::Category::WriteFailed, dir, "", "cannot create the plot folder" +
                         (ec ? ": " + ec.message() : std::string()));
  auto write = [&](const Eigen::MatrixXd& angles, const io::Dataset& data, const std::string& name) {
    if (angles.size()) io::write_trajectory_csv(dir + "/" + name, data.t, angles, r.baseline.fitted.coordinate_names);
  };
  write(r.baseline.angles, train, "train_baseline.csv");
  write(r.final_fit.angles, train, "train_final.csv");
  write(r.baseline_test_angles, test, "test_baseline.csv");
  write(r.final_test_angles, test, "test_final.csv");
  const auto& names = r.baseline.fitted.coordinate_names;
  if (r.baseline_residual.size()) io::write_trajectory_csv(dir + "/residual_baseline.csv", train.t, r.baseline_residual, names);
  if (r.final_residual.size()) io::write_trajectory_csv(dir + "/residual_final.csv", train.t, r.final_residual, names);
  const std::string script = std::string(SOFTRNE_SOURCE_DIR) + "/tools/plot_loop.py";
  const char* py = std::getenv("SOFTRNE_PYTHON");
  const std::string cmd = std::string(py && *py ? py : "python3") + " '" + script + "' --dir '" + dir + "' --train '" + train.source + "' --test '" +
                          test.source + "' > /dev/null 2>&1";
  if (std::system(cmd.c_str()) != 0)
    std::fprintf(stderr, "softrne-loop: %s: plot data written; PNGs need python3 with numpy and matplotlib (%s)\n",
                 dir.c_str(), script.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  using namespace softrne;
  return cli::run("softrne-loop", [&] {
    cli::App app(
        "softrne-loop",
        "--robot R.json --train train.csv [--train ...] --test test.csv [--test ...] --out report.json [--plots DIR]",
        "Fits the declared model, screens every effect in every scope by its predicted held-out "
        "simulation error, refits the best in cross-validation folds of the training data, adds "
        "those that lower the held-out error in every fold, refits, and reports the error before "
        "and after, the sensor noise floor and what stays unexplained "
        "(docs/closing-the-loop.md). The test data only measures. With several training "
        "recordings the folds hold out whole recordings.");
    std::string robot_path, out_path, plots_dir, initial_motion = "rest";
    std::vector<std::string> train_paths, test_paths;
    fit::LoopOptions opt;
    app.add_option("--robot", robot_path, "robot description (softrne-robot/1)")
        ->type_name("R.json")
        ->required();
    cli::add_recordings_option(app, "--train", train_paths, "training data (pressures and measured angles)",
                               "train.csv")
        ->required();
    cli::add_recordings_option(app, "--test", test_paths, "test data: measured only, never used to select",
                               "test.csv")
        ->required();
    cli::add_initial_motion_option(app, initial_motion);
    app.add_option("--out", out_path, "the report (softrne-loop-report/2)")
        ->type_name("report.json")
        ->required();
    app.add_option("--plots", plots_dir,
                   "also write the data for plots and draw them with tools/plot_loop.py (python3 "
                   "with numpy and matplotlib; another interpreter via the environment variable "
                   "SOFTRNE_PYTHON)")
        ->type_name("DIR");
    opt.fit.optimiser.threads = 2;
    app.add_integer("--threads", opt.fit.optimiser.threads, "parallel simulations", 1, 64)
        ->capture_default_str();
    app.add_integer("--max-effects", opt.max_effects, "at most this many effects", 0, 16)
        ->capture_default_str();
    bool quiet = false;
    app.add_flag("--quiet", quiet, "no progress lines");
    if (!app.parse_command_line(argc, argv)) return cli::kExitOk;
    std::vector<cli::FileOption> inputs{{"--robot", robot_path}};
    cli::append_file_options(inputs, "--train", train_paths);
    cli::append_file_options(inputs, "--test", test_paths);
    cli::check_outputs_are_not_inputs(inputs, {{"--out", out_path}});
    const io::RobotSpec spec = io::read_robot_json(robot_path);
    const io::Dataset train = cli::read_recordings(train_paths, spec, true, initial_motion, "--train");
    const io::Dataset test = cli::read_recordings(test_paths, spec, true, initial_motion, "--test");
    const ArmDescription desc = cli::build_robot(spec, robot_path);
    if (!quiet)
      opt.log = [](const std::string& s) { std::fprintf(stderr, "softrne-loop: %s\n", s.c_str()); };
    fit::LoopResult r;
    cli::stop_on_interrupt();
    opt.fit.simulation.cvode.stop = &cli::interrupted;
    try {
      r = fit::run_loop(desc, train, &test, opt);
    } catch (const std::invalid_argument& e) {
      throw cli::Failure(e.what());
    }
    cli::throw_if_interrupted("the closed loop");
    if (!plots_dir.empty()) write_plot_data(plots_dir, r, train, test);
    nlohmann::ordered_json report = cli::loop_report_json(r, true, opt);
    // Per held-out recording, the median error before and after (several test recordings).
    const std::vector<cli::RecordingMedians> medians = cli::loop_test_medians(r, test);
    cli::add_recordings(report, train, &test, &medians);
    io::detail::write_text_file(out_path, report.dump(2) + "\n");
    std::printf("closed loop in %.1f s (%d simulations)\n", r.wall_seconds, r.simulations);
    std::printf("sensor noise estimated from the training angles: floor (median |error| of noise alone) %.4f rad\n",
                r.noise_floor);
    if (r.inertia.tried) {
      std::printf("inertia model of the CC joints: distributed instead of lumped, held-out");
      for (double g : r.inertia.fold_gains) std::printf(" %+6.1f %%", -100 * g);
      if (r.inertia.adopted)
        std::printf(" -> adopted in round %d\n", r.inertia.round);
      else
        std::printf(" (last try) -> kept as declared\n");
    }
    for (std::size_t k = 0; k < r.rounds.size(); ++k) {
      std::printf("round %zu: candidates by predicted held-out gain (screen), refitted ones with the measured gain\n",
                  k + 1);
      int shown = 0;
      for (const auto& c : r.rounds[k]) {
        if (!c.confirmed && shown >= 8) continue;  // the full list is in the report
        ++shown;
        std::printf("  %-48s predicted", c.label.c_str());
        for (double g : c.predicted_gains) std::printf(" %+6.1f %%", -100 * g);
        if (c.confirmed) {
          std::printf("   held-out");
          for (double g : c.fold_gains) std::printf(" %+6.1f %%", -100 * g);
        }
        std::printf("%s\n", c.added ? "   -> added" : "");
      }
    }
    if (r.added.empty())
      std::printf(r.inertia.adopted ? "no effect earned its place\n"
                                    : "no effect earned its place: the declared model stands\n");
    for (const auto& a : r.added) std::printf("added %s: %s\n", a.label.c_str(), a.evidence.c_str());
    for (const auto& a : r.removed) std::printf("removed %s: %s\n", a.label.c_str(), a.evidence.c_str());
    std::printf("%s\n", r.unexplained_train.statement.c_str());
    std::printf("%s", cli::parameter_table(r.final_fit).c_str());
    std::printf("%s", format_error_table(r.baseline.stats, "train, baseline").c_str());
    std::printf("%s", format_error_table(r.final_train, "train, final").c_str());
    std::printf("%s", format_error_table(r.baseline_test, "test, baseline").c_str());
    std::printf("%s", format_error_table(r.final_test, "test, final").c_str());
    for (const auto& m : medians)
      std::printf("  %s: median error %.4f -> %.4f rad\n", m.source.c_str(), m.baseline, m.final);
    std::printf("test median error: %.4f -> %.4f rad\nwrote %s\n", r.baseline_test.total.median,
                r.final_test.total.median, out_path.c_str());
    return cli::kExitOk;
  });
}
