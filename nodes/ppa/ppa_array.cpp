#include "nodes/ppa/ppa_array.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "core/hash.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace nadir::ppa {

namespace {

constexpr int kPes = kWidth * kHeight;
constexpr std::uint64_t kOnes = ~std::uint64_t{0};

inline float saturate(float v) { return std::min(std::max(v, kAnalogMin), kAnalogMax); }

// ---- lanes of floats: SSE2 (4 lanes) on x86-64, one lane elsewhere. The analog
// kernels are written on these so saturation is minps/maxps whatever the
// auto-vectoriser decides: std::min/max on floats vectorises only to
// compare-and-blend (NaN and signed-zero rules), 3-6x slower.
#if defined(__SSE2__)
constexpr int kLanes = 4;
struct F4 {
  __m128 v;
};
inline F4 load4(const float* p) { return {_mm_loadu_ps(p)}; }
inline void store4(float* p, F4 a) { _mm_storeu_ps(p, a.v); }
inline F4 zero4() { return {_mm_setzero_ps()}; }
inline F4 operator+(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
inline F4 operator-(F4 a) { return {_mm_xor_ps(a.v, _mm_set1_ps(-0.0f))}; }
inline F4 saturate(F4 a) {
  return {_mm_min_ps(_mm_max_ps(a.v, _mm_set1_ps(kAnalogMin)), _mm_set1_ps(kAnalogMax))};
}
inline F4 blend(__m128 m, F4 a, F4 b) {
  return {_mm_or_ps(_mm_and_ps(m, a.v), _mm_andnot_ps(m, b.v))};
}
// Four FLAG bits as lane masks.
struct NibbleMasks {
  alignas(16) std::uint32_t m[16][4];
  NibbleMasks() {
    for (int n = 0; n < 16; ++n) {
      for (int i = 0; i < 4; ++i) m[n][i] = ((n >> i) & 1) ? 0xffffffffu : 0u;
    }
  }
};
const NibbleMasks kNibbleMasks;
// bits (low 4) ? a : b per lane.
inline F4 select(std::uint64_t bits, F4 a, F4 b) {
  return blend(_mm_load_ps(reinterpret_cast<const float*>(kNibbleMasks.m[bits & 15])), a, b);
}
// t > 0 ? a : b per lane.
inline F4 selectPositive(F4 t, F4 a, F4 b) {
  return blend(_mm_cmpgt_ps(t.v, _mm_setzero_ps()), a, b);
}
#else
constexpr int kLanes = 1;
struct F4 {
  float v;
};
inline F4 load4(const float* p) { return {*p}; }
inline void store4(float* p, F4 a) { *p = a.v; }
inline F4 zero4() { return {0.0f}; }
inline F4 operator+(F4 a, F4 b) { return {a.v + b.v}; }
inline F4 operator-(F4 a) { return {-a.v}; }
inline F4 saturate(F4 a) { return {saturate(a.v)}; }
inline F4 select(std::uint64_t bits, F4 a, F4 b) { return (bits & 1) ? a : b; }
inline F4 selectPositive(F4 t, F4 a, F4 b) { return t.v > 0.0f ? a : b; }
#endif
static_assert(kWidth % kLanes == 0);

// ---- analog kernel building blocks: a noise source and a FLAG-conditional
// writer, each for lanes (F4) and for single PEs (row ends). The kernels are
// generic lambdas instantiated per combination, so the common case (no noise,
// FLAG all ones) is a bare loop of loads, arithmetic and stores.

struct NoNoise {
  template <class T>
  T operator()(int /*transfer*/, int /*pe*/, T v) const {
    return v;
  }
};

struct WithNoise {
  const float* n[3];
  F4 operator()(int transfer, int pe, F4 v) const { return v + load4(n[transfer] + pe); }
  float operator()(int transfer, int pe, float v) const { return v + n[transfer][pe]; }
};

// A writer gives the FLAG of a group of PEs (at(pe): kLanes PEs, or one for
// the float overloads' callers) and writes a group where it is 1. Kernels take
// at() once per group: stores may alias anything, so FLAG would be reloaded.
struct WriteAll {
  struct Flag {};
  Flag at(int /*pe*/) const { return {}; }
  void operator()(float* out, int pe, F4 v, Flag) const { store4(out + pe, v); }
  void operator()(float* out, int pe, float v, Flag) const { out[pe] = v; }
};

// Writes where FLAG = 1, from FLAG's packed bits (PE i is bit i % 64 of word i / 64).
struct WriteWhereFlag {
  const std::uint64_t* flag;
  std::uint64_t at(int pe) const { return flag[pe >> 6] >> (pe & 63); }
  void operator()(float* out, int pe, F4 v, std::uint64_t bits) const {
    store4(out + pe, select(bits, v, load4(out + pe)));
  }
  void operator()(float* out, int pe, float v, std::uint64_t bits) const {
    if (bits & 1) out[pe] = v;
  }
};

// ---- noise: counter-based, so a plane depends only on (seed, transfer counter).

using core::splitmix64;

// Box-Muller on pairs of 32-bit uniforms (a[j], b[j]) with polynomial log, sin
// and cos (errors below 1e-5) and no branches: out[j] and out[j + n] get the pair.
// u1 = ((a >> 8) + 1) / 2^24 in (0, 1]: ln(u1) = e ln2 + ln(m), m in [1, 2), by
// atanh's series; the angle's quadrant is b's top two bits, the rest in [0, pi/2).
constexpr float kLn2 = 0.693147180559945f;
constexpr float kHalfPi = 1.57079632679490f;

#if defined(__SSE2__)
void boxMuller(const std::uint32_t* a, const std::uint32_t* b, int n, float sigma, float* out) {
  const auto f = [](float v) { return _mm_set1_ps(v); };
  const auto i32 = [](int v) { return _mm_set1_epi32(v); };
  for (int j = 0; j < n; j += 4) {
    const __m128i ai = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + j));
    const __m128i bi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + j));
    const __m128 u1 =
        _mm_mul_ps(_mm_cvtepi32_ps(_mm_add_epi32(_mm_srli_epi32(ai, 8), i32(1))), f(0x1p-24f));
    const __m128i ub = _mm_castps_si128(u1);
    const __m128 e = _mm_cvtepi32_ps(_mm_sub_epi32(_mm_srli_epi32(ub, 23), i32(127)));
    const __m128 m =
        _mm_castsi128_ps(_mm_or_si128(_mm_and_si128(ub, i32(0x007fffff)), i32(0x3f800000)));
    const __m128 s = _mm_div_ps(_mm_sub_ps(m, f(1.0f)), _mm_add_ps(m, f(1.0f)));
    const __m128 s2 = _mm_mul_ps(s, s);
    __m128 poly = _mm_add_ps(f(1.0f / 7), _mm_mul_ps(s2, f(1.0f / 9)));
    poly = _mm_add_ps(f(1.0f / 5), _mm_mul_ps(s2, poly));
    poly = _mm_add_ps(f(1.0f / 3), _mm_mul_ps(s2, poly));
    poly = _mm_add_ps(f(1.0f), _mm_mul_ps(s2, poly));
    const __m128 ln_m = _mm_mul_ps(_mm_mul_ps(f(2.0f), s), poly);
    const __m128 ln_u1 = _mm_add_ps(_mm_mul_ps(e, f(kLn2)), ln_m);
    const __m128 r = _mm_mul_ps(
        f(sigma), _mm_sqrt_ps(_mm_max_ps(_mm_mul_ps(f(-2.0f), ln_u1), _mm_setzero_ps())));
    const __m128i q = _mm_srli_epi32(bi, 30);
    const __m128 t =
        _mm_mul_ps(_mm_cvtepi32_ps(_mm_and_si128(bi, i32(0x3fffffff))), f(0x1p-30f * kHalfPi));
    const __m128 t2 = _mm_mul_ps(t, t);
    __m128 sn = _mm_add_ps(f(-1.0f / 5040), _mm_mul_ps(t2, f(1.0f / 362880)));
    sn = _mm_add_ps(f(1.0f / 120), _mm_mul_ps(t2, sn));
    sn = _mm_add_ps(f(-1.0f / 6), _mm_mul_ps(t2, sn));
    sn = _mm_mul_ps(t, _mm_add_ps(f(1.0f), _mm_mul_ps(t2, sn)));
    __m128 cs = _mm_sub_ps(f(1.0f / 40320), _mm_mul_ps(t2, f(1.0f / 3628800)));
    cs = _mm_add_ps(f(-1.0f / 720), _mm_mul_ps(t2, cs));
    cs = _mm_add_ps(f(1.0f / 24), _mm_mul_ps(t2, cs));
    cs = _mm_add_ps(f(-0.5f), _mm_mul_ps(t2, cs));
    cs = _mm_add_ps(f(1.0f), _mm_mul_ps(t2, cs));
    // Quadrant q: (x, y) = (c, s), (-s, c), (-c, -s), (s, -c).
    const __m128 odd =
        _mm_castsi128_ps(_mm_sub_epi32(_mm_setzero_si128(), _mm_and_si128(q, i32(1))));
    const __m128 x_sign = _mm_castsi128_ps(
        _mm_slli_epi32(_mm_and_si128(_mm_xor_si128(q, _mm_srli_epi32(q, 1)), i32(1)), 31));
    const __m128 y_sign = _mm_castsi128_ps(_mm_slli_epi32(_mm_srli_epi32(q, 1), 31));
    const __m128 x = _mm_xor_ps(_mm_or_ps(_mm_and_ps(odd, sn), _mm_andnot_ps(odd, cs)), x_sign);
    const __m128 y = _mm_xor_ps(_mm_or_ps(_mm_and_ps(odd, cs), _mm_andnot_ps(odd, sn)), y_sign);
    _mm_storeu_ps(out + j, _mm_mul_ps(r, x));
    _mm_storeu_ps(out + j + n, _mm_mul_ps(r, y));
  }
}
#else
void boxMuller(const std::uint32_t* a, const std::uint32_t* b, int n, float sigma, float* out) {
  for (int j = 0; j < n; ++j) {
    const float u1 = static_cast<float>(static_cast<std::int32_t>((a[j] >> 8) + 1)) * 0x1p-24f;
    const std::uint32_t ub = std::bit_cast<std::uint32_t>(u1);
    const float e = static_cast<float>(static_cast<std::int32_t>(ub >> 23) - 127);
    const float m = std::bit_cast<float>((ub & 0x007fffffu) | 0x3f800000u);
    const float s = (m - 1.0f) / (m + 1.0f);
    const float s2 = s * s;
    const float ln_m =
        2.0f * s * (1.0f + s2 * (1.0f / 3 + s2 * (1.0f / 5 + s2 * (1.0f / 7 + s2 * (1.0f / 9)))));
    const float r = sigma * std::sqrt(std::max(0.0f, -2.0f * (e * kLn2 + ln_m)));
    const std::uint32_t q = b[j] >> 30;
    const float t =
        static_cast<float>(static_cast<std::int32_t>(b[j] & 0x3fffffffu)) * (0x1p-30f * kHalfPi);
    const float t2 = t * t;
    const float sn =
        t * (1.0f + t2 * (-1.0f / 6 + t2 * (1.0f / 120 + t2 * (-1.0f / 5040 + t2 / 362880))));
    const float cs =
        1.0f +
        t2 * (-0.5f + t2 * (1.0f / 24 + t2 * (-1.0f / 720 + t2 * (1.0f / 40320 - t2 / 3628800))));
    const std::uint32_t odd = 0u - (q & 1u);
    const std::uint32_t sb = std::bit_cast<std::uint32_t>(sn);
    const std::uint32_t cb = std::bit_cast<std::uint32_t>(cs);
    const std::uint32_t xb = ((sb & odd) | (cb & ~odd)) ^ (((q ^ (q >> 1)) & 1u) << 31);
    const std::uint32_t yb = ((cb & odd) | (sb & ~odd)) ^ ((q >> 1) << 31);
    out[j] = r * std::bit_cast<float>(xb);
    out[j + n] = r * std::bit_cast<float>(yb);
  }
}
#endif

