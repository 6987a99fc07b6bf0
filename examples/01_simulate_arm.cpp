// 01_simulate_arm: simulate the bundled three-joint arm on its recorded test pressures and
// write the simulated joint angles, like the paper's Fig. 6 and Table II.
//
//   01_simulate_arm [robot.json pressures.csv out.csv]
//
// Defaults: examples/data/arm-a-1/{robot.json,test.csv}, output <build>/examples/
// arm-a-1-test-simulated.csv. Plot it against the measurement with
//   python3 tools/plot_simulation.py --measured examples/data/arm-a-1/test.csv
//       --simulated build/examples/arm-a-1-test-simulated.csv --out sim.png

#include <cstdio>
#include <exception>
#include <string>

#include <Eigen/Core>

#include "softrne/arm/arm_description.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/signals/error_stats.hpp"
#include "softrne/sim/arm_simulation.hpp"

int main(int argc, char** argv) {
  const std::string dir = std::string(SOFTRNE_EXAMPLE_DATA_DIR) + "/arm-a-1";
  const std::string robot_path = argc > 1 ? argv[1] : dir + "/robot.json";
  const std::string data_path = argc > 2 ? argv[2] : dir + "/test.csv";
  const std::string out_path =
      argc > 3 ? argv[3] : std::string(SOFTRNE_EXAMPLE_OUTPUT_DIR) + "/arm-a-1-test-simulated.csv";
  try {
    // 1. The robot (softrne-robot/1) and the arm model of paper eq. 23 built from it.
    const softrne::io::RobotSpec robot = softrne::io::read_robot_json(robot_path);
    const softrne::ArmDescription arm = softrne::build_arm(robot);

    // 2. The recorded pressures (and, if present, the measured angles) on their time grid.
    const softrne::io::Dataset data =
        softrne::io::read_dataset(data_path, robot, /*require_angles=*/false);

    // 3. Simulate from rest at the first measured configuration (zero if none is given).
    //    Defaults: CVODE BDF, rtol 1e-6, atol 1e-5 rad (1e-2 rad/s), PCHIP pressures.
    const Eigen::VectorXd q0 = data.has_angles ? Eigen::VectorXd(data.angles.row(0).transpose())
                                               : Eigen::VectorXd::Zero(arm.nq);
    softrne::sim::ArmSimulationOptions options;
    const softrne::sim::ArmSimulation sim =
        softrne::sim::simulate_arm(arm, data.t, data.pressures, q0, options);
    if (!sim.ok()) {
      std::fprintf(stderr, "01_simulate_arm: %s: %s\n", data_path.c_str(),
                   sim.result.message.c_str());
      return 1;
    }

    // 4. Write t,u1,v1,... (formats.md section 3) and report.
    softrne::io::write_trajectory_csv(out_path, data.t, sim.angles, arm.coordinate_names);
    const double duration = data.t(data.t.size() - 1) - data.t(0);
    const auto& s = sim.result.stats;
    std::printf(
        "simulated %.2f s of %s in %.2f ms (%.0fx real time): %ld steps, %ld rhs, %ld "
        "Jacobians\nwrote %s\n",
        duration, data_path.c_str(), 1e3 * s.wall_seconds, duration / s.wall_seconds, s.steps,
        s.rhs_evals, s.jac_evals, out_path.c_str());
    if (data.has_angles) {
      const softrne::signals::ErrorStats err =
          softrne::signals::error_stats(sim.angles, data.angles, arm.coordinate_names);
      std::printf("%s",
                  softrne::signals::format_error_table(err, "simulation vs measurement:").c_str());
    }
    return 0;
  } catch (const std::exception& e) {  // io::InputError: "<file>: <where>: <what>"
    std::fprintf(stderr, "01_simulate_arm: %s\n", e.what());
    return 1;
  }
}
