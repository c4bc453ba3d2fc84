// The SCAMP-5 emulator against a straightforward per-PE reference written here.

#include "nodes/ppa/ppa_array.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace nadir::ppa {
namespace {

constexpr int kN = kWidth * kHeight;
using Bits = std::vector<std::uint8_t>;  // one PE a byte, row major
using Plane = std::vector<float>;

constexpr std::array<Areg, 7> kAregs = {Areg::A, Areg::B, Areg::C,   Areg::D,
                                        Areg::E, Areg::F, Areg::NEWS};
constexpr std::array<Dir, 4> kDirs = {Dir::North, Dir::East, Dir::South, Dir::West};

int idx(int x, int y) { return y * kWidth + x; }

float sat(float v) { return std::min(std::max(v, kAnalogMin), kAnalogMax); }

// The neighbour of (x, y) in direction `from`; false beyond the edge.
bool neighbour(int x, int y, Dir from, int& nx, int& ny) {
  nx = x + (from == Dir::East ? 1 : from == Dir::West ? -1 : 0);
  ny = y + (from == Dir::South ? 1 : from == Dir::North ? -1 : 0);
  return nx >= 0 && nx < kWidth && ny >= 0 && ny < kHeight;
}

DigitalPlane pack(const Bits& b) {
  DigitalPlane p{};
  for (int i = 0; i < kN; ++i) {
    if (b[i]) p[i / 64] |= std::uint64_t{1} << (i % 64);
  }
  return p;
}

Bits unpack(const DigitalPlane& p) {
  Bits b(kN);
  for (int i = 0; i < kN; ++i) b[i] = (p[i / 64] >> (i % 64)) & 1u;
  return b;
}

Plane randomPlane(std::mt19937& rng, float lo = kAnalogMin, float hi = kAnalogMax) {
  std::uniform_real_distribution<float> u(lo, hi);
  Plane p(kN);
  for (auto& v : p) v = u(rng);
  // A few exact extremes, where negation saturates.
  for (int k = 0; k < 64; ++k) p[rng() % kN] = (k % 2) ? kAnalogMin : kAnalogMax;
  return p;
}

Bits randomBits(std::mt19937& rng, double p_one) {
  std::bernoulli_distribution b(p_one);
  Bits bits(kN);
  for (auto& v : bits) v = b(rng);
  return bits;
}

// The reference: every instruction PE by PE, exactly as the header describes it.
struct Ref {
  std::array<Plane, kAnalogRegisters> a;
  std::array<Bits, kDigitalRegisters> d;
  Bits flag = Bits(kN, 1);

  Ref() {
    for (auto& p : a) p.assign(kN, 0.0f);
    for (auto& p : d) p.assign(kN, 0);
  }
  Plane& A(Areg r) { return a[static_cast<int>(r)]; }
  Bits& D(Dreg r) { return d[static_cast<int>(r)]; }

  // One transfer: dst = sat(v) where FLAG.
  void write(Areg dst, const Plane& v) {
    for (int i = 0; i < kN; ++i) {
      if (flag[i]) A(dst)[i] = sat(v[i]);
    }
  }
  void bus(Areg dst, Areg src) {
    Plane v(kN);
    for (int i = 0; i < kN; ++i) v[i] = -A(src)[i];
    write(dst, v);
  }
  void bus(Areg dst, Areg s1, Areg s2) {
    Plane v(kN);
    for (int i = 0; i < kN; ++i) v[i] = -(A(s1)[i] + A(s2)[i]);
    write(dst, v);
  }
  void busFrom(Areg dst, Dir from) {
    Plane v(kN);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        int nx, ny;
        v[idx(x, y)] = neighbour(x, y, from, nx, ny) ? -A(Areg::NEWS)[idx(nx, ny)] : 0.0f;
      }
    }
    write(dst, v);
  }
  void where(Areg src) {
    for (int i = 0; i < kN; ++i) flag[i] = A(src)[i] > 0.0f;
  }
  void whereDigital(Dreg src) { flag = D(src); }
  void all() { std::fill(flag.begin(), flag.end(), 1); }
  // Macros: sources are read first; the transfers follow the header's sequences.
  void mov(Areg dst, Areg src) {
    const Plane s = A(src);
    Plane v(kN);
    for (int i = 0; i < kN; ++i) v[i] = -s[i];
    write(Areg::NEWS, v);
    for (int i = 0; i < kN; ++i) v[i] = -sat(-s[i]);
    write(dst, v);
  }
  void add(Areg dst, Areg s1, Areg s2) {
    const Plane a1 = A(s1), a2 = A(s2);
    Plane v(kN);
    for (int i = 0; i < kN; ++i) v[i] = -sat(-(a1[i] + a2[i]));
    for (int i = 0; i < kN; ++i) {
      if (flag[i]) A(Areg::NEWS)[i] = sat(-(a1[i] + a2[i]));
    }
    write(dst, v);
  }
  void sub(Areg dst, Areg s1, Areg s2) {
    const Plane a1 = A(s1), a2 = A(s2);
    Plane news(kN);
    for (int i = 0; i < kN; ++i) news[i] = sat(-(a1[i] + sat(-a2[i])));  // NEWS = -(s1 + -s2)
    Plane v(kN);
    for (int i = 0; i < kN; ++i) v[i] = -news[i];
    write(Areg::NEWS, news);
    write(dst, v);
  }
  void abs(Areg dst, Areg src) {
    const Plane s = A(src);
    all();
    Plane news(kN), v(kN);
    for (int i = 0; i < kN; ++i) {
      news[i] = sat(-s[i]);
      v[i] = news[i] > 0.0f ? -s[i] : -news[i];  // where(NEWS): -src, else the moved src
    }
    write(Areg::NEWS, news);
    write(dst, v);
  }
  void movFrom(Areg dst, Areg src, Dir from) {
    bus(Areg::NEWS, src);
    busFrom(dst, from);
  }
  void dmovFrom(Dreg dst, Dreg src, Dir from, bool edge) {
    Bits v(kN);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        int nx, ny;
        v[idx(x, y)] = neighbour(x, y, from, nx, ny) ? D(src)[idx(nx, ny)] : edge;
      }
    }
    D(dst) = v;
  }
};

