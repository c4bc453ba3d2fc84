#include "nodes/ppa/gate_tracker.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "nodes/ppa/ppa_kernels.h"

namespace nadir::ppa {

namespace {

constexpr Dreg kDark = Dreg::R0;
constexpr Dreg kBright = Dreg::R1;
constexpr Dreg kTmp = Dreg::R2;
constexpr Dreg kLeft = Dreg::R3;
constexpr Dreg kClean = Dreg::R4;
constexpr Dreg kPoint = Dreg::R5;
constexpr Dreg kTmp2 = Dreg::R6;

std::array<double, 2> centre(const BoundingBox& box) {
  return {0.5 * (box.x_min + box.x_max), 0.5 * (box.y_min + box.y_max)};
}

}  // namespace

void GateTrackerParams::visit(core::ParamVisitor& v) {
  v.field("threshold", &threshold,
          {.doc = "PIX counts below which a PE is dark", .min = -128.0, .max = 127.0});
  v.field("boundaries", &boundaries,
          {.doc = "flood-and-invert rounds that leave the disks", .min = 1, .max = 64});
  v.field(
      "denoise_step", &denoise_step,
      {.doc = "de-noising shift (Liu et al.'s (2021) P_step), PEs; 0: off", .min = 0, .max = 16});
  v.field("min_disk_px", &min_disk_px,
          {.doc = "smallest disk bounding box side, px", .min = 1, .max = 256});
  v.field("max_disk_px", &max_disk_px,
          {.doc = "largest disk bounding box side, px", .min = 1, .max = 256});
  v.field("max_components", &max_components,
          {.doc = "components examined per frame at most", .min = 4, .max = 1000});
}

GateTracker::GateTracker(const GateTrackerParams& params) : params_(params) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "ppa gate tracker");
  if (params_.min_disk_px > params_.max_disk_px) {
    throw core::ParamError("ppa gate tracker: min_disk_px exceeds max_disk_px");
  }
}

void GateTracker::reset() { has_previous_ = false; }

bool GateTracker::isDisk(const BoundingBox& box) const {
  if (!box.found) return false;
  const int w = box.x_max - box.x_min + 1;
  const int h = box.y_max - box.y_min + 1;
  return std::min(w, h) >= params_.min_disk_px && std::max(w, h) <= params_.max_disk_px &&
         std::max(w, h) <= 2 * std::min(w, h);
}

GateResult GateTracker::processFrame(Ppa& ppa) {
  Program program(ppa);
  GateResult result;
  binariseDark(program, kDark, params_.threshold);
  ppa.notOp(kBright, kDark);
  floodAndInvert(program, kLeft, kBright, params_.boundaries, kTmp);
  if (params_.denoise_step > 0) {
    denoiseAnd4(program, kClean, kLeft, params_.denoise_step, kTmp);
  } else {
    ppa.mov(kClean, kLeft);
  }

  std::vector<BoundingBox> disks;
  for (const BoundingBox& box :
       extractComponents(program, kClean, kPoint, kTmp, params_.max_components)) {
    if (isDisk(box)) disks.push_back(box);
  }
  result.squares_intact = disks.size() == 4;

  if (!result.squares_intact) {
    disks.clear();
    if (has_previous_) {
      // Algorithm 1's else-branch: each previous centre, loaded as a point,
      // floods its disk in the (de-noised) dark image; the disk is then removed.
      if (params_.denoise_step > 0) {
        denoiseAnd4(program, kClean, kDark, params_.denoise_step, kTmp);
      } else {
        ppa.mov(kClean, kDark);
      }
      for (const auto& c : previous_) {
        program.loadPoint(kPoint, static_cast<int>(std::lround(c[0])),
                          static_cast<int>(std::lround(c[1])));
        ppa.flood(kPoint, kClean);
        const BoundingBox box = ppa.boundingBox(kPoint);
        ppa.notOp(kTmp2, kClean);
        ppa.nor(kClean, kTmp2, kPoint);
        if (!isDisk(box)) break;
        disks.push_back(box);
      }
    }
  }

  if (disks.size() == 4) {
    // Top two by y, then each pair by x.
    std::sort(disks.begin(), disks.end(), [](const BoundingBox& a, const BoundingBox& b) {
      return a.y_min + a.y_max < b.y_min + b.y_max;
    });
    const auto by_x = [](const BoundingBox& a, const BoundingBox& b) {
      return a.x_min + a.x_max < b.x_min + b.x_max;
    };
    std::sort(disks.begin(), disks.begin() + 2, by_x);
    std::sort(disks.begin() + 2, disks.end(), by_x);
    result.detected = true;
    result.box = disks[0];
    for (int i = 0; i < 4; ++i) {
      result.disk_centres_px[i] = centre(disks[i]);
      result.box.x_min = std::min(result.box.x_min, disks[i].x_min);
      result.box.y_min = std::min(result.box.y_min, disks[i].y_min);
      result.box.x_max = std::max(result.box.x_max, disks[i].x_max);
      result.box.y_max = std::max(result.box.y_max, disks[i].y_max);
    }
    previous_ = result.disk_centres_px;
    has_previous_ = true;
  } else {
    result.squares_intact = false;
  }
  result.instructions = program.instructions();
  return result;
}

}  // namespace nadir::ppa
