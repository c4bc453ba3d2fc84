#pragma once
// Building blocks of the on-sensor programs (visual odometry, target
// extraction, gate tracking) and the register allocation they share.
//
// Register allocation. The programs run one after the other on the same frame
// (visual odometry first, then target extraction or gate tracking), so they
// share the array:
//   R12      the VO's key-frame edge image K: persists across frames.
//   R7..R11  the VO's warped copies of K (the current rotation/scale and its
//            four neighbours): persist across frames.
//   R0..R6   scratch: any program may overwrite them (the VO keeps this
//            frame's edge image and its translated copy in R6 and R5, and
//            uses R0..R4 for temporaries; target extraction uses R0..R3, the
//            gate tracker R0..R6).
//   A..F, NEWS  scratch: nothing analog is kept between calls (on the chip
//            analog values decay within milliseconds anyway).
// A program that is not the VO never writes R7..R12.

#include <cstdint>
#include <vector>

#include "nodes/ppa/ppa_array.h"

namespace nadir::ppa {

inline constexpr Dreg kRegKeyframe = Dreg::R12;
inline constexpr Dreg kRegWarpedKeyframes[5] = {Dreg::R11, Dreg::R10, Dreg::R9, Dreg::R8, Dreg::R7};

// One run of a program on the array. It wraps the Ppa and adds the three
// controller operations SCAMP-5 has but the emulator does not offer as
// instructions: loading a constant through the analog input bus (scamp5_in),
// and a rectangle or a single point through the row/column address decoders
// (scamp5_load_rect, scamp5_load_point). On the chip each is one short
// controller operation; here it is a host write (Ppa::loadAnalog /
// loadDigital), counted as one instruction in instructions().
class Program {
 public:
  explicit Program(Ppa& ppa) : ppa_(ppa), start_(ppa.instructions()) {}

  Ppa& ppa() { return ppa_; }
  // Instructions executed since construction: the emulator's count plus the
  // controller operations below.
  std::uint64_t instructions() const { return ppa_.instructions() - start_ + controller_; }

  // dst = value in every PE (whatever FLAG).
  void loadConstant(Areg dst, float value);
  // dst = 1 in the rectangle [x_min, x_max] x [y_min, y_max] (inclusive, clipped
  // to the array), 0 elsewhere.
  void loadRect(Dreg dst, int x_min, int y_min, int x_max, int y_max);
  // dst = 1 at (x, y) only (nothing if outside the array).
  void loadPoint(Dreg dst, int x, int y);

 private:
  Ppa& ppa_;
  std::uint64_t start_;
  std::uint64_t controller_ = 0;
};

// ---- kernels: sequences of instructions

// dst = src with its content moved by (dx, dy) PEs (x right, y down); zeros
// enter at the edges. |dx| + |dy| moves; dst may be src.
void translate(Program& program, Dreg dst, Dreg src, int dx, int dy);

// Liu et al. 2021, algorithm 2: dst = AND of src moved `step` PEs north, south, west
// and east, which removes white specks and lines narrower than 2 step + 1 and
// shrinks regions by `step` without moving their centres. tmp is clobbered;
// dst, src and tmp must differ.
void denoiseAnd4(Program& program, Dreg dst, Dreg src, int step, Dreg tmp);

// The number of PEs set in both a and b (tmp = a & b).
int countAnd(Program& program, Dreg a, Dreg b, Dreg tmp);

// dst = (PIX < threshold_counts): the dark parts of the current exposure. A is
// left holding the image, B and F are clobbered, FLAG is all on return.
void binariseDark(Program& program, Dreg dst, double threshold_counts);

// McConville et al.'s (2020) flood-and-invert, `boundaries` (>= 1) times, starting from the
// bright set `bright` (consumed): dst = the PEs inside more than `boundaries`
// boundaries of the binary image. tmp is clobbered; dst, bright and tmp differ.
void floodAndInvert(Program& program, Dreg dst, Dreg bright, int boundaries, Dreg tmp);

// Splits `plane` into its 4-connected components one at a time, as on the
// chip: scan one event, load it as a point, flood it within the plane, read
// the bounding box, remove the component. At most max_components; the
// components found are removed from `plane`. point and tmp are clobbered.
std::vector<BoundingBox> extractComponents(Program& program, Dreg plane, Dreg point, Dreg tmp,
                                           int max_components);

}  // namespace nadir::ppa
