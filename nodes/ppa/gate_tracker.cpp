#include "nodes/ppa/gate_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "nodes/ppa/ppa_kernels.h"

namespace nadir::ppa {

namespace {

constexpr Dreg kDark = Dreg::R0;
constexpr Dreg kBright = Dreg::R1;
constexpr Dreg kTmp = Dreg::R2;
constexpr Dreg kInner = Dreg::R3;
constexpr Dreg kPoint = Dreg::R4;
constexpr Dreg kDisks = Dreg::R5;
constexpr Dreg kPattern = Dreg::R6;

std::array<double, 2> centre(const BoundingBox& box) {
  return {0.5 * (box.x_min + box.x_max), 0.5 * (box.y_min + box.y_max)};
}

int side(const BoundingBox& box) {
  return std::max(box.x_max - box.x_min, box.y_max - box.y_min) + 1;
}

BoundingBox unite(const std::vector<BoundingBox>& boxes) {
  BoundingBox all = boxes.front();
  for (const BoundingBox& b : boxes) {
    all.x_min = std::min(all.x_min, b.x_min);
    all.y_min = std::min(all.y_min, b.y_min);
    all.x_max = std::max(all.x_max, b.x_max);
    all.y_max = std::max(all.y_max, b.y_max);
  }
  return all;
}

}  // namespace

const char* patternKindName(PatternKind kind) {
  switch (kind) {
    case PatternKind::kGate:
      return "gate";
    case PatternKind::kSlalomLeft:
      return "slalom_left";
    case PatternKind::kSlalomRight:
      return "slalom_right";
    default:
      return "none";
  }
}

void GateTrackerParams::visit(core::ParamVisitor& v) {
  v.field("threshold", &threshold,
          {.doc = "PIX counts below which a PE is dark", .min = -128.0, .max = 127.0});
  v.field("boundaries", &boundaries,
          {.doc = "boundaries around the disks on a bright surround", .min = 2, .max = 64});
  v.field(
      "denoise_step", &denoise_step,
      {.doc = "de-noising shift (Liu et al.'s (2021) P_step), PEs; 0: off", .min = 0, .max = 16});
  v.field("min_disk_px", &min_disk_px,
          {.doc = "smallest disk bounding box side, px", .min = 1, .max = 256});
  v.field("max_disk_px", &max_disk_px,
          {.doc = "largest disk bounding box side, px", .min = 1, .max = 256});
  v.field("max_components", &max_components,
          {.doc = "components examined per frame at most", .min = 4, .max = 1000});
  v.field("max_recovery_frames", &max_recovery_frames,
          {.doc = "frames the previous centres may stand in for broken squares; 0: never",
           .min = 0,
           .max = 10000});
  v.field("max_recovery_shift_px", &max_recovery_shift_px,
          {.doc = "how far a recovered disk may lie from its previous centre, px",
           .min = 0.5,
           .max = 256});
}

PatternKind classifyDisks(const std::vector<BoundingBox>& disks, GateResult& result) {
  const std::size_t n = disks.size();
  if (n != 3 && n != 4) return PatternKind::kNone;
  int smallest = side(disks.front()), largest = smallest;
  for (const BoundingBox& d : disks) {
    smallest = std::min(smallest, side(d));
    largest = std::max(largest, side(d));
  }
  // One pattern's disks are one size, give or take what perspective does.
  if (largest > 2 * smallest + 1) return PatternKind::kNone;
  std::vector<std::array<double, 2>> c;
  for (const BoundingBox& d : disks) c.push_back(centre(d));
  std::vector<std::array<double, 2>> ordered;
  PatternKind kind = PatternKind::kNone;
  if (n == 4) {
    std::vector<int> index = {0, 1, 2, 3};
    std::sort(index.begin(), index.end(), [&](int a, int b) { return c[a][1] < c[b][1]; });
    const auto by_x = [&](int a, int b) { return c[a][0] < c[b][0]; };
    std::sort(index.begin(), index.begin() + 2, by_x);
    std::sort(index.begin() + 2, index.end(), by_x);
    const auto& tl = c[index[0]];
    const auto& tr = c[index[1]];
    const auto& bl = c[index[2]];
    const auto& br = c[index[3]];
    const double row_gap = 0.5 * (bl[1] + br[1] - tl[1] - tr[1]);
    const double column_gap = 0.5 * (tr[0] + br[0] - tl[0] - bl[0]);
    // Two rows and two columns, each clearly apart and each roughly straight.
    const bool grid =
        row_gap > 0.5 * smallest && column_gap > 0.5 * smallest &&
        std::abs(tl[1] - tr[1]) < 0.5 * row_gap && std::abs(bl[1] - br[1]) < 0.5 * row_gap &&
        std::abs(tl[0] - bl[0]) < 0.5 * column_gap && std::abs(tr[0] - br[0]) < 0.5 * column_gap;
    if (!grid) return PatternKind::kNone;
    kind = PatternKind::kGate;
    ordered = {tl, tr, bl, br};
  } else {
    for (int tip = 0; tip < 3 && kind == PatternKind::kNone; ++tip) {
      const auto& a = c[(tip + 1) % 3];
      const auto& b = c[(tip + 2) % 3];
      const auto& t = c[tip];
      const double column_dy = std::abs(a[1] - b[1]);
      const double column_x = 0.5 * (a[0] + b[0]);
      const bool column = column_dy > 0.5 * smallest && std::abs(a[0] - b[0]) < 0.3 * column_dy;
      const bool beside = std::abs(t[0] - column_x) > 0.5 * column_dy &&
                          t[1] > std::min(a[1], b[1]) && t[1] < std::max(a[1], b[1]);
      if (column && beside) {
        kind = t[0] > column_x ? PatternKind::kSlalomRight : PatternKind::kSlalomLeft;
        ordered = a[1] < b[1] ? std::vector{a, b, t} : std::vector{b, a, t};
      }
    }
    if (kind == PatternKind::kNone) return kind;
  }
  result.kind = kind;
  result.box = unite(disks);
  result.num_disks = static_cast<int>(n);
  result.disk_centres_px = {};
  for (std::size_t i = 0; i < ordered.size(); ++i) result.disk_centres_px[i] = ordered[i];
  return kind;
}

GateTracker::GateTracker(const GateTrackerParams& params) : params_(params) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "ppa gate tracker");
  if (params_.min_disk_px > params_.max_disk_px) {
    throw core::ParamError("ppa gate tracker: min_disk_px exceeds max_disk_px");
  }
}

