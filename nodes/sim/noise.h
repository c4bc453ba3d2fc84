#pragma once

#include <cstdint>
#include <random>

namespace nadir::sim {

// Gaussian noise source: std::mt19937_64 and Box-Muller, identical on every
// platform's standard library (up to the last bit of std::log/std::cos).
class GaussianNoise {
 public:
  explicit GaussianNoise(std::uint64_t seed) : engine_(seed) {}
  // A standard normal variate.
  double standardNormal();
  double normal(double sigma) { return sigma * standardNormal(); }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace nadir::sim
