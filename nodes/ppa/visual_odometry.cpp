#include "nodes/ppa/visual_odometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

namespace nadir::ppa {

namespace {

// Digital registers (see ppa_kernels.h): R7..R12 persist; R0..R6 are this frame's.
constexpr Dreg kEdges = Dreg::R6;
constexpr Dreg kMovedEdges = Dreg::R5;  // E_u
constexpr Dreg kMoved = Dreg::R0;       // the moved copies of a family
constexpr Dreg kMask = Dreg::R1;        // a band
constexpr Dreg kAnd = Dreg::R2;         // overlaps to count
constexpr Dreg kStage = Dreg::R3;       // between two families of a render
constexpr double kCentre = (kWidth - 1) / 2.0;
static_assert(kWidth == kHeight, "the shift families assume a square array");

// out(z) = in(z + f(z)) along x (shift_x) or y, f(z) = round(slope (z - c))
// with z the row (by_row: a shear, every row moves rigidly) or the column
// (a stretch). f is monotonic, so the z where f = k form one band of rows or
// columns: out is the OR over k of (in moved k PEs) AND band_k, the moved
// copies made one move at a time outwards from k = 0. 5 instructions per k.
void shiftFamily(Program& program, Dreg in, Dreg out, bool shift_x, bool by_row, double slope) {
  Ppa& ppa = program.ppa();
  std::array<int, kWidth> f{};
  int f_min = 0, f_max = 0;
  for (int z = 0; z < kWidth; ++z) {
    f[z] = static_cast<int>(std::lround(slope * (z - kCentre)));
    f_min = std::min(f_min, f[z]);
    f_max = std::max(f_max, f[z]);
  }
  const auto loadBand = [&](int k) {
    const int z0 = static_cast<int>(std::find(f.begin(), f.end(), k) - f.begin());
    int z1 = z0;
    while (z1 + 1 < kWidth && f[z1 + 1] == k) ++z1;
    if (by_row) {
      program.loadRect(kMask, 0, z0, kWidth - 1, z1);
    } else {
      program.loadRect(kMask, z0, 0, z1, kHeight - 1);
    }
  };
  loadBand(0);  // |slope| < 1: the middle rows or columns never move
  ppa.andOp(out, in, kMask);
  for (const int sign : {1, -1}) {
    const Dir from =
        shift_x ? (sign > 0 ? Dir::East : Dir::West) : (sign > 0 ? Dir::South : Dir::North);
    for (int k = 1; k <= (sign > 0 ? f_max : -f_min); ++k) {
      ppa.movFrom(kMoved, k == 1 ? in : kMoved, from);
      loadBand(sign * k);
      ppa.andOp(kMask, kMask, kMoved);
      ppa.orOp(out, out, kMask);
    }
  }
}

// True if the family moves anything.
bool moves(double slope) { return std::lround(slope * (kWidth - 1 - kCentre)) != 0; }

}  // namespace

void VisualOdometryParams::visit(core::ParamVisitor& v) {
  v.field("edge_threshold", &edge_threshold,
          {.doc = "an edge PE is brighter than a 4-neighbour by more than this, PIX counts",
           .min = 0.0,
           .max = 255.0});
  v.field("edge_denoise", &edge_denoise,
          {.doc = "drop edge PEs without an edge among their 4 neighbours"});
  v.field("keyframe_strength", &keyframe_strength,
          {.doc = "new key-frame when the aligned strength (shared / key-frame edges) is below",
           .min = 0.0,
           .max = 1.0});
  v.field("max_iterations", &max_iterations,
          {.doc = "alignment iterations (four pairs each) per frame", .min = 1, .max = 1000});
  v.field("rotation_step_rad", &rotation_step_rad,
          {.doc = "rotation of one adjustment, rad", .min = 1e-4, .max = 0.1});
  v.field("scale_step", &scale_step,
          {.doc = "scaling of one adjustment (0.005: 0.5 %)", .min = 1e-4, .max = 0.1});
  v.field("max_rotation_rad", &max_rotation_rad,
          {.doc = "largest rotation searched, rad", .min = 0.0, .max = 0.5});
  v.field("max_scale_change", &max_scale_change,
          {.doc = "largest |scale - 1| searched", .min = 0.0, .max = 0.4});
  v.field("max_translation_px", &max_translation_px,
          {.doc = "largest translation searched, px", .min = 0, .max = 255});
}

VisualOdometry::VisualOdometry(const VisualOdometryParams& params) : params_(params) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "ppa visual odometry");
  for (int i = 0; i < 5; ++i) slots_[i].reg = kRegWarpedKeyframes[i];
}

