#pragma once
// Robots built in code for the sim tests (no robot file needed).
#include <string>

#include <Eigen/Core>

#include "softrne/io/robot_spec.hpp"

namespace softrne::test {

inline io::RigidLinkSpec link(const std::string& name, double mass, double length, double com_z,
                                    double ixx, double izz) {
  io::RigidLinkSpec l;
  l.name = name;
  l.mass = mass;
  l.length = length;
  l.com = Eigen::Vector3d(0, 0, com_z);
  l.inertia = Eigen::Vector3d(ixx, ixx, izz).asDiagonal();
  return l;
}

/// The bundled arm's layout (three CC joints with links), hanging, in code.
inline io::RobotSpec three_joint_arm() {
  using io::make_cc_joint;
  io::RobotSpec s;
  s.name = "three-joint test arm";
  s.gravity = Eigen::Vector3d(0, 0, 9.81);
  for (int j = 1; j <= 3; ++j) {
    s.segments.push_back(make_cc_joint("joint" + std::to_string(j), 0.8, 0.2, 0.2, 0.06, 0.03,
                                       Eigen::Vector2d(20 + 3 * j, 30 - 4 * j),
                                       Eigen::Vector2d(2.0, 1.5 + 0.3 * j)));
    s.segments.push_back(link("link" + std::to_string(j), j == 3 ? 0.4 : 1.5, j == 3 ? 0.05 : 0.15,
                              j == 3 ? 0.025 : 0.075, j == 3 ? 3.3e-4 : 5.2e-3,
                              j == 3 ? 5e-4 : 4.8e-3));
  }
  return s;
}

}  // namespace softrne::test