// ---- digital rows: 4 words, bit i of word w is x = 64 w + i.

// dst = src moved one PE, taking each PE's value from its neighbour in
// direction `from`; `edge` (0 or all ones) enters at the edge. In-place safe.
void shiftPlane(const std::uint64_t* src, std::uint64_t* dst, Dir from, std::uint64_t edge) {
  switch (from) {
    case Dir::North:  // row y takes row y - 1
      std::memmove(dst + kWordsPerRow, src,
                   (kWordsPerPlane - kWordsPerRow) * sizeof(std::uint64_t));
      std::fill(dst, dst + kWordsPerRow, edge);
      break;
    case Dir::South:  // row y takes row y + 1
      std::memmove(dst, src + kWordsPerRow,
                   (kWordsPerPlane - kWordsPerRow) * sizeof(std::uint64_t));
      std::fill(dst + kWordsPerPlane - kWordsPerRow, dst + kWordsPerPlane, edge);
      break;
    case Dir::East:  // x takes x + 1: bits move down
      for (int r = 0; r < kWordsPerPlane; r += kWordsPerRow) {
        const std::uint64_t w0 = src[r], w1 = src[r + 1], w2 = src[r + 2], w3 = src[r + 3];
        dst[r] = (w0 >> 1) | (w1 << 63);
        dst[r + 1] = (w1 >> 1) | (w2 << 63);
        dst[r + 2] = (w2 >> 1) | (w3 << 63);
        dst[r + 3] = (w3 >> 1) | (edge << 63);
      }
      break;
    case Dir::West:  // x takes x - 1: bits move up
      for (int r = 0; r < kWordsPerPlane; r += kWordsPerRow) {
        const std::uint64_t w0 = src[r], w1 = src[r + 1], w2 = src[r + 2], w3 = src[r + 3];
        dst[r] = (w0 << 1) | (edge >> 63);
        dst[r + 1] = (w1 << 1) | (w0 >> 63);
        dst[r + 2] = (w2 << 1) | (w1 >> 63);
        dst[r + 3] = (w3 << 1) | (w2 >> 63);
      }
      break;
  }
}

