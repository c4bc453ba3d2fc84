#pragma once
// Image-alignment visual odometry on the pixel processor array (McConville et
// al. 2020, section 2.2.1, after Bose et al. 2017), written as a kernel of Ppa
// instructions; the host only reads global counts. Each frame's edge image is
// aligned to the key-frame's by small steps of translation, rotation and scale;
// docs/ppa.md ("How the alignment is computed") says how, and what it costs.

#include <cstdint>

#include "core/params.h"
#include "nodes/ppa/ppa_array.h"
#include "nodes/ppa/ppa_kernels.h"

namespace nadir::ppa {

struct VisualOdometryParams {
  // A PE brighter than a 4-neighbour by more than this (PIX counts) is an edge.
  double edge_threshold = 4.0;
  // Drop edge PEs that have no edge among their 4 neighbours (noise).
  bool edge_denoise = true;
  // A new key-frame when the strength after alignment falls below this.
  double keyframe_strength = 0.35;
  // Alignment iterations (each tries the four pairs) per frame.
  int max_iterations = 12;
  // One rotation adjustment, rad (0.005 moves the array's corners 0.9 px).
  double rotation_step_rad = 0.005;
  // One scaling adjustment: the scale changes by the factor 1 + scale_step.
  double scale_step = 0.005;
  // Limits of the transform searched (beyond them a new key-frame is due anyway).
  double max_rotation_rad = 0.3;
  double max_scale_change = 0.25;
  int max_translation_px = 200;

  void visit(core::ParamVisitor& v);
};

struct VisualOdometryResult {
  // The transform aligning this frame to the key-frame it was compared with
  // (the key-frame BEFORE any switch this frame causes): a pixel p of this
  // frame shows what the key-frame shows at
  //   c + t + scale * R(rotation) (p - c),  c = (127.5, 127.5),
  // pixels x right, y down; rotation positive clockwise in the image (from x
  // towards y); scale > 1: the content looks smaller in this frame than in
  // the key-frame (the camera moved away), the alignment enlarges it.
  double translation_x_px = 0, translation_y_px = 0, rotation_rad = 0, scale = 1;
  // Shared edge pixels / key-frame edge pixels after alignment.
  double strength = 0;
  // This frame becomes the key-frame for the next frames.
  bool new_keyframe = false;
  // Edge pixels of the key-frame the next frame will be compared with.
  int keyframe_edge_count = 0;
  // Edge pixels of this frame.
  int edge_count = 0;
  // Alignment iterations run (0 for a first frame).
  int iterations = 0;
  // Instructions this call executed (emulator count + controller loads).
  std::uint64_t instructions = 0;
};

class VisualOdometry {
 public:
  // Throws core::ParamError for invalid parameters.
  explicit VisualOdometry(const VisualOdometryParams& params);

  // The light of the frame is already set (ppa.setLight). The first frame
  // becomes the key-frame. R7..R12 persist across frames (the key-frame and
  // its warped copies), R0..R6 are scratch; analog registers are scratch.
  VisualOdometryResult processFrame(Ppa& ppa);
  // Forget the key-frame: the next frame becomes one.
  void reset();

  const VisualOdometryParams& params() const { return params_; }

 private:
  struct Transform {
    int ux = 0, uy = 0, kr = 0, ks = 0;
  };
  // A warped key-frame G(kr, ks) held in a register.
  struct Slot {
    Dreg reg;
    bool valid = false;
    int kr = 0, ks = 0;
    // Its overlap with E_u, valid while eu_version matches.
    int score = 0;
    std::uint64_t eu_version = ~std::uint64_t{0};
    std::uint64_t used = 0;
  };

  void extractEdges(Program& program);
  void makeKeyframe(Program& program);
  // E_u = E moved by (ux, uy) (from the current E_u where that is exact).
  void moveEdges(Program& program, int ux, int uy);
  // The slot holding G(kr, ks), rendering it if needed (never evicting the
  // current transform's slot or `keep`).
  Slot& render(Program& program, int kr, int ks, const Slot* keep);
  void renderInto(Program& program, Dreg dst, int kr, int ks);
  int slotScore(Program& program, Slot& slot);
  bool inLimits(int kr, int ks) const;

  VisualOdometryParams params_;
  bool has_keyframe_ = false;
  int keyframe_count_ = 0;
  Transform transform_;
  // The translation E_u currently holds, and a counter of its changes.
  int eu_x_ = 0, eu_y_ = 0;
  std::uint64_t eu_version_ = 0;
  std::uint64_t use_counter_ = 0;
  Slot slots_[5];
};

}  // namespace nadir::ppa
