#pragma once
// Platform-independent N(0,1) samples for the tests' synthetic noise: Box-Muller on raw
// mt19937_64 bits (std::normal_distribution differs between standard libraries).
#include <cmath>
#include <cstdint>
#include <random>

namespace softrne::test {

struct Gauss {
  explicit Gauss(std::uint64_t seed) : gen(seed) {}
  double uniform() { return (static_cast<double>(gen() >> 11) + 0.5) * 0x1.0p-53; }
  double operator()() {
    return std::sqrt(-2.0 * std::log(uniform())) * std::cos(2.0 * M_PI * uniform());
  }
  std::mt19937_64 gen;
};

}  // namespace softrne::test
