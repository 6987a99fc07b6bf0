// softrne-sim: simulate an arm (robot.json) from recorded chamber pressures (CSV) with CVODE,
// write the joint angles on the input's time grid and, where the input holds measured angles,
// print the error table of the paper's Tables I-II (shared/spec/formats.md sections 2, 3, 6).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/cli.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/model/arm_model.hpp"
#include "softrne/model/error_stats.hpp"
#include "softrne/sim/arm_simulation.hpp"

namespace {

constexpr const char* kTool = "softrne-sim";

using softrne::cli::Failure;
using softrne::cli::UsageError;
using PI = softrne::sim::ArmSimulationOptions::PressureInterpolation;

/// Progress on stderr: only on a terminal, only once the run has taken a second, at most
/// ten updates a second; erased at the end.
class Progress {
 public:
  Progress(bool enabled, double t0, double t1) : enabled_(enabled), t0_(t0), t1_(t1) {}
  void update(double t) {
    if (!enabled_) return;
    const double wall = seconds();
    if (wall < 1.0 || wall - last_ < 0.1) return;
    last_ = wall;
    const double frac = std::clamp((t - t0_) / (t1_ - t0_), 0.0, 1.0);
    std::fprintf(stderr, "\r%s: simulating: %5.1f%% (t = %.2f of %.2f s, %.1f s wall)", kTool,
                 100 * frac, t, t1_, wall);
    std::fflush(stderr);
    shown_ = true;
  }
  void finish() {
    if (shown_) std::fprintf(stderr, "\r\033[K");
    shown_ = false;
  }
  ~Progress() { finish(); }

