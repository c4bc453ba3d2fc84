#include "nodes/sim/noise.h"

#include <cmath>
#include <numbers>

namespace nadir::sim {

double GaussianNoise::standardNormal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  constexpr double kScale = 1.0 / 9007199254740992.0;  // 2^-53
  // u1 in (0, 1] keeps the logarithm finite; u2 in [0, 1).
  const double u1 = static_cast<double>((engine_() >> 11) + 1) * kScale;
  const double u2 = static_cast<double>(engine_() >> 11) * kScale;
  const double radius = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * std::numbers::pi * u2;
  spare_ = radius * std::sin(angle);
  has_spare_ = true;
  return radius * std::cos(angle);
}

}  // namespace nadir::sim
