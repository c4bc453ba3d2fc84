#include "terrain/procedural_world.h"

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

// Internally x is east and y is north (metres, world frame), so that angles
// and rotations read as in the plane; only groundUp_m and imagery() speak
// (north, east).
//
// Layers, each a pure function of the seed and the position:
//  - terrain: domain-warped ridged/smooth fBm hills that fall into valleys
//    along the rivers (the zero set of a flow-aligned noise, its signed
//    distance from the noise's analytic gradient), a regional tilt down the
//    flow direction and a carved channel;
//  - land cover: a road network on the edges of a warped Voronoi diagram of
//    "blocks"; inside each block strip-like Voronoi fields in the block's own
//    orientation, each with a crop, a colour and rows in its own direction;
//    a forest mask (clumpy noise) with individual tree crowns; hedgerow,
//    riverside and lone trees; farmsteads along the roads;
//  - lighting: Lambertian hillshade from the same sun that casts the shadows of
//    trees and buildings.
// Randomness is integer hashing of (layer seed, cell) (splitmix64's finaliser)
// feeding gradient noise for the terrain and masks, and a 256 x 256 table of
// hashed values (built once from the seed) for the texture evaluated at every
// pixel.
//
// Filtering to the pixel's footprint: noise octaves fade out before they would
// alias; lines, bands and edges (roads, rivers, margins, tracks, field edges)
// take their area coverage; buildings are supersampled; trees are drawn while
// their crowns span a few pixels and beyond that forests take their mean colour
// (calibrated at construction by drawing closed forest) with a crown-scale
// grain; fields narrower than a pixel blend into their analytic mean colour.
//
// A square is rendered in blocks of at most kBlockPx pixels (in parallel with
// cv::parallel_for_); each block evaluates the smooth fields (height,
// hillshade, river distance, masks) on a world-anchored grid, then colours
// every pixel, then draws tree and building sprites in a global order. Pixel
// positions come from global pixel indices and every decision from world
// positions, so the result depends neither on how the square is cut into
// blocks, nor on the number of threads, nor on earlier calls; adjacent squares
// at the same pixel size meet without seams. Memory per block is bounded
// (a few MB of per-thread scratch).

namespace nadir::terrain {
namespace {

using u64 = std::uint64_t;
using i64 = std::int64_t;

constexpr double kPi = 3.14159265358979323846;
constexpr int kBlockPx = 256;
constexpr double kMaxShadow = 40.0;  // longest tree shadow drawn, m

// ---------------------------------------------------------------- hashing --

u64 mix64(u64 z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

u64 hash2(u64 seed, i64 i, i64 j) {
  return mix64(seed + static_cast<u64>(i) * 0x9E3779B97F4A7C15ULL +
               static_cast<u64>(j) * 0xC2B2AE3D27D4EB4FULL);
}

// The k-th uniform number in [0, 1) drawn from hash h.
double uniform(u64 h, u64 k) {
  return static_cast<double>(mix64(h + (k + 1) * 0xD6E8FEB86659FD93ULL) >> 11) * 0x1.0p-53;
}

// Three independent 21-bit uniform numbers in [0, 1) from one hash (k = 0, 1, 2).
double bits(u64 h, int k) { return static_cast<double>((h >> (21 * k)) & 0x1FFFFFu) * 0x1.0p-21; }

u64 pairKey(u64 a, u64 b) { return a < b ? mix64(a ^ mix64(b)) : mix64(b ^ mix64(a)); }

// ------------------------------------------------------------------ maths --

double clamp01(double v) { return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v); }
double smooth01(double t) {
  t = clamp01(t);
  return t * t * (3.0 - 2.0 * t);
}
double smoothstep(double e0, double e1, double x) { return smooth01((x - e0) / (e1 - e0)); }
double lerp(double a, double b, double t) { return a + (b - a) * t; }

struct Rgb {
  double r = 0.0, g = 0.0, b = 0.0;
};
Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
Rgb operator-(Rgb a, Rgb b) { return {a.r - b.r, a.g - b.g, a.b - b.b}; }
Rgb operator*(Rgb a, double k) { return {a.r * k, a.g * k, a.b * k}; }
Rgb mix(Rgb a, Rgb b, double t) { return a + (b - a) * t; }

// Fraction of the pixel footprint [d - px/2, d + px/2] inside [-hw, hw].
double bandCoverage(double d, double hw, double px) {
  const double lo = std::max(d - 0.5 * px, -hw);
  const double hi = std::min(d + 0.5 * px, hw);
  return hi > lo ? (hi - lo) / px : 0.0;
}

// Coverage of bands of half width hw centred on offset + k * period, averaged
// over the footprint; tends to the mean 2 hw / period as the footprint grows.
double periodicBand(double x, double period, double offset, double hw, double px) {
  const double mean = 2.0 * hw / period;
  const double ratio = px / period;
  if (ratio >= 1.0) return mean;
  double t = x - offset;
  t -= period * std::floor(t / period + 0.5);
  const double cov =
      bandCoverage(t, hw, px) + bandCoverage(t - period, hw, px) + bandCoverage(t + period, hw, px);
  return lerp(mean, cov, smooth01((1.0 - ratio) * 2.0));
}

// Weight of detail of wavelength lambda in a pixel of size fp: 1 while it is
// well resolved (lambda >= 4 fp), 0 at and below the Nyquist limit.
double detailWeight(double lambda, double fp) {
  if (fp <= 0.0) return 1.0;
  return smooth01((lambda / fp - 2.0) * 0.5);
}

// Amplitude of a sine wave of wavelength lambda averaged over a pixel of size
// px (a sinc), faded out before it aliases.
double sineAmplitude(double lambda, double px) {
  const double ratio = px / lambda;
  if (ratio >= 0.5) return 0.0;
  const double a = kPi * ratio;
  const double sinc = a > 1e-9 ? std::sin(a) / a : 1.0;
  return sinc * smooth01((0.5 - ratio) * 4.0);
}

// ------------------------------------------------------------------ noise --

struct Grad {
  double x, y;
};
constexpr std::array<Grad, 16> kGrad = {{{1.0, 0.0},
                                         {0.9238795325, 0.3826834324},
                                         {0.7071067812, 0.7071067812},
                                         {0.3826834324, 0.9238795325},
                                         {0.0, 1.0},
                                         {-0.3826834324, 0.9238795325},
                                         {-0.7071067812, 0.7071067812},
                                         {-0.9238795325, 0.3826834324},
                                         {-1.0, 0.0},
                                         {-0.9238795325, -0.3826834324},
                                         {-0.7071067812, -0.7071067812},
                                         {-0.3826834324, -0.9238795325},
                                         {0.0, -1.0},
                                         {0.3826834324, -0.9238795325},
                                         {0.7071067812, -0.7071067812},
                                         {0.9238795325, -0.3826834324}}};

double quintic(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// 2D gradient (Perlin) noise in about [-1, 1], zero mean, unit lattice.
double gradNoise(double x, double y, u64 seed) {
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  const i64 ix = static_cast<i64>(fx);
  const i64 iy = static_cast<i64>(fy);
  const double dx = x - fx;
  const double dy = y - fy;
  const auto corner = [seed](i64 i, i64 j, double ox, double oy) {
    const Grad& g = kGrad[hash2(seed, i, j) & 15u];
    return g.x * ox + g.y * oy;
  };
  const double n00 = corner(ix, iy, dx, dy);
  const double n10 = corner(ix + 1, iy, dx - 1.0, dy);
  const double n01 = corner(ix, iy + 1, dx, dy - 1.0);
  const double n11 = corner(ix + 1, iy + 1, dx - 1.0, dy - 1.0);
  const double u = quintic(dx);
  const double v = quintic(dy);
  const double a = n00 + u * (n10 - n00);
  const double b = n01 + u * (n11 - n01);
  return 1.4 * (a + v * (b - a));
}

struct NoiseD {
  double v, dx, dy;
};

// gradNoise with its derivatives (per unit of x and y).
NoiseD gradNoiseD(double x, double y, u64 seed) {
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  const i64 ix = static_cast<i64>(fx);
  const i64 iy = static_cast<i64>(fy);
  const double dx = x - fx;
  const double dy = y - fy;
  const Grad& g00 = kGrad[hash2(seed, ix, iy) & 15u];
  const Grad& g10 = kGrad[hash2(seed, ix + 1, iy) & 15u];
  const Grad& g01 = kGrad[hash2(seed, ix, iy + 1) & 15u];
  const Grad& g11 = kGrad[hash2(seed, ix + 1, iy + 1) & 15u];
  const double n00 = g00.x * dx + g00.y * dy;
  const double n10 = g10.x * (dx - 1.0) + g10.y * dy;
  const double n01 = g01.x * dx + g01.y * (dy - 1.0);
  const double n11 = g11.x * (dx - 1.0) + g11.y * (dy - 1.0);
  const double u = quintic(dx), v = quintic(dy);
  const double du = 30.0 * dx * dx * (dx - 1.0) * (dx - 1.0);
  const double dv = 30.0 * dy * dy * (dy - 1.0) * (dy - 1.0);
  const double a = n00 + u * (n10 - n00);
  const double b = n01 + u * (n11 - n01);
  const double ax = g00.x + u * (g10.x - g00.x) + du * (n10 - n00);
  const double ay = g00.y + u * (g10.y - g00.y);
  const double bx = g01.x + u * (g11.x - g01.x) + du * (n11 - n01);
  const double by = g01.y + u * (g11.y - g01.y);
  return {1.4 * (a + v * (b - a)), 1.4 * (ax + v * (bx - ax)),
          1.4 * (ay + v * (by - ay) + dv * (b - a))};
}

// Fractal sum of gradient noise: octaves of wavelength lambda, lambda/2, ...
// with amplitudes 1, gain, gain^2, ...; each octave rotated and shifted, and
// faded out once finer than the footprint fp allows.
double fbm(double x, double y, u64 seed, double lambda, int octaves, double gain, double fp) {
  double sum = 0.0;
  double amp = 1.0;
  for (int o = 0; o < octaves; ++o) {
    const double w = detailWeight(lambda, fp);
    if (w <= 0.0) break;
    sum +=
        amp * w * gradNoise(x / lambda + 0.31 * o, y / lambda + 0.57 * o, seed + 0x51ED27ULL * o);
    const double rx = 0.8 * x - 0.6 * y;
    y = 0.6 * x + 0.8 * y;
    x = rx;
    lambda *= 0.5;
    amp *= gain;
  }
  return sum;
}

i64 floorToInt(double v) {
  const i64 i = static_cast<i64>(v);
  return v < static_cast<double>(i) ? i - 1 : i;
}

// Value noise from a periodic table of 256 x 256 random values, for the
// texture evaluated at every pixel: several times cheaper than hashing, and
// small enough to stay in cache. Octaves are rotated and shifted, so the
// period (256 wavelengths) never shows.
class ValueTable {
 public:
  static constexpr int kBits = 8;
  static constexpr int kSize = 1 << kBits;
  static constexpr i64 kMask = kSize - 1;

  explicit ValueTable(u64 seed) : v_(static_cast<std::size_t>(kSize) * kSize) {
    for (int j = 0; j < kSize; ++j) {
      for (int i = 0; i < kSize; ++i) {
        v_[static_cast<std::size_t>(j) * kSize + i] =
            static_cast<float>(2.0 * bits(hash2(seed, i, j), 0) - 1.0);
      }
    }
  }

  // Smooth value noise in [-1, 1], zero mean, unit lattice.
  double noise(double x, double y) const {
    const i64 fx = floorToInt(x), fy = floorToInt(y);
    const i64 ix = fx & kMask, iy = fy & kMask;
    const i64 ix1 = (ix + 1) & kMask, iy1 = (iy + 1) & kMask;
    const double dx = x - static_cast<double>(fx), dy = y - static_cast<double>(fy);
    const float* r0 = &v_[static_cast<std::size_t>(iy) * kSize];
    const float* r1 = &v_[static_cast<std::size_t>(iy1) * kSize];
    const double u = dx * dx * (3.0 - 2.0 * dx), v = dy * dy * (3.0 - 2.0 * dy);
    const double a = r0[ix] + u * (r0[ix1] - r0[ix]);
    const double b = r1[ix] + u * (r1[ix1] - r1[ix]);
    return a + v * (b - a);
  }

 private:
  std::vector<float> v_;
};

// A fractal sum of ValueTable octaves prepared for one pixel size: octaves of
// wavelength lambda, lambda / 2, ... with amplitudes gain^k, rotated and
// shifted, each faded out once finer than the pixel allows.
class Octaves {
 public:
  Octaves(double lambda, int octaves, double gain, double px, double norm, double shift) {
    double amp = norm, c = 0.8775825619, s = 0.4794255386;  // rotated by 0.5 rad
    for (int o = 0; o < octaves && o < kMax; ++o) {
      const double w = detailWeight(lambda, px);
      if (w <= 0.0) break;
      oct_[n_++] = {c / lambda, s / lambda, 17.31 * o + shift, 41.73 * o, amp * w};
      const double nc = 0.8 * c - 0.6 * s;
      s = 0.6 * c + 0.8 * s;
      c = nc;
      lambda *= 0.5;
      amp *= gain;
    }
  }
  double operator()(const ValueTable& table, double x, double y) const {
    double sum = 0.0;
    for (int o = 0; o < n_; ++o) {
      const Oct& q = oct_[o];
      sum += q.amp * table.noise(q.c * x - q.s * y + q.ox, q.s * x + q.c * y + q.oy);
    }
    return sum;
  }

 private:
  static constexpr int kMax = 6;
  struct Oct {
    double c, s, ox, oy, amp;
  };
  std::array<Oct, kMax> oct_{};
  int n_ = 0;
};

// sin(2 pi t) from a table, for crop rows at every pixel.
class SineTable {
 public:
  static constexpr int kSize = 1024;
  SineTable() {
    for (int i = 0; i <= kSize; ++i) v_[i] = std::sin(2.0 * kPi * i / kSize);
  }
  double operator()(double turns) const {
    const double t = (turns - std::floor(turns)) * kSize;
    const int i = std::min(static_cast<int>(t), kSize - 1);
    return v_[i] + (t - i) * (v_[i + 1] - v_[i]);
  }

 private:
  std::array<double, kSize + 1> v_{};
};

// --------------------------------------------------------------- palettes --

constexpr Rgb kSoilDark{98, 84, 68};
constexpr Rgb kSoilLight{158, 140, 112};
constexpr Rgb kMarginGrass{104, 114, 72};
constexpr Rgb kForestFloor{60, 68, 46};
constexpr Rgb kBroadleaf{84, 104, 58};
constexpr Rgb kConifer{60, 78, 54};
constexpr Rgb kWaterDeep{50, 64, 62};
constexpr Rgb kWaterShallow{78, 88, 74};
constexpr Rgb kMud{112, 104, 84};
constexpr Rgb kRiverGrass{96, 112, 66};
constexpr Rgb kAsphalt{112, 111, 106};
constexpr Rgb kShoulder{152, 145, 128};
constexpr Rgb kGravel{164, 153, 130};
constexpr Rgb kTrackGrass{110, 118, 76};
constexpr Rgb kDirt{150, 136, 110};

enum class Crop { kCereal, kRipe, kMaize, kRape, kMeadow, kPasture, kSoil, kStubble };

struct FieldInfo {
  u64 id = 0;
  Crop crop = Crop::kCereal;
  Rgb plant, dry;     // plant colour and its dry/yellow variant
  double soil_k = 1;  // soil brightness factor
  double cover = 0.8;
  double bright = 1.0;
  double row_nx = 1, row_ny = 0;  // unit normal to the rows
  double row_lambda = 0;          // 0: no rows
  double row_phase = 0;
  double row_amp1 = 0, row_amp2 = 0;  // the rows' harmonics filtered to the pixel
  double row_cover = 0;               // coverage modulation by the rows
  double row_bright = 0;              // brightness modulation by the rows
  double tram_lambda = 0;
  double tram_phase = 0;
  double band_lambda = 0;  // mowing / swath bands along the rows
  double band_phase = 0;
  double band_hw = 0;
  double band_bright = 0;
  double var_cover = 0;
  double var_bright = 0;
  double detail = 0.05;  // mid-scale (24..6 m) texture amplitude
  double fine = 0.08;    // fine (3..0.75 m) texture amplitude
  double headland = 0;
  double margin_hw = 0.6;
};

// A block of the road network: its Voronoi site, id and field layout frame.
struct Site {
  double x = 0, y = 0;
  u64 id = 0;
};

// The 3 x 3 block sites around a cell, with the bisectors of the nearest.
struct BlockCell {
  bool valid = false;
  i64 ci = 0, cj = 0;
  std::array<Site, 9> sites;
  int nearest = -1;
  std::array<double, 9> nx{}, ny{}, off{};  // distance to bisector m: off - q . n
};

struct BlockHit {
  const Site* sites = nullptr;  // the 9 sites, owned by a BlockCell
  int nearest = 0;
  std::array<double, 9> edge_dist{};  // distance to the bisector with each site
  double edge = 1e300;                // distance to the block's boundary
  int edge_site = -1;
};

struct BlockFrame {
  u64 id = 0;
  double c = 1, s = 0;  // field axis (cos, sin)
  double lu = 1, lv = 1;
};

struct FieldCell {
  bool valid = false;
  u64 block = 0;
  i64 cj = 0;
  std::array<i64, 3> ci{};
  std::array<double, 9> su{}, sv{};
  std::array<u64, 9> ids{};
  int nearest = -1;
  std::array<double, 9> nu{}, nv{}, off{};  // distance in metres: off - (u, v) . n
};

struct FieldHit {
  u64 id = 0;
  double edge = 1e300;  // distance to the field's boundary, m
  u64 neighbour = 0;
};

struct Tree {
  double x, y, r;
  double shadow_short;  // shadow length on surrounding canopy, m
  double crown_off;     // crown shadow's centre along the shadow direction, m
  double crown_half;    // half the elongation of the crown's shadow, m
  bool interior;        // deep in a forest: only the short shadow can show
  double alpha;
  double wob_c, wob_s;  // crown outline: r (1 + wob_c cos 3t + wob_s sin 3t + ...)
  Rgb colour;
  bool conifer;
  u64 h;
};

struct Building {
  double x, y, ux, uy, hl, hw, height;
  Rgb roof;
  bool gable;
  u64 h;
};

struct Yard {
  double x, y, ux, uy, hl, hw;
  Rgb colour;
  u64 h;
};

struct Pix {
  double shade, sd, hw, mask, wx, wy, var, tint, soil, conifer, mask_grad;
};

struct Scratch {
  std::vector<double> nodes, up, line;
  std::vector<Rgb> col;
  std::vector<float> fcov, shadow, shade, detail;
};

// Pixel centres of a block of an imagery square, from global pixel indices.
struct PixelFrame {
  double east_min = 0, north_min = 0, px = 1;
  int size_px = 1, r0 = 0, c0 = 0, rows = 0, cols = 0;
  double x(int c) const { return east_min + (c0 + c + 0.5) * px; }
  double y(int r) const { return north_min + (size_px - (r0 + r) - 0.5) * px; }
  static int clampIndex(double v, int lo, int hi) {
    return static_cast<int>(std::clamp(v, static_cast<double>(lo), static_cast<double>(hi)));
  }
  // Local column range whose centres lie in [xa, xb] (empty when ca > cb).
  void colRange(double xa, double xb, int& ca, int& cb) const {
    ca = clampIndex(std::ceil((xa - east_min) / px - 0.5) - c0, 0, cols);
    cb = clampIndex(std::floor((xb - east_min) / px - 0.5) - c0, -1, cols - 1);
  }
  void rowRange(double ya, double yb, int& ra, int& rb) const {
    ra = clampIndex(std::ceil(size_px - 0.5 - (yb - north_min) / px) - r0, 0, rows);
    rb = clampIndex(std::floor(size_px - 0.5 - (ya - north_min) / px) - r0, -1, rows - 1);
  }
};

struct TerrainSample {
  double up = 0;
  double sd = 1e9;   // signed distance to the river's centre line (approx.), m
  double sdv = 1e9;  // the same without the small meanders, for the valley's shape
  double hw = 10;    // river half width, m
  double valley = 1;
};

}  // namespace

// ====================================================================== Impl

struct ProceduralWorld::Impl {
  explicit Impl(const ProceduralWorldParams& params);