// The reference flood: synchronous steps t |= mask & N4(t), computed from the
// frontier (the PEs added by the previous step) so long paths stay affordable.
// Runs `max_steps` steps (0 = until stable) and returns the number that changed t.
int refFlood(Bits& t, const Bits& mask, int max_steps = 0) {
  std::vector<int> frontier;
  for (int i = 0; i < kN; ++i) {
    if (t[i]) frontier.push_back(i);
  }
  int steps = 0;
  while (!frontier.empty() && (max_steps == 0 || steps < max_steps)) {
    std::vector<int> next;
    for (int i : frontier) {
      for (Dir dir : kDirs) {
        int nx, ny;
        if (!neighbour(i % kWidth, i / kWidth, dir, nx, ny)) continue;
        const int j = idx(nx, ny);
        if (mask[j] && !t[j]) {
          t[j] = 2;  // added this step: not a source until the next one
          next.push_back(j);
        }
      }
    }
    for (int j : next) t[j] = 1;
    if (!next.empty()) ++steps;
    frontier.swap(next);
  }
  return steps;
}

// The plain definition of one step, to check the frontier reference against.
void refFloodStepNaive(Bits& t, const Bits& mask) {
  Bits out = t;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      for (Dir dir : kDirs) {
        int nx, ny;
        if (neighbour(x, y, dir, nx, ny) && t[idx(nx, ny)] && mask[idx(x, y)]) out[idx(x, y)] = 1;
      }
    }
  }
  t = out;
}

