// softrne-fit: fit stiffness and damping (formats.md section 6).
#include <cstdio>
#include <iostream>

#include "common/cli.hpp"
#include "common/report.hpp"
#include "softrne/fit/arm_fit.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"

int main(int argc, char** argv) {
  using namespace softrne;
  return cli::run("softrne-fit", [&] {
    cli::ArgParser args("softrne-fit", "--robot R.json --data train.csv --out fitted.json [--test test.csv]",
                        "Fits the per-axis stiffness and damping of every joint (and the parameters of the "
                        "robot's effects) to measured angles by simulation error: the model is simulated from "
                        "the first sample with the recorded pressures. Prints the fitted values with their "
                        "standard errors and the error tables (paper Tables I-II) before and after.");
    args.option("robot", "R.json", "robot description (softrne-robot/1); its values are the starting guesses").required();
    args.option("data", "train.csv", "pressures and measured angles").required();
    args.option("out", "fitted.json", "where to write the fitted robot").required();
    args.option("test", "test.csv", "a held-out data set: only measured, never fitted");
    args.option("report", "R.json",
                "also write the fit report here (softrne-fit-report/1: parameters, standard errors, "
                "error statistics, fitted robot)");
    args.flag("pressure-gain", "also fit one gain on K_prs per CC joint");
    args.option("seed", "N", "optimiser seed (default 1)");
    args.option("threads", "N", "parallel simulations (default 2)");
    args.flag("quiet", "no progress line");
    if (!args.parse(argc, argv)) return cli::kExitOk;
    cli::check_outputs_are_not_inputs(args, {"robot", "data", "test"}, {"out", "report"});
    const io::RobotSpec spec = io::read_robot_json(args.value("robot"));
    const io::Dataset train = io::read_dataset(args.value("data"), spec, true);
    io::Dataset test;
    const bool has_test = args.has("test");
    if (has_test) test = io::read_dataset(args.value("test"), spec, true);
    ArmDescription desc;
    try {
      desc = build_arm(spec);
    } catch (const std::invalid_argument& e) {
      throw cli::Failure(args.value("robot") + ": " + e.what());
    }
    fit::ArmFitOptions opt;
    opt.pressure_gain = args.has("pressure-gain");
    opt.optimiser.seed = static_cast<unsigned>(args.integer("seed", 1, 0, 4294967295L));
    opt.optimiser.threads = static_cast<int>(args.integer("threads", 2, 1, 64));
    const bool quiet = args.has("quiet");
    if (!quiet)
      opt.optimiser.progress = [nq = desc.nq](int evals, double cost) {
        // The residual is scaled so that 2 cost = nq * (mean squared angle error).
        std::fprintf(stderr, "\rsoftrne-fit: %d simulations, best rms error %.5f rad   ", evals,
                     std::sqrt(2 * cost / nq));
      };
    cli::stop_on_interrupt();
    opt.simulation.cvode.stop = &cli::interrupted;
    const cli::FitRun run = cli::run_fit(desc, train, has_test ? &test : nullptr, opt);
    cli::throw_if_interrupted("the fit");
    if (!quiet) std::fprintf(stderr, "\n");
    const fit::ArmFitResult& r = run.result;
    io::write_robot_json(to_robot_spec(r.fitted), args.value("out"));
    if (args.has("report"))
      io::detail::write_text_file(args.value("report"), cli::fit_report_json(run).dump(2) + "\n");
    std::printf("fitted %d parameters in %.1f s (%d simulations)\n", r.parameters.size(), r.wall_seconds, r.simulations);
    std::printf("%s", cli::parameter_table(r).c_str());
    if (!r.fit.identifiability_report.empty()) std::printf("identifiability:\n%s\n", r.fit.identifiability_report.c_str());
    std::printf("%s", format_error_table(run.train_before, "train, before (" + train.source + ")").c_str());
    std::printf("%s", format_error_table(r.stats, "train, after").c_str());
    if (has_test) {
      std::printf("%s", format_error_table(run.test_before, "test, before (" + test.source + ")").c_str());
      std::printf("%s", format_error_table(run.test_after, "test, after").c_str());
    }
    std::printf("wrote %s\n", args.value("out").c_str());
    return cli::kExitOk;
  });
}
