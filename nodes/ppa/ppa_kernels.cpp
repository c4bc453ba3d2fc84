#include "nodes/ppa/ppa_kernels.h"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <stdexcept>

namespace nadir::ppa {

namespace {

constexpr std::uint64_t kOnes = ~std::uint64_t{0};

// Bits [lo, hi] (inclusive, within 0..63) of a word.
std::uint64_t bitRange(int lo, int hi) {
  const std::uint64_t upto_hi = hi >= 63 ? kOnes : (std::uint64_t{1} << (hi + 1)) - 1;
  return upto_hi & (kOnes << lo);
}

}  // namespace

void Program::loadConstant(Areg dst, float value) {
  // A plane per value, made once per thread: the host side of `in`.
  thread_local std::map<float, std::vector<float>> planes;
  auto it = planes.find(value);
  if (it == planes.end()) {
    if (planes.size() >= 16) planes.clear();
    it = planes.emplace(value, std::vector<float>(kWidth * kHeight, value)).first;
  }
  ppa_.loadAnalog(dst, it->second);
  ++controller_;
}

void Program::loadRect(Dreg dst, int x_min, int y_min, int x_max, int y_max) {
  x_min = std::max(x_min, 0);
  y_min = std::max(y_min, 0);
  x_max = std::min(x_max, kWidth - 1);
  y_max = std::min(y_max, kHeight - 1);
  DigitalPlane plane{};
  if (x_min <= x_max && y_min <= y_max) {
    std::uint64_t row[kWordsPerRow] = {};
    for (int w = 0; w < kWordsPerRow; ++w) {
      const int lo = std::max(x_min - 64 * w, 0);
      const int hi = std::min(x_max - 64 * w, 63);
      if (lo <= hi) row[w] = bitRange(lo, hi);
    }
    for (int y = y_min; y <= y_max; ++y) {
      std::copy(row, row + kWordsPerRow, plane.begin() + y * kWordsPerRow);
    }
  }
  ppa_.loadDigital(dst, plane);
  ++controller_;
}

void Program::loadPoint(Dreg dst, int x, int y) {
  DigitalPlane plane{};
  if (x >= 0 && x < kWidth && y >= 0 && y < kHeight) {
    plane[y * kWordsPerRow + x / 64] = std::uint64_t{1} << (x % 64);
  }
  ppa_.loadDigital(dst, plane);
  ++controller_;
}

void translate(Program& program, Dreg dst, Dreg src, int dx, int dy) {
  Ppa& ppa = program.ppa();
  if (dx == 0 && dy == 0) {
    if (dst != src) ppa.mov(dst, src);
    return;
  }
  Dreg from = src;
  // Content moving right takes each PE's value from its west neighbour.
  for (int i = 0; i < std::abs(dx); ++i, from = dst) {
    ppa.movFrom(dst, from, dx > 0 ? Dir::West : Dir::East);
  }
  for (int i = 0; i < std::abs(dy); ++i, from = dst) {
    ppa.movFrom(dst, from, dy > 0 ? Dir::North : Dir::South);
  }
}

void denoiseAnd4(Program& program, Dreg dst, Dreg src, int step, Dreg tmp) {
  if (dst == src || dst == tmp || src == tmp) {
    throw std::invalid_argument("denoiseAnd4: dst, src and tmp must differ");
  }
  Ppa& ppa = program.ppa();
  translate(program, dst, src, 0, -step);  // moved north
  translate(program, tmp, src, 0, step);   // moved south
  ppa.andOp(dst, dst, tmp);
  translate(program, tmp, src, -step, 0);  // moved west
  ppa.andOp(dst, dst, tmp);
  translate(program, tmp, src, step, 0);  // moved east
  ppa.andOp(dst, dst, tmp);
}

int countAnd(Program& program, Dreg a, Dreg b, Dreg tmp) {
  program.ppa().andOp(tmp, a, b);
  return program.ppa().globalCount(tmp);
}

void binariseDark(Program& program, Dreg dst, double threshold_counts) {
  Ppa& ppa = program.ppa();
  ppa.all();
  ppa.getImage(Areg::A);
  program.loadConstant(Areg::F, static_cast<float>(-threshold_counts));
  ppa.bus(Areg::B, Areg::A, Areg::F);  // B = threshold - A
  ppa.where(Areg::B);
  ppa.storeFlag(dst);
  ppa.all();
}

void floodAndInvert(Program& program, Dreg dst, Dreg bright, int boundaries, Dreg tmp) {
  if (dst == bright || dst == tmp || bright == tmp) {
    throw std::invalid_argument("floodAndInvert: dst, bright and tmp must differ");
  }
  Ppa& ppa = program.ppa();
  // S_0 = bright. Each round: R = the part of S reached from the border; what
  // is left (S & !R) lies inside one more boundary; its inverse !S | R is the
  // next round's S.
  for (int k = 1; k <= boundaries; ++k) {
    ppa.floodFromBorder(tmp, bright);
    ppa.notOp(bright, bright);
    if (k < boundaries) {
      ppa.orOp(bright, bright, tmp);
    } else {
      ppa.nor(dst, bright, tmp);  // S & !R = !(!S | R)
    }
  }
}

std::vector<BoundingBox> extractComponents(Program& program, Dreg plane, Dreg point, Dreg tmp,
                                           int max_components) {
  Ppa& ppa = program.ppa();
  std::vector<BoundingBox> boxes;
  while (static_cast<int>(boxes.size()) < max_components) {
    const std::vector<Event> events = ppa.scanEvents(plane, 1);
    if (events.empty()) break;
    program.loadPoint(point, events[0].x, events[0].y);
    ppa.flood(point, plane);
    boxes.push_back(ppa.boundingBox(point));
    ppa.notOp(tmp, plane);
    ppa.nor(plane, tmp, point);  // plane & !component
  }
  return boxes;
}

}  // namespace nadir::ppa