// out = the 4-neighbourhood of t (zero beyond the edges), not including t.
void neighbours4(const std::uint64_t* t, std::uint64_t* out) {
  for (int y = 0; y < kHeight; ++y) {
    const int r = y * kWordsPerRow;
    const std::uint64_t w0 = t[r], w1 = t[r + 1], w2 = t[r + 2], w3 = t[r + 3];
    std::uint64_t o[4] = {
        (w0 >> 1) | (w1 << 63) | (w0 << 1),
        (w1 >> 1) | (w2 << 63) | (w1 << 1) | (w0 >> 63),
        (w2 >> 1) | (w3 << 63) | (w2 << 1) | (w1 >> 63),
        (w3 >> 1) | (w3 << 1) | (w2 >> 63),
    };
    for (int i = 0; i < kWordsPerRow; ++i) {
      if (y > 0) o[i] |= t[r - kWordsPerRow + i];
      if (y + 1 < kHeight) o[i] |= t[r + kWordsPerRow + i];
      out[r + i] = o[i];
    }
  }
}

// g (a subset of m) grown east (to higher x) through m: each run of m gets the
// bits from its lowest seed to its end. One 256-bit addition: m + g carries
// from the lowest seed of a run through its end.
inline void fillEast(const std::uint64_t* m, std::uint64_t* g) {
  std::uint64_t carry = 0;
  for (int i = 0; i < kWordsPerRow; ++i) {
    const std::uint64_t t = m[i] + g[i];
    const std::uint64_t c1 = t < m[i];
    const std::uint64_t sum = t + carry;
    const std::uint64_t c2 = sum < t;
    carry = c1 | c2;
    g[i] = m[i] & ((sum ^ m[i]) | g[i]);
  }
}