::testing::AssertionResult samePlane(const Plane& got, const Plane& want, const std::string& what) {
  for (int i = 0; i < kN; ++i) {
    if (got[i] != want[i]) {
      return ::testing::AssertionFailure() << what << " differs at (" << i % kWidth << ", "
                                           << i / kWidth << "): " << got[i] << " vs " << want[i];
    }
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult sameBits(const Bits& got, const Bits& want, const std::string& what) {
  for (int i = 0; i < kN; ++i) {
    if ((got[i] != 0) != (want[i] != 0)) {
      return ::testing::AssertionFailure()
             << what << " differs at (" << i % kWidth << ", " << i / kWidth << "): " << int(got[i])
             << " vs " << int(want[i]);
    }
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult sameState(const Ppa& ppa, const Ref& ref) {
  for (int r = 0; r < kAnalogRegisters; ++r) {
    auto res = samePlane(ppa.analogPlane(static_cast<Areg>(r)), ref.a[r],
                         "analog register " + std::to_string(r));
    if (!res) return res;
  }
  for (int r = 0; r < kDigitalRegisters; ++r) {
    auto res = sameBits(unpack(ppa.digitalPlane(static_cast<Dreg>(r))), ref.d[r],
                        "digital register R" + std::to_string(r));
    if (!res) return res;
  }
  Bits flag(kN);
  for (int i = 0; i < kN; ++i) flag[i] = ppa.flag(i % kWidth, i / kWidth);
  return sameBits(flag, ref.flag, "FLAG");
}

// Loads the same random analog registers into both.
void loadRandomAnalog(Ppa& ppa, Ref& ref, std::mt19937& rng) {
  for (Areg r : kAregs) {
    const Plane p = randomPlane(rng);
    ppa.loadAnalog(r, p);
    ref.A(r) = p;
  }
}

// Sets the same random FLAG in both (where on a random plane).
void randomFlag(Ppa& ppa, Ref& ref, std::mt19937& rng) {
  const Plane p = randomPlane(rng, -1.0f, 1.0f);
  ppa.loadAnalog(Areg::F, p);
  ref.A(Areg::F) = p;
  ppa.where(Areg::F);
  ref.where(Areg::F);
}

// Runs `op` on both after loading fresh random registers, with FLAG all ones
// and with a random FLAG, and compares every register and FLAG afterwards.
void checkAnalogOp(const std::string& name, const std::function<void(Ppa&)>& on_ppa,
                   const std::function<void(Ref&)>& on_ref) {
  for (int flagged = 0; flagged < 2; ++flagged) {
    std::mt19937 rng(1234 + flagged);
    Ppa ppa;
    Ref ref;
    loadRandomAnalog(ppa, ref, rng);
    if (flagged) randomFlag(ppa, ref, rng);
    on_ppa(ppa);
    on_ref(ref);
    EXPECT_TRUE(sameState(ppa, ref))
        << name << (flagged ? " with a random FLAG" : " with FLAG all");
  }
}

// Bus transfers (one and two sources, and neg) negate and saturate like the reference.
TEST(PpaArray, BusTransfersMatchReference) {
  checkAnalogOp(
      "bus(A, B)", [](Ppa& p) { p.bus(Areg::A, Areg::B); },
      [](Ref& r) { r.bus(Areg::A, Areg::B); });
  checkAnalogOp(
      "bus(C, C)", [](Ppa& p) { p.bus(Areg::C, Areg::C); },
      [](Ref& r) { r.bus(Areg::C, Areg::C); });
  checkAnalogOp(
      "bus(A, B, C)", [](Ppa& p) { p.bus(Areg::A, Areg::B, Areg::C); },
      [](Ref& r) { r.bus(Areg::A, Areg::B, Areg::C); });
  checkAnalogOp(
      "bus(NEWS, NEWS, D)", [](Ppa& p) { p.bus(Areg::NEWS, Areg::NEWS, Areg::D); },
      [](Ref& r) { r.bus(Areg::NEWS, Areg::NEWS, Areg::D); });
  checkAnalogOp(
      "neg(E, D)", [](Ppa& p) { p.neg(Areg::E, Areg::D); },
      [](Ref& r) { r.bus(Areg::E, Areg::D); });
}

// The macros mov, add, sub and abs match the reference, also with NEWS or dst as a source.
TEST(PpaArray, AnalogMacrosMatchReference) {
  checkAnalogOp(
      "mov(A, B)", [](Ppa& p) { p.mov(Areg::A, Areg::B); },
      [](Ref& r) { r.mov(Areg::A, Areg::B); });
  checkAnalogOp(
      "mov(B, NEWS)", [](Ppa& p) { p.mov(Areg::B, Areg::NEWS); },
      [](Ref& r) { r.mov(Areg::B, Areg::NEWS); });
  checkAnalogOp(
      "mov(NEWS, C)", [](Ppa& p) { p.mov(Areg::NEWS, Areg::C); },
      [](Ref& r) { r.mov(Areg::NEWS, Areg::C); });
  checkAnalogOp(
      "add(A, B, C)", [](Ppa& p) { p.add(Areg::A, Areg::B, Areg::C); },
      [](Ref& r) { r.add(Areg::A, Areg::B, Areg::C); });
  checkAnalogOp(
      "add(B, B, NEWS)", [](Ppa& p) { p.add(Areg::B, Areg::B, Areg::NEWS); },
      [](Ref& r) { r.add(Areg::B, Areg::B, Areg::NEWS); });
  checkAnalogOp(
      "sub(A, B, C)", [](Ppa& p) { p.sub(Areg::A, Areg::B, Areg::C); },
      [](Ref& r) { r.sub(Areg::A, Areg::B, Areg::C); });
  checkAnalogOp(
      "sub(C, NEWS, C)", [](Ppa& p) { p.sub(Areg::C, Areg::NEWS, Areg::C); },
      [](Ref& r) { r.sub(Areg::C, Areg::NEWS, Areg::C); });
  checkAnalogOp(
      "sub(D, E, NEWS)", [](Ppa& p) { p.sub(Areg::D, Areg::E, Areg::NEWS); },
      [](Ref& r) { r.sub(Areg::D, Areg::E, Areg::NEWS); });
  checkAnalogOp(
      "abs(A, B)", [](Ppa& p) { p.abs(Areg::A, Areg::B); },
      [](Ref& r) { r.abs(Areg::A, Areg::B); });
  checkAnalogOp(
      "abs(C, C)", [](Ppa& p) { p.abs(Areg::C, Areg::C); },
      [](Ref& r) { r.abs(Areg::C, Areg::C); });
  checkAnalogOp(
      "abs(NEWS, D)", [](Ppa& p) { p.abs(Areg::NEWS, Areg::D); },
      [](Ref& r) { r.abs(Areg::NEWS, Areg::D); });
}

// busFrom and movFrom read the neighbour in each direction and 0 beyond each edge.
TEST(PpaArray, NeighbourReadsAtTheEdges) {
  for (Dir dir : kDirs) {
    const std::string name = "direction " + std::to_string(static_cast<int>(dir));
    checkAnalogOp(
        "busFrom(A) " + name, [dir](Ppa& p) { p.busFrom(Areg::A, dir); },
        [dir](Ref& r) { r.busFrom(Areg::A, dir); });
    checkAnalogOp(
        "busFrom(NEWS) " + name, [dir](Ppa& p) { p.busFrom(Areg::NEWS, dir); },
        [dir](Ref& r) { r.busFrom(Areg::NEWS, dir); });
    checkAnalogOp(
        "movFrom(B, C) " + name, [dir](Ppa& p) { p.movFrom(Areg::B, Areg::C, dir); },
        [dir](Ref& r) { r.movFrom(Areg::B, Areg::C, dir); });
    checkAnalogOp(
        "movFrom(D, D) " + name, [dir](Ppa& p) { p.movFrom(Areg::D, Areg::D, dir); },
        [dir](Ref& r) { r.movFrom(Areg::D, Areg::D, dir); });
  }
  // Hand-checked: A = x + 1 (1..127 then 127), moved from the East.
  Ppa ppa;
  Plane ramp(kN);
  for (int i = 0; i < kN; ++i) ramp[i] = static_cast<float>(std::min(i % kWidth + 1, 127));
  ppa.loadAnalog(Areg::A, ramp);
  ppa.movFrom(Areg::B, Areg::A, Dir::East);
  EXPECT_EQ(ppa.analog(Areg::B, 0, 7), 2.0f);
  EXPECT_EQ(ppa.analog(Areg::B, 255, 7), 0.0f);
  ppa.movFrom(Areg::B, Areg::A, Dir::West);
  EXPECT_EQ(ppa.analog(Areg::B, 0, 7), 0.0f);
  EXPECT_EQ(ppa.analog(Areg::B, 5, 7), 5.0f);
}

// Saturation at both ends, and the asymmetric range: -(-128) saturates to 127.
TEST(PpaArray, SaturationAndNegation) {
  Ppa ppa;
  Plane a(kN, 100.0f), b(kN, 90.0f), c(kN, kAnalogMin);
  ppa.loadAnalog(Areg::A, a);
  ppa.loadAnalog(Areg::B, b);
  ppa.loadAnalog(Areg::C, c);
  ppa.bus(Areg::D, Areg::A, Areg::B);  // -(190) -> -128
  EXPECT_EQ(ppa.analog(Areg::D, 3, 4), kAnalogMin);
  ppa.bus(Areg::D, Areg::D);  // -(-128) -> 127
  EXPECT_EQ(ppa.analog(Areg::D, 3, 4), kAnalogMax);
  ppa.add(Areg::E, Areg::A, Areg::B);  // NEWS = -128, E = 127
  EXPECT_EQ(ppa.analog(Areg::E, 0, 0), kAnalogMax);
  ppa.bus(Areg::E, Areg::A);
  EXPECT_EQ(ppa.analog(Areg::E, 0, 0), -100.0f);
  ppa.mov(Areg::E, Areg::C);  // NEWS = 127, E = -127: the chip loses -128
  EXPECT_EQ(ppa.analog(Areg::E, 0, 0), -127.0f);
  ppa.sub(Areg::F, Areg::A, Areg::C);  // 100 - (-128): NEWS = 127, NEWS = -128, F = 127
  EXPECT_EQ(ppa.analog(Areg::F, 9, 9), kAnalogMax);
  ppa.abs(Areg::F, Areg::C);
  EXPECT_EQ(ppa.analog(Areg::F, 9, 9), kAnalogMax);
  ppa.loadAnalog(Areg::A, Plane(kN, 1000.0f));  // loads clamp
  EXPECT_EQ(ppa.analog(Areg::A, 1, 1), kAnalogMax);
}

// where, whereDigital, all and storeFlag set and read FLAG as the reference does.
TEST(PpaArray, FlagInstructions) {
  std::mt19937 rng(7);
  Ppa ppa;
  Ref ref;
  loadRandomAnalog(ppa, ref, rng);
  ppa.where(Areg::B);
  ref.where(Areg::B);
  ppa.storeFlag(Dreg::R3);
  ref.D(Dreg::R3) = ref.flag;
  EXPECT_TRUE(sameState(ppa, ref));
  const Bits bits = randomBits(rng, 0.3);
  ppa.loadDigital(Dreg::R5, pack(bits));
  ref.D(Dreg::R5) = bits;
  ppa.whereDigital(Dreg::R5);
  ref.whereDigital(Dreg::R5);
  ppa.bus(Areg::A, Areg::C);  // written only where R5
  ref.bus(Areg::A, Areg::C);
  EXPECT_TRUE(sameState(ppa, ref));
  ppa.all();
  ref.all();
  ppa.storeFlag(Dreg::R6);
  ref.D(Dreg::R6) = ref.flag;
  ppa.bus(Areg::A, Areg::C);
  ref.bus(Areg::A, Areg::C);
  EXPECT_TRUE(sameState(ppa, ref));
  // A FLAG of all ones made by whereDigital takes the fast path and still writes everywhere.
  ppa.set(Dreg::R7);
  ref.D(Dreg::R7).assign(kN, 1);
  ppa.whereDigital(Dreg::R7);
  ref.whereDigital(Dreg::R7);
  ppa.mov(Areg::D, Areg::E);
  ref.mov(Areg::D, Areg::E);
  EXPECT_TRUE(sameState(ppa, ref));
}

// A long random program of analog instructions and macros, with random FLAGs, never diverges.
TEST(PpaArray, RandomAnalogProgramMatchesReference) {
  std::mt19937 rng(99);
  Ppa ppa;
  Ref ref;
  loadRandomAnalog(ppa, ref, rng);
  auto reg = [&] { return kAregs[rng() % kAregs.size()]; };
  for (int step = 0; step < 150; ++step) {
    const Areg d = reg(), s1 = reg(), s2 = reg();
    const Dir dir = kDirs[rng() % 4];
    const int op = static_cast<int>(rng() % 11);
    switch (op) {
      case 0:
        ppa.bus(d, s1), ref.bus(d, s1);
        break;
      case 1:
        ppa.bus(d, s1, s2), ref.bus(d, s1, s2);
        break;
      case 2:
        ppa.busFrom(d, dir), ref.busFrom(d, dir);
        break;
      case 3:
        ppa.where(s1), ref.where(s1);
        break;
      case 4:
        ppa.all(), ref.all();
        break;
      case 5:
        ppa.mov(d, s1), ref.mov(d, s1);
        break;
      case 6:
        ppa.add(d, s1, s2), ref.add(d, s1, s2);
        break;
      case 7:
        ppa.sub(d, s1, s2), ref.sub(d, s1, s2);
        break;
      case 8:
        ppa.abs(d, s1), ref.abs(d, s1);
        break;
      case 9:
        ppa.movFrom(d, s1, dir), ref.movFrom(d, s1, dir);
        break;
      default: {  // refresh a register so values don't all saturate away
        const Plane p = randomPlane(rng);
        ppa.loadAnalog(d, p);
        ref.A(d) = p;
      }
    }
    ASSERT_TRUE(sameState(ppa, ref)) << "after step " << step << " (op " << op << ")";
  }
}

// Digital logic (set, clr, mov, not, nor, or, and, xor) on random planes, in place too.
TEST(PpaArray, DigitalLogicMatchesReference) {
  std::mt19937 rng(5);
  Ppa ppa;
  Ref ref;
  for (int r = 0; r < kDigitalRegisters; ++r) {
    const Bits b = randomBits(rng, 0.5);
    ppa.loadDigital(static_cast<Dreg>(r), pack(b));
    ref.d[r] = b;
  }
  auto binary = [&](Dreg dst, Dreg x, Dreg y, auto f) {
    Bits out(kN);
    for (int i = 0; i < kN; ++i) out[i] = f(ref.D(x)[i], ref.D(y)[i]) & 1;
    ref.D(dst) = out;
  };
  ppa.orOp(Dreg::R0, Dreg::R1, Dreg::R2);
  binary(Dreg::R0, Dreg::R1, Dreg::R2, [](int a, int b) { return a | b; });
  ppa.andOp(Dreg::R3, Dreg::R4, Dreg::R5);
  binary(Dreg::R3, Dreg::R4, Dreg::R5, [](int a, int b) { return a & b; });
  ppa.xorOp(Dreg::R6, Dreg::R6, Dreg::R7);
  binary(Dreg::R6, Dreg::R6, Dreg::R7, [](int a, int b) { return a ^ b; });
  ppa.nor(Dreg::R8, Dreg::R9, Dreg::R8);
  binary(Dreg::R8, Dreg::R9, Dreg::R8, [](int a, int b) { return !(a | b); });
  ppa.notOp(Dreg::R10, Dreg::R10);
  binary(Dreg::R10, Dreg::R10, Dreg::R10, [](int a, int) { return !a; });
  ppa.mov(Dreg::R11, Dreg::R1);
  ref.D(Dreg::R11) = ref.D(Dreg::R1);
  EXPECT_TRUE(sameState(ppa, ref));
  ppa.set(Dreg::R12);
  ref.D(Dreg::R12).assign(kN, 1);
  ppa.clr(Dreg::R1);
  ref.D(Dreg::R1).assign(kN, 0);
  EXPECT_TRUE(sameState(ppa, ref));
}

// Digital movFrom in all four directions, with edge value 0 and 1, also in place.
TEST(PpaArray, DigitalMovesMatchReference) {
  std::mt19937 rng(11);
  for (Dir dir : kDirs) {
    for (bool edge : {false, true}) {
      Ppa ppa;
      Ref ref;
      const Bits b = randomBits(rng, 0.5);
      ppa.loadDigital(Dreg::R1, pack(b));
      ref.D(Dreg::R1) = b;
      ppa.movFrom(Dreg::R2, Dreg::R1, dir, edge);
      ref.dmovFrom(Dreg::R2, Dreg::R1, dir, edge);
      ppa.movFrom(Dreg::R1, Dreg::R1, dir, edge);
      ref.dmovFrom(Dreg::R1, Dreg::R1, dir, edge);
      EXPECT_TRUE(sameState(ppa, ref)) << "direction " << static_cast<int>(dir) << " edge " << edge;
    }
  }
  // Hand-checked: one PE at x = 63 (a word's last bit) moves across the word boundary.
  Ppa ppa;
  Bits one(kN, 0);
  one[idx(63, 10)] = 1;
  ppa.loadDigital(Dreg::R0, pack(one));
  ppa.movFrom(Dreg::R1, Dreg::R0, Dir::West);  // each PE takes its west neighbour
  EXPECT_TRUE(ppa.digital(Dreg::R1, 64, 10));
  ppa.movFrom(Dreg::R1, Dreg::R1, Dir::East);
  EXPECT_TRUE(ppa.digital(Dreg::R1, 63, 10));
  ppa.movFrom(Dreg::R1, Dreg::R1, Dir::North);  // takes the PE above: moves down
  EXPECT_TRUE(ppa.digital(Dreg::R1, 63, 11));
  EXPECT_EQ(ppa.globalCount(Dreg::R1), 1);
}

// Each instruction and macro adds its documented count; host calls add nothing.
TEST(PpaArray, InstructionCounts) {
  Ppa ppa;
  std::vector<std::uint8_t> light(kN, 10);
  auto cost = [&](const std::function<void()>& f) {
    const std::uint64_t before = ppa.instructions();
    f();
    return ppa.instructions() - before;
  };
  EXPECT_EQ(cost([&] { ppa.setLight(light.data()); }), 0u);
  EXPECT_EQ(cost([&] { ppa.loadAnalog(Areg::A, Plane(kN, 1.0f)); }), 0u);
  EXPECT_EQ(cost([&] { ppa.loadDigital(Dreg::R0, DigitalPlane{}); }), 0u);
  EXPECT_EQ(cost([&] { (void)ppa.analog(Areg::A, 0, 0); }), 0u);
  EXPECT_EQ(cost([&] { ppa.getImage(Areg::A); }), 1u);
  EXPECT_EQ(cost([&] { ppa.bus(Areg::A, Areg::B); }), 1u);
  EXPECT_EQ(cost([&] { ppa.bus(Areg::A, Areg::B, Areg::C); }), 1u);
  EXPECT_EQ(cost([&] { ppa.busFrom(Areg::A, Dir::North); }), 1u);
  EXPECT_EQ(cost([&] { ppa.where(Areg::A); }), 1u);
  EXPECT_EQ(cost([&] { ppa.whereDigital(Dreg::R0); }), 1u);
  EXPECT_EQ(cost([&] { ppa.all(); }), 1u);
  EXPECT_EQ(cost([&] { ppa.mov(Areg::A, Areg::B); }), 2u);
  EXPECT_EQ(cost([&] { ppa.add(Areg::A, Areg::B, Areg::C); }), 2u);
  EXPECT_EQ(cost([&] { ppa.sub(Areg::A, Areg::B, Areg::C); }), 3u);
  EXPECT_EQ(cost([&] { ppa.neg(Areg::A, Areg::B); }), 1u);
  EXPECT_EQ(cost([&] { ppa.abs(Areg::A, Areg::B); }), 6u);
  EXPECT_EQ(cost([&] { ppa.movFrom(Areg::A, Areg::B, Dir::East); }), 2u);
  EXPECT_EQ(cost([&] { ppa.set(Dreg::R0); }), 1u);
  EXPECT_EQ(cost([&] { ppa.clr(Dreg::R0); }), 1u);
  EXPECT_EQ(cost([&] { ppa.mov(Dreg::R0, Dreg::R1); }), 1u);
  EXPECT_EQ(cost([&] { ppa.notOp(Dreg::R0, Dreg::R1); }), 1u);
  EXPECT_EQ(cost([&] { ppa.nor(Dreg::R0, Dreg::R1, Dreg::R2); }), 1u);
  EXPECT_EQ(cost([&] { ppa.orOp(Dreg::R0, Dreg::R1, Dreg::R2); }), 1u);
  EXPECT_EQ(cost([&] { ppa.andOp(Dreg::R0, Dreg::R1, Dreg::R2); }), 2u);
  EXPECT_EQ(cost([&] { ppa.xorOp(Dreg::R0, Dreg::R1, Dreg::R2); }), 3u);
  EXPECT_EQ(cost([&] { ppa.storeFlag(Dreg::R0); }), 1u);
  EXPECT_EQ(cost([&] { ppa.movFrom(Dreg::R0, Dreg::R1, Dir::South, true); }), 1u);
  EXPECT_EQ(cost([&] { ppa.flood(Dreg::R0, Dreg::R1); }), 1u);
  EXPECT_EQ(cost([&] { ppa.flood(Dreg::R0, Dreg::R1, 5); }), 1u);
  EXPECT_EQ(cost([&] { ppa.floodFromBorder(Dreg::R0, Dreg::R1); }), 1u);
  EXPECT_EQ(cost([&] { (void)ppa.globalOr(Dreg::R0); }), 1u);
  EXPECT_EQ(cost([&] { (void)ppa.globalCount(Dreg::R0); }), 1u);
  EXPECT_EQ(cost([&] { (void)ppa.scanEvents(Dreg::R0, 10); }), 1u);
  EXPECT_EQ(cost([&] { (void)ppa.boundingBox(Dreg::R0); }), 1u);
  ppa.resetInstructionCount();
  EXPECT_EQ(ppa.instructions(), 0u);
}

// ---- flood

// A square ring of 0s (side 51 at 100..150) in a mask of 1s.
Bits ringMask() {
  Bits m(kN, 1);
  for (int k = 100; k <= 150; ++k) {
    m[idx(k, 100)] = m[idx(k, 150)] = m[idx(100, k)] = m[idx(150, k)] = 0;
  }
  return m;
}

bool insideRing(int x, int y) { return x > 100 && x < 150 && y > 100 && y < 150; }

// Runs the emulator's flood from `seed` through `mask`; returns the target plane.
Bits ppaFlood(const Bits& seed, const Bits& mask, int iterations = 0) {
  Ppa ppa;
  ppa.loadDigital(Dreg::R1, pack(seed));
  ppa.loadDigital(Dreg::R2, pack(mask));
  ppa.flood(Dreg::R1, Dreg::R2, iterations);
  return unpack(ppa.digitalPlane(Dreg::R1));
}

// The flood from outside an enclosed region fills everything else but never enters it.
TEST(PpaFlood, EnclosedRegionStaysEmpty) {
  const Bits mask = ringMask();
  Bits seed(kN, 0);
  seed[idx(10, 10)] = 1;
  const Bits got = ppaFlood(seed, mask);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const bool want = mask[idx(x, y)] && !insideRing(x, y);
      ASSERT_EQ(got[idx(x, y)] != 0, want) << "at (" << x << ", " << y << ")";
    }
  }
  Bits ref = seed;
  refFlood(ref, mask);
  EXPECT_TRUE(sameBits(got, ref, "flood"));
}

// A gap in the ring lets the flood into the region.
TEST(PpaFlood, OpenRegionIsFilled) {
  Bits mask = ringMask();
  mask[idx(125, 150)] = 1;  // the gap
  Bits seed(kN, 0);
  seed[idx(3, 250)] = 1;
  const Bits got = ppaFlood(seed, mask);
  EXPECT_TRUE(got[idx(125, 125)]);
  EXPECT_TRUE(got[idx(101, 101)]);
  EXPECT_FALSE(got[idx(100, 100)]);
  Bits ref = seed;
  refFlood(ref, mask);
  EXPECT_TRUE(sameBits(got, ref, "flood"));
}

// A region touching the border fills up to the border; a seed outside the mask
// still spreads into its mask neighbours and stays set.
TEST(PpaFlood, RegionTouchingTheBorder) {
  Bits mask(kN, 0);
  for (int y = 0; y < 40; ++y) {
    for (int x = 200; x < kWidth; ++x) mask[idx(x, y)] = 1;  // the top right corner
  }
  Bits seed(kN, 0);
  seed[idx(199, 20)] = 1;  // outside the mask, next to it
  const Bits got = ppaFlood(seed, mask);
  EXPECT_TRUE(got[idx(255, 0)]);
  EXPECT_TRUE(got[idx(200, 39)]);
  EXPECT_TRUE(got[idx(199, 20)]);
  EXPECT_FALSE(got[idx(199, 21)]);
  int count = 0;
  for (auto v : got) count += v;
  EXPECT_EQ(count, 56 * 40 + 1);
}

// A one-PE-wide spiral corridor (ring k at offset 2k) from (0, 0) to the centre.
Bits spiralMask() {
  Bits m(kN, 0);
  const int n = kWidth;
  for (int k = 0; 4 * k + 3 < n; ++k) {
    const int lo = 2 * k, hi = n - 1 - 2 * k;
    for (int x = lo; x <= hi; ++x) m[idx(x, lo)] = 1;      // top, eastwards
    for (int y = lo; y <= hi; ++y) m[idx(hi, y)] = 1;      // right, southwards
    for (int x = lo; x <= hi; ++x) m[idx(x, hi)] = 1;      // bottom, westwards
    for (int y = lo + 2; y <= hi; ++y) m[idx(lo, y)] = 1;  // left, northwards
    if (4 * k + 7 < n) m[idx(lo + 1, lo + 2)] = 1;         // into the next ring
  }
  return m;
}

Bits mirrorX(const Bits& b) {
  Bits out(kN);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) out[idx(x, y)] = b[idx(kWidth - 1 - x, y)];
  }
  return out;
}

