#pragma once
// Gate pattern tracking on the pixel processor array (Liu et al. 2021, algorithms 1
// and 2), written as a kernel of Ppa instructions: four black disks inside two
// concentric black squares.
//
// Each frame: binarise (dark = 1); flood-and-invert from the bright set
// `boundaries` times, which on a bright surround leaves exactly the disks (the
// outer square, the gap, the inner square and the inner area are the four
// boundaries around them); de-noise by the AND of the copies moved
// denoise_step PEs north, south, west and east (algorithm 2); then take the
// components one at a time (scan an event, load it as a point, flood it,
// bounding box, remove) and keep the disk-sized ones. Four disks: the squares
// are intact. Otherwise (the squares are broken or merged, so the flood leaks
// in and nothing is left) the previous frame's disk centres are loaded as
// points and flooded within the de-noised dark image instead, one disk at a
// time (algorithm 1's else-branch).
//
// Registers: R0..R6 (scratch), A, B, F (see ppa_kernels.h).

#include <array>
#include <cstdint>

#include "core/params.h"
#include "nodes/ppa/ppa_array.h"

namespace nadir::ppa {

struct GateTrackerParams {
  // PIX below this (counts of 127 at full light) is dark.
  double threshold = 97.0;
  // Flood-and-invert rounds that leave the disks (4 on a bright surround).
  int boundaries = 4;
  // Algorithm 2's P_step, PEs; 0 turns de-noising off.
  int denoise_step = 1;
  // A disk's bounding box side after de-noising, px.
  int min_disk_px = 3;
  int max_disk_px = 64;
  // Components examined per frame at most.
  int max_components = 32;

  void visit(core::ParamVisitor& v);
};

struct GateResult {
  bool detected = false;
  // The four disks together.
  BoundingBox box;
  // Disk centres (bounding-box centres), px: top-left, top-right, bottom-left,
  // bottom-right as seen in the image.
  std::array<std::array<double, 2>, 4> disk_centres_px{};
  // The disks were found inside intact squares (not from the previous centres).
  bool squares_intact = false;
  std::uint64_t instructions = 0;
};

class GateTracker {
 public:
  // Throws core::ParamError for invalid parameters.
  explicit GateTracker(const GateTrackerParams& params);

  // The light of the frame is already set (ppa.setLight); captures its own image.
  GateResult processFrame(Ppa& ppa);
  // Forget the previous frame's disk centres.
  void reset();

  const GateTrackerParams& params() const { return params_; }

 private:
  bool isDisk(const BoundingBox& box) const;

  GateTrackerParams params_;
  bool has_previous_ = false;
  std::array<std::array<double, 2>, 4> previous_{};
};

}  // namespace nadir::ppa
