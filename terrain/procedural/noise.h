#pragma once
// Hashing, scalar maths, footprint filters and noise shared by the parts of
// the procedural world (terrain/procedural/). Internal to terrain/.
//
// Randomness is integer hashing of (layer seed, cell) (splitmix64's finaliser)
// feeding gradient noise for the terrain and masks, and a 256 x 256 table of
// hashed values (built once from the seed) for the texture evaluated at every
// pixel.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace nadir::terrain::procedural {

using u64 = std::uint64_t;
using i64 = std::int64_t;

inline constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------- hashing --

inline u64 mix64(u64 z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

inline u64 hash2(u64 seed, i64 i, i64 j) {
  return mix64(seed + static_cast<u64>(i) * 0x9E3779B97F4A7C15ULL +
               static_cast<u64>(j) * 0xC2B2AE3D27D4EB4FULL);
}

// The k-th uniform number in [0, 1) drawn from hash h.
inline double uniform(u64 h, u64 k) {
  return static_cast<double>(mix64(h + (k + 1) * 0xD6E8FEB86659FD93ULL) >> 11) * 0x1.0p-53;
}

// Three independent 21-bit uniform numbers in [0, 1) from one hash (k = 0, 1, 2).
inline double bits(u64 h, int k) {
  return static_cast<double>((h >> (21 * k)) & 0x1FFFFFu) * 0x1.0p-21;
}

inline u64 pairKey(u64 a, u64 b) { return a < b ? mix64(a ^ mix64(b)) : mix64(b ^ mix64(a)); }

// ------------------------------------------------------------------ maths --

inline double clamp01(double v) { return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v); }
inline double smooth01(double t) {
  t = clamp01(t);
  return t * t * (3.0 - 2.0 * t);
}
inline double smoothstep(double e0, double e1, double x) { return smooth01((x - e0) / (e1 - e0)); }
inline double lerp(double a, double b, double t) { return a + (b - a) * t; }

// Fraction of the pixel footprint [d - px/2, d + px/2] inside [-hw, hw].
inline double bandCoverage(double d, double hw, double px) {
  const double lo = std::max(d - 0.5 * px, -hw);
  const double hi = std::min(d + 0.5 * px, hw);
  return hi > lo ? (hi - lo) / px : 0.0;
}

// Coverage of bands of half width hw centred on offset + k * period, averaged
// over the footprint; tends to the mean 2 hw / period as the footprint grows.
inline double periodicBand(double x, double period, double offset, double hw, double px) {
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
inline double detailWeight(double lambda, double fp) {
  if (fp <= 0.0) return 1.0;
  return smooth01((lambda / fp - 2.0) * 0.5);
}

// Amplitude of a sine wave of wavelength lambda averaged over a pixel of size
// px (a sinc), faded out before it aliases.
inline double sineAmplitude(double lambda, double px) {
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
inline constexpr std::array<Grad, 16> kGrad = {{{1.0, 0.0},
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

inline double quintic(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// 2D gradient (Perlin) noise in about [-1, 1], zero mean, unit lattice.
inline double gradNoise(double x, double y, u64 seed) {
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
inline NoiseD gradNoiseD(double x, double y, u64 seed) {
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
inline double fbm(double x, double y, u64 seed, double lambda, int octaves, double gain,
                  double fp) {
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

inline i64 floorToInt(double v) {
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

}  // namespace nadir::terrain::procedural