// The fast flood along a spiral (a path of tens of thousands of steps, turning
// every way) equals the reference iterated to stability, in both orientations.
TEST(PpaFlood, SpiralMatchesReferenceToStability) {
  for (bool mirrored : {false, true}) {
    const Bits mask = mirrored ? mirrorX(spiralMask()) : spiralMask();
    Bits seed(kN, 0);
    seed[idx(mirrored ? kWidth - 1 : 0, 0)] = 1;
    Bits ref = seed;
    const int steps = refFlood(ref, mask);
    EXPECT_GT(steps, 10000);
    int filled = 0, in_mask = 0;
    for (int i = 0; i < kN; ++i) filled += ref[i], in_mask += mask[i];
    EXPECT_EQ(filled, in_mask) << "the spiral is one corridor";
    EXPECT_TRUE(sameBits(ppaFlood(seed, mask), ref, mirrored ? "mirrored spiral" : "spiral"));
    // From the centre outwards too.
    Bits centre(kN, 0);
    for (int i = kN - 1; i >= 0; --i) {
      if (mask[i] && (i / kWidth) > 100 && (i / kWidth) < 156) {
        centre[i] = 1;
        break;
      }
    }
    Bits ref2 = centre;
    refFlood(ref2, mask);
    EXPECT_TRUE(sameBits(ppaFlood(centre, mask), ref2, "spiral from inside"));
  }
}