// One Kogge-Stone step west by K (< 64): g |= p & (g moved K west).
template <int K>
inline void westStep(const std::uint64_t* p, std::uint64_t* g) {
  const std::uint64_t w0 = (g[0] >> K) | (g[1] << (64 - K));
  const std::uint64_t w1 = (g[1] >> K) | (g[2] << (64 - K));
  const std::uint64_t w2 = (g[2] >> K) | (g[3] << (64 - K));
  const std::uint64_t w3 = g[3] >> K;
  g[0] |= p[0] & w0;
  g[1] |= p[1] & w1;
  g[2] |= p[2] & w2;
  g[3] |= p[3] & w3;
}

// b = a & (a moved K west), for 0 < K < 64.
template <int K>
inline void andWest(const std::uint64_t* a, std::uint64_t* b) {
  b[0] = a[0] & ((a[0] >> K) | (a[1] << (64 - K)));
  b[1] = a[1] & ((a[1] >> K) | (a[2] << (64 - K)));
  b[2] = a[2] & ((a[2] >> K) | (a[3] << (64 - K)));
  b[3] = a[3] & (a[3] >> K);
}

// g grown west (to lower x) through the mask, Kogge-Stone: p[j] (row of the
// j-th propagate plane) has bit x set iff the mask is set on [x, x + 2^j).
inline void fillWest(const std::uint64_t* const* p, std::uint64_t* g) {
  westStep<1>(p[0], g);
  westStep<2>(p[1], g);
  westStep<4>(p[2], g);
  westStep<8>(p[3], g);
  // Runs are mostly short: stop once no mask PE west of g can join.
  const std::uint64_t open = (p[0][0] & ~g[0] & ((g[0] >> 1) | (g[1] << 63))) |
                             (p[0][1] & ~g[1] & ((g[1] >> 1) | (g[2] << 63))) |
                             (p[0][2] & ~g[2] & ((g[2] >> 1) | (g[3] << 63))) |
                             (p[0][3] & ~g[3] & (g[3] >> 1));
  if (open == 0) return;
  westStep<16>(p[4], g);
  westStep<32>(p[5], g);
  g[0] |= p[6][0] & g[1];
  g[1] |= p[6][1] & g[2];
  g[2] |= p[6][2] & g[3];
  g[0] |= p[7][0] & g[2];
  g[1] |= p[7][1] & g[3];
}

// Set bits in n words. The x86-64 baseline has no popcnt instruction (std::popcount
// becomes a libgcc call, ~5x slower), so use it when the CPU has it.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__POPCNT__)
__attribute__((target("popcnt"))) int countBitsPopcnt(const std::uint64_t* w, int n) {
  int count = 0;
  for (int i = 0; i < n; ++i) count += __builtin_popcountll(w[i]);
  return count;
}
const bool kHasPopcnt = [] {
  __builtin_cpu_init();  // this runs as a static initialiser
  return __builtin_cpu_supports("popcnt") != 0;
}();
#endif

int countBits(const std::uint64_t* w, int n) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__POPCNT__)
  if (kHasPopcnt) return countBitsPopcnt(w, n);
#endif
  int count = 0;
  for (int i = 0; i < n; ++i) count += std::popcount(w[i]);
  return count;
}

void checkXy(int x, int y) {
  if (x < 0 || x >= kWidth || y < 0 || y >= kHeight) {
    throw std::out_of_range("ppa: PE (" + std::to_string(x) + ", " + std::to_string(y) +
                            ") is outside the 256 x 256 array");
  }
}

inline bool bitAt(const DigitalPlane& p, int x, int y) {
  return (p[y * kWordsPerRow + x / 64] >> (x % 64)) & 1u;
}

}  // namespace

// ---------------------------------------------------------------- host side

Ppa::Ppa(const PpaParams& params) : params_(params) {
  if (!std::isfinite(params_.analog_noise_sigma) || params_.analog_noise_sigma < 0) {
    throw std::invalid_argument("ppa: analog_noise_sigma must be finite and >= 0, got " +
                                std::to_string(params_.analog_noise_sigma));
  }
  if (!std::isfinite(params_.pix_gain) || params_.pix_gain <= 0) {
    throw std::invalid_argument("ppa: pix_gain must be finite and > 0, got " +
                                std::to_string(params_.pix_gain));
  }
  if (params_.pix_response == "linear") {
    for (int g = 0; g < 256; ++g) {
      pix_lut_[g] = static_cast<float>(std::min<double>(params_.pix_gain * g, kAnalogMax));
    }
  } else if (params_.pix_response == "log") {
    const double full = std::log1p(params_.pix_gain * 255.0);
    for (int g = 0; g < 256; ++g) {
      pix_lut_[g] = static_cast<float>(kAnalogMax * std::log1p(params_.pix_gain * g) / full);
    }
  } else {
    throw std::invalid_argument("ppa: pix_response must be 'linear' or 'log', got '" +
                                params_.pix_response + "'");
  }
  for (auto& a : analog_) a.assign(kPes, 0.0f);
  flag_.fill(kOnes);
  pix_.assign(kPes, 0.0f);
  scratch_.resize(kPes);
  if (params_.analog_noise_sigma > 0) {
    for (auto& n : noise_) n.resize(kPes);
    noise_bits_.resize(kPes);
  }
  flood_scratch_.resize(8 * static_cast<std::size_t>(kWordsPerPlane));  // 8 rows per row
}

