// softrne side of tools/pinocchio_check.py: evaluates a robot file at given states.
//
//   softrne_pinocchio_eval ROBOT.json STATES.txt
//
// ROBOT.json is a softrne-robot/1 file (read and validated by softrne::io, chain built by
// softrne::build_arm). STATES.txt holds one state per line: q, qdot, qddot, tau (nq numbers
// each, whitespace separated; '#' lines are comments). For every state one JSON object is
// printed on its own line, numbers in shortest round-trip form:
//   {"nq":N, "rnea":[...], "mass_matrix":[[...],...], "gravity":[...], "bias":[...],
//    "forward_dynamics":[...]}
// rnea = M qddot + C qdot + G; bias = C qdot + G; forward_dynamics = M^-1 (tau - C qdot - G).
#include <cstdio>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "softrne/arm/arm_description.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/softrne.hpp"

namespace {

nlohmann::json vec(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s ROBOT.json STATES.txt\n", argv[0]);
    return 2;
  }
  try {
    const softrne::io::RobotSpec spec = softrne::io::read_robot_json(argv[1]);
    const softrne::ArmDescription arm = softrne::build_arm(spec);
    const softrne::DynamicChain<double> chain = arm.make_chain<double>();
    auto data = chain.make_data();
    const int nq = chain.num_coordinates();

    std::ifstream in(argv[2]);
    if (!in) {
      std::fprintf(stderr, "%s: cannot open %s\n", argv[0], argv[2]);
      return 1;
    }
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
      ++line_no;
      if (line.empty() || line[0] == '#') continue;
      std::istringstream ss(line);
      std::vector<double> x;
      double d;
      while (ss >> d) x.push_back(d);
      if (static_cast<int>(x.size()) != 4 * nq) {
        std::fprintf(stderr, "%s:%d: expected %d numbers (q, qdot, qddot, tau), got %zu\n", argv[2],
                     line_no, 4 * nq, x.size());
        return 1;
      }
      const Eigen::Map<const Eigen::VectorXd> all(x.data(), 4 * nq);
      const Eigen::VectorXd q = all.segment(0, nq), qd = all.segment(nq, nq),
                            qdd = all.segment(2 * nq, nq), tau = all.segment(3 * nq, nq);
      nlohmann::json out;
      out["nq"] = nq;
      out["rnea"] = vec(softrne::rnea(chain, data, q, qd, qdd));
      const Eigen::MatrixXd M = softrne::mass_matrix(chain, data, q);
      nlohmann::json rows = nlohmann::json::array();
      for (int i = 0; i < nq; ++i) rows.push_back(vec(M.row(i).transpose()));
      out["mass_matrix"] = rows;
      out["gravity"] = vec(softrne::gravity(chain, data, q));
      out["bias"] = vec(softrne::bias(chain, data, q, qd, true));
      out["forward_dynamics"] = vec(softrne::forward_dynamics(chain, data, q, qd, tau));
      std::printf("%s\n", out.dump().c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