// flood with an iteration count does exactly that many steps, on the spiral and
// on a random texture; the frontier reference equals the plain per-PE step.
TEST(PpaFlood, LimitedIterationsMatchReferenceSteps) {
  const Bits spiral = spiralMask();
  Bits seed(kN, 0);
  seed[0] = 1;
  for (int k : {1, 2, 7, 300, 1000}) {
    Bits ref = seed;
    EXPECT_EQ(refFlood(ref, spiral, k), k);
    EXPECT_TRUE(sameBits(ppaFlood(seed, spiral, k), ref, "spiral, " + std::to_string(k)));
  }
  std::mt19937 rng(3);
  const Bits mask = randomBits(rng, 0.65);
  const Bits start = randomBits(rng, 0.002);
  Bits naive = start;
  for (int k = 1; k <= 6; ++k) {
    refFloodStepNaive(naive, mask);
    Bits ref = start;
    refFlood(ref, mask, k);
    ASSERT_TRUE(sameBits(ref, naive, "frontier reference vs naive step " + std::to_string(k)));
    EXPECT_TRUE(sameBits(ppaFlood(start, mask, k), ref, "texture, " + std::to_string(k)));
  }
}

// The fast flood on random textures near the percolation threshold, with seeds
// inside and outside the mask, equals the reference.
TEST(PpaFlood, RandomTexturesMatchReference) {
  std::mt19937 rng(17);
  for (double density : {0.45, 0.59, 0.62, 0.75}) {
    const Bits mask = randomBits(rng, density);
    const Bits seed = randomBits(rng, 0.0005);
    Bits ref = seed;
    refFlood(ref, mask);
    EXPECT_TRUE(sameBits(ppaFlood(seed, mask), ref, "density " + std::to_string(density)));
  }
}

