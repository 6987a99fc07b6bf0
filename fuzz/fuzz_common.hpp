#pragma once
// Shared by the libFuzzer targets and tests/fuzz_regressions: the robot specs the
// CSV target reads data for, and the calls each target makes. Every parser call
// may throw softrne::io::InputError only; anything else (another exception, a
// crash, a sanitizer report) is a finding.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"

namespace softrne_fuzz {

/// Robot examples/data/arm-a-1 (three cc joints with 4 chambers each, three links),
/// embedded so that the fuzzers need no file at run time.
inline const char* const kArmA = R"({
  "format": "softrne-robot/1", "name": "arm A", "gravity": [0.0, 0.0, 9.81],
  "segments": [
    {"type": "cc_joint", "name": "joint1", "mass": 0.8, "height": 0.2, "diameter": 0.2,
     "chamber_distance": 0.06, "chamber_radius": 0.03, "stiffness": [23.4, 37.1], "damping": [2.5, 2.5]},
    {"type": "rigid_link", "name": "link1", "mass": 1.5, "length": 0.15, "com": [0.0, 0.0, 0.075],
     "inertia": [0.0052125, 0.0052125, 0.0048, 0.0, 0.0, 0.0]},
    {"type": "cc_joint", "name": "joint2", "mass": 0.8, "height": 0.2, "diameter": 0.2,
     "chamber_distance": 0.06, "chamber_radius": 0.03, "stiffness": [17.8, 24.2], "damping": [2.6, 1.5]},
    {"type": "rigid_link", "name": "link2", "mass": 1.5, "length": 0.15, "com": [0.0, 0.0, 0.075],
     "inertia": [0.0052125, 0.0052125, 0.0048, 0.0, 0.0, 0.0]},
    {"type": "cc_joint", "name": "joint3", "mass": 0.8, "height": 0.2, "diameter": 0.2,
     "chamber_distance": 0.06, "chamber_radius": 0.03, "stiffness": [13.9, 19.0], "damping": [1.1, 1.5]},
    {"type": "rigid_link", "name": "link3", "mass": 0.4, "length": 0.05, "com": [0.0, 0.0, 0.025],
     "inertia": [0.00033, 0.00033, 0.0005, 0.0, 0.0, 0.0]}
  ]})";

/// A hybrid robot: a cc joint with a custom 3-chamber map, a link, a revolute joint
/// (columns t, p1_0..p1_2, u1, v1, qwrist).
inline const char* const kHybrid = R"({
  "format": "softrne-robot/1", "name": "hybrid", "gravity": [0.0, 0.0, 9.81],
  "segments": [
    {"type": "cc_joint", "name": "joint1", "mass": 0.8, "height": 0.2, "diameter": 0.2,
     "chamber_distance": 0.06, "chamber_radius": 0.03, "stiffness": [40.0, 40.0], "damping": [3.0, 3.0],
     "pressure_to_torque": [[1e-4, -5e-5, -5e-5], [0.0, 8.66e-5, -8.66e-5]]},
    {"type": "rigid_link", "name": "link1", "mass": 1.5, "length": 0.15, "com": [0.0, 0.0, 0.075],
     "inertia": [0.0052, 0.0052, 0.0048, 0.0, 0.0, 0.0]},
    {"type": "revolute_joint", "name": "wrist", "axis": [0.0, 0.0, 1.0], "stiffness": 0.0, "damping": 0.1}
  ]})";

/// The fixed robots of the CSV target (parsed once).
inline const std::vector<softrne::io::RobotSpec>& csv_robots() {
  static const std::vector<softrne::io::RobotSpec> robots{
      softrne::io::parse_robot_json(kArmA, "arm-a.json"),
      softrne::io::parse_robot_json(kHybrid, "hybrid.json")};
  return robots;
}

/// What fuzz_robot_json does with one input.
inline void run_robot_json(const std::string& text) {
  try {
    (void)softrne::io::parse_robot_json(text, "fuzz");
  } catch (const softrne::io::InputError&) {
  }
}

/// What fuzz_csv does with one input: the generic table reader, then the data-set
/// reader for each fixed robot, with and without required angles.
inline void run_csv(const std::string& text) {
  try {
    (void)softrne::io::parse_csv(text, "fuzz.csv");
  } catch (const softrne::io::InputError&) {
  }
  for (const auto& robot : csv_robots()) {
    for (const bool require_angles : {false, true}) {
      try {
        (void)softrne::io::parse_dataset(text, "fuzz.csv", robot, require_angles);
      } catch (const softrne::io::InputError&) {
      }
    }
  }
}

}  // namespace softrne_fuzz
