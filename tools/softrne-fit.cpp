// softrne-fit: fit stiffness and damping (formats.md section 6).
#include <cstdio>
#include <iostream>

#include <Eigen/Geometry>

#include "common/cli.hpp"
#include "common/outputs.hpp"
#include "common/robot_file.hpp"
#include "common/recordings.hpp"
#include "common/report.hpp"
#include "softrne/fit/arm_fit.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"

int main(int argc, char** argv) {
  using namespace softrne;
  return cli::run("softrne-fit", [&] {
    cli::App app(
        "softrne-fit", "--robot R.json --data train.csv [--data ...] --out fitted.json [--test test.csv ...]",
        "Fits the per-axis stiffness and damping of every joint (and the parameters of the "
        "robot's effects) to measured angles by simulation error: the model is simulated from "
        "the first sample with the recorded pressures (each recording from its own first "
        "sample). Prints the fitted values with their standard errors and the error tables "
        "(paper Tables I-II) before and after.");
    std::string robot_path, out_path, report_path, initial_motion = "rest", fit_to = "all";
    std::vector<std::string> data_paths, test_paths;
    fit::ArmFitOptions opt;
    app.add_option("--robot", robot_path,
                   "robot description (softrne-robot/1); its values are the starting guesses")
        ->type_name("R.json")
        ->required();
    cli::add_recordings_option(app, "--data", data_paths, "pressures and measured angles", "train.csv")
        ->required();
    app.add_option("--out", out_path, "where to write the fitted robot")
        ->type_name("fitted.json")
        ->required();
    cli::add_recordings_option(app, "--test", test_paths, "a held-out data set: only measured, never fitted",
                               "test.csv");
    cli::add_initial_motion_option(app, initial_motion);
    app.add_flag("--frame-per-recording", opt.capture_frame_per_recording,
                 "one motion-capture frame per recording (logs with different calibrations) instead of one "
                 "for all; held-out recordings are then measured in frames fitted to each (6 numbers, the "
                 "physics untouched)");
    app.add_option("--fit-to", fit_to,
                   "what the objective holds: 'all' the measurements the data have, or only their 'angles' "
                   "or their 'markers' (the rest is still measured and reported; a fit to markers starts each "
                   "recording at rest in the equilibrium of its first pressures, never seeing an angle)")
        ->type_name("all|angles|markers")
        ->check(CLI::IsMember({"all", "angles", "markers"}))
        ->capture_default_str();
    app.add_option("--report", report_path,
                   "also write the fit report here (softrne-fit-report/1: parameters, standard "
                   "errors, error statistics, fitted robot)")
        ->type_name("R.json");
    app.add_flag("--pressure-gain", opt.pressure_gain, "also fit one gain on K_prs per CC joint");
    app.add_integer("--seed", opt.optimiser.seed, "optimiser seed", 0L, 4294967295L)
        ->capture_default_str();
    opt.optimiser.threads = 2;
    app.add_integer("--threads", opt.optimiser.threads, "parallel simulations", 1, 64)
        ->capture_default_str();
    bool quiet = false;
    app.add_flag("--quiet", quiet, "no progress line");
    if (!app.parse_command_line(argc, argv)) return cli::kExitOk;
    std::vector<cli::FileOption> inputs{{"--robot", robot_path}};
    cli::append_file_options(inputs, "--data", data_paths);
    cli::append_file_options(inputs, "--test", test_paths);
    cli::check_outputs_are_not_inputs(inputs, {{"--out", out_path}, {"--report", report_path}});
    const io::RobotSpec spec = io::read_robot_json(robot_path);
    const io::Dataset train = cli::read_recordings(data_paths, spec, true, initial_motion, "--data");
    io::Dataset test;
    const bool has_test = !test_paths.empty();
    if (has_test) test = cli::read_recordings(test_paths, spec, true, initial_motion, "--test");
    const ArmDescription desc = cli::build_robot(spec, robot_path);
    if (!quiet)
      opt.optimiser.progress = [nq = desc.nq, angles_only = !train.has_markers](int evals, double cost) {
        // The residual is scaled so that 2 cost = nq * (mean squared angle error) (angles only;
        // with markers it holds their weighted errors too).
        std::fprintf(stderr, "\rsoftrne-fit: %d simulations, best rms %s %.5f   ", evals,
                     angles_only ? "angle error (rad)" : "residual", std::sqrt(2 * cost / nq));
      };
    cli::stop_on_interrupt();
    opt.simulation.cvode.stop = &cli::interrupted;
    const cli::FitRun run = cli::run_fit(desc, train, has_test ? &test : nullptr, opt, fit_to);
    cli::throw_if_interrupted("the fit");
    if (!quiet) std::fprintf(stderr, "\n");
    const fit::ArmFitResult& r = run.result;
    io::write_robot_json(to_robot_spec(r.fitted), out_path);
    if (!report_path.empty()) {
      nlohmann::ordered_json report = cli::fit_report_json(run);
      cli::add_recordings(report, train, has_test ? &test : nullptr);
      io::detail::write_text_file(report_path, report.dump(2) + "\n");
    }
    std::printf("fitted %d parameters in %.1f s (%d simulations)\n", r.parameters.size(), r.wall_seconds, r.simulations);
    std::printf("%s", cli::parameter_table(r).c_str());
    if (!r.fit.identifiability_report.empty()) std::printf("identifiability:\n%s\n", r.fit.identifiability_report.c_str());
    if (train.has_angles) {
      std::printf("%s", format_error_table(run.train_before, "train, before (" + train.source + ")").c_str());
      std::printf("%s", format_error_table(run.train_after, "train, after").c_str());
    }
    if (has_test && test.has_angles) {
      std::printf("%s", format_error_table(run.test_before, "test, before (" + test.source + ")").c_str());
      std::printf("%s", format_error_table(run.test_after, "test, after").c_str());
    }
    if (run.has_markers) {
      for (std::size_t g = 0; g < run.frames.size(); ++g) {
        const auto& f = run.frames[g];
        const Eigen::AngleAxisd aa(f.R);
        std::printf("capture frame%s (y = R x_base + t): rotation %.4f rad about (%.4f, %.4f, %.4f); translation "
                    "(%.4f, %.4f, %.4f) m",
                    run.frame_per_recording ? (" of " + train.recordings.at(g).source).c_str() : "", aa.angle(),
                    aa.axis()(0), aa.axis()(1), aa.axis()(2), f.t(0), f.t(1), f.t(2));
        if (g < run.frame_std_errors.size() && run.frame_std_errors[g].size() == 6) {
          const Eigen::VectorXd& se = run.frame_std_errors[g];
          std::printf("; std errors %.2g %.2g %.2g rad, %.2g %.2g %.2g m\n", se(0), se(1), se(2), se(3), se(4), se(5));
        } else {
          std::printf(" (fitted in closed form to the fitted model: the fit did not use the markers)\n");
        }
      }
      const auto table = [](const signals::ErrorStats& e, const std::string& title) {
        std::printf("%s", format_error_table(e, title, "marker", "mm").c_str());
      };
      table(run.markers_train_before, "train markers, before (mm, in the frame fitted to the starting model)");
      table(run.markers_train_after, "train markers, after (mm)");
      if (has_test && test.has_markers) {
        table(run.markers_test_before, run.frame_per_recording
                                           ? "test markers, before (mm, each recording in a frame fitted to it)"
                                           : "test markers, before (mm, in the starting model's training frame)");
        table(run.markers_test_after, run.frame_per_recording
                                          ? "test markers, after (mm, each recording in a frame fitted to it)"
                                          : "test markers, after (mm, in the fitted training frame)");
      }
    }
    std::printf("wrote %s\n", out_path.c_str());
    return cli::kExitOk;
  });
}
