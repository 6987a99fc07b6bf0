// The C++ side of python/bench/bench_python.py: the time per state of softrne::rnea called in a
// C++ loop over N states on the DynamicChain of a robot file (the chain the Python module uses),
// one workspace, median of repeats. Prints one JSON line.
//
//   softrne_py_bench_cpp ROBOT.json N REPEATS
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "softrne/arm/arm_description.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/softrne.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s ROBOT.json N REPEATS\n", argv[0]);
    return 2;
  }
  const softrne::ArmDescription arm = softrne::build_arm(softrne::io::read_robot_json(argv[1]));
  const softrne::DynamicChain<double> chain = arm.make_chain<double>();
  auto data = chain.make_data();
  const int nq = chain.num_coordinates();
  const long n = std::atol(argv[2]);
  const int repeats = std::atoi(argv[3]);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  Eigen::MatrixXd q(nq, n), qd(nq, n), qdd(nq, n), tau(nq, n);
  for (long k = 0; k < n; ++k)
    for (int i = 0; i < nq; ++i) q(i, k) = u(rng), qd(i, k) = 3 * u(rng), qdd(i, k) = 8 * u(rng);
  std::vector<double> per_state;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (long k = 0; k < n; ++k) tau.col(k) = softrne::rnea(chain, data, q.col(k), qd.col(k), qdd.col(k));
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    per_state.push_back(s / static_cast<double>(n));
  }
  std::sort(per_state.begin(), per_state.end());
  std::printf("{\"nq\": %d, \"states\": %ld, \"repeats\": %d, \"median_ns_per_state\": %.2f, \"checksum\": %.17g}\n",
              nq, n, repeats, 1e9 * per_state[per_state.size() / 2], tau.sum());
  return 0;
}