void VisualOdometry::reset() {
  has_keyframe_ = false;
  keyframe_count_ = 0;
  transform_ = {};
  for (Slot& slot : slots_) slot.valid = false;
}

bool VisualOdometry::inLimits(int kr, int ks) const {
  const double rotation = std::abs(kr * params_.rotation_step_rad);
  const double scale = std::pow(1.0 + params_.scale_step, ks);
  return rotation <= params_.max_rotation_rad + 1e-12 &&
         std::abs(scale - 1.0) <= params_.max_scale_change + 1e-12;
}

void VisualOdometry::extractEdges(Program& program) {
  Ppa& ppa = program.ppa();
  // PE p is an edge when A(p) - A(n) - threshold > 0 for a 4-neighbour n: the
  // bright side of every step of more than the threshold. Two transfers per
  // direction: C = A(n) from the neighbour's NEWS, D = -(C + B), B = threshold - A.
  ppa.all();
  ppa.getImage(Areg::A);
  program.loadConstant(Areg::F, static_cast<float>(-params_.edge_threshold));
  ppa.bus(Areg::NEWS, Areg::A);        // NEWS = -A
  ppa.bus(Areg::B, Areg::A, Areg::F);  // B = threshold - A
  ppa.busFrom(Areg::C, Dir::East);     // C = A(east)
  ppa.bus(Areg::D, Areg::C, Areg::B);  // D = A - A(east) - threshold
  ppa.busFrom(Areg::C, Dir::West);
  ppa.bus(Areg::E, Areg::C, Areg::B);
  ppa.where(Areg::D);
  ppa.storeFlag(Dreg::R0);
  ppa.where(Areg::E);
  ppa.storeFlag(Dreg::R1);
  ppa.all();
  ppa.busFrom(Areg::C, Dir::South);
  ppa.bus(Areg::D, Areg::C, Areg::B);
  ppa.busFrom(Areg::C, Dir::North);
  ppa.bus(Areg::E, Areg::C, Areg::B);
  ppa.where(Areg::D);
  ppa.storeFlag(Dreg::R2);
  ppa.where(Areg::E);
  ppa.storeFlag(Dreg::R3);
  ppa.all();
  ppa.orOp(Dreg::R0, Dreg::R0, Dreg::R1);
  ppa.orOp(Dreg::R2, Dreg::R2, Dreg::R3);
  ppa.orOp(kEdges, Dreg::R0, Dreg::R2);
  // Beyond the array a neighbour reads 0, so the border PEs are not edges.
  program.loadRect(Dreg::R1, 1, 1, kWidth - 2, kHeight - 2);
  ppa.andOp(kEdges, kEdges, Dreg::R1);
  if (params_.edge_denoise) {
    ppa.movFrom(Dreg::R0, kEdges, Dir::North);
    ppa.movFrom(Dreg::R1, kEdges, Dir::South);
    ppa.orOp(Dreg::R0, Dreg::R0, Dreg::R1);
    ppa.movFrom(Dreg::R1, kEdges, Dir::East);
    ppa.orOp(Dreg::R0, Dreg::R0, Dreg::R1);
    ppa.movFrom(Dreg::R1, kEdges, Dir::West);
    ppa.orOp(Dreg::R0, Dreg::R0, Dreg::R1);
    ppa.andOp(kEdges, kEdges, Dreg::R0);
  }
}