  ProceduralWorldParams p;
  ValueTable table;
  SineTable sine;
  Octaves stand_full{350.0, 2, 0.6, 0.0, 1.0, 333.0};
  Octaves var_full{96.0, 3, 0.6, 0.0, 0.8, 555.0};
  Octaves forest_large{2400.0, 4, 0.5, 0.0, 1.0, 1234.5};
  Octaves forest_edge{110.0, 2, 0.5, 0.0, 1.0, 2345.6};
  u64 seed = 0;
  u64 s_warp_x, s_warp_y, s_hills, s_base, s_river, s_meander1, s_meander2, s_width, s_valley,
      s_bwarp_x, s_bwarp_y, s_block, s_field, s_region, s_tint, s_soil, s_conifer, s_trees, s_bld,
      s_settle, s_roof;
  double flow_x = 1, flow_y = 0;  // unit vector rivers run along (downhill)
  double sun_x = 0, sun_y = 0, sun_z = 1;
  double shadow_x = 0, shadow_y = 0;  // ground shadow offset per metre of height
  double inv_tan_sun = 1;
  double tilt_per_m = 0;
  double forest_threshold = 0;
  // Mean colour of closed forest at conifer shares 0, 1/4, ..., 1.
  std::array<Rgb, 5> forest_mean;
  Rgb forest_mean_broadleaf;
  Rgb forestMean(double conifer_share) const {
    const double t = std::clamp(conifer_share, 0.0, 1.0) * (forest_mean.size() - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(t), forest_mean.size() - 2);
    return mix(forest_mean[i], forest_mean[i + 1], t - static_cast<double>(i));
  }
  // The mean field colour is field_soil * soil + field_plant + dryness * field_dry.
  double field_soil = 0;
  Rgb field_plant, field_dry;

  // Forest stands: age and species patches, tens to hundreds of metres.
  double stand(double x, double y) const { return stand_full(table, x, y); }

  Rgb soilColour(const Pix& c) const {
    return mix(kSoilDark, kSoilLight, smooth01(0.5 + 1.2 * c.soil));
  }
  double dryness(const Pix& c) const { return clamp01(0.3 + 0.9 * c.tint); }
  Rgb meanFieldColour(const Pix& c) const {
    return soilColour(c) * field_soil + field_plant + field_dry * dryness(c);
  }