// Rows fill exactly in both directions across word boundaries: isolated rows
// (odd rows empty) of runs and gaps from 1 to 150 PEs, seeded at random.
TEST(PpaFlood, RowFillsMatchReference) {
  std::mt19937 rng(29);
  for (int round = 0; round < 6; ++round) {
    Bits mask(kN, 0), seed(kN, 0);
    for (int y = 0; y < kHeight; y += 2) {
      const int mean_run = std::array<int, 4>{3, 12, 60, 150}[rng() % 4];
      std::geometric_distribution<int> run(1.0 / mean_run), gap(1.0 / (1 + rng() % 10));
      for (int x = static_cast<int>(rng() % 8); x < kWidth;) {
        const int end = std::min(kWidth, x + 1 + run(rng));
        for (; x < end; ++x) mask[idx(x, y)] = 1;
        x += 1 + gap(rng);
      }
      for (int k = static_cast<int>(rng() % 3); k >= 0; --k) seed[idx(rng() % kWidth, y)] = 1;
    }
    Bits ref = seed;
    refFlood(ref, mask);
    ASSERT_TRUE(sameBits(ppaFlood(seed, mask), ref, "round " + std::to_string(round)));
  }
  // Hand-made: the mask is [0, 55] and [60, 255]; a seed at 100 fills [60, 255] only.
  Bits mask(kN, 0), seed(kN, 0);
  for (int x = 0; x < kWidth; ++x) mask[idx(x, 5)] = x <= 55 || x >= 60;
  seed[idx(100, 5)] = 1;
  const Bits got = ppaFlood(seed, mask);
  for (int x = 0; x < kWidth; ++x) EXPECT_EQ(got[idx(x, 5)] != 0, x >= 60) << "x = " << x;
}

