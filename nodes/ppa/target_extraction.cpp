#include "nodes/ppa/target_extraction.h"

#include <algorithm>

#include "nodes/ppa/ppa_kernels.h"

namespace nadir::ppa {

void TargetExtractionParams::visit(core::ParamVisitor& v) {
  v.field("boundaries", &boundaries,
          {.doc = "flood-and-invert rounds: a target lies inside more boundaries than this",
           .min = 1,
           .max = 64});
  v.field("threshold", &threshold,
          {.doc = "PIX counts below which a PE is dark", .min = -128.0, .max = 127.0});
  v.field("min_size_px", &min_size_px,
          {.doc = "smallest box side of a target's remaining part, px", .min = 1, .max = 256});
  v.field("max_size_px", &max_size_px,
          {.doc = "largest box side of a target's remaining part, px", .min = 1, .max = 256});
  v.field("max_aspect", &max_aspect,
          {.doc = "largest ratio of the box's sides", .min = 1.0, .max = 256.0});
}

TargetExtractor::TargetExtractor(const TargetExtractionParams& params) : params_(params) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); },
                       "ppa target extraction");
  if (params_.min_size_px > params_.max_size_px) {
    throw core::ParamError("ppa target extraction: min_size_px exceeds max_size_px");
  }
}

TargetExtractionResult TargetExtractor::processFrame(Ppa& ppa) {
  Program program(ppa);
  TargetExtractionResult result;
  binariseDark(program, Dreg::R0, params_.threshold);
  ppa.notOp(Dreg::R1, Dreg::R0);  // bright: the mat and its white bands
  floodAndInvert(program, Dreg::R3, Dreg::R1, params_.boundaries, Dreg::R2);
  result.box = ppa.boundingBox(Dreg::R3);
  if (result.box.found) {
    result.remaining_px = ppa.globalCount(Dreg::R3);
    const int w = result.box.x_max - result.box.x_min + 1;
    const int h = result.box.y_max - result.box.y_min + 1;
    result.center_x_px = 0.5 * (result.box.x_min + result.box.x_max);
    result.center_y_px = 0.5 * (result.box.y_min + result.box.y_max);
    result.detected = std::min(w, h) >= params_.min_size_px &&
                      std::max(w, h) <= params_.max_size_px &&
                      std::max(w, h) <= params_.max_aspect * std::min(w, h);
  }
  result.instructions = program.instructions();
  return result;
}

}  // namespace nadir::ppa