 private:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  bool enabled_;
  double t0_, t1_;
  double last_ = 0;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

int run_sim(int argc, char** argv) {
  softrne::cli::ArgParser args(
      kTool, "--robot R.json --pressures P.csv [--out S.csv] [options]",
      "Simulates the arm described by R.json from rest at the first row of P.csv (its measured\n"
      "angles, or zero) under the recorded chamber pressures of P.csv, with CVODE (BDF,\n"
      "Jacobian by automatic differentiation). Writes t,u1,v1,... on the input's time grid\n"
      "(--out); where P.csv also holds measured angles, prints the error table (mean, median\n"
      "and max absolute error per angle, rad). Then prints the real-time factor (simulated\n"
      "seconds per wall-clock second) and the solver's counters.");
  args.option("robot", "R.json", "robot description (softrne-robot/1)").required();
  args.option("pressures", "P.csv", "recorded pressures: t,p1_0,...; angles u1,v1,... optional")
      .required();
  args.option("out", "S.csv",
              "write the simulated angles here ('-' = stdout; the report then "
              "goes to stderr)");
  const softrne::sim::ArmSimulationOptions defaults;
  const double def_rtol = defaults.cvode.rtol, def_atol = defaults.cvode.atol;
  const double def_vf = defaults.velocity_atol_factor;
  args.option("rtol", "X", "relative tolerance of the integrator")
      .default_value(softrne::io::detail::format_double(def_rtol));
  args.option("atol", "X",
              "absolute tolerance of the angles (rad); well below the angle "
              "sensors' noise")
      .default_value(softrne::io::detail::format_double(def_atol));
  args.option("atol-velocity", "X", "absolute tolerance of the angular velocities (rad/s)")
      .default_value(softrne::io::detail::format_double(def_vf) + " x atol");
  args.option("interpolation", "MODE",
              "recorded pressures between samples: pchip (C1, no overshoot), linear, zoh")
      .default_value("pchip");
  args.option("smooth", "SIGMA",
              "OPTIONAL pre-smoothing of the recorded pressures by a Gaussian kernel of standard "
              "deviation SIGMA seconds (zero phase). Changes the model's input: removes sensor "
              "noise the integrator would otherwise resolve (faster), rounds off steps")
      .default_value("off");
  args.option("jacobian", "METHOD",
              "Jacobian for the integrator's Newton iteration: ad (AutoDiff through inverse "
              "dynamics), ad-forward (AutoDiff through forward dynamics), fd (CVODE's "
              "differences)")
      .default_value("ad");
  args.option("max-steps", "N", "integrator step limit").default_value("max(1e5, 1e4 per s)");
  args.flag("quiet",
            "no progress indicator (shown on a terminal for runs over a second) and no solver "
            "statistics; the error table stays");
  args.epilog(
      "example:\n"
      "  softrne-sim --robot examples/data/arm-a-1/robot.json \\\n"
      "              --pressures examples/data/arm-a-1/test.csv --out sim.csv\n\n" +
      softrne::cli::ArgParser::exit_code_text());
  if (!args.parse(argc, argv)) return softrne::cli::kExitOk;
  softrne::cli::check_outputs_are_not_inputs(args, {"robot", "pressures"}, {"out"});

  const std::string robot_path = args.value("robot");
  const std::string data_path = args.value("pressures");
  const std::string out_path = args.value("out");
  const bool quiet = args.has("quiet");
  softrne::sim::ArmSimulationOptions opt;
  opt.cvode.rtol = args.number("rtol", def_rtol, 0.0, 1.0, true);
  opt.cvode.atol = args.number("atol", def_atol, 0.0, HUGE_VAL, true);
  if (args.has("atol-velocity"))
    opt.velocity_atol_factor =
        args.number("atol-velocity", 0.0, 0.0, HUGE_VAL, true) / opt.cvode.atol;
  const std::string mode = args.choice("interpolation", {"pchip", "linear", "zoh"}, "pchip");
  opt.interpolation = mode == "pchip"    ? PI::pchip
                      : mode == "linear" ? PI::linear
                                         : PI::zero_order_hold;
  opt.pressure_smoothing = args.number("smooth", 0.0, 0.0, HUGE_VAL);
  const std::string jac = args.choice("jacobian", {"ad", "ad-forward", "fd"}, "ad");
  opt.autodiff_jacobian = jac != "fd";
  opt.jacobian_method = jac == "ad-forward"
                            ? softrne::sim::ArmSimulationOptions::JacobianMethod::forward_dynamics
                            : softrne::sim::ArmSimulationOptions::JacobianMethod::inverse_dynamics;
  const long max_steps_arg = args.integer("max-steps", 0, 1, 1000000000L);

  // Inputs: every problem is an io::InputError naming the file.
  const softrne::io::RobotSpec robot = softrne::io::read_robot_json(robot_path);
  softrne::ArmDescription desc;
  try {
    desc = softrne::build_arm(robot);
  } catch (const std::invalid_argument& e) {
    throw softrne::io::InputError(softrne::io::Category::InvalidValue, robot_path, "effects",
                                  e.what());
  }
  const softrne::io::Dataset data = softrne::io::read_dataset(data_path, robot, false);
  const Eigen::Index n = data.t.size();
  const double t0 = data.t(0), t1 = data.t(n - 1);
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(desc.nq);
  if (data.has_angles) q0 = data.angles.row(0).transpose();
  opt.cvode.max_steps =
      max_steps_arg > 0 ? max_steps_arg : std::max(100000L, static_cast<long>(1e4 * (t1 - t0)));

  Progress progress(!quiet && softrne::cli::stderr_is_terminal(), t0, t1);
  opt.progress = [&](double t) { progress.update(t); };
  softrne::cli::stop_on_interrupt();
  opt.cvode.stop = &softrne::cli::interrupted;
  const softrne::sim::ArmSimulation sim =
      softrne::sim::simulate_arm(desc, data.t, data.pressures, q0, opt);
  progress.finish();
  if (!sim.ok()) {
    std::string hint;
    if (sim.result.message.find("too many steps") != std::string::npos)
      hint = " (raise --max-steps, or loosen --rtol/--atol)";
    throw Failure(data_path + ": " + sim.result.message + hint);
  }

  std::ostream& report = out_path == "-" ? std::cerr : std::cout;
  if (out_path == "-") {
    std::vector<std::string> header{"t"};
    header.insert(header.end(), desc.coordinate_names.begin(), desc.coordinate_names.end());
    Eigen::MatrixXd values(n, 1 + desc.nq);
    values.col(0) = data.t;
    values.rightCols(desc.nq) = sim.angles;
    std::cout << softrne::io::format_csv(header, values);
    std::cout.flush();
    if (!std::cout)
      throw softrne::io::InputError(softrne::io::Category::WriteFailed, "<stdout>", "",
                                    "cannot write the simulated angles");
  } else if (!out_path.empty()) {
    softrne::io::write_trajectory_csv(out_path, data.t, sim.angles, desc.coordinate_names);
  }

  if (data.has_angles) {
    const softrne::ErrorStats stats =
        softrne::error_stats(sim.angles, data.angles, desc.coordinate_names);
    report << softrne::format_error_table(
        stats, "absolute error, simulation vs measured angles of " + data_path + ":");
  }
  if (opt.pressure_smoothing > 0)
    report << "note: recorded pressures pre-smoothed (--smooth " << opt.pressure_smoothing
           << " s): the model's input differs from the recording\n";
  if (!quiet) {
    const auto& s = sim.result.stats;
    char line[256];
    std::snprintf(line, sizeof line, "simulated %.3f s in %.4f s wall: %.0fx real time\n", t1 - t0,
                  s.wall_seconds, s.wall_seconds > 0 ? (t1 - t0) / s.wall_seconds : 0.0);
    report << line;
    std::snprintf(line, sizeof line,
                  "CVODE: %ld steps, %ld rhs evals, %ld jacobian evals, %ld restarts "
                  "(%ld error test failures, %ld convergence failures)\n",
                  s.steps, s.rhs_evals, s.jac_evals, s.restarts, s.error_test_failures,
                  s.nonlinear_convergence_failures);
    report << line;
  }
  report.flush();
  if (!report)
    throw softrne::io::InputError(softrne::io::Category::WriteFailed, "<stdout>", "",
                                  "cannot write the report");
  return softrne::cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return softrne::cli::run(kTool, [&] { return run_sim(argc, argv); });
}