// floodFromBorder keeps exactly the mask components touching the border,
// replacing the target's old content.
TEST(PpaFlood, FloodFromBorder) {
  std::mt19937 rng(23);
  std::vector<Bits> masks = {ringMask(),           spiralMask(), randomBits(rng, 0.55),
                             randomBits(rng, 0.6), Bits(kN, 0),  Bits(kN, 1)};
  for (std::size_t k = 0; k < masks.size(); ++k) {
    const Bits& mask = masks[k];
    Bits ref(kN, 0);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const bool border = x == 0 || y == 0 || x == kWidth - 1 || y == kHeight - 1;
        ref[idx(x, y)] = border && mask[idx(x, y)];
      }
    }
    refFlood(ref, mask);
    Ppa ppa;
    ppa.set(Dreg::R4);  // old content must go
    ppa.loadDigital(Dreg::R5, pack(mask));
    ppa.floodFromBorder(Dreg::R4, Dreg::R5);
    EXPECT_TRUE(sameBits(unpack(ppa.digitalPlane(Dreg::R4)), ref, "mask " + std::to_string(k)));
  }
  // With target = mask: floodFromBorder keeps the border components, flood changes nothing.
  {
    const Bits mask = randomBits(rng, 0.6);
    Bits ref(kN, 0);
    for (int i = 0; i < kN; ++i) {
      const int x = i % kWidth, y = i / kWidth;
      ref[i] = mask[i] && (x == 0 || y == 0 || x == kWidth - 1 || y == kHeight - 1);
    }
    refFlood(ref, mask);
    Ppa ppa;
    ppa.loadDigital(Dreg::R5, pack(mask));
    ppa.flood(Dreg::R5, Dreg::R5);
    EXPECT_TRUE(sameBits(unpack(ppa.digitalPlane(Dreg::R5)), mask, "flood(R5, R5)"));
    ppa.floodFromBorder(Dreg::R5, Dreg::R5);
    EXPECT_TRUE(sameBits(unpack(ppa.digitalPlane(Dreg::R5)), ref, "floodFromBorder(R5, R5)"));
  }
  // The ring: outside filled, inside (not touching the border) empty.
  Ppa ppa;
  ppa.loadDigital(Dreg::R5, pack(ringMask()));
  ppa.floodFromBorder(Dreg::R4, Dreg::R5);
  EXPECT_TRUE(ppa.digital(Dreg::R4, 99, 99));
  EXPECT_FALSE(ppa.digital(Dreg::R4, 125, 125));
  EXPECT_EQ(ppa.globalCount(Dreg::R4), kN - 4 * 50 - 49 * 49);
}

// ---- global readouts

// globalOr, globalCount, scanEvents (raster order, max) and boundingBox on sparse,
// empty and full planes.
TEST(PpaArray, GlobalReadouts) {
  std::mt19937 rng(31);
  Ppa ppa;
  EXPECT_FALSE(ppa.globalOr(Dreg::R0));
  EXPECT_EQ(ppa.globalCount(Dreg::R0), 0);
  EXPECT_TRUE(ppa.scanEvents(Dreg::R0, 10).empty());
  EXPECT_FALSE(ppa.boundingBox(Dreg::R0).found);

  const Bits bits = randomBits(rng, 0.001);
  ppa.loadDigital(Dreg::R1, pack(bits));
  std::vector<Event> want;
  int x_min = kWidth, x_max = -1, y_min = kHeight, y_max = -1;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (!bits[idx(x, y)]) continue;
      want.push_back({x, y});
      x_min = std::min(x_min, x), x_max = std::max(x_max, x);
      y_min = std::min(y_min, y), y_max = std::max(y_max, y);
    }
  }
  ASSERT_GT(want.size(), 20u);
  EXPECT_TRUE(ppa.globalOr(Dreg::R1));
  EXPECT_EQ(ppa.globalCount(Dreg::R1), static_cast<int>(want.size()));
  const auto all_events = ppa.scanEvents(Dreg::R1, 100000);
  ASSERT_EQ(all_events.size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) {
    EXPECT_EQ(all_events[k].x, want[k].x);
    EXPECT_EQ(all_events[k].y, want[k].y);
  }
  const auto first = ppa.scanEvents(Dreg::R1, 5);
  ASSERT_EQ(first.size(), 5u);
  EXPECT_EQ(first[4].x, want[4].x);
  EXPECT_EQ(first[4].y, want[4].y);
  EXPECT_TRUE(ppa.scanEvents(Dreg::R1, 0).empty());
  const BoundingBox box = ppa.boundingBox(Dreg::R1);
  EXPECT_TRUE(box.found);
  EXPECT_EQ(box.x_min, x_min);
  EXPECT_EQ(box.x_max, x_max);
  EXPECT_EQ(box.y_min, y_min);
  EXPECT_EQ(box.y_max, y_max);

  // One blob across a word boundary.
  Bits blob(kN, 0);
  for (int y = 30; y <= 33; ++y) {
    for (int x = 60; x <= 130; ++x) blob[idx(x, y)] = 1;
  }
  ppa.loadDigital(Dreg::R2, pack(blob));
  const BoundingBox b2 = ppa.boundingBox(Dreg::R2);
  EXPECT_TRUE(b2.found);
  EXPECT_EQ(b2.x_min, 60);
  EXPECT_EQ(b2.x_max, 130);
  EXPECT_EQ(b2.y_min, 30);
  EXPECT_EQ(b2.y_max, 33);

  ppa.set(Dreg::R3);
  EXPECT_EQ(ppa.globalCount(Dreg::R3), kN);
  const BoundingBox full = ppa.boundingBox(Dreg::R3);
  EXPECT_TRUE(full.found);
  EXPECT_EQ(full.x_min, 0);
  EXPECT_EQ(full.y_min, 0);
  EXPECT_EQ(full.x_max, kWidth - 1);
  EXPECT_EQ(full.y_max, kHeight - 1);
  const auto ev = ppa.scanEvents(Dreg::R3, 300);
  ASSERT_EQ(ev.size(), 300u);
  EXPECT_EQ(ev[255].x, 255);
  EXPECT_EQ(ev[256].x, 0);
  EXPECT_EQ(ev[256].y, 1);
}