void VisualOdometry::makeKeyframe(Program& program) {
  Ppa& ppa = program.ppa();
  ppa.mov(kRegKeyframe, kEdges);
  keyframe_count_ = ppa.globalCount(kRegKeyframe);
  has_keyframe_ = true;
  transform_ = {};
  for (Slot& slot : slots_) slot.valid = false;
}

void VisualOdometry::moveEdges(Program& program, int ux, int uy) {
  if (ux == eu_x_ && uy == eu_y_) return;
  // Moving E_u on loses nothing while |u| grows along each axis; otherwise
  // what it lost at the border must come back from E.
  const int dx = ux - eu_x_, dy = uy - eu_y_;
  if (eu_x_ * dx >= 0 && eu_y_ * dy >= 0) {
    translate(program, kMovedEdges, kMovedEdges, dx, dy);
  } else {
    translate(program, kMovedEdges, kEdges, ux, uy);
  }
  eu_x_ = ux;
  eu_y_ = uy;
  ++eu_version_;
}

void VisualOdometry::renderInto(Program& program, Dreg dst, int kr, int ks) {
  // G(q) = K(c + M (q - c)), M = s R(theta) = [[1 + a, -b], [b, 1 + a]].
  const double theta = kr * params_.rotation_step_rad;
  const double s = std::pow(1.0 + params_.scale_step, ks);
  const double a = s * std::cos(theta) - 1.0;
  const double b = s * std::sin(theta);
  // The x pull acts on K's rows before the y pull gathers them, so it is
  // written in K's row y' = y + v: u = a (x - c) - b (y - c) with
  // y - c = (y' - c - b (x - c)) / (1 + a); v = b (x - c) + a (y - c).
  const double ux = a + b * b / (1.0 + a);
  const double uy = -b / (1.0 + a);
  // Four families, K -> ... -> dst, through kStage; those that move nothing are skipped.
  struct Family {
    bool shift_x, by_row;
    double slope;
  };
  std::array<Family, 4> families = {
      {{true, true, uy}, {true, false, ux}, {false, false, b}, {false, true, a}}};
  const auto end = std::remove_if(families.begin(), families.end(),
                                  [](const Family& family) { return !moves(family.slope); });
  const int n = static_cast<int>(end - families.begin());
  if (n == 0) {
    program.ppa().mov(dst, kRegKeyframe);
    return;
  }
  // The last family writes dst; the one before kStage, and so on backwards.
  Dreg in = kRegKeyframe;
  for (int i = 0; i < n; ++i) {
    const Dreg out = (n - 1 - i) % 2 == 0 ? dst : kStage;
    shiftFamily(program, in, out, families[i].shift_x, families[i].by_row, families[i].slope);
    in = out;
  }
}

VisualOdometry::Slot& VisualOdometry::render(Program& program, int kr, int ks, const Slot* keep) {
  for (Slot& slot : slots_) {
    if (slot.valid && slot.kr == kr && slot.ks == ks) {
      slot.used = ++use_counter_;
      return slot;
    }
  }
  // Evict what the next adjustments will not ask for: the current transform's
  // four neighbours stay while possible.
  const auto wanted = [this](const Slot& slot) {
    const int dr = std::abs(slot.kr - transform_.kr), ds = std::abs(slot.ks - transform_.ks);
    return dr + ds <= 1;
  };
  Slot* victim = nullptr;
  for (Slot& slot : slots_) {
    if (&slot == keep) continue;
    if (slot.valid && slot.kr == transform_.kr && slot.ks == transform_.ks) continue;
    const auto rank = [&](const Slot& s) { return !s.valid ? 0 : !wanted(s) ? 1 : 2; };
    if (victim == nullptr || rank(slot) < rank(*victim) ||
        (rank(slot) == rank(*victim) && slot.used < victim->used)) {
      victim = &slot;
    }
  }
  renderInto(program, victim->reg, kr, ks);
  victim->valid = true;
  victim->kr = kr;
  victim->ks = ks;
  victim->eu_version = ~std::uint64_t{0};
  victim->used = ++use_counter_;
  return *victim;
}

