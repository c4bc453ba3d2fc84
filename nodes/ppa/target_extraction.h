#pragma once
// Target extraction on the pixel processor array (McConville et al. 2020, section 2.2.2),
// written as a kernel of Ppa instructions: the image is binarised (dark target
// rings against the bright mat), then flooded from the array's border,
// inverted, and so on `boundaries` times; whatever is left lies inside more
// than `boundaries` boundaries, which in a cluttered scene only the nested
// rings of the target provide. Its bounding box (a global readout) is the
// target's inner part; tiny or huge boxes are discarded.
//
// Registers: R0..R3 (scratch), A, B, F (see ppa_kernels.h).
//
// What is left after N rounds is the part of the image inside at least N
// boundaries, of one brightness (dark for even N). For terrain's concentric
// mat with r rings (2 r + 1 bands of width size / (2 (2 r + 1)) from the white
// margin, band 0, to the white centre, band 2 r) that is bands N + 1, N + 3, ...
// on a bright surround, whose box lies N + 1 band widths in from the mat's
// edge (N < 2 r). On a dark surround the margin is one boundary more: bands
// N - 1, N + 1, ..., two bands wider. The box's centre is the mat's either way.

#include <cstdint>

#include "core/params.h"
#include "nodes/ppa/ppa_array.h"

namespace nadir::ppa {

struct TargetExtractionParams {
  // Flood-and-invert rounds: what is left lies inside more than this many boundaries.
  int boundaries = 6;
  // PIX below this (counts of 127 at full light) is dark.
  double threshold = 97.0;
  // The box of what is left, each side, px: smaller or larger is no target.
  int min_size_px = 4;
  int max_size_px = 160;
  // The box's longer side over its shorter side (a mat is square at any yaw).
  double max_aspect = 2.0;

  void visit(core::ParamVisitor& v);
};

struct TargetExtractionResult {
  bool detected = false;
  // What was left after the rounds (also when not detected: found says whether anything was).
  BoundingBox box;
  // The box's centre, px (x right, y down, PE centres at integers).
  double center_x_px = 0, center_y_px = 0;
  // PEs left after the rounds.
  int remaining_px = 0;
  std::uint64_t instructions = 0;
};

class TargetExtractor {
 public:
  // Throws core::ParamError for invalid parameters.
  explicit TargetExtractor(const TargetExtractionParams& params);

  // The light of the frame is already set (ppa.setLight); captures its own image.
  TargetExtractionResult processFrame(Ppa& ppa);

  const TargetExtractionParams& params() const { return params_; }

 private:
  TargetExtractionParams params_;
};

}  // namespace nadir::ppa