// ---- noise and PIX

// Noise of one transfer: mean ~0, sigma within 5 %, ~68.3 % within one sigma,
// uncorrelated between transfers, written only where FLAG = 1.
TEST(PpaNoise, Statistics) {
  PpaParams params;
  params.analog_noise_sigma = 2.0;
  params.noise_seed = 42;
  Ppa ppa(params);
  ppa.bus(Areg::A, Areg::B);  // B = 0, so A is pure noise
  ppa.bus(Areg::C, Areg::B);
  const Plane& a = ppa.analogPlane(Areg::A);
  const Plane& c = ppa.analogPlane(Areg::C);
  for (int half = 0; half < 2; ++half) {  // Box-Muller's two outputs separately
    double sum = 0, sum2 = 0;
    int within = 0;
    const int n = kN / 2;
    for (int i = half * n; i < (half + 1) * n; ++i) {
      sum += a[i];
      sum2 += double(a[i]) * a[i];
      within += std::abs(a[i]) < 2.0f;
    }
    const double mean = sum / n;
    const double sigma = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(mean, 0.0, 0.05) << "half " << half;
    EXPECT_NEAR(sigma, 2.0, 0.1) << "half " << half;
    EXPECT_NEAR(double(within) / n, 0.6827, 0.01) << "half " << half;
  }
  // Uncorrelated between transfers, between neighbouring PEs and between the
  // PEs that share one Box-Muller draw (i and i + kN / 2).
  double cross = 0, next = 0, partner = 0;
  for (int i = 0; i < kN; ++i) cross += double(a[i]) * c[i];
  for (int i = 0; i + 1 < kN; ++i) next += double(a[i]) * a[i + 1];
  for (int i = 0; i < kN / 2; ++i) partner += double(a[i]) * a[i + kN / 2];
  EXPECT_LT(std::abs(cross / kN / 4.0), 0.02);
  EXPECT_LT(std::abs(next / kN / 4.0), 0.02);
  EXPECT_LT(std::abs(partner / (kN / 2) / 4.0), 0.03);
  // Only flagged PEs get written (and so get noise).
  Bits half_flag(kN, 0);
  for (int i = 0; i < kN / 2; ++i) half_flag[i] = 1;
  ppa.loadDigital(Dreg::R0, pack(half_flag));
  ppa.whereDigital(Dreg::R0);
  ppa.bus(Areg::D, Areg::B);
  int noisy_outside = 0, noisy_inside = 0;
  for (int i = 0; i < kN; ++i)
    (i < kN / 2 ? noisy_inside : noisy_outside) += ppa.analogPlane(Areg::D)[i] != 0.0f;
  EXPECT_EQ(noisy_outside, 0);
  EXPECT_GT(noisy_inside, kN / 2 - 10);
}

// The same seed and program give the same noise; another seed gives other noise.
TEST(PpaNoise, Deterministic) {
  auto run = [](std::uint64_t seed) {
    PpaParams params;
    params.analog_noise_sigma = 1.5;
    params.noise_seed = seed;
    Ppa ppa(params);
    ppa.mov(Areg::A, Areg::B);
    ppa.sub(Areg::C, Areg::A, Areg::B);
    ppa.abs(Areg::D, Areg::C);
    return ppa.analogPlane(Areg::D);
  };
  const Plane first = run(7);
  EXPECT_TRUE(samePlane(run(7), first, "same seed"));
  const Plane other = run(8);
  int differ = 0;
  for (int i = 0; i < kN; ++i) differ += other[i] != first[i];
  EXPECT_GT(differ, kN * 9 / 10);
}

// PIX linear and log responses at hand-computed values.
TEST(PpaPix, LinearAndLogResponses) {
  std::vector<std::uint8_t> light(kN, 0);
  light[idx(1, 0)] = 3;
  light[idx(2, 0)] = 15;
  light[idx(3, 0)] = 100;
  light[idx(4, 0)] = 200;
  light[idx(5, 0)] = 255;
  auto response = [&](const std::string& kind, double gain, int x) {
    PpaParams params;
    params.pix_response = kind;
    params.pix_gain = gain;
    Ppa ppa(params);
    ppa.setLight(light.data());
    ppa.getImage(Areg::E);
    return ppa.analog(Areg::E, x, 0);
  };
  EXPECT_FLOAT_EQ(response("linear", 1.0, 0), 0.0f);
  EXPECT_FLOAT_EQ(response("linear", 1.0, 3), 100.0f);
  EXPECT_FLOAT_EQ(response("linear", 1.0, 4), 127.0f);  // saturates
  EXPECT_FLOAT_EQ(response("linear", 0.5, 4), 100.0f);
  EXPECT_FLOAT_EQ(response("log", 1.0, 0), 0.0f);
  EXPECT_NEAR(response("log", 1.0, 1), 31.75f, 1e-4);  // 127 ln 4 / ln 256
  EXPECT_NEAR(response("log", 1.0, 2), 63.5f, 1e-4);   // 127 ln 16 / ln 256
  EXPECT_NEAR(response("log", 1.0, 5), 127.0f, 1e-4);
  // gain 3: 127 ln(1 + 3 * 100) / ln(1 + 3 * 255)
  EXPECT_NEAR(response("log", 3.0, 3), 127.0 * std::log(301.0) / std::log(766.0), 1e-4);
}

// Bad parameters and out-of-range accesses are refused with a clear exception.
TEST(PpaArray, RejectsBadInput) {
  PpaParams bad_response;
  bad_response.pix_response = "gamma";
  EXPECT_THROW(Ppa{bad_response}, std::invalid_argument);
  PpaParams bad_sigma;
  bad_sigma.analog_noise_sigma = -1.0;
  EXPECT_THROW(Ppa{bad_sigma}, std::invalid_argument);
  PpaParams bad_gain;
  bad_gain.pix_gain = 0.0;
  EXPECT_THROW(Ppa{bad_gain}, std::invalid_argument);
  Ppa ppa;
  EXPECT_THROW((void)ppa.analog(Areg::A, 256, 0), std::out_of_range);
  EXPECT_THROW((void)ppa.digital(Dreg::R0, 0, -1), std::out_of_range);
  EXPECT_THROW(ppa.loadAnalog(Areg::A, Plane(10, 0.0f)), std::invalid_argument);
}

}  // namespace
}  // namespace nadir::ppa