  // ------------------------------------------------------------ terrain --
  // Rivers are the zero set of a noise stretched along the flow direction,
  // with meanders from a warp across it. The signed distance is the noise over
  // its (analytic) gradient, accurate near the river.
  void river(double x, double y, TerrainSample& t) const {
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

  TerrainSample terrain(double x, double y, double fp) const {
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

  // Forest where positive: clumps of kilometres with ragged edges. Cheap
  // enough (table noise) to evaluate exactly wherever an edge may be near.
  double forestMask(double x, double y) const {
    return forest_large(table, x, y) + 0.22 * forest_edge(table, x, y) - forest_threshold;
  }

  double blockWarpX(double x, double y) const {
    return 22.0 * fbm(x, y, s_bwarp_x, 700.0, 2, 0.5, 0.0);
  }
  double blockWarpY(double x, double y) const {
    return 22.0 * fbm(x, y, s_bwarp_y, 700.0, 2, 0.5, 0.0);
  }
  // Within-field and within-forest variation, tens of metres.
  double varNoise(double x, double y) const { return var_full(table, x, y); }
  double tintNoise(double x, double y) const { return fbm(x, y, s_tint, 2600.0, 2, 0.5, 0.0); }
  double soilNoise(double x, double y) const { return fbm(x, y, s_soil, 1500.0, 2, 0.5, 0.0); }
  double coniferShare(double x, double y) const {
    return smooth01(0.5 + 1.6 * fbm(x, y, s_conifer, 2200.0, 2, 0.5, 0.0));
  }
  double settlement(double x, double y) const {
    return 0.25 + 1.75 * smooth01(0.5 + 1.3 * fbm(x, y, s_settle, 3000.0, 2, 0.5, 0.0));
  }

  // ------------------------------------------------------------- blocks --
  Site blockSite(i64 i, i64 j) const {
    const u64 h = hash2(s_block, i, j);
    const double b = p.block_size_m;
    return {(static_cast<double>(i) + 0.5 + 0.6 * (bits(h, 0) - 0.5)) * b,
            (static_cast<double>(j) + 0.5 + 0.6 * (bits(h, 1) - 0.5)) * b, h};
  }

  // The block around warped position q. The 3 x 3 sites and the bisectors of
  // the nearest one are kept in cell and reused while q stays in the same
  // cell: they are pure functions of the cell, so results do not depend on
  // what was asked before.
  BlockHit blockAt(double qx, double qy, BlockCell& cell) const {
    const i64 ci = static_cast<i64>(std::floor(qx / p.block_size_m));
    const i64 cj = static_cast<i64>(std::floor(qy / p.block_size_m));
    if (!cell.valid || ci != cell.ci || cj != cell.cj) {
      int k = 0;
      for (i64 dj = -1; dj <= 1; ++dj) {
        for (i64 di = -1; di <= 1; ++di, ++k) cell.sites[k] = blockSite(ci + di, cj + dj);
      }
      cell.ci = ci;
      cell.cj = cj;
      cell.valid = true;
      cell.nearest = -1;
    }
    BlockHit hit;
    hit.sites = cell.sites.data();
    double best = 1e300;
    for (int k = 0; k < 9; ++k) {
      const double dx = cell.sites[k].x - qx, dy = cell.sites[k].y - qy;
      const double d2 = dx * dx + dy * dy;
      if (d2 < best) {
        best = d2;
        hit.nearest = k;
      }
    }
    if (hit.nearest != cell.nearest) {
      const Site& a = cell.sites[hit.nearest];
      for (int m = 0; m < 9; ++m) {
        if (m == hit.nearest) continue;
        const Site& b = cell.sites[m];
        const double nx = b.x - a.x, ny = b.y - a.y;
        const double inv = 1.0 / std::sqrt(nx * nx + ny * ny);
        cell.nx[m] = nx * inv;
        cell.ny[m] = ny * inv;
        cell.off[m] = (0.5 * (a.x + b.x) * nx + 0.5 * (a.y + b.y) * ny) * inv;
      }
      cell.nearest = hit.nearest;
    }
    for (int m = 0; m < 9; ++m) {
      if (m == hit.nearest) {
        hit.edge_dist[m] = 1e300;
        continue;
      }
      const double d = cell.off[m] - (qx * cell.nx[m] + qy * cell.ny[m]);
      hit.edge_dist[m] = d;
      if (d < hit.edge) {
        hit.edge = d;
        hit.edge_site = m;
      }
    }
    return hit;
  }

  BlockFrame blockFrame(const Site& a) const {
    BlockFrame f;
    f.id = a.id;
    const double region = kPi * fbm(a.x, a.y, s_region, 7000.0, 2, 0.5, 0.0);
    const double angle =
        region + 0.6 * (uniform(a.id, 3) - 0.5) + (uniform(a.id, 4) < 0.25 ? 0.5 * kPi : 0.0);
    f.c = std::cos(angle);
    f.s = std::sin(angle);
    const double fs = p.field_size_m;
    const double big = uniform(a.id, 7) < 0.25 ? 1.7 : 1.0;
    f.lu = big * fs * (1.0 + 1.0 * uniform(a.id, 5));
    f.lv = big * fs * (0.4 + 0.35 * uniform(a.id, 6));
    return f;
  }

  // The field of block f at warped position q. Sites sit in staggered rows
  // across the block's field axis (scaled by lu, lv): strips of fields with
  // long near-parallel sides and offset ends.
  FieldHit fieldAt(const BlockFrame& f, double qx, double qy, FieldCell& cell) const {
    const double u = (qx * f.c + qy * f.s) / f.lu;
    const double v = (-qx * f.s + qy * f.c) / f.lv;
    const i64 cj = static_cast<i64>(std::floor(v));
    std::array<i64, 3> ci;
    std::array<double, 3> offs;
    for (int r = 0; r < 3; ++r) {
      const double stagger = static_cast<double>(cj + r - 1) * 0.6180339887;
      offs[r] = stagger - std::floor(stagger);
      ci[r] = static_cast<i64>(std::floor(u - offs[r]));
    }
    if (!cell.valid || cell.block != f.id || cell.cj != cj || cell.ci[0] != ci[0] ||
        cell.ci[1] != ci[1] || cell.ci[2] != ci[2]) {
      const u64 fseed = s_field ^ f.id;
      int k = 0;
      for (int r = 0; r < 3; ++r) {
        const i64 row = cj + r - 1;
        for (i64 di = -1; di <= 1; ++di, ++k) {
          const u64 h = hash2(fseed, ci[r] + di, row);
          cell.ids[k] = h;
          cell.su[k] = static_cast<double>(ci[r] + di) + offs[r] + 0.5 + 0.7 * (bits(h, 0) - 0.5);
          cell.sv[k] = static_cast<double>(row) + 0.5 + 0.2 * (bits(h, 1) - 0.5);
        }
      }
      cell.block = f.id;
      cell.cj = cj;
      cell.ci = ci;
      cell.valid = true;
      cell.nearest = -1;
    }
    double best = 1e300;
    int nearest = 0;
    for (int k = 0; k < 9; ++k) {
      const double du = cell.su[k] - u, dv = cell.sv[k] - v;
      const double d2 = du * du + dv * dv;
      if (d2 < best) {
        best = d2;
        nearest = k;
      }
    }
    if (nearest != cell.nearest) {
      for (int m = 0; m < 9; ++m) {
        if (m == nearest) continue;
        const double nu = cell.su[m] - cell.su[nearest], nv = cell.sv[m] - cell.sv[nearest];
        const double gu = nu / f.lu, gv = nv / f.lv;
        const double inv_g = 1.0 / std::sqrt(gu * gu + gv * gv);
        cell.nu[m] = nu * inv_g;
        cell.nv[m] = nv * inv_g;
        cell.off[m] = (0.5 * (cell.su[m] + cell.su[nearest]) * nu +
                       0.5 * (cell.sv[m] + cell.sv[nearest]) * nv) *
                      inv_g;
      }
      cell.nearest = nearest;
    }
    FieldHit hit;
    hit.id = cell.ids[nearest];
    for (int m = 0; m < 9; ++m) {
      if (m == nearest) continue;
      const double d = cell.off[m] - (u * cell.nu[m] + v * cell.nv[m]);
      if (d < hit.edge) {
        hit.edge = d;
        hit.neighbour = cell.ids[m];
      }
    }
    return hit;
  }

  FieldInfo fieldInfo(u64 id, const BlockFrame& f, double px) const {
    FieldInfo fi = fieldInfoAt(id, f);
    if (fi.row_lambda > 0.0) {
      fi.row_amp1 = sineAmplitude(fi.row_lambda, px);
      fi.row_amp2 = sineAmplitude(0.5 * fi.row_lambda, px);
    }
    return fi;
  }

  FieldInfo fieldInfoAt(u64 id, const BlockFrame& f) const {
    FieldInfo fi;
    fi.id = id;
    // Fifteen uniform numbers from five hashes.
    const std::array<u64, 5> hs = {mix64(id + 0x1111), mix64(id + 0x2222), mix64(id + 0x3333),
                                   mix64(id + 0x4444), mix64(id + 0x5555)};
    const auto U = [&hs](int k) { return bits(hs[static_cast<std::size_t>(k / 3)], k % 3); };
    const double u0 = U(0);
    if (u0 < p.bare_soil_fraction) {
      fi.crop = Crop::kSoil;
    } else {
      const double u = (u0 - p.bare_soil_fraction) / std::max(1e-9, 1.0 - p.bare_soil_fraction);
      static constexpr std::array<double, 7> kCum = {0.30, 0.40, 0.52, 0.58, 0.82, 0.94, 1.0};
      static constexpr std::array<Crop, 7> kCrops = {Crop::kCereal, Crop::kRipe,   Crop::kMaize,
                                                     Crop::kRape,   Crop::kMeadow, Crop::kPasture,
                                                     Crop::kStubble};
      fi.crop = Crop::kStubble;
      for (std::size_t i = 0; i < kCum.size(); ++i) {
        if (u < kCum[i]) {
          fi.crop = kCrops[i];
          break;
        }
      }
    }
    const double j1 = U(1), j2 = U(2), j3 = U(3), j4 = U(4), j5 = U(5), j6 = U(6);
    fi.bright = 0.9 + 0.2 * j1;
    fi.soil_k = 0.92 + 0.16 * j2;
    // Rows along the field's long axis mostly, else across it or skewed.
    double nx = -f.s, ny = f.c;
    if (j3 > 0.75) {
      nx = f.c;
      ny = f.s;
    }
    if (j3 > 0.92) {
      const double rx = 0.939372713 * nx - 0.342897807 * ny;
      ny = 0.342897807 * nx + 0.939372713 * ny;
      nx = rx;
    }
    const double jitter = 0.04 * (j4 - 0.5);
    const double norm = 1.0 / std::sqrt(1.0 + jitter * jitter);
    fi.row_nx = (nx - jitter * ny) * norm;
    fi.row_ny = (ny + jitter * nx) * norm;
    fi.row_phase = j5 * 100.0;
    fi.tram_phase = j6 * 100.0;
    fi.band_phase = U(7) * 100.0;
    fi.margin_hw = 0.4 + 0.9 * U(8);
    fi.headland = 8.0 + 8.0 * U(9);
    const double hue = U(10);
    switch (fi.crop) {
      case Crop::kCereal:
        fi.plant = mix(Rgb{92, 112, 60}, Rgb{108, 120, 66}, hue);
        fi.dry = Rgb{150, 146, 92};
        fi.cover = 0.88;
        fi.row_lambda = 1.4 + 1.2 * U(11);
        fi.row_cover = 0.05;
        fi.row_bright = 0.05;
        fi.tram_lambda = 18.0 + 6.0 * std::floor(U(12) * 2.0);
        fi.var_cover = 0.05;
        fi.var_bright = 0.04;
        fi.detail = 0.05;
        fi.fine = 0.07;
        break;
      case Crop::kRipe:
        fi.plant = mix(Rgb{178, 160, 106}, Rgb{196, 176, 124}, hue);
        fi.dry = Rgb{200, 184, 138};
        fi.cover = 0.92;
        fi.row_lambda = 1.2 + 1.0 * U(11);
        fi.row_cover = 0.03;
        fi.row_bright = 0.04;
        fi.tram_lambda = 18.0 + 6.0 * std::floor(U(12) * 2.0);
        fi.var_cover = 0.04;
        fi.var_bright = 0.03;
        fi.detail = 0.045;
        fi.fine = 0.06;
        break;
      case Crop::kMaize:
        fi.plant = mix(Rgb{66, 90, 46}, Rgb{80, 100, 52}, hue);
        fi.dry = Rgb{110, 118, 70};
        fi.cover = 0.72;
        fi.row_lambda = 0.75;
        fi.row_cover = 0.25;
        fi.row_bright = 0.06;
        fi.var_cover = 0.05;
        fi.var_bright = 0.035;
        fi.detail = 0.07;
        fi.headland = 6.0;
        fi.fine = 0.1;
        break;
      case Crop::kRape:
        fi.plant = mix(Rgb{100, 114, 64}, Rgb{120, 126, 72}, hue);
        fi.dry = Rgb{146, 140, 88};
        fi.cover = 0.9;
        fi.row_lambda = 1.5 + 0.8 * U(11);
        fi.row_cover = 0.04;
        fi.row_bright = 0.04;
        fi.tram_lambda = 24.0;
        fi.var_cover = 0.06;
        fi.var_bright = 0.04;
        fi.detail = 0.06;
        fi.fine = 0.08;
        break;
      case Crop::kMeadow:
        fi.plant = mix(Rgb{96, 118, 66}, Rgb{116, 130, 78}, hue);
        fi.dry = Rgb{150, 148, 100};
        fi.cover = 0.95;
        if (U(13) < 0.5) {
          fi.band_lambda = 3.0 + 3.0 * U(14);
          fi.band_hw = 0.25 * fi.band_lambda;
          fi.band_bright = 0.07;
        }
        fi.var_cover = 0.025;
        fi.var_bright = 0.04;
        fi.detail = 0.06;
        fi.headland = 0.0;
        fi.fine = 0.13;
        break;
      case Crop::kPasture:
        fi.plant = mix(Rgb{116, 128, 80}, Rgb{132, 138, 90}, hue);
        fi.dry = Rgb{160, 152, 108};
        fi.cover = 0.85;
        fi.var_cover = 0.06;
        fi.var_bright = 0.04;
        fi.detail = 0.07;
        fi.headland = 0.0;
        fi.fine = 0.15;
        break;
      case Crop::kSoil:
        fi.plant = Rgb{104, 112, 70};
        fi.dry = Rgb{120, 118, 80};
        fi.cover = 0.04 * U(11);
        fi.row_lambda = 0.9 + 2.2 * U(12);
        fi.row_cover = 0.0;
        fi.row_bright = 0.06 + 0.05 * U(13);
        fi.var_cover = 0.025;
        fi.var_bright = 0.08;
        fi.detail = 0.07;
        fi.headland = 10.0;
        fi.fine = 0.14;
        break;
      case Crop::kStubble:
        fi.plant = mix(Rgb{184, 168, 128}, Rgb{196, 180, 140}, hue);
        fi.dry = Rgb{200, 186, 146};
        fi.cover = 0.8;
        fi.row_lambda = 1.5 + 1.0 * U(11);
        fi.row_cover = 0.04;
        fi.row_bright = 0.03;
        fi.band_lambda = 5.0 + 3.0 * U(14);
        fi.band_hw = 0.6;
        fi.band_bright = 0.1;
        fi.tram_lambda = 18.0 + 6.0 * std::floor(U(12) * 2.0);
        fi.var_cover = 0.05;
        fi.var_bright = 0.035;
        fi.detail = 0.06;
        fi.fine = 0.09;
        break;
    }
    return fi;
  }

  // Colour of field fi at (q) with the pixel's smooth fields, edge distance e.
  Rgb fieldColour(const FieldInfo& fi, double qx, double qy, double e, double px, const Pix& c,
                  double mid, double fine) const {
    const double detail = 0.6 * mid + 0.8 * fine;
    double across = qx * fi.row_nx + qy * fi.row_ny;
    const bool headland = e < fi.headland;
    if (headland) across = e + fi.row_phase;
    double cover = fi.cover + fi.var_cover * c.var * 2.0;
    double bright =
        fi.bright * (1.0 + fi.var_bright * c.var * 2.0) * (1.0 + fi.detail * mid + fi.fine * fine);
    if (fi.row_lambda > 0.0) {
      const double turns = (across + fi.row_phase) / fi.row_lambda;
      const double sn = sine(turns), cs = sine(turns + 0.25);
      const double s = fi.row_amp1 * sn + 0.7 * fi.row_amp2 * sn * cs;
      cover += fi.row_cover * s;
      bright *= 1.0 + fi.row_bright * s;
    }
    if (fi.tram_lambda > 0.0 && !headland) {
      const double t = periodicBand(across, fi.tram_lambda, fi.tram_phase - 0.9, 0.25, px) +
                       periodicBand(across, fi.tram_lambda, fi.tram_phase + 0.9, 0.25, px);
      cover = lerp(cover, 0.1, 0.75 * t);
    }
    if (fi.band_lambda > 0.0 && !headland) {
      const double b = periodicBand(across, fi.band_lambda, fi.band_phase, fi.band_hw, px) -
                       2.0 * fi.band_hw / fi.band_lambda;
      bright *= 1.0 + fi.band_bright * b;
    }
    const Rgb soil = soilColour(c) * fi.soil_k;
    const Rgb plant = mix(fi.plant, fi.dry, dryness(c));
    Rgb col = mix(soil, plant, clamp01(cover)) * bright;
    const double m = bandCoverage(e, fi.margin_hw, px);
    if (m > 0.0) col = mix(col, kMarginGrass * (1.0 + 0.12 * detail), m);
    return col;
  }

  // ---------------------------------------------------------------- roads --
  struct Road {
    bool kept;
    double hw;
    bool gravel;
  };
  Road roadOf(u64 key) const {
    Road r;
    r.kept = uniform(key, 0) < p.road_density;
    const double cls = uniform(key, 1);
    r.gravel = cls > 0.72;
    r.hw = cls < 0.3 ? 3.0 + 1.0 * uniform(key, 2)
                     : (r.gravel ? 2.0 + 0.4 * uniform(key, 2) : 2.1 + 0.7 * uniform(key, 2));
    return r;
  }

  // Road coverage of a pixel and its colour; the block hit is at warped q.
  double roadAt(const BlockHit& hit, double qx, double qy, double px, Rgb& colour,
                double detail) const {
    const Site& a = hit.sites[hit.nearest];
    double best = 0.0;
    for (int m = 0; m < 9; ++m) {
      const double d = hit.edge_dist[m];
      if (d > 4.0 + px) continue;
      const Site& b = hit.sites[m];
      const u64 key = pairKey(a.id, b.id);
      const Road road = roadOf(key);
      if (!road.kept) continue;
      const double cov = bandCoverage(d, road.hw, px);
      if (cov <= best) continue;
      const bool real = onEdge(hit, m, qx, qy, road.hw);
      if (!real) continue;
      best = cov;
      if (road.gravel) {
        const double grass = bandCoverage(d, 0.35, px);
        const double tracks = bandCoverage(d - 0.9, 0.3, px);
        const Rgb g = kGravel * (1.0 + 0.06 * detail);
        colour =
            (g * (cov - grass - tracks) + kTrackGrass * grass + g * 0.82 * tracks) * (1.0 / cov);
      } else {
        const double inner = bandCoverage(d, road.hw - 0.5, px);
        const double k = 0.94 + 0.12 * uniform(key, 3);
        colour = (kAsphalt * (k * (1.0 + 0.04 * detail)) * inner + kShoulder * (cov - inner)) *
                 (1.0 / cov);
      }
    }
    return best;
  }

  // Distance from q to the nearest kept road (approximate), for placing things.
  // Is the point of the bisector with site m nearest to q on the block's real
  // edge, or past the edge's ends by no more than slack?
  static bool onEdge(const BlockHit& hit, int m, double qx, double qy, double slack) {
    const Site& a = hit.sites[hit.nearest];
    const Site& b = hit.sites[m];
    const double d = hit.edge_dist[m];
    const double nx = b.x - a.x, ny = b.y - a.y;
    const double len = std::sqrt(nx * nx + ny * ny);
    const double fx = qx + nx / len * d, fy = qy + ny / len * d;
    for (int o = 0; o < 9; ++o) {
      if (o == hit.nearest || o == m) continue;
      const Site& s = hit.sites[o];
      const double ox = s.x - a.x, oy = s.y - a.y;
      const double olen = std::sqrt(ox * ox + oy * oy);
      const double beyond = ((fx - 0.5 * (a.x + s.x)) * ox + (fy - 0.5 * (a.y + s.y)) * oy) / olen;
      if (beyond > slack) return false;
    }
    return true;
  }

  // Distance from q to the nearest kept road of q's block (1e300 if none),
  // that road's half width and the site across it.
  double roadDistance(const BlockHit& hit, double qx, double qy, double& hw, int& site) const {
    const Site& a = hit.sites[hit.nearest];
    double best = 1e300;
    for (int m = 0; m < 9; ++m) {
      if (m == hit.nearest || hit.edge_dist[m] >= best) continue;
      const Road road = roadOf(pairKey(a.id, hit.sites[m].id));
      if (!road.kept || !onEdge(hit, m, qx, qy, road.hw)) continue;
      best = hit.edge_dist[m];
      hw = road.hw;
      site = m;
    }
    return best;
  }

  // ---------------------------------------------------------------- trees --
  // Trees whose crowns may touch [x0, x1] x [y0, y1]; forest trees get
  // alpha_forest, the others alpha_other (a class with alpha 0 is skipped).
  // calibrate_share >= 0: closed forest everywhere with that share of
  // conifers (for the calibration of the mean colour).
  void collectTrees(double x0, double y0, double x1, double y1, double alpha_forest,
                    double alpha_other, double calibrate_share, std::vector<Tree>& out) const;
  void drawTrees(const std::vector<Tree>& trees, const PixelFrame& pf, std::vector<Rgb>& col,
                 const std::vector<float>& fcov, std::vector<float>& shadow) const;
  void collectBuildings(double x0, double y0, double x1, double y1, std::vector<Building>& b,
                        std::vector<Yard>& yards) const;

  void renderBlock(const GroundSquare& sq, int size_px, int r0, int r1, int c0, int c1,
                   cv::Mat& out) const;
  Rgb calibrateForest(double conifer_share) const;
};

// ---------------------------------------------------------------- construction

ProceduralWorld::Impl::Impl(const ProceduralWorldParams& params)
    : p(params), table(mix64(static_cast<u64>(params.seed) ^ 0x7AB1E5EEDULL)) {
  seed = mix64(static_cast<u64>(p.seed) ^ 0x6E61646972ULL);
  // One independent hash seed per layer (stream numbers are fixed: changing
  // one layer leaves the others as they were).
  const auto stream = [this](u64 k) { return mix64(seed + 0x9E3779B97F4A7C15ULL * k); };
  s_warp_x = stream(1);
  s_warp_y = stream(2);
  s_hills = stream(3);
  s_base = stream(4);
  s_river = stream(5);
  s_meander1 = stream(6);
  s_meander2 = stream(7);
  s_width = stream(8);
  s_valley = stream(9);
  s_bwarp_x = stream(12);
  s_bwarp_y = stream(13);
  s_block = stream(14);
  s_field = stream(15);
  s_region = stream(16);
  s_tint = stream(18);
  s_soil = stream(19);
  s_conifer = stream(20);
  s_trees = stream(22);
  s_bld = stream(24);
  s_settle = stream(25);
  s_roof = stream(26);

  const double flow_angle = 2.0 * kPi * uniform(seed, 100);
  flow_x = std::cos(flow_angle);
  flow_y = std::sin(flow_angle);
  const double az = p.sun_azimuth_deg * kPi / 180.0;
  const double el = p.sun_elevation_deg * kPi / 180.0;
  sun_x = std::sin(az) * std::cos(el);
  sun_y = std::cos(az) * std::cos(el);
  sun_z = std::sin(el);
  inv_tan_sun = std::cos(el) / std::sin(el);
  shadow_x = -std::sin(az) * inv_tan_sun;
  shadow_y = -std::cos(az) * inv_tan_sun;
  tilt_per_m = 0.2 * p.relief_m / p.size_m;

  // Forest threshold: the quantile of the mask that covers forest_fraction of
  // a fixed sample of the world.
  {
    std::vector<double> samples;
    const int n = 64;
    const double span = std::max(p.size_m, 8000.0);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double x = ((i + 0.5) / n - 0.5) * span;
        const double y = ((j + 0.5) / n - 0.5) * span;
        samples.push_back(forestMask(x, y));
      }
    }
    std::sort(samples.begin(), samples.end());
    const double q = std::clamp(1.0 - p.forest_fraction, 0.0, 1.0);
    if (p.forest_fraction <= 0.0) {
      forest_threshold = 1e9;
    } else {
      const std::size_t idx = std::min(
          samples.size() - 1, static_cast<std::size_t>(q * static_cast<double>(samples.size())));
      forest_threshold = samples[idx];
    }
  }
  {
    BlockFrame frame;
    const int n = 8192;
    for (int i = 0; i < n; ++i) {
      const FieldInfo fi = fieldInfoAt(mix64(seed + 0xF1E1DULL * (i + 1)), frame);
      const double cover = clamp01(fi.cover);
      field_soil += fi.bright * (1.0 - cover) * fi.soil_k;
      field_plant = field_plant + fi.plant * (fi.bright * cover);
      field_dry = field_dry + (fi.dry - fi.plant) * (fi.bright * cover);
    }
    field_soil /= n;
    field_plant = field_plant * (1.0 / n);
    field_dry = field_dry * (1.0 / n);
  }
  for (std::size_t m = 0; m < forest_mean.size(); ++m) {
    forest_mean[m] = calibrateForest(static_cast<double>(m) / (forest_mean.size() - 1));
  }
  forest_mean_broadleaf = forest_mean.front();
}

// ------------------------------------------------------------------ trees

void ProceduralWorld::Impl::collectTrees(double x0, double y0, double x1, double y1,
                                         double alpha_forest, double alpha_other,
                                         double calibrate_share, std::vector<Tree>& out) const {
  const bool force = calibrate_share >= 0.0;
  constexpr double kCell = 5.0;
  const i64 i0 = static_cast<i64>(std::floor(x0 / kCell)) - 1;
  const i64 i1 = static_cast<i64>(std::floor(x1 / kCell)) + 1;
  const i64 j0 = static_cast<i64>(std::floor(y0 / kCell)) - 1;
  const i64 j1 = static_cast<i64>(std::floor(y1 / kCell)) + 1;
  // Smooth fields for the decisions on a fixed, world-anchored grid, so every
  // block and level that draws a tree decides it identically.
  constexpr double kGrid = 8.0;
  const i64 gx0 = static_cast<i64>(std::floor(static_cast<double>(i0) * kCell / kGrid)) - 1;
  const i64 gx1 = static_cast<i64>(std::floor(static_cast<double>(i1 + 1) * kCell / kGrid)) + 2;
  const i64 gy0 = static_cast<i64>(std::floor(static_cast<double>(j0) * kCell / kGrid)) - 1;
  const i64 gy1 = static_cast<i64>(std::floor(static_cast<double>(j1 + 1) * kCell / kGrid)) + 2;
  const int gnx = force ? 0 : static_cast<int>(gx1 - gx0 + 1);
  const int gny = force ? 0 : static_cast<int>(gy1 - gy0 + 1);
  struct TreeNode {
    double mask, sd, hw, wx, wy, var, conifer;
  };
  std::vector<TreeNode> grid(static_cast<std::size_t>(gnx) * gny);
  for (int j = 0; j < gny; ++j) {
    for (int i = 0; i < gnx; ++i) {
      const double x = static_cast<double>(gx0 + i) * kGrid;
      const double y = static_cast<double>(gy0 + j) * kGrid;
      TerrainSample t;
      river(x, y, t);
      grid[static_cast<std::size_t>(j) * gnx + i] = {
          0.0, t.sd, t.hw, blockWarpX(x, y), blockWarpY(x, y), varNoise(x, y), coniferShare(x, y)};
    }
  }
  const auto at = [&](double x, double y) {
    const double gx = x / kGrid - static_cast<double>(gx0);
    const double gy = y / kGrid - static_cast<double>(gy0);
    const int i = std::clamp(static_cast<int>(std::floor(gx)), 0, gnx - 2);
    const int j = std::clamp(static_cast<int>(std::floor(gy)), 0, gny - 2);
    const double tx = gx - i, ty = gy - j;
    const TreeNode* a = &grid[static_cast<std::size_t>(j) * gnx + i];
    const TreeNode* c = a + gnx;
    const auto bl = [&](double TreeNode::*f) {
      return (1 - ty) * ((1 - tx) * a->*f + tx * a[1].*f) + ty * ((1 - tx) * c->*f + tx * c[1].*f);
    };
    return TreeNode{bl(&TreeNode::mask),   bl(&TreeNode::sd), bl(&TreeNode::hw),
                    bl(&TreeNode::wx),     bl(&TreeNode::wy), bl(&TreeNode::var),
                    bl(&TreeNode::conifer)};
  };

  BlockCell bcell;
  FieldCell fcell;
  BlockFrame frame;
  bool have_frame = false;
  for (i64 j = j1; j >= j0; --j) {  // north to south: a fixed, global order
    for (i64 i = i0; i <= i1; ++i) {
      const u64 h = hash2(s_trees, i, j);
      const double x = (static_cast<double>(i) + 0.5 + 0.8 * (bits(h, 0) - 0.5)) * kCell;
      const double y = (static_cast<double>(j) + 0.5 + 0.8 * (bits(h, 1) - 0.5)) * kCell;
      const double u = bits(h, 2);
      bool exists = false, interior = force, conifer = false;
      double size = 1.0, var = 0.0, alpha = alpha_forest;
      // Conifers stand in every cell; broadleaf crowns are larger and sparser.
      if (force) {
        conifer = uniform(h, 3) < calibrate_share;
        exists = u < (conifer ? 0.97 : 0.65);
      } else {
        const TreeNode t = at(x, y);
        var = t.var;
        const double mask = forestMask(x, y);
        const bool forest = mask > -0.01;
        if (forest ? alpha_forest <= 0.0 : alpha_other <= 0.0) continue;
        if (forest) {
          conifer = uniform(h, 3) < t.conifer;
          exists = u < (conifer ? 0.97 : 0.65);
          interior = mask > 0.3;  // the mask changes by < 0.01 per metre
        } else {
          alpha = alpha_other;
        }
        if (!forest && mask > -0.08 && u < 0.1 * (1.0 + mask * 12.0)) {
          exists = true;  // scattered trees along the forest's edge
        }
        const double bank = std::abs(t.sd) - t.hw;
        if (!exists && bank > 3.0 && bank < 11.0 &&
            u < 0.75 * smooth01(0.5 + 2.0 * table.noise(x / 150.0, y / 150.0))) {
          exists = true;  // riverside trees
          size = 0.9;
        }
        const double qx = x + t.wx, qy = y + t.wy;
        const BlockHit bh = blockAt(qx, qy, bcell);
        if (!exists) {  // hedgerows and a few trees in meadows
          const Site& a = bh.sites[bh.nearest];
          if (!have_frame || frame.id != a.id) {
            frame = blockFrame(a);
            have_frame = true;
          }
          const FieldHit fh = fieldAt(frame, qx, qy, fcell);
          if (fh.edge < 2.2 && fh.edge < bh.edge && u < 0.9 &&
              uniform(pairKey(fh.id, fh.neighbour), 7) < p.hedge_fraction &&
              table.noise(x / 40.0 + 0.5, y / 40.0) > -0.45) {
            exists = true;
            size = 0.9;
          } else if (u < 0.0015) {
            const Crop crop = fieldInfoAt(fh.id, frame).crop;
            if (crop == Crop::kMeadow || crop == Crop::kPasture) {
              exists = true;
              size = 1.3;
            }
          }
        }
        if (exists) {  // keep roads and water open
          double hw = 0;
          int site = -1;
          if (roadDistance(bh, qx, qy, hw, site) < hw + 1.5) exists = false;
          if (std::abs(t.sd) < t.hw + 1.5) exists = false;
        }
      }
      if (!exists) continue;
      Tree t;
      t.x = x;
      t.y = y;
      t.h = h;
      t.conifer = conifer;
      t.interior = interior;
      t.alpha = alpha;
      const double k = 0.8 + 0.4 * uniform(h, 4);
      const double hue = uniform(h, 5);
      t.colour = (conifer ? kConifer : kBroadleaf) * k;
      t.colour = hue < 0.5 ? mix(t.colour, Rgb{112, 116, 62}, 0.5 * (0.5 - hue))
                           : mix(t.colour, Rgb{58, 80, 70}, 0.4 * (hue - 0.5));
      if (!force) t.colour = t.colour * (1.0 + 0.25 * var + 0.18 * stand(x, y));
      t.r = size * (conifer ? 1.8 + 1.1 * uniform(h, 6) : 3.2 + 2.0 * uniform(h, 6));
      const double height = (conifer ? 14.0 : 10.0) + 8.0 * uniform(h, 7);
      // The crown, a ball of radius r at height - r, casts an ellipse; the
      // trunk a thin line up to it. Inside a forest only the top few metres
      // stand out of the canopy.
      t.crown_half = std::max(0.0, t.r / std::max(sun_z, 0.2) - t.r);
      t.crown_off = std::min(kMaxShadow - t.crown_half - t.r, (height - t.r) * inv_tan_sun);
      t.shadow_short = std::min(kMaxShadow, (1.0 + 2.0 * uniform(h, 8)) * inv_tan_sun);
      const double w = 2.0 * kPi * uniform(h, 9);
      t.wob_c = 0.11 * std::cos(w);
      t.wob_s = 0.11 * std::sin(w);
      out.push_back(t);
    }
  }
}

void ProceduralWorld::Impl::drawTrees(const std::vector<Tree>& trees, const PixelFrame& pf,
                                      std::vector<Rgb>& col, const std::vector<float>& fcov,
                                      std::vector<float>& shadow) const {
  const double px = pf.px;
  const int cols = pf.cols;
  const double sl = std::sqrt(shadow_x * shadow_x + shadow_y * shadow_y);
  const double sdx = sl > 0 ? shadow_x / sl : 0.0, sdy = sl > 0 ? shadow_y / sl : 0.0;
  const double leaf_w = detailWeight(0.9, px), clump_w = detailWeight(1.7, px);
  const double twig_w = detailWeight(0.4, px);
  // Shadows first (into the shadow buffer), then crowns in order.
  for (const Tree& t : trees) {
    const double far =
        t.interior ? t.shadow_short : std::max(t.shadow_short, t.crown_off + t.crown_half);
    const double ex = t.x + sdx * far, ey = t.y + sdy * far;
    int ca, cb, ra, rb;
    pf.colRange(std::min(t.x, ex) - t.r - px, std::max(t.x, ex) + t.r + px, ca, cb);
    pf.rowRange(std::min(t.y, ey) - t.r - px, std::max(t.y, ey) + t.r + px, ra, rb);
    const double crown_a = std::max(0.0, t.crown_off - t.crown_half);
    const double crown_b = t.crown_off + t.crown_half;
    for (int r = ra; r <= rb; ++r) {
      const double y = pf.y(r);
      for (int c = ca; c <= cb; ++c) {
        const double x = pf.x(c);
        const double dx = x - t.x, dy = y - t.y;
        if (dx * dx + dy * dy < t.r * t.r) continue;  // own crown
        const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
        const double along = dx * sdx + dy * sdy;
        const double perp = std::abs(-dx * sdy + dy * sdx);
        if (perp > t.r + px || along < -t.r - px) continue;
        const auto capsule = [&](double a0, double a1) {
          const double ca0 = std::clamp(along, a0, a1) - along;
          return std::sqrt(ca0 * ca0 + perp * perp);
        };
        double cov;
        if (t.interior || fcov[idx] > 0.5f) {
          cov = clamp01(0.5 + (t.r * 0.9 - capsule(0.0, t.shadow_short)) / px);
        } else {
          cov = std::max(clamp01(0.5 + (t.r * 0.95 - capsule(crown_a, crown_b)) / px),
                         bandCoverage(capsule(0.0, crown_a), 0.2, px) * 0.8);
        }
        cov *= 0.5 * t.alpha;
        if (cov > shadow[idx]) shadow[idx] = static_cast<float>(cov);
      }
    }
  }
  const bool lumpy = px < 0.7;
  for (const Tree& t : trees) {
    const double reach = t.r * (lumpy ? 1.15 : 1.0) + px;
    int ra, rb;
    pf.rowRange(t.y - reach, t.y + reach, ra, rb);
    for (int r = ra; r <= rb; ++r) {
      const double y = pf.y(r);
      const double dy = y - t.y;
      const double half = std::sqrt(std::max(0.0, reach * reach - dy * dy));
      int ca, cb;
      pf.colRange(t.x - half, t.x + half, ca, cb);
      for (int c = ca; c <= cb; ++c) {
        const double x = pf.x(c);
        const double dx = x - t.x;
        const double d = std::sqrt(dx * dx + dy * dy);
        double rr = t.r;
        if (lumpy && d > 0.5 * t.r) {  // a lumpy outline: 3rd and 5th harmonics of the angle
          const double cx = dx / d, cy = dy / d;
          const double c3 = cx * (4.0 * cx * cx - 3.0), s3 = cy * (3.0 - 4.0 * cy * cy);
          const double c5 = c3 * (2.0 * cx * cx - 1.0) - s3 * (2.0 * cx * cy);
          rr *= 1.0 + t.wob_c * c3 + t.wob_s * s3 + 0.8 * t.wob_s * c5 + 0.5 * t.wob_c * s3 * c3;
        }
        const double cov = clamp01(0.5 + (rr - d) / px) * t.alpha;
        if (cov <= 0.0) continue;
        double lam;
        if (t.conifer) {
          const double inv = d > 1e-6 ? 1.0 / d : 0.0;
          lam = 0.75 * (dx * inv * sun_x + dy * inv * sun_y) + 0.66 * sun_z;
        } else {
          const double ux = dx / t.r, uy = dy / t.r;
          const double nz = std::sqrt(std::max(0.0, 1.0 - ux * ux - uy * uy));
          // A flattened dome: softer than a ball.
          const double nn = std::sqrt(0.5 * (ux * ux + uy * uy) + nz * nz) + 1e-9;
          lam = (0.7 * (ux * sun_x + uy * sun_y) + nz * sun_z) / nn;
        }
        double bright = 0.62 + 0.5 * std::max(0.0, lam);
        if (clump_w > 0.0) {  // clumps of foliage, lit from the sun's side
          const double ox = t.wob_c * 300.0, oy = t.wob_s * 300.0;
          const double cx = x / 1.7 + ox, cy = y / 1.7 + oy;
          const double n0 = table.noise(cx, cy);
          const double gx = table.noise(cx + 0.25, cy) - n0, gy = table.noise(cx, cy + 0.25) - n0;
          bright *= 1.0 + clump_w * (0.1 * n0 - 1.6 * (gx * sun_x + gy * sun_y)) +
                    0.25 * leaf_w * table.noise(x / 0.9 + oy, y / 0.9 + ox);
          if (twig_w > 0.0) bright *= 1.0 + 0.3 * twig_w * table.noise(x / 0.4 + ox, y / 0.4);
        }
        const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
        col[idx] = mix(col[idx], t.colour * bright, cov);
      }
    }
  }
}

Rgb ProceduralWorld::Impl::calibrateForest(double conifer_share) const {
  // The mean colour of closed forest drawn tree by tree at 0.4 m/px: what a
  // coarse pixel over forest shows once the crowns are finer than it.
  PixelFrame pf;
  pf.size_px = 300;
  pf.px = 0.4;
  pf.east_min = 1000.0;
  pf.north_min = 1000.0;
  pf.rows = pf.cols = pf.size_px;
  const std::size_t n = static_cast<std::size_t>(pf.rows) * pf.cols;
  std::vector<Rgb> col(n, kForestFloor);
  std::vector<float> fcov(n, 1.0f), shadow(n, 0.0f);
  std::vector<Tree> trees;
  const double m = kMaxShadow + 6.0;
  collectTrees(pf.east_min - m, pf.north_min - m, pf.east_min + 120.0 + m, pf.north_min + 120.0 + m,
               1.0, 1.0, conifer_share, trees);
  drawTrees(trees, pf, col, fcov, shadow);
  Rgb sum;
  for (std::size_t i = 0; i < n; ++i) sum = sum + col[i] * (1.0 - shadow[i]);
  return sum * (1.0 / static_cast<double>(n));
}

// ------------------------------------------------------------------ buildings

namespace {

// Does the segment from (px, py) along (dx, dy) (t in [0, 1]) meet the box |u| <= hl, |v| <= hw?
bool segmentHitsBox(double pu, double pv, double du, double dv, double hl, double hw) {
  double t0 = 0.0, t1 = 1.0;
  const auto slab = [&](double p0, double d, double h) {
    if (std::abs(d) < 1e-12) return std::abs(p0) <= h;
    double ta = (-h - p0) / d, tb = (h - p0) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    return t0 <= t1;
  };
  return slab(pu, du, hl) && slab(pv, dv, hw);
}

constexpr std::array<Rgb, 7> kRoofs = {{{150, 78, 60},
                                        {164, 96, 72},
                                        {124, 88, 70},
                                        {76, 76, 80},
                                        {136, 138, 138},
                                        {110, 66, 54},
                                        {170, 166, 158}}};

}  // namespace

void ProceduralWorld::Impl::collectBuildings(double x0, double y0, double x1, double y1,
                                             std::vector<Building>& out,
                                             std::vector<Yard>& yards) const {
  constexpr double kCell = 150.0;
  const i64 i0 = static_cast<i64>(std::floor(x0 / kCell));
  const i64 i1 = static_cast<i64>(std::floor(x1 / kCell));
  const i64 j0 = static_cast<i64>(std::floor(y0 / kCell));
  const i64 j1 = static_cast<i64>(std::floor(y1 / kCell));
  const double per_cell = p.buildings_per_km2 * kCell * kCell / 1e6 / 2.5;
  BlockCell bcell;
  for (i64 j = j1; j >= j0; --j) {
    for (i64 i = i0; i <= i1; ++i) {
      const u64 h = hash2(s_bld, i, j);
      double x = (static_cast<double>(i) + 0.15 + 0.7 * uniform(h, 1)) * kCell;
      double y = (static_cast<double>(j) + 0.15 + 0.7 * uniform(h, 2)) * kCell;
      if (uniform(h, 0) >= per_cell * settlement(x, y)) continue;
      const double wx = blockWarpX(x, y), wy = blockWarpY(x, y);
      const BlockHit bh = blockAt(x + wx, y + wy, bcell);
      double rhw = 0;
      int site = -1;
      const double dr = roadDistance(bh, x + wx, y + wy, rhw, site);
      double ux, uy, nx, ny;
      const bool by_road = dr < 90.0 && site >= 0;
      double setback = 0.0;
      if (by_road) {
        const Site& a = bh.sites[bh.nearest];
        const Site& b = bh.sites[site];
        const double len = std::hypot(a.x - b.x, a.y - b.y);
        nx = (a.x - b.x) / len;
        ny = (a.y - b.y) / len;
        setback = rhw + 10.0 + 12.0 * uniform(h, 3);
        x += nx * (setback - dr);
        y += ny * (setback - dr);
        ux = -ny;
        uy = nx;
      } else if (uniform(h, 4) < 0.12) {
        const BlockFrame f = blockFrame(bh.sites[bh.nearest]);
        ux = f.c;
        uy = f.s;
        nx = -uy;
        ny = ux;
      } else {
        continue;
      }
      if (forestMask(x, y) > -0.08) continue;
      TerrainSample t;
      river(x, y, t);
      if (std::abs(t.sd) < t.hw + 30.0) continue;
      {
        BlockCell cell2;
        const double qx2 = x + blockWarpX(x, y), qy2 = y + blockWarpY(x, y);
        const BlockHit bh2 = blockAt(qx2, qy2, cell2);
        double hw2 = 0;
        int s2 = -1;
        const double d2 = roadDistance(bh2, qx2, qy2, hw2, s2);
        if (d2 < hw2 + 8.0 || (by_road && d2 > hw2 + 40.0)) continue;
      }
      // A farmstead: a house and up to three barns around a yard.
      const int count = 1 + static_cast<int>(uniform(h, 5) * 3.3);
      double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
      double along = 0.0;
      for (int k = 0; k < count; ++k) {
        const u64 hk = mix64(h + 77 * (k + 1));
        Building b;
        b.h = hk;
        double bu, bv;  // centre in the farmstead frame (u along the road, v away)
        bool rotated;
        if (k == 0) {
          b.hl = 5.0 + 2.5 * uniform(hk, 0);
          b.hw = 4.0 + 1.5 * uniform(hk, 1);
          b.height = 7.0 + 2.0 * uniform(hk, 2);
          b.gable = true;
          b.roof = kRoofs[static_cast<std::size_t>(uniform(hk, 3) * 4.0)];
          rotated = uniform(hk, 4) < 0.3;
          bu = 0.0;
          bv = 0.0;
          along = rotated ? b.hw : b.hl;
        } else {
          b.hl = 8.0 + 10.0 * uniform(hk, 0);
          b.hw = 5.0 + 3.5 * uniform(hk, 1);
          b.height = 6.0 + 3.0 * uniform(hk, 2);
          b.gable = uniform(hk, 5) < 0.6;
          b.roof = kRoofs[3 + static_cast<std::size_t>(uniform(hk, 3) * 4.0)];
          rotated = uniform(hk, 4) < 0.45;
          const double half_u = rotated ? b.hw : b.hl;
          const double half_v = rotated ? b.hl : b.hw;
          if (k % 2 == 1) {  // beside, along the road
            bu = along + 5.0 + 4.0 * uniform(hk, 6) + half_u;
            bv = (half_v - 5.0) + 3.0 * uniform(hk, 7);
            along = bu + half_u;
          } else {  // behind
            bu = (uniform(hk, 6) - 0.3) * 12.0;
            bv = 6.0 + 8.0 + 4.0 * uniform(hk, 7) + half_v;
          }
        }
        const double half_u = rotated ? b.hw : b.hl;
        const double half_v = rotated ? b.hl : b.hw;
        umin = std::min(umin, bu - half_u);
        umax = std::max(umax, bu + half_u);
        vmin = std::min(vmin, bv - half_v);
        vmax = std::max(vmax, bv + half_v);
        b.x = x + ux * bu + nx * bv;
        b.y = y + uy * bu + ny * bv;
        b.ux = rotated ? nx : ux;
        b.uy = rotated ? ny : uy;
        out.push_back(b);
      }
      Yard yard;
      const double cu = 0.5 * (umin + umax), cv = 0.5 * (vmin + vmax);
      yard.x = x + ux * cu + nx * cv;
      yard.y = y + uy * cu + ny * cv;
      yard.ux = ux;
      yard.uy = uy;
      yard.hl = 0.5 * (umax - umin) + 4.0 + 3.0 * uniform(h, 8);
      yard.hw = 0.5 * (vmax - vmin) + 4.0 + 3.0 * uniform(h, 9);
      yard.colour = mix(Rgb{146, 140, 126}, Rgb{120, 116, 104}, uniform(h, 10));
      yard.h = h;
      yards.push_back(yard);
      if (by_road) {  // a gravel driveway from the road to the yard
        Yard drive;
        const double v0 = -(setback - rhw), v1 = cv - yard.hw + 1.0;
        const double du = (uniform(h, 11) - 0.5) * 10.0;
        drive.x = x + ux * du + nx * 0.5 * (v0 + v1);
        drive.y = y + uy * du + ny * 0.5 * (v0 + v1);
        drive.ux = nx;
        drive.uy = ny;
        drive.hl = std::max(0.0, 0.5 * (v1 - v0));
        drive.hw = 1.8;
        drive.colour = kDirt;
        drive.h = mix64(h + 5);
        if (drive.hl > 0.0) yards.push_back(drive);
      }
    }
  }
}

// ------------------------------------------------------------------ rendering

void ProceduralWorld::Impl::renderBlock(const GroundSquare& sq, int size_px, int r0, int r1, int c0,
                                        int c1, cv::Mat& out) const {
  PixelFrame pf;
  pf.east_min = sq.east_min_m;
  pf.north_min = sq.north_min_m;
  pf.px = sq.size_m / size_px;
  pf.size_px = size_px;
  pf.r0 = r0;
  pf.c0 = c0;
  pf.rows = r1 - r0;
  pf.cols = c1 - c0;
  const double px = pf.px;
  const int rows = pf.rows, cols = pf.cols;
  const double xmin = pf.x(0), xmax = pf.x(cols - 1);
  const double ymax = pf.y(0), ymin = pf.y(rows - 1);

  // Smooth fields on a world-anchored grid of spacing s (a power of two, 4 to
  // 8 pixels), evaluated at the grid's footprint.
  const double s = std::max(2.0, std::exp2(std::floor(std::log2(8.0 * px))));
  const i64 kx0 = static_cast<i64>(std::floor(xmin / s)) - 1;
  const i64 kx1 = static_cast<i64>(std::floor(xmax / s)) + 2;
  const i64 ky0 = static_cast<i64>(std::floor(ymin / s)) - 1;
  const i64 ky1 = static_cast<i64>(std::floor(ymax / s)) + 2;
  const int nx = static_cast<int>(kx1 - kx0 + 1), ny = static_cast<int>(ky1 - ky0 + 1);
  constexpr int kCh = 11;  // channels of Pix, in order
  // Per-thread scratch buffers, reused from block to block (every element
  // used is written first, so nothing carries over).
  thread_local Scratch scratch;
  std::vector<double>& nodes = scratch.nodes;
  std::vector<double>& up = scratch.up;
  nodes.resize(static_cast<std::size_t>(nx) * ny * kCh);
  up.resize(static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = static_cast<double>(kx0 + i) * s;
      const double y = static_cast<double>(ky0 + j) * s;
      const TerrainSample t = terrain(x, y, s);
      const std::size_t k = static_cast<std::size_t>(j) * nx + i;
      up[k] = t.up;
      double* n = &nodes[k * kCh];
      n[1] = t.sd;
      n[2] = t.hw;
      n[3] = forestMask(x, y);
      n[4] = blockWarpX(x, y);
      n[5] = blockWarpY(x, y);
      n[6] = 0.0;  // per pixel, below
      n[7] = tintNoise(x, y);
      n[8] = soilNoise(x, y);
      n[9] = coniferShare(x, y);
      n[10] = 0.0;
    }
  }
  for (int j = 0; j < ny; ++j) {  // hillshade, and the forest mask's gradient
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * nx + i;
      const int ia = std::max(i - 1, 0), ib = std::min(i + 1, nx - 1);
      const int ja = std::max(j - 1, 0), jb = std::min(j + 1, ny - 1);
      const auto idx = [&](int a, int b) { return static_cast<std::size_t>(b) * nx + a; };
      const double gx = (up[idx(ib, j)] - up[idx(ia, j)]) / ((ib - ia) * s);
      const double gy = (up[idx(i, jb)] - up[idx(i, ja)]) / ((jb - ja) * s);
      const double lam = (-gx * sun_x - gy * sun_y + sun_z) / std::sqrt(gx * gx + gy * gy + 1.0);
      nodes[k * kCh] = std::clamp(1.0 + 0.9 * (lam / sun_z - 1.0), 0.35, 1.6);
      const double mx =
          (nodes[idx(ib, j) * kCh + 3] - nodes[idx(ia, j) * kCh + 3]) / ((ib - ia) * s);
      const double my =
          (nodes[idx(i, jb) * kCh + 3] - nodes[idx(i, ja) * kCh + 3]) / ((jb - ja) * s);
      nodes[k * kCh + 10] = std::max(std::sqrt(mx * mx + my * my), 1e-6);
    }
  }
  // Per pixel row, the grid interpolated to the row's y; per pixel, along x.
  std::vector<double>& line = scratch.line;
  line.resize(static_cast<std::size_t>(nx) * kCh);
  const auto prepareRow = [&](double y) {
    const double gy = y / s - static_cast<double>(ky0);
    const int j = std::clamp(static_cast<int>(std::floor(gy)), 0, ny - 2);
    const double ty = gy - j;
    const double* a = &nodes[static_cast<std::size_t>(j) * nx * kCh];
    const double* b = a + static_cast<std::size_t>(nx) * kCh;
    for (std::size_t k = 0; k < line.size(); ++k) line[k] = a[k] + ty * (b[k] - a[k]);
  };
  const auto interp = [&](double x) {
    const double gx = x / s - static_cast<double>(kx0);
    const int i = std::clamp(static_cast<int>(std::floor(gx)), 0, nx - 2);
    const double tx = gx - i;
    const double* a = &line[static_cast<std::size_t>(i) * kCh];
    std::array<double, kCh> v;
    for (int k = 0; k < kCh; ++k) v[k] = a[k] + tx * (a[k + kCh] - a[k]);
    Pix q;
    q.shade = v[0];
    q.sd = v[1];
    q.hw = v[2];
    q.mask = v[3];
    q.wx = v[4];
    q.wy = v[5];
    q.var = v[6];
    q.tint = v[7];
    q.soil = v[8];
    q.conifer = v[9];
    q.mask_grad = v[10];
    return q;
  };

