// softrne-sim: simulate an arm (robot.json) from recorded chamber pressures (CSV) with CVODE,
// write the joint angles on the input's time grid and, where the input holds measured angles,
// print the error table of the paper's Tables I-II (docs/formats.md sections 2, 3, 6).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/cli.hpp"
#include "common/outputs.hpp"
#include "common/robot_file.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/arm/markers.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/signals/error_stats.hpp"
#include "softrne/sim/arm_simulation.hpp"

namespace {

constexpr const char* kTool = "softrne-sim";

using softrne::cli::Failure;
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
  using softrne::cli::FiniteNumber;
  softrne::cli::App app(
      kTool, "--robot R.json --pressures P.csv [--out S.csv] [options]",
      "Simulates the arm described by R.json from rest at the first row of P.csv (its measured "
      "angles, or zero) under the recorded chamber pressures of P.csv, with CVODE (BDF, "
      "Jacobian by automatic differentiation). Writes t,u1,v1,... on the input's time grid "
      "(--out); where P.csv also holds measured angles, prints the error table (mean, median "
      "and max absolute error per angle, rad). Then prints the real-time factor (simulated "
      "seconds per wall-clock second) and the solver's counters.",
      "  softrne-sim --robot examples/data/arm-a-1/robot.json \\\n"
      "              --pressures examples/data/arm-a-1/test.csv --out sim.csv");
  std::string robot_path, data_path, out_path;
  app.add_option("--robot", robot_path, "robot description (softrne-robot/1)")
      ->type_name("R.json")
      ->required();
  app.add_option("--pressures", data_path,
                 "recorded pressures: t,p1_0,...; angles u1,v1,... optional")
      ->type_name("P.csv")
      ->required();
  app.add_option("--out", out_path,
                 "write the simulated angles here ('-' = stdout; the report then goes to stderr)")
      ->type_name("S.csv");
  softrne::sim::ArmSimulationOptions opt;
  app.add_option("--rtol", opt.cvode.rtol, "relative tolerance of the integrator")
      ->type_name("X")
      ->capture_default_str()
      ->check(FiniteNumber(0, 1, FiniteNumber::open));
  app.add_option("--atol", opt.cvode.atol,
                 "absolute tolerance of the angles (rad); well below the angle sensors' noise")
      ->type_name("X")
      ->capture_default_str()
      ->check(FiniteNumber(0, HUGE_VAL, FiniteNumber::open));
  double atol_velocity = 0;
  const CLI::Option* atol_velocity_opt =
      app.add_option("--atol-velocity", atol_velocity,
                     "absolute tolerance of the angular velocities (rad/s)")
          ->type_name("X")
          ->default_str(softrne::io::detail::format_double(opt.velocity_atol_factor) + " x atol")
          ->check(FiniteNumber(0, HUGE_VAL, FiniteNumber::open));
  std::string mode = "pchip";
  app.add_option("--interpolation", mode,
                 "recorded pressures between samples: pchip (C1, no overshoot), linear, zoh")
      ->type_name("MODE")
      ->capture_default_str()
      ->check(CLI::IsMember({"pchip", "linear", "zoh"}));
  app.add_option(
         "--smooth", opt.pressure_smoothing,
         "OPTIONAL pre-smoothing of the recorded pressures by a Gaussian kernel of standard "
         "deviation SIGMA seconds (zero phase). Changes the model's input: removes sensor "
         "noise the integrator would otherwise resolve (faster), rounds off steps")
      ->type_name("SIGMA")
      ->default_str("off")
      ->check(FiniteNumber(0));
  std::string jac = "ad";
  app.add_option(
         "--jacobian", jac,
         "Jacobian for the integrator's Newton iteration: ad (AutoDiff through inverse "
         "dynamics), ad-forward (AutoDiff through forward dynamics), fd (CVODE's differences)")
      ->type_name("METHOD")
      ->capture_default_str()
      ->check(CLI::IsMember({"ad", "ad-forward", "fd"}));
  long max_steps = 0;
  app.add_integer("--max-steps", max_steps, "integrator step limit", 1L, 1000000000L)
      ->default_str("max(1e5, 1e4 per s)");
  bool quiet = false;
  app.add_flag("--quiet", quiet,
               "no progress indicator (shown on a terminal for runs over a second) and no solver "
               "statistics; the error table stays");
  if (!app.parse_command_line(argc, argv)) return softrne::cli::kExitOk;
  softrne::cli::check_outputs_are_not_inputs({{"--robot", robot_path}, {"--pressures", data_path}},
                                             {{"--out", out_path}});

  if (atol_velocity_opt->count()) opt.velocity_atol_factor = atol_velocity / opt.cvode.atol;
  opt.interpolation = mode == "pchip"    ? PI::pchip
                      : mode == "linear" ? PI::linear
                                         : PI::zero_order_hold;
  opt.autodiff_jacobian = jac != "fd";
  opt.jacobian_method = jac == "ad-forward"
                            ? softrne::sim::ArmSimulationOptions::JacobianMethod::forward_dynamics
                            : softrne::sim::ArmSimulationOptions::JacobianMethod::inverse_dynamics;

  // Inputs: every problem is an io::InputError naming the file.
  const softrne::io::RobotSpec robot = softrne::io::read_robot_json(robot_path);
  const softrne::ArmDescription desc = softrne::cli::build_robot(robot, robot_path);
  const softrne::io::Dataset data = softrne::io::read_dataset(data_path, robot, false);
  const Eigen::Index n = data.t.size();
  const double t0 = data.t(0), t1 = data.t(n - 1);
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(desc.nq);
  if (data.has_angles) q0 = data.angles.row(0).transpose();
  opt.cvode.max_steps =
      max_steps > 0 ? max_steps : std::max(100000L, static_cast<long>(1e4 * (t1 - t0)));

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

  // The simulated angles and, for a robot with markers, their positions in the base frame.
  std::vector<std::string> columns = desc.coordinate_names;
  const std::vector<std::string> marker_columns = softrne::io::marker_column_names(robot);
  columns.insert(columns.end(), marker_columns.begin(), marker_columns.end());
  Eigen::MatrixXd simulated(n, static_cast<Eigen::Index>(columns.size()));
  simulated.leftCols(desc.nq) = sim.angles;
  if (!marker_columns.empty()) simulated.rightCols(static_cast<Eigen::Index>(marker_columns.size())) =
      softrne::marker_positions(desc, sim.states);
  std::ostream& report = out_path == "-" ? std::cerr : std::cout;
  if (out_path == "-") {
    std::vector<std::string> header{"t"};
    header.insert(header.end(), columns.begin(), columns.end());
    Eigen::MatrixXd values(n, 1 + simulated.cols());
    values.col(0) = data.t;
    values.rightCols(simulated.cols()) = simulated;
    std::cout << softrne::io::format_csv(header, values);
    std::cout.flush();
    if (!std::cout)
      throw softrne::io::InputError(softrne::io::Category::WriteFailed, "<stdout>", "",
                                    "cannot write the simulated angles");
  } else if (!out_path.empty()) {
    softrne::io::write_trajectory_csv(out_path, data.t, simulated, columns);
  }

  if (data.has_angles) {
    const softrne::signals::ErrorStats stats =
        softrne::signals::error_stats(sim.angles, data.angles, desc.coordinate_names);
    report << softrne::signals::format_error_table(
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