void Ppa::setLight(const std::uint8_t* gray) {
  if (gray == nullptr) throw std::invalid_argument("ppa: setLight(nullptr)");
  for (int i = 0; i < kPes; ++i) pix_[i] = pix_lut_[gray[i]];
}

float Ppa::analog(Areg reg, int x, int y) const {
  checkXy(x, y);
  return analog_[static_cast<int>(reg)][y * kWidth + x];
}

bool Ppa::digital(Dreg reg, int x, int y) const {
  checkXy(x, y);
  return bitAt(digital_[static_cast<int>(reg)], x, y);
}

bool Ppa::flag(int x, int y) const {
  checkXy(x, y);
  return bitAt(flag_, x, y);
}

const std::vector<float>& Ppa::analogPlane(Areg reg) const {
  return analog_[static_cast<int>(reg)];
}

const DigitalPlane& Ppa::digitalPlane(Dreg reg) const { return digital_[static_cast<int>(reg)]; }

void Ppa::loadAnalog(Areg reg, const std::vector<float>& values) {
  if (values.size() != static_cast<std::size_t>(kPes)) {
    throw std::invalid_argument("ppa: loadAnalog needs " + std::to_string(kPes) + " values, got " +
                                std::to_string(values.size()));
  }
  float* d = plane(reg).data();
  for (int i = 0; i < kPes; ++i) d[i] = saturate(values[i]);
}

void Ppa::loadDigital(Dreg reg, const DigitalPlane& plane) { dplane(reg) = plane; }

std::vector<float>& Ppa::plane(Areg reg) { return analog_[static_cast<int>(reg)]; }

DigitalPlane& Ppa::dplane(Dreg reg) { return digital_[static_cast<int>(reg)]; }

// ---------------------------------------------------------------- analog machinery

void Ppa::flagChanged() {
  flag_all_ = std::all_of(flag_.begin(), flag_.end(), [](std::uint64_t w) { return w == kOnes; });
}

void Ppa::makeNoise(int k) {
  // Each transfer draws one counter value; its plane is a hash of that and the seed.
  const std::uint64_t key = splitmix64(params_.noise_seed ^ splitmix64(noise_counter_++));
  std::uint32_t* a = noise_bits_.data();
  std::uint32_t* b = a + kPes / 2;
  for (int j = 0; j < kPes / 2; ++j) {
    const std::uint64_t h = splitmix64(key + static_cast<std::uint64_t>(j));
    a[j] = static_cast<std::uint32_t>(h);
    b[j] = static_cast<std::uint32_t>(h >> 32);
  }
  boxMuller(a, b, kPes / 2, static_cast<float>(params_.analog_noise_sigma), noise_[k].data());
}

template <class Kernel>
void Ppa::runAnalog(int transfers, Kernel&& kernel) {
  if (params_.analog_noise_sigma > 0) {
    WithNoise noise{};
    for (int k = 0; k < transfers; ++k) {
      makeNoise(k);
      noise.n[k] = noise_[k].data();
    }
    if (flag_all_) {
      kernel(noise, WriteAll{});
    } else {
      kernel(noise, WriteWhereFlag{flag_.data()});
    }
  } else if (flag_all_) {
    kernel(NoNoise{}, WriteAll{});
  } else {
    kernel(NoNoise{}, WriteWhereFlag{flag_.data()});
  }
}

// ---------------------------------------------------------------- analog instructions

// The kernels declare their plane pointers inside the lambda: as locals they
// stay in registers, where captured ones would be reloaded after every store.

void Ppa::getImage(Areg dst) {
  ++instructions_;
  runAnalog(1, [this, dst](auto noise, auto write) {
    float* d = plane(dst).data();
    const float* p = pix_.data();
    for (int i = 0; i < kPes; i += kLanes)
      write(d, i, saturate(noise(0, i, load4(p + i))), write.at(i));
  });
}

void Ppa::bus(Areg dst, Areg src) {
  ++instructions_;
  runAnalog(1, [this, dst, src](auto noise, auto write) {
    float* d = plane(dst).data();
    const float* s = plane(src).data();
    for (int i = 0; i < kPes; i += kLanes)
      write(d, i, saturate(noise(0, i, -load4(s + i))), write.at(i));
  });
}

void Ppa::bus(Areg dst, Areg src1, Areg src2) {
  ++instructions_;
  runAnalog(1, [this, dst, src1, src2](auto noise, auto write) {
    float* d = plane(dst).data();
    const float* a = plane(src1).data();
    const float* b = plane(src2).data();
    for (int i = 0; i < kPes; i += kLanes) {
      write(d, i, saturate(noise(0, i, -(load4(a + i) + load4(b + i)))), write.at(i));
    }
  });
}