  const std::size_t n = static_cast<std::size_t>(rows) * cols;
  std::vector<Rgb>& col = scratch.col;
  std::vector<float>& fcov = scratch.fcov;
  std::vector<float>& shadow = scratch.shadow;
  std::vector<float>& shade_px = scratch.shade;
  std::vector<float>& detail_px = scratch.detail;
  col.resize(n);
  fcov.assign(n, 0.0f);
  shadow.assign(n, 0.0f);
  shade_px.resize(n);
  detail_px.resize(n);
  // Trees are drawn one by one while their crowns span a few pixels; beyond,
  // forests take their calibrated mean colour with a canopy-scale texture,
  // and hedgerows and riverside trees their mean share of the pixel.
  const double alpha_forest = smooth01((2.0 - px) / 1.0);
  const double alpha_trees = smooth01((2.5 - px) / 1.25);
  const double coarse_forest = 1.0 - alpha_forest;
  const double coarse = 1.0 - alpha_trees;

  BlockCell bcell;
  FieldCell fcell, fcell_nb;
  BlockFrame frame, frame_nb;
  bool have_frame = false, have_frame_nb = false;
  std::array<FieldInfo, 8> cache;
  std::array<bool, 8> cache_ok{};
  const auto info = [&](u64 id, const BlockFrame& f) -> const FieldInfo& {
    const std::size_t k = static_cast<std::size_t>(mix64(id) & 7u);
    if (!cache_ok[k] || cache[k].id != id) {
      cache[k] = fieldInfo(id, f, px);
      cache_ok[k] = true;
    }
    return cache[k];
  };
  // Beyond these distances from a field's or block's edge nothing depends on
  // the exact distance (headlands, margins, hedges, roads, edge blending), so
  // a lookup is reused while its edge is provably that far (the warp stretches
  // distances by less than 1.5).
  const Octaves mid_octaves(24.0, 3, 0.75, px, 1.0 / 1.2, 0.0);
  const Octaves fine_octaves(3.0, 4, 0.85, px, 1.0 / 1.3, 101.0);
  const Octaves stand_octaves(350.0, 2, 0.6, px, 1.0, 333.0);
  const Octaves ripple_octaves(2.4, 3, 0.7, px, 1.0, 777.0);
  const Octaves var_octaves(96.0, 3, 0.6, px, 0.8, 555.0);
  const Octaves canopy_octaves(9.0, 2, 0.7, px, 1.0, 999.0);
  const double grain_scale = 1.0 / std::max(5.0, 1.3 * px);
  const double grain_amp = 0.3 * std::min(1.0, 6.0 / px);
  const double far_field = std::max(17.0, 3.2 + 1.5 * px);
  const double far_block = std::max(far_field, 5.0 + 1.5 * px);

