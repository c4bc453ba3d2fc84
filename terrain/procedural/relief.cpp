// Relief: domain-warped ridged and smooth fBm hills that fall into valleys
// along the rivers (water.cpp), a regional tilt down the flow direction and a
// carved channel. Heights stay within [-0.65, +0.7] * relief_m of the origin
// plane.

#include <algorithm>
#include <array>
#include <cmath>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {

TerrainSample Generator::terrain(double x, double y, double fp) const {
  TerrainSample t;
  river(x, y, t);
  const double r = p.relief_m;
  const double dist = std::abs(t.sdv) - t.hw;
  const double vn = gradNoise(x / 2000.0, y / 2000.0, s_valley);
  const double plain = 30.0 + 50.0 * (0.5 + 0.5 * vn);
  const double side = 500.0 + 300.0 * (0.5 - 0.5 * vn);
  const double over = std::max(0.0, dist - plain);
  // Valley sides rise concave from the floodplain (C1 at its edge).
  t.valley = 1.0 - std::exp(-over * over / (over + 60.0) / side);
  const double hill_share = smooth01(over / 900.0);
  if (r <= 0.0) {
    t.up = 0.0;
    return t;
  }
  // Hills: domain-warped broad swells, ridged hills and small undulation.
  const double qx = x + 450.0 * fbm(x, y, s_warp_x, 3200.0, 2, 0.5, 0.0);
  const double qy = y + 450.0 * fbm(x, y, s_warp_y, 3200.0, 2, 0.5, 0.0);
  static constexpr std::array<double, 10> kAmp = {1.0,  0.6,  0.45,  0.3,    0.15,
                                                  0.06, 0.02, 0.007, 0.0025, 0.001};
  static constexpr std::array<double, 10> kRidge = {0.0, 0.3, 0.75, 0.75, 0.5,
                                                    0.2, 0.0, 0.0,  0.0,  0.0};
  double sum = 0.0, lambda = 6400.0, hx = qx, hy = qy;
  for (int o = 0; o < 10; ++o) {
    const double w = detailWeight(lambda, fp);
    if (w <= 0.0) break;
    const double n =
        gradNoise(hx / lambda + 0.37 * o, hy / lambda + 0.11 * o, s_hills + 0x9E37ULL * o);
    const double ridge = 1.0 - std::sqrt(n * n + 0.02);
    sum += kAmp[o] * w * lerp(n, 2.0 * ridge * ridge - 0.9, kRidge[o]);
    const double rx = 0.8 * hx - 0.6 * hy;
    hy = 0.6 * hx + 0.8 * hy;
    hx = rx;
    lambda *= 0.5;
  }
  const double hills = 0.5 + 0.5 * std::tanh(1.5 * sum);  // (0, 1)
  const double base = 0.5 + 0.5 * std::tanh(fbm(x, y, s_base, 9000.0, 2, 0.5, 0.0));
  const double along = std::clamp(x * flow_x + y * flow_y, -0.5 * p.size_m, 0.5 * p.size_m);
  const double channel =
      std::min(2.0, 0.03 * r) * (1.0 - smoothstep(0.5 * t.hw, t.hw + 3.0, std::abs(t.sd)));
  t.up = r * (0.45 * t.valley + 0.55 * hills * hill_share + 0.1 * base) - tilt_per_m * along -
         channel - 0.5 * r;
  return t;
}

}  // namespace nadir::terrain::procedural
