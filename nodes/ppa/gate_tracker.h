#pragma once
// Gate and slalom pattern tracking on the pixel processor array (Liu et al.
// 2021, algorithms 1 and 2), written as a kernel of Ppa instructions. A gate's
// pattern is four black disks inside two concentric black squares; a slalom
// board's is three disks (two in a column and one beside them: the side to
// turn to) inside the same squares. Of several patterns in view the largest
// (the nearest) is tracked.
//
// Each frame: binarise (dark = 1); flood-and-invert from the bright set
// `boundaries` - 1 times, which on a bright surround leaves each pattern's
// inner area (inside the outer square, the gap and the inner square) with
// holes where its disks are; one more flood from the border finds the holes:
// the disks, de-noised by the AND of
// their copies moved denoise_step PEs north, south, west and east (algorithm
// 2). Then, one pattern at a time (scan an event of the inner areas, load it
// as a point, flood it, bounding box, remove), the disks inside its box are
// taken out one at a time the same way, and the pattern is classified: four
// disks in two rows and two columns is a gate, three in an arrow head a slalom
// board, anything else is not a pattern (a decoy). Where the squares are
// broken or merged no pattern is left: while a pattern was found within the
// last max_recovery_frames frames, its disk centres are loaded as points and
// flooded within the de-noised dark image instead, one disk at a time
// (algorithm 1's else-branch), and kept if they still form the pattern near
// where it was.
//
// Registers: R0..R6 (scratch), A, B, F (see ppa_kernels.h).

#include <array>
#include <cstdint>
#include <string>

#include "core/params.h"
#include "nodes/ppa/ppa_array.h"

namespace nadir::ppa {

struct GateTrackerParams {
  // PIX below this (counts of 127 at full light) is dark.
  double threshold = 97.0;
  // Boundaries around the disks on a bright surround: the outer square's two
  // edges and the inner square's two.
  int boundaries = 4;
  // Algorithm 2's P_step, PEs; 0 turns de-noising off.
  int denoise_step = 1;
  // A disk's bounding box side after de-noising, px.
  int min_disk_px = 2;
  int max_disk_px = 64;
  // Components examined per frame at most (patterns, and disks in each).
  int max_components = 32;
  // Frames the previous centres may stand in for broken squares, and how far
  // a disk may have moved from its previous centre, px.
  int max_recovery_frames = 20;
  double max_recovery_shift_px = 6.0;

  void visit(core::ParamVisitor& v);
};

enum class PatternKind { kNone, kGate, kSlalomLeft, kSlalomRight };
const char* patternKindName(PatternKind kind);

// Emulated instructions of each stage of the pipeline (Liu et al. 2021, table 2).
struct GateStageInstructions {
  std::uint64_t threshold = 0;    // capture and threshold
  std::uint64_t flood = 0;        // flood-and-invert to the inner areas and the disks
  std::uint64_t denoise = 0;      // algorithm 2
  std::uint64_t coordinates = 0;  // patterns, disks and their centres (and recovery)
};

struct GateResult {
  PatternKind kind = PatternKind::kNone;
  bool detected() const { return kind != PatternKind::kNone; }
  // The pattern's disks together.
  BoundingBox box;
  // Disk centres (bounding-box centres), px, x right and y down: a gate's
  // top-left, top-right, bottom-left, bottom-right; a slalom board's column
  // (top, bottom) then its tip.
  int num_disks = 0;
  std::array<std::array<double, 2>, 4> disk_centres_px{};
  // The disks were found inside intact squares (not from the previous centres).
  bool squares_intact = false;
  // Patterns of any kind (gates, slalom boards) in view this frame.
  int patterns_in_view = 0;
  GateStageInstructions stages;
  std::uint64_t instructions = 0;
  // What each stage took the emulator on the host, ns (threshold, flood,
  // denoise, coordinates): wall-clock time, for benchmarks, never published.
  std::array<double, 4> host_ns{};
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
  GateResult previous_;
  int frames_since_found_ = 0;
};

// Classifies disk boxes: four in two rows and two columns (a gate), three with
// two in a column and one beside (a slalom board, turning to the single one's
// side), else kNone. Sets the result's kind, box, centres and count in order.
PatternKind classifyDisks(const std::vector<BoundingBox>& disks, GateResult& result);

}  // namespace nadir::ppa