void Ppa::busFrom(Areg dst, Dir from) {
  ++instructions_;
  if (dst == Areg::NEWS) {  // every PE reads its neighbour's old NEWS
    std::copy_n(plane(Areg::NEWS).data(), kPes, scratch_.data());
  }
  runAnalog(1, [this, dst, from](auto noise, auto write) {
    float* d = plane(dst).data();
    const float* news = dst == Areg::NEWS ? scratch_.data() : plane(Areg::NEWS).data();
    // Row y of dst takes row y + dy of NEWS shifted by dx; PEs without a neighbour get 0.
    const int dy = from == Dir::North ? -1 : from == Dir::South ? 1 : 0;
    const int dx = from == Dir::West ? -1 : from == Dir::East ? 1 : 0;
    for (int y = 0; y < kHeight; ++y) {
      const int sy = y + dy;
      const int row = y * kWidth;
      if (sy < 0 || sy >= kHeight) {
        for (int x = 0; x < kWidth; x += kLanes) {
          write(d, row + x, saturate(noise(0, row + x, zero4())), write.at(row + x));
        }
        continue;
      }
      const float* s = news + sy * kWidth;  // s[x + dx] is the neighbour of x
      int x = 0;
      if (dx < 0) {  // x = 0 has no west neighbour; lanes start at a multiple of kLanes
        write(d, row, saturate(noise(0, row, 0.0f)), write.at(row));
        for (x = 1; x % kLanes != 0; ++x)
          write(d, row + x, saturate(noise(0, row + x, -s[x - 1])), write.at(row + x));
      }
      const int end = dx > 0 ? kWidth - 1 : kWidth;
      for (; x + kLanes <= end; x += kLanes) {
        write(d, row + x, saturate(noise(0, row + x, -load4(s + x + dx))), write.at(row + x));
      }
      for (; x < end; ++x)
        write(d, row + x, saturate(noise(0, row + x, -s[x + dx])), write.at(row + x));
      if (dx > 0) write(d, row + end, saturate(noise(0, row + end, 0.0f)), write.at(row + end));
    }
  });
}

void Ppa::where(Areg src) {
  ++instructions_;
  const float* s = plane(src).data();
  for (int w = 0; w < kWordsPerPlane; ++w) {
    const float* p = s + w * 64;
    std::uint64_t bits = 0;
#if defined(__SSE2__)
    const __m128 zero = _mm_setzero_ps();
    for (int k = 0; k < 16; ++k) {
      const int m = _mm_movemask_ps(_mm_cmpgt_ps(_mm_loadu_ps(p + 4 * k), zero));
      bits |= static_cast<std::uint64_t>(m) << (4 * k);
    }
#else
    for (int i = 0; i < 64; ++i) bits |= static_cast<std::uint64_t>(p[i] > 0.0f) << i;
#endif
    flag_[w] = bits;
  }
  flagChanged();
}

void Ppa::whereDigital(Dreg src) {
  ++instructions_;
  flag_ = dplane(src);
  flagChanged();
}

void Ppa::all() {
  ++instructions_;
  flag_.fill(kOnes);
  flag_all_ = true;
}

// ---------------------------------------------------------------- analog macros
// Fused loops: each PE's transfers run in order in registers, so one pass over
// the planes does the work of several instructions.

// The two-transfer macros: the first transfer's value (already negated) into
// NEWS, then NEWS negated into dst.
template <class FirstTransfer>
void Ppa::viaNews(Areg dst, FirstTransfer first) {
  instructions_ += 2;
  runAnalog(2, [this, dst, &first](auto noise, auto write) {
    float* d = plane(dst).data();
    float* news = plane(Areg::NEWS).data();
    for (int i = 0; i < kPes; i += kLanes) {
      const auto here = write.at(i);  // FLAG of these PEs
      const F4 t = saturate(noise(0, i, first(i)));
      write(news, i, t, here);
      write(d, i, saturate(noise(1, i, -t)), here);
    }
  });
}

void Ppa::mov(Areg dst, Areg src) {
  const float* s = plane(src).data();
  viaNews(dst, [s](int i) { return -load4(s + i); });
}

void Ppa::add(Areg dst, Areg src1, Areg src2) {
  const float* a = plane(src1).data();
  const float* b = plane(src2).data();
  viaNews(dst, [a, b](int i) { return -(load4(a + i) + load4(b + i)); });
}

void Ppa::sub(Areg dst, Areg src1, Areg src2) {
  instructions_ += 3;
  runAnalog(3, [this, dst, src1, src2](auto noise, auto write) {
    float* d = plane(dst).data();
    float* news = plane(Areg::NEWS).data();
    const float* a = plane(src1).data();
    const float* b = plane(src2).data();
    for (int i = 0; i < kPes; i += kLanes) {
      const auto here = write.at(i);  // FLAG of these PEs
      const F4 nb = saturate(noise(0, i, -load4(b + i)));
      const F4 t = saturate(noise(1, i, -(load4(a + i) + nb)));
      write(news, i, t, here);
      write(d, i, saturate(noise(2, i, -t)), here);
    }
  });
}

void Ppa::neg(Areg dst, Areg src) { bus(dst, src); }

void Ppa::abs(Areg dst, Areg src) {
  all();
  instructions_ += 5;  // mov (2), where, bus, all
  runAnalog(3, [this, dst, src](auto noise, auto write) {
    float* d = plane(dst).data();
    float* news = plane(Areg::NEWS).data();
    const float* s = plane(src).data();
    for (int i = 0; i < kPes; i += kLanes) {
      const auto here = write.at(i);  // FLAG of these PEs
      const F4 src_v = load4(s + i);
      const F4 t = saturate(noise(0, i, -src_v));
      const F4 moved = saturate(noise(1, i, -t));
      const F4 negated = saturate(noise(2, i, -src_v));
      write(news, i, t, here);
      write(d, i, selectPositive(t, negated, moved), here);
    }
  });
}