  for (int r = 0; r < rows; ++r) {
    const double y = pf.y(r);
    prepareRow(y);
    bool have_hit = false;
    double ref_x = 0.0;
    BlockHit bh;
    FieldHit fh;
    for (int c = 0; c < cols; ++c) {
      const double x = pf.x(c);
      const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
      Pix f = interp(x);
      f.var = var_octaves(table, x, y);
      const double mid = mid_octaves(table, x, y);
      const double fine = fine_octaves(table, x, y);
      const double detail = 0.6 * mid + 0.8 * fine;
      detail_px[idx] = static_cast<float>(detail);
      shade_px[idx] = static_cast<float>(f.shade);
      const double qx = x + f.wx, qy = y + f.wy;
      const double moved = 1.5 * (x - ref_x);
      const bool reuse = have_hit && fh.edge - moved > far_field && bh.edge - moved > far_block;
      if (!reuse) {
        bh = blockAt(qx, qy, bcell);
        const Site& site = bh.sites[bh.nearest];
        if (!have_frame || frame.id != site.id) {
          frame = blockFrame(site);
          have_frame = true;
        }
        if (smoothstep(0.25, 0.8, px / frame.lv) < 1.0) {
          fh = fieldAt(frame, qx, qy, fcell);
          ref_x = x;
          have_hit = true;
        } else {
          fh = FieldHit{};
          have_hit = false;
        }
      }
      const double fe = reuse ? far_field : fh.edge;
      const double be = reuse ? far_block : bh.edge;
      const double e = std::min(fe, be);
      // Once pixels span several fields, their colours average out.
      const double to_mean = smoothstep(0.25, 0.8, px / frame.lv);
      Rgb colour = meanFieldColour(f) * (1.0 + 0.08 * mid);
      if (to_mean < 1.0) {
        const FieldInfo& fi = info(fh.id, frame);
        Rgb field = fieldColour(fi, qx, qy, e, px, f, mid, fine);
        if (e < 0.5 * px && px >= 4.0) {
          // Coarse: the pixel's share beyond the edge gets the fields' mean.
          field = mix(field, colour, clamp01(0.5 - e / px));
        } else if (e < 0.5 * px) {  // the neighbouring field's share of the pixel
          Rgb other;
          if (fe <= be) {
            other = fieldColour(info(fh.neighbour, frame), qx, qy, e, px, f, mid, fine);
          } else {
            const Site& nb = bh.sites[bh.edge_site];
            if (!have_frame_nb || frame_nb.id != nb.id) {
              frame_nb = blockFrame(nb);
              have_frame_nb = true;
            }
            const FieldHit nh = fieldAt(frame_nb, qx, qy, fcell_nb);
            other = fieldColour(info(nh.id, frame_nb), qx, qy, e, px, f, mid, fine);
          }
          field = mix(field, other, clamp01(0.5 - e / px));
        }
        // Hedgerows seen from afar: their trees' mean share of the pixel.
        if (coarse > 0.0 && fe < 2.2 + px && fe <= be &&
            uniform(pairKey(fh.id, fh.neighbour), 7) < p.hedge_fraction) {
          const double hc = bandCoverage(fe, 2.2, px) * 0.7 * coarse;
          field = mix(field, forest_mean_broadleaf, hc);
        }
        // Farm tracks along a few field edges: bare ruts and a grassy middle.
        if (fe < 2.0 + px && fe <= be && uniform(pairKey(fh.id, fh.neighbour), 8) < 0.07) {
          const double track = bandCoverage(fe, 1.6, px);
          if (track > 0.0) {
            const double grass = bandCoverage(fe, 0.35, px);
            const Rgb dirt = kDirt * (1.0 + 0.1 * detail);
            field =
                mix(field, (dirt * (track - grass) + kTrackGrass * grass) * (1.0 / track), track);
          }
        }
        colour = mix(field, colour, to_mean);
      }
      // Forest.
      // Seen coarsely, the canopy reaches a crown's radius beyond the floor.
      // The grid's mask is exact enough except near an edge (its error grows
      // as s^2): evaluate it there.
      const double reach_mask = coarse_forest * (0.01 + 4.0 * f.mask_grad);
      const double mask = std::abs(f.mask + reach_mask) <
                                  3e-4 * s * s + 0.6 * f.mask_grad * std::max(px, 0.5) + 0.01
                              ? forestMask(x, y)
                              : f.mask;
      const double fc = clamp01(0.5 + (mask + reach_mask) / (f.mask_grad * std::max(px, 0.5)));
      fcov[idx] = static_cast<float>(fc);
      if (fc > 0.0) {
        Rgb mean = forestMean(f.conifer) * (1.0 + 0.25 * f.var + 0.18 * stand_octaves(table, x, y));
        if (coarse_forest > 0.0) {
          // Crowns too small to draw still make a grain that averages out
          // slowly (random, so sampling it near the pixel scale cannot alias
          // into patterns).
          const double grain = table.noise(x * grain_scale + 7.7, y * grain_scale + 3.3);
          mean = mean *
                 (1.0 + coarse_forest * (0.2 * canopy_octaves(table, x, y) + grain_amp * grain));
        }
        const Rgb floor = kForestFloor * (1.0 + 0.25 * detail);
        colour = mix(colour, mix(floor, mean, coarse_forest), fc);
      }
      // River, its banks and the grass and trees along them.
      const double ad = std::abs(f.sd);
      if (ad < f.hw + 14.0 + px) {
        const double reach = 5.0 + 3.0 * f.var;
        const double grass =
            bandCoverage(ad - (f.hw + 2.0 + 0.5 * reach), 0.5 * reach, px) * (1.0 - fc);
        colour = mix(colour, kRiverGrass * (1.0 + 0.1 * detail), grass);
        if (coarse > 0.0) {
          colour = mix(colour, forest_mean_broadleaf,
                       bandCoverage(ad - (f.hw + 7.0), 4.0, px) * 0.3 * coarse);
        }
        const double mud = bandCoverage(ad - (f.hw + 1.0), 1.2, px);
        colour = mix(colour, kMud * (1.0 + 0.1 * detail), mud);
        const double water = bandCoverage(ad, f.hw, px);
        if (water > 0.0) {
          // Ripples across the current and a sheen varying along it.
          const double ripple = ripple_octaves(table, x, y);
          const Rgb w = mix(kWaterDeep, kWaterShallow, smoothstep(f.hw - 4.0, f.hw, ad)) *
                        (1.0 + 0.08 * mid + 0.16 * ripple + 0.03 * f.var);
          colour = mix(colour, w, water);
        }
      }
      // Roads.
      if (!reuse) {
        Rgb road;
        const double rc = roadAt(bh, qx, qy, px, road, detail);
        if (rc > 0.0) colour = mix(colour, road, rc);
      }
      col[idx] = colour;
    }
  }