void GateTracker::reset() {
  previous_ = GateResult{};
  frames_since_found_ = 0;
}

bool GateTracker::isDisk(const BoundingBox& box) const {
  if (!box.found) return false;
  const int w = box.x_max - box.x_min + 1;
  const int h = box.y_max - box.y_min + 1;
  return std::min(w, h) >= params_.min_disk_px && std::max(w, h) <= params_.max_disk_px &&
         std::max(w, h) <= 2 * std::min(w, h) + 1;
}

GateResult GateTracker::processFrame(Ppa& ppa) {
  Program program(ppa);
  GateResult result;
  std::uint64_t mark = 0;
  auto clock_mark = std::chrono::steady_clock::now();
  std::size_t stage_index = 0;
  const auto stage = [&](std::uint64_t& into) {
    into += program.instructions() - mark;
    mark = program.instructions();
    const auto now = std::chrono::steady_clock::now();
    result.host_ns[stage_index++] =
        std::chrono::duration<double, std::nano>(now - clock_mark).count();
    clock_mark = now;
  };

  binariseDark(program, kDark, params_.threshold);
  stage(result.stages.threshold);
  // What lies inside boundaries - 1 boundaries: each pattern's inner area,
  // bright, with holes; the holes (what the border cannot reach around it)
  // are the disks, and the areas with their holes filled the patterns.
  ppa.notOp(kBright, kDark);
  floodAndInvert(program, kInner, kBright, params_.boundaries - 1, kTmp);
  ppa.notOp(kBright, kInner);
  ppa.floodFromBorder(kTmp, kBright);
  ppa.nor(kPattern, kInner, kTmp);
  ppa.orOp(kInner, kInner, kPattern);
  stage(result.stages.flood);
  if (params_.denoise_step > 0) {
    denoiseAnd4(program, kDisks, kPattern, params_.denoise_step, kTmp);
  } else {
    ppa.mov(kDisks, kPattern);
  }
  stage(result.stages.denoise);

  // One pattern at a time; the largest wins: the nearest board, the one to
  // steer by now (a farther one comes next).
  std::vector<GateResult> found;
  const std::vector<BoundingBox> areas =
      extractComponents(program, kInner, kPoint, kTmp, params_.max_components);
  for (const BoundingBox& area : areas) {
    if (std::min(area.x_max - area.x_min, area.y_max - area.y_min) + 1 < 2 * params_.min_disk_px) {
      continue;
    }
    program.loadRect(kPattern, area.x_min, area.y_min, area.x_max, area.y_max);
    ppa.andOp(kPattern, kPattern, kDisks);
    std::vector<BoundingBox> disks;
    bool all_disks = true;
    for (const BoundingBox& box :
         extractComponents(program, kPattern, kPoint, kTmp, params_.max_components)) {
      if (isDisk(box)) {
        disks.push_back(box);
      } else if (side(box) > params_.min_disk_px) {
        all_disks = false;  // a blob that is no disk: not a pattern
      }
    }
    GateResult candidate;
    if (all_disks && classifyDisks(disks, candidate) != PatternKind::kNone) {
      found.push_back(candidate);
    }
  }
  result.patterns_in_view = static_cast<int>(found.size());
  if (!found.empty()) {
    const GateResult& best = *std::max_element(
        found.begin(), found.end(),
        [](const GateResult& a, const GateResult& b) { return side(a.box) < side(b.box); });
    result.kind = best.kind;
    result.box = best.box;
    result.num_disks = best.num_disks;
    result.disk_centres_px = best.disk_centres_px;
    result.squares_intact = true;
  } else if (previous_.detected() && frames_since_found_ < params_.max_recovery_frames) {
    // Algorithm 1's else-branch: each previous centre, loaded as a point,
    // floods its disk in the (de-noised) dark image; the disk is then removed.
    if (params_.denoise_step > 0) {
      denoiseAnd4(program, kBright, kDark, params_.denoise_step, kTmp);
    } else {
      ppa.mov(kBright, kDark);
    }
    std::vector<BoundingBox> disks;
    for (int i = 0; i < previous_.num_disks; ++i) {
      const auto& c = previous_.disk_centres_px[static_cast<std::size_t>(i)];
      program.loadPoint(kPoint, static_cast<int>(std::lround(c[0])),
                        static_cast<int>(std::lround(c[1])));
      ppa.flood(kPoint, kBright);
      const BoundingBox box = ppa.boundingBox(kPoint);
      ppa.notOp(kTmp, kBright);
      ppa.nor(kBright, kTmp, kPoint);
      const auto moved = centre(box);
      if (!isDisk(box) ||
          std::hypot(moved[0] - c[0], moved[1] - c[1]) > params_.max_recovery_shift_px) {
        break;
      }
      disks.push_back(box);
    }
    GateResult recovered;
    if (static_cast<int>(disks.size()) == previous_.num_disks &&
        classifyDisks(disks, recovered) == previous_.kind) {
      result.kind = recovered.kind;
      result.box = recovered.box;
      result.num_disks = recovered.num_disks;
      result.disk_centres_px = recovered.disk_centres_px;
    }
  }
  stage(result.stages.coordinates);

  if (result.detected()) {
    if (result.squares_intact) frames_since_found_ = 0;
    ++frames_since_found_;
    previous_ = result;
  } else {
    previous_ = GateResult{};
    frames_since_found_ = 0;
  }
  result.instructions = program.instructions();
  return result;
}

}  // namespace nadir::ppa