void Ppa::movFrom(Areg dst, Areg src, Dir from) {
  bus(Areg::NEWS, src);
  busFrom(dst, from);
}

// ---------------------------------------------------------------- digital

void Ppa::set(Dreg dst) {
  ++instructions_;
  dplane(dst).fill(kOnes);
}

void Ppa::clr(Dreg dst) {
  ++instructions_;
  dplane(dst).fill(0);
}

void Ppa::mov(Dreg dst, Dreg src) {
  ++instructions_;
  dplane(dst) = dplane(src);
}

void Ppa::notOp(Dreg dst, Dreg src) {
  ++instructions_;
  std::uint64_t* d = dplane(dst).data();
  const std::uint64_t* s = dplane(src).data();
  for (int i = 0; i < kWordsPerPlane; ++i) d[i] = ~s[i];
}

void Ppa::nor(Dreg dst, Dreg src1, Dreg src2) {
  ++instructions_;
  std::uint64_t* d = dplane(dst).data();
  const std::uint64_t* a = dplane(src1).data();
  const std::uint64_t* b = dplane(src2).data();
  for (int i = 0; i < kWordsPerPlane; ++i) d[i] = ~(a[i] | b[i]);
}

void Ppa::orOp(Dreg dst, Dreg src1, Dreg src2) {
  ++instructions_;
  std::uint64_t* d = dplane(dst).data();
  const std::uint64_t* a = dplane(src1).data();
  const std::uint64_t* b = dplane(src2).data();
  for (int i = 0; i < kWordsPerPlane; ++i) d[i] = a[i] | b[i];
}

void Ppa::andOp(Dreg dst, Dreg src1, Dreg src2) {
  instructions_ += 2;
  std::uint64_t* d = dplane(dst).data();
  const std::uint64_t* a = dplane(src1).data();
  const std::uint64_t* b = dplane(src2).data();
  for (int i = 0; i < kWordsPerPlane; ++i) d[i] = a[i] & b[i];
}

void Ppa::xorOp(Dreg dst, Dreg src1, Dreg src2) {
  instructions_ += 3;
  std::uint64_t* d = dplane(dst).data();
  const std::uint64_t* a = dplane(src1).data();
  const std::uint64_t* b = dplane(src2).data();
  for (int i = 0; i < kWordsPerPlane; ++i) d[i] = a[i] ^ b[i];
}

void Ppa::storeFlag(Dreg dst) {
  ++instructions_;
  dplane(dst) = flag_;
}

void Ppa::movFrom(Dreg dst, Dreg src, Dir from, bool edge_value) {
  ++instructions_;
  shiftPlane(dplane(src).data(), dplane(dst).data(), from, edge_value ? kOnes : 0);
}

void Ppa::fillComponents(DigitalPlane& fill, const DigitalPlane& mask) {
  std::uint64_t* f = fill.data();
  const std::uint64_t* m = mask.data();
  std::uint64_t any_seed = 0;
  for (int i = 0; i < kWordsPerPlane; ++i) any_seed |= f[i];
  if (any_seed == 0) return;

  // Westward propagate rows, built for a row the first time it is filled:
  // p[0] = the mask row, p[j + 1] = p[j] & (p[j] moved 2^j west).
  constexpr int kPropWords = 8 * kWordsPerRow;
  std::uint64_t* prop = flood_scratch_.data();
  std::array<bool, kHeight> prop_ready{};
  auto propRow = [&](int y) {
    std::uint64_t* p = prop + y * kPropWords;
    if (!prop_ready[y]) {
      prop_ready[y] = true;
      std::copy_n(m + y * kWordsPerRow, kWordsPerRow, p);
      // p[j + 1] = p[j] & (p[j] moved 2^j west): Kogge-Stone steps on the mask.
      andWest<1>(p, p + 4);
      andWest<2>(p + 4, p + 8);
      andWest<4>(p + 8, p + 12);
      andWest<8>(p + 12, p + 16);
      andWest<16>(p + 16, p + 20);
      andWest<32>(p + 20, p + 24);
      p[28] = p[24] & p[25];
      p[29] = p[25] & p[26];
      p[30] = p[26] & p[27];
      p[31] = 0;
    }
    return p;
  };

  // Sweeps down and up the rows: a row takes the seeds of the row before it in
  // the sweep (within the mask), then fills the runs of its mask that hold a
  // seed in both directions. A row is looked at again only if that neighbour
  // changed since (in the previous sweep or this one). Done when a sweep after
  // the first changes nothing.
  std::array<std::uint8_t, kHeight + 2> changed_before{}, changed_now{};  // row y at y + 1
  for (int sweep = 0;; ++sweep) {
    const bool down = sweep % 2 == 0;
    bool changed = false;
    changed_now.fill(0);
    for (int n = 0; n < kHeight; ++n) {
      const int y = down ? n : kHeight - 1 - n;
      const int nb = down ? y - 1 : y + 1;  // may be -1 or kHeight: flags are 0 there
      if (sweep > 0 && !changed_before[nb + 1] && !changed_now[nb + 1]) continue;
      const int r = y * kWordsPerRow;
      const bool has_nb = nb >= 0 && nb < kHeight;
      std::uint64_t g[4];
      std::uint64_t fresh = 0, any = 0;
      for (int i = 0; i < kWordsPerRow; ++i) {
        g[i] = f[r + i] | (has_nb ? m[r + i] & f[nb * kWordsPerRow + i] : 0);
        fresh |= g[i] & ~f[r + i];
        any |= g[i];
      }
      // The first sweep fills every row that has seeds; later ones only rows
      // given new seeds (rows are whole runs after their first fill).
      if (sweep == 0 ? any == 0 : fresh == 0) continue;
      fillEast(m + r, g);
      const std::uint64_t* p = propRow(y);
      const std::uint64_t* rows[8];
      for (int j = 0; j < 8; ++j) rows[j] = p + j * kWordsPerRow;
      fillWest(rows, g);
      bool row_changed = sweep == 0;  // new to both neighbours
      for (int i = 0; i < kWordsPerRow; ++i) {
        row_changed |= g[i] != f[r + i];
        f[r + i] = g[i];
      }
      changed |= row_changed;
      changed_now[y + 1] = row_changed;
    }
    if (sweep > 0 && !changed) break;
    changed_before = changed_now;
  }
}