  // Buildings' yards, trees, shadows, roofs.
  const double alpha_bld = p.buildings_per_km2 > 0.0 ? smooth01((8.0 - px) / 4.0) : 0.0;
  std::vector<Building> buildings;
  std::vector<Yard> yards;
  const auto sub_k = [&]() {
    return px < 0.5 ? 2 : std::min(6, static_cast<int>(std::ceil(px / 0.5)));
  };
  if (alpha_bld > 0.0) {
    const double m = 100.0;
    collectBuildings(xmin - m, ymin - m, xmax + m, ymax + m, buildings, yards);
    const int k = sub_k();
    for (const Yard& yd : yards) {
      const double ext = std::abs(yd.ux) * yd.hl + std::abs(yd.uy) * yd.hw + px;
      const double eyt = std::abs(yd.uy) * yd.hl + std::abs(yd.ux) * yd.hw + px;
      int ca, cb, ra, rb;
      pf.colRange(yd.x - ext, yd.x + ext, ca, cb);
      pf.rowRange(yd.y - eyt, yd.y + eyt, ra, rb);
      for (int r = ra; r <= rb; ++r) {
        for (int c = ca; c <= cb; ++c) {
          int inside = 0;
          for (int sj = 0; sj < k; ++sj) {
            for (int si = 0; si < k; ++si) {
              const double x = pf.x(c) + ((si + 0.5) / k - 0.5) * px - yd.x;
              const double y = pf.y(r) + ((sj + 0.5) / k - 0.5) * px - yd.y;
              const double u = x * yd.ux + y * yd.uy, v = -x * yd.uy + y * yd.ux;
              if (std::abs(u) <= yd.hl && std::abs(v) <= yd.hw) ++inside;
            }
          }
          if (inside == 0) continue;
          const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
          col[idx] = mix(col[idx], yd.colour * (1.0 + 0.1 * detail_px[idx]),
                         alpha_bld * inside / static_cast<double>(k * k));
        }
      }
    }
  }
  if (alpha_trees > 0.0 || alpha_forest > 0.0) {
    std::vector<Tree> trees;
    const double m = kMaxShadow + 6.0;
    collectTrees(xmin - m, ymin - m, xmax + m, ymax + m, alpha_forest, alpha_trees, -1.0, trees);
    drawTrees(trees, pf, col, fcov, shadow);
  }
  if (alpha_bld > 0.0) {
    const int k = sub_k();
    const double cos_el = std::sqrt(sun_x * sun_x + sun_y * sun_y);
    const double sdx = cos_el > 1e-9 ? sun_x / cos_el : 0.0,
                 sdy = cos_el > 1e-9 ? sun_y / cos_el : 0.0;
    for (const Building& b : buildings) {  // shadows
      const double len = b.height * inv_tan_sun;
      const double ex = std::abs(b.ux) * b.hl + std::abs(b.uy) * b.hw + px;
      const double ey = std::abs(b.uy) * b.hl + std::abs(b.ux) * b.hw + px;
      const double sx = -sdx * len, sy = -sdy * len;
      int ca, cb, ra, rb;
      pf.colRange(b.x + std::min(0.0, sx) - ex, b.x + std::max(0.0, sx) + ex, ca, cb);
      pf.rowRange(b.y + std::min(0.0, sy) - ey, b.y + std::max(0.0, sy) + ey, ra, rb);
      const double du = (sdx * b.ux + sdy * b.uy) * len, dv = (-sdx * b.uy + sdy * b.ux) * len;
      for (int r = ra; r <= rb; ++r) {
        for (int c = ca; c <= cb; ++c) {
          int inside = 0;
          for (int sj = 0; sj < k; ++sj) {
            for (int si = 0; si < k; ++si) {
              const double x = pf.x(c) + ((si + 0.5) / k - 0.5) * px - b.x;
              const double y = pf.y(r) + ((sj + 0.5) / k - 0.5) * px - b.y;
              const double u = x * b.ux + y * b.uy, v = -x * b.uy + y * b.ux;
              if (segmentHitsBox(u, v, du, dv, b.hl, b.hw)) ++inside;
            }
          }
          if (inside == 0) continue;
          const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
          const float cov = static_cast<float>(0.6 * alpha_bld * inside / (k * k));
          if (cov > shadow[idx]) shadow[idx] = cov;
        }
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) col[i] = col[i] * (1.0 - shadow[i]);
  if (alpha_bld > 0.0) {
    const int k = sub_k();
    const double tile_w = detailWeight(2.5, px);
    for (const Building& b : buildings) {  // roofs
      const double ex = std::abs(b.ux) * b.hl + std::abs(b.uy) * b.hw + px;
      const double ey = std::abs(b.uy) * b.hl + std::abs(b.ux) * b.hw + px;
      int ca, cb, ra, rb;
      pf.colRange(b.x - ex, b.x + ex, ca, cb);
      pf.rowRange(b.y - ey, b.y + ey, ra, rb);
      // Gable roof halves face +v and -v, pitched 35 deg.
      const double vx = -b.uy, vy = b.ux;
      const double sp = std::sin(0.61), cp = std::cos(0.61);
      const double lam_pos = (sp * (vx * sun_x + vy * sun_y) + cp * sun_z);
      const double lam_neg = (-sp * (vx * sun_x + vy * sun_y) + cp * sun_z);
      const double k_pos = 0.5 + 0.6 * std::max(0.0, lam_pos) / sun_z * 0.85;
      const double k_neg = 0.5 + 0.6 * std::max(0.0, lam_neg) / sun_z * 0.85;
      const Rgb roof = b.roof * (0.92 + 0.16 * uniform(b.h, 20));
      for (int r = ra; r <= rb; ++r) {
        for (int c = ca; c <= cb; ++c) {
          Rgb sum;
          int inside = 0;
          for (int sj = 0; sj < k; ++sj) {
            for (int si = 0; si < k; ++si) {
              const double wxp = pf.x(c) + ((si + 0.5) / k - 0.5) * px;
              const double wyp = pf.y(r) + ((sj + 0.5) / k - 0.5) * px;
              const double x = wxp - b.x, y = wyp - b.y;
              const double u = x * b.ux + y * b.uy, v = -x * b.uy + y * b.ux;
              if (std::abs(u) > b.hl || std::abs(v) > b.hw) continue;
              ++inside;
              double kk;
              if (b.gable) {
                kk = v >= 0.0 ? k_pos : k_neg;
                if (std::abs(v) < 0.25) kk *= 0.85;
              } else {
                kk = 0.95;
                if (b.hl - std::abs(u) < 0.4 || b.hw - std::abs(v) < 0.4) kk = 1.08;
              }
              if (b.hl - std::abs(u) < 0.3 || b.hw - std::abs(v) < 0.3) kk *= 0.8;
              if (tile_w > 0.0)
                kk *= 1.0 + 0.07 * tile_w * gradNoise(wxp / 2.5, wyp / 2.5, s_roof + b.h);
              sum = sum + roof * kk;
            }
          }
          if (inside == 0) continue;
          const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
          const double cov = alpha_bld * inside / static_cast<double>(k * k);
          col[idx] = mix(col[idx], sum * (1.0 / inside), cov);
        }
      }
    }
  }

  for (int r = 0; r < rows; ++r) {
    auto* row = out.ptr<cv::Vec3b>(r0 + r);
    for (int c = 0; c < cols; ++c) {
      const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
      Rgb v = col[idx] * shade_px[idx];
      const double lum = 0.3 * v.r + 0.59 * v.g + 0.11 * v.b;
      v = Rgb{lum, lum, lum} + (v - Rgb{lum, lum, lum}) * 0.88;  // the haze of distance
      row[c0 + c] = cv::Vec3b(cv::saturate_cast<uchar>(v.r), cv::saturate_cast<uchar>(v.g),
                              cv::saturate_cast<uchar>(v.b));
    }
  }
}

// ==================================================================== public

ProceduralWorld::ProceduralWorld(const ProceduralWorldParams& params) {
  ProceduralWorldParams checked = params;
  core::validateParams([&checked](core::ParamVisitor& v) { checked.visit(v); }, "procedural world");
  impl_ = std::make_unique<const Impl>(checked);
}

ProceduralWorld::~ProceduralWorld() = default;

double ProceduralWorld::groundUp_m(double north_m, double east_m) const {
  const double half = 0.5 * impl_->p.size_m;
  const double n = std::clamp(north_m, -half, half);
  const double e = std::clamp(east_m, -half, half);
  return impl_->terrain(e, n, 0.0).up;
}

void ProceduralWorld::imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const {
  if (size_px <= 0 || !(square.size_m > 0.0) || !std::isfinite(square.size_m) ||
      !std::isfinite(square.north_min_m) || !std::isfinite(square.east_min_m)) {
    throw std::invalid_argument("ProceduralWorld::imagery: needs size_px > 0 and a finite square");
  }
  rgb.create(size_px, size_px, CV_8UC3);
  const int nb = (size_px + kBlockPx - 1) / kBlockPx;
  const Impl& impl = *impl_;
  cv::parallel_for_(cv::Range(0, nb * nb), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      const int br = b / nb, bc = b % nb;
      const int r0 = br * kBlockPx, c0 = bc * kBlockPx;
      impl.renderBlock(square, size_px, r0, std::min(size_px, r0 + kBlockPx), c0,
                       std::min(size_px, c0 + kBlockPx), rgb);
    }
  });
}

double ProceduralWorld::imageryResolution_m() const { return impl_->p.imagery_resolution_m; }

double ProceduralWorld::elevationResolution_m() const { return 4.0; }

WorldExtent ProceduralWorld::extent() const {
  const double half = 0.5 * impl_->p.size_m;
  return {-half, half, -half, half};
}

const ProceduralWorldParams& ProceduralWorld::params() const { return impl_->p; }

}  // namespace nadir::terrain
