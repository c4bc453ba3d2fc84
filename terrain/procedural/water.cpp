// Water: rivers, the zero set of a noise stretched along the flow direction
// with meanders from a warp across it, and what a pixel near one shows (the
// water, its muddy banks, the grass and, seen from afar, the trees along it).

#include <algorithm>
#include <cmath>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {
namespace {

constexpr Rgb kWaterDeep{50, 64, 62};
constexpr Rgb kWaterShallow{78, 88, 74};
constexpr Rgb kMud{112, 104, 84};
constexpr Rgb kRiverGrass{96, 112, 66};

}  // namespace

// The signed distance is the noise over its (analytic) gradient, accurate near
// the river.
void Generator::river(double x, double y, TerrainSample& t) const {
  const double a = x * flow_x + y * flow_y;
  const double b = -x * flow_y + y * flow_x;
  const NoiseD m1 = gradNoiseD(a / 520.0, b / 1300.0, s_meander1);
  const NoiseD m2 = gradNoiseD(a / 190.0 + 0.3, b / 600.0, s_meander2);
  const NoiseD m3 = gradNoiseD(a / 75.0 + 0.7, b / 260.0, s_meander2 + 1);
  const double bw = b + 120.0 * m1.v + 38.0 * m2.v + 7.0 * m3.v;
  const double bw_a = 120.0 / 520.0 * m1.dx + 38.0 / 190.0 * m2.dx + 7.0 / 75.0 * m3.dx;
  const double bw_b = 1.0 + 120.0 / 1300.0 * m1.dy + 38.0 / 600.0 * m2.dy + 7.0 / 260.0 * m3.dy;
  // fbm of (A, B) = (a / 3, bw) with its derivatives.
  double X = a / 3.0, Y = bw;
  double r00 = 1, r01 = 0, r10 = 0, r11 = 1;  // (X, Y) = R (A, B)
  double n = 0, nA = 0, nB = 0, amp = 1, lambda = 1.3 * p.river_spacing_m;
  for (int o = 0; o < 3; ++o) {
    const NoiseD d =
        gradNoiseD(X / lambda + 0.31 * o, Y / lambda + 0.57 * o, s_river + 0x51ED27ULL * o);
    n += amp * d.v;
    nA += amp * (d.dx * r00 + d.dy * r10) / lambda;
    nB += amp * (d.dx * r01 + d.dy * r11) / lambda;
    const double rx = 0.8 * X - 0.6 * Y;
    Y = 0.6 * X + 0.8 * Y;
    X = rx;
    const double q00 = 0.8 * r00 - 0.6 * r10, q01 = 0.8 * r01 - 0.6 * r11;
    const double q10 = 0.6 * r00 + 0.8 * r10, q11 = 0.6 * r01 + 0.8 * r11;
    r00 = q00;
    r01 = q01;
    r10 = q10;
    r11 = q11;
    lambda *= 0.5;
    amp *= 0.35;
  }
  const double na = nA / 3.0 + nB * bw_a;
  const double nb = nB * bw_b;
  const double gx = na * flow_x - nb * flow_y;
  const double gy = na * flow_y + nb * flow_x;
  t.sd = n / std::max(std::sqrt(gx * gx + gy * gy), 1e-12);
  const double sa = nA / 3.0 + nB * 120.0 / 520.0 * m1.dx;
  const double sb = nB * (1.0 + 120.0 / 1300.0 * m1.dy);
  t.sdv = n / std::max(std::sqrt(sa * sa + sb * sb), 1e-12);
  t.hw = 5.0 + 10.0 * smooth01(0.5 + 0.9 * gradNoise(x / 3500.0, y / 3500.0, s_width));
}

namespace {

// The river, its banks and the grass and trees along them over colour; fc is
// the forest's cover of the pixel.
Rgb riverside(const Generator& gen, Rgb colour, const GroundPixel& g, const PixelScale& sc,
              double fc) {
  const ValueTable& table = gen.table;
  const Pix& f = g.f;
  const double px = sc.px, x = g.x, y = g.y, mid = g.mid, detail = g.detail;
  const double ad = std::abs(f.sd);
  if (ad < f.hw + 14.0 + px) {
    const double reach = 5.0 + 3.0 * f.var;
    const double grass =
        bandCoverage(ad - (f.hw + 2.0 + 0.5 * reach), 0.5 * reach, px) * (1.0 - fc);
    colour = mix(colour, kRiverGrass * (1.0 + 0.1 * detail), grass);
    if (sc.coarse > 0.0) {
      colour = mix(colour, gen.forest_mean_broadleaf,
                   bandCoverage(ad - (f.hw + 7.0), 4.0, px) * 0.3 * sc.coarse);
    }
    const double mud = bandCoverage(ad - (f.hw + 1.0), 1.2, px);
    colour = mix(colour, kMud * (1.0 + 0.1 * detail), mud);
    const double water = bandCoverage(ad, f.hw, px);
    if (water > 0.0) {
      // Ripples across the current and a sheen varying along it.
      const double ripple = sc.ripple_octaves(table, x, y);
      const Rgb w = mix(kWaterDeep, kWaterShallow, smoothstep(f.hw - 4.0, f.hw, ad)) *
                    (1.0 + 0.08 * mid + 0.16 * ripple + 0.03 * f.var);
      colour = mix(colour, w, water);
    }
  }
  return colour;
}

}  // namespace

void Generator::paintWater(const GroundRow& row, const PixelScale& sc, std::span<Rgb> col) const {
  for (std::size_t c = 0; c < col.size(); ++c) {
    col[c] = riverside(*this, col[c], row.pixels[c], sc, row.forest_cover[c]);
  }
}

}  // namespace nadir::terrain::procedural
