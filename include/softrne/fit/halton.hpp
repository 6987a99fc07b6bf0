#pragma once
/// \file
/// \brief Seeded, shifted Halton points in \f$[0,1]^p\f$: the screening set of multistart.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace softrne::fit::detail {

/// Radical inverse of `index` in `base` (van der Corput).
inline double radical_inverse(std::uint64_t index, std::uint64_t base) {
  double result = 0.0, f = 1.0 / static_cast<double>(base);
  while (index > 0) {
    result += f * static_cast<double>(index % base);
    index /= base;
    f /= static_cast<double>(base);
  }
  return result;
}

/// `count` points of a Halton sequence in [0,1]^p with a seeded
/// Cranley-Patterson shift (the same on every platform: raw mt19937_64 bits).
inline std::vector<Eigen::VectorXd> shifted_halton(int p, int count, unsigned seed) {
  std::vector<std::uint64_t> primes;
  for (std::uint64_t c = 2; static_cast<int>(primes.size()) < p; ++c) {
    bool prime = true;
    for (const std::uint64_t q : primes)
      if (c % q == 0) {
        prime = false;
        break;
      }
    if (prime) primes.push_back(c);
  }
  std::mt19937_64 gen(seed);
  Eigen::VectorXd shift(p);
  for (int j = 0; j < p; ++j) shift[j] = static_cast<double>(gen() >> 11) * 0x1.0p-53;
  std::vector<Eigen::VectorXd> points;
  points.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    Eigen::VectorXd x(p);
    for (int j = 0; j < p; ++j) {
      const double v = radical_inverse(static_cast<std::uint64_t>(k) + 1, primes[j]) + shift[j];
      x[j] = v - std::floor(v);
    }
    points.push_back(std::move(x));
  }
  return points;
}

}  // namespace softrne::fit::detail