int VisualOdometry::slotScore(Program& program, Slot& slot) {
  if (slot.eu_version != eu_version_) {
    slot.score = countAnd(program, slot.reg, kMovedEdges, kAnd);
    slot.eu_version = eu_version_;
  }
  return slot.score;
}

VisualOdometryResult VisualOdometry::processFrame(Ppa& ppa) {
  Program program(ppa);
  VisualOdometryResult result;
  extractEdges(program);
  result.edge_count = ppa.globalCount(kEdges);

  if (!has_keyframe_) {
    makeKeyframe(program);
    result.strength = keyframe_count_ > 0 ? 1.0 : 0.0;
    result.new_keyframe = true;
    result.keyframe_edge_count = keyframe_count_;
    result.instructions = program.instructions();
    return result;
  }

  // This frame's E_u, from E.
  translate(program, kMovedEdges, kEdges, transform_.ux, transform_.uy);
  eu_x_ = transform_.ux;
  eu_y_ = transform_.uy;
  ++eu_version_;
  Slot* current = &render(program, transform_.kr, transform_.ks, nullptr);
  int best = slotScore(program, *current);

  // A translation candidate: E_u moved one PE more (content by +1 along the axis).
  const auto translated_score = [&](Dir from) {
    ppa.movFrom(kAnd, kMovedEdges, from);
    ppa.andOp(kAnd, kAnd, current->reg);
    return ppa.globalCount(kAnd);
  };
  const int max_u = params_.max_translation_px;

  int iteration = 0;
  while (iteration < params_.max_iterations) {
    ++iteration;
    bool improved = false;

    // Left / right, then up / down.
    for (const bool along_x : {true, false}) {
      int& u = along_x ? transform_.ux : transform_.uy;
      const int plus = u + 1 <= max_u ? translated_score(along_x ? Dir::West : Dir::North) : -1;
      const int minus = u - 1 >= -max_u ? translated_score(along_x ? Dir::East : Dir::South) : -1;
      const int score = std::max(plus, minus);
      if (score > best) {
        best = score;
        u += plus >= minus ? 1 : -1;
        moveEdges(program, transform_.ux, transform_.uy);
        current->score = best;
        current->eu_version = eu_version_;
        improved = true;
      }
    }

    // Clockwise / anti-clockwise, then larger / smaller: warped key-frames,
    // rendered from K once and kept while the key-frame lasts.
    for (const bool rotation : {true, false}) {
      Slot* candidates[2] = {nullptr, nullptr};
      int scores[2] = {-1, -1};
      for (int i = 0; i < 2; ++i) {
        const int step = i == 0 ? 1 : -1;
        const int kr = transform_.kr + (rotation ? step : 0);
        const int ks = transform_.ks + (rotation ? 0 : step);
        if (!inLimits(kr, ks)) continue;
        candidates[i] = &render(program, kr, ks, i == 1 ? candidates[0] : current);
        scores[i] = slotScore(program, *candidates[i]);
      }
      const int i = scores[0] >= scores[1] ? 0 : 1;
      if (candidates[i] != nullptr && scores[i] > best) {
        best = scores[i];
        current = candidates[i];
        transform_.kr = current->kr;
        transform_.ks = current->ks;
        improved = true;
      }
    }
    if (!improved) break;
  }

  // T(q) = c + M (q + u - c) = c + M u + M (q - c).
  const double theta = transform_.kr * params_.rotation_step_rad;
  const double s = std::pow(1.0 + params_.scale_step, transform_.ks);
  result.iterations = iteration;
  result.translation_x_px = s * (std::cos(theta) * transform_.ux - std::sin(theta) * transform_.uy);
  result.translation_y_px = s * (std::sin(theta) * transform_.ux + std::cos(theta) * transform_.uy);
  result.rotation_rad = theta;
  result.scale = s;
  result.strength = keyframe_count_ > 0 ? static_cast<double>(best) / keyframe_count_ : 0.0;
  if (result.strength < params_.keyframe_strength) {
    makeKeyframe(program);
    result.new_keyframe = true;
  }
  result.keyframe_edge_count = keyframe_count_;
  result.instructions = program.instructions();
  return result;
}

}  // namespace nadir::ppa