void Ppa::flood(Dreg target, Dreg mask, int iterations) {
  ++instructions_;
  std::uint64_t* t = dplane(target).data();
  const std::uint64_t* m = dplane(mask).data();
  DigitalPlane near{};
  if (iterations > 0) {
    // Exactly `iterations` synchronous steps: t |= m & N4(t).
    for (int it = 0; it < iterations; ++it) {
      neighbours4(t, near.data());
      std::uint64_t grown = 0;
      for (int i = 0; i < kWordsPerPlane; ++i) {
        const std::uint64_t add = m[i] & near[i] & ~t[i];
        grown |= add;
        t[i] |= add;
      }
      if (grown == 0) break;
    }
    return;
  }
  // To completion: the components of the mask that hold a mask PE in or next to
  // the target.
  neighbours4(t, near.data());
  DigitalPlane fill;
  for (int i = 0; i < kWordsPerPlane; ++i) fill[i] = m[i] & (t[i] | near[i]);
  fillComponents(fill, dplane(mask));
  for (int i = 0; i < kWordsPerPlane; ++i) t[i] |= fill[i];
}

void Ppa::floodFromBorder(Dreg target, Dreg mask) {
  ++instructions_;
  const DigitalPlane& m = dplane(mask);
  DigitalPlane fill;
  for (int y = 0; y < kHeight; ++y) {
    const int r = y * kWordsPerRow;
    const bool edge_row = y == 0 || y == kHeight - 1;
    for (int i = 0; i < kWordsPerRow; ++i) {
      std::uint64_t border = edge_row ? kOnes : 0;
      if (i == 0) border |= 1;
      if (i == kWordsPerRow - 1) border |= std::uint64_t{1} << 63;
      fill[r + i] = m[r + i] & border;
    }
  }
  fillComponents(fill, m);
  dplane(target) = fill;
}

// ---------------------------------------------------------------- global readouts

bool Ppa::globalOr(Dreg src) {
  ++instructions_;
  const std::uint64_t* s = dplane(src).data();
  std::uint64_t any = 0;
  for (int i = 0; i < kWordsPerPlane; ++i) any |= s[i];
  return any != 0;
}

int Ppa::globalCount(Dreg src) {
  ++instructions_;
  return countBits(dplane(src).data(), kWordsPerPlane);
}

std::vector<Event> Ppa::scanEvents(Dreg src, int max_events) {
  ++instructions_;
  std::vector<Event> events;
  if (max_events <= 0) return events;
  const std::uint64_t* s = dplane(src).data();
  for (int i = 0; i < kWordsPerPlane; ++i) {
    for (std::uint64_t w = s[i]; w != 0; w &= w - 1) {
      events.push_back({(i % kWordsPerRow) * 64 + std::countr_zero(w), i / kWordsPerRow});
      if (static_cast<int>(events.size()) == max_events) return events;
    }
  }
  return events;
}

BoundingBox Ppa::boundingBox(Dreg src) {
  ++instructions_;
  const std::uint64_t* s = dplane(src).data();
  BoundingBox box;
  std::uint64_t columns[kWordsPerRow] = {};
  for (int y = 0; y < kHeight; ++y) {
    const int r = y * kWordsPerRow;
    const std::uint64_t row = s[r] | s[r + 1] | s[r + 2] | s[r + 3];
    if (row == 0) continue;
    if (!box.found) box.y_min = y;
    box.found = true;
    box.y_max = y;
    for (int i = 0; i < kWordsPerRow; ++i) columns[i] |= s[r + i];
  }
  if (!box.found) return box;
  for (int i = 0; i < kWordsPerRow; ++i) {
    if (columns[i] != 0) {
      box.x_min = i * 64 + std::countr_zero(columns[i]);
      break;
    }
  }
  for (int i = kWordsPerRow - 1; i >= 0; --i) {
    if (columns[i] != 0) {
      box.x_max = i * 64 + 63 - std::countl_zero(columns[i]);
      break;
    }
  }
  return box;
}

}  // namespace nadir::ppa
