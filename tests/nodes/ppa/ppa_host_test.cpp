// The PPA host: pixels to metres with the height and lens, rotation removed with the
// attitude, yaw applied, target correction (McConville et al. 2020, equations 1-5, section 3.2).

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/frames.h"
#include "nodes/ppa/ppa_host.h"

namespace nadir::ppa {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// 256 px over 50 deg: f = 128 / tan(25 deg) = 274.4966 px.
const double kF = 128.0 / std::tan(25.0 * kDeg);

PpaHost makeHost(std::vector<Eigen::Vector2d> targets = {}) {
  return PpaHost({}, PpaCamera::fromFov(256, 256, 50.0 * kDeg, core::rotationBodyFromDownCamera()),
                 std::move(targets));
}

PpaHostInput frame(double range_m, const core::RollPitchYaw& rpy, double tx_px, double ty_px,
                   bool new_keyframe = false) {
  PpaHostInput input;
  input.range_m = range_m;
  input.q_world_body = core::quaternionFromRpy(rpy);
  input.alignment.translation_x_px = tx_px;
  input.alignment.translation_y_px = ty_px;
  input.alignment.new_keyframe = new_keyframe;
  input.alignment.keyframe_edge_count = 1000;
  // A well-aligned frame: 60 % of the key-frame's edges shared, 1000 of 65536 pixels edges.
  input.alignment.strength = 0.6;
  input.alignment.edge_count = 1000;
  return input;
}

// Before the start pose is known the estimate is INITIALIZING; the first frame is the start.
TEST(PpaHost, StartsAtTheGivenPose) {
  PpaHost host = makeHost();
  EXPECT_EQ(host.update(frame(5.0, {}, 0, 0, true)).status, PpaStatus::kInitializing);
  host.initialise({10.0, 20.0, -7.0});
  const PpaHostOutput out = host.update(frame(5.0, {}, 0, 0, true));
  EXPECT_EQ(out.status, PpaStatus::kTracking);
  EXPECT_NEAR((out.p_ned_m - Eigen::Vector3d(10.0, 20.0, -7.0)).norm(), 0.0, 1e-12);
}

// Sensor noise above the edge threshold fills the edge image: half the
// pixels edges (32768 of 256 x 256) share half of any key-frame's edges by
// chance. A strength of 0.52 is (0.52 - 0.5) / (1 - 0.5) = 0.04 above that
// chance, under the default 0.07: LOST; 0.6 is 0.2 above it: TRACKING. The
// same 0.52 over a sparse edge image (1000 edges) is 0.51 above chance.
TEST(PpaHost, AnAlignmentNoBetterThanChanceIsLost) {
  PpaHost host = makeHost();
  host.initialise({0, 0, -5});
  host.update(frame(5.0, {}, 0, 0, true));
  PpaHostInput noisy = frame(5.0, {}, 1.0, 0.0);
  noisy.alignment.edge_count = 32768;
  noisy.alignment.strength = 0.52;
  const PpaHostOutput guess = host.update(noisy);
  EXPECT_NEAR(guess.strength_above_chance, 0.04, 1e-12);
  EXPECT_EQ(guess.status, PpaStatus::kLost);
  noisy.alignment.strength = 0.6;
  const PpaHostOutput aligned = host.update(noisy);
  EXPECT_NEAR(aligned.strength_above_chance, 0.2, 1e-12);
  EXPECT_EQ(aligned.status, PpaStatus::kTracking);
  PpaHostInput sparse = frame(5.0, {}, 1.0, 0.0);
  sparse.alignment.strength = 0.52;
  const PpaHostOutput clean = host.update(sparse);
  EXPECT_NEAR(clean.strength_above_chance, (0.52 - 1000.0 / 65536) / (1 - 1000.0 / 65536), 1e-12);
  EXPECT_EQ(clean.status, PpaStatus::kTracking);
}

// Level, heading north at 5 m: the ground below now sits 10 px above the key-frame's
// centre, so the vehicle moved 10 * 5 / f = 0.18215 m north.
TEST(PpaHost, PixelsBecomeMetresWithHeightAndLens) {
  PpaHost host = makeHost();
  host.initialise({0, 0, -5});
  host.update(frame(5.0, {}, 0, 0, true));
  const PpaHostOutput out = host.update(frame(5.0, {}, 0.0, -10.0));
  EXPECT_NEAR(out.p_ned_m.x(), 10.0 * 5.0 / kF, 1e-9);
  EXPECT_NEAR(out.p_ned_m.y(), 0.0, 1e-9);
  // 7 px to the right of the centre: east.
  const PpaHostOutput right = host.update(frame(5.0, {}, 7.0, 0.0));
  EXPECT_NEAR(right.p_ned_m.y(), 7.0 * 5.0 / kF, 1e-9);
}

// Heading east (yaw 90 deg), the same image motion is a move east.
TEST(PpaHost, YawTurnsImageAxesIntoTheWorld) {
  PpaHost host = makeHost();
  host.initialise({0, 0, -5});
  const core::RollPitchYaw east{.yaw_rad = 90.0 * kDeg};
  host.update(frame(5.0, east, 0, 0, true));
  const PpaHostOutput out = host.update(frame(5.0, east, 0.0, -10.0));
  EXPECT_NEAR(out.p_ned_m.x(), 0.0, 1e-9);
  EXPECT_NEAR(out.p_ned_m.y(), 10.0 * 5.0 / kF, 1e-9);
}

// Pitching 5 deg nose up without moving shifts the ground f tan(5 deg) = 24.0 px down the
// image (the key-frame's centre now appears there); with the attitude, no motion results.
// Likewise rolling 4 deg right wing down shifts it f tan(4 deg) px to the right.
TEST(PpaHost, RotationIsNotMistakenForMotion) {
  PpaHost host = makeHost();
  host.initialise({0, 0, -5});
  // Range along the tilted body axis: 5 / cos(5 deg) keeps the height at 5 m.
  host.update(frame(5.0, {}, 0, 0, true));
  const PpaHostOutput pitched = host.update(frame(
      5.0 / std::cos(5.0 * kDeg), {.pitch_rad = 5.0 * kDeg}, 0.0, -kF * std::tan(5.0 * kDeg)));
  EXPECT_NEAR(pitched.p_ned_m.head<2>().norm(), 0.0, 1e-9);
  EXPECT_NEAR(pitched.height_m, 5.0, 1e-9);
  const PpaHostOutput rolled = host.update(
      frame(5.0 / std::cos(4.0 * kDeg), {.roll_rad = 4.0 * kDeg}, -kF * std::tan(4.0 * kDeg), 0.0));
  EXPECT_NEAR(rolled.p_ned_m.head<2>().norm(), 0.0, 1e-9);
  // Without the attitude the same pixels would read as McConville et al.'s (2020) h tan(5 deg) =
  // 0.437 m.
  const PpaHostOutput ignored = host.update(frame(5.0, {}, 0.0, -kF * std::tan(5.0 * kDeg)));
  EXPECT_NEAR(ignored.p_ned_m.x(), 5.0 * std::tan(5.0 * kDeg), 1e-9);
}

// Positions chain across key-frames: each new key-frame starts where the last frame was.
TEST(PpaHost, KeyframesChain) {
  PpaHost host = makeHost();
  host.initialise({0, 0, -5});
  host.update(frame(5.0, {}, 0, 0, true));
  host.update(frame(5.0, {}, 0.0, -20.0, true));  // 20 px north, becomes the key-frame
  const PpaHostOutput out = host.update(frame(5.0, {}, 0.0, -20.0));
  EXPECT_NEAR(out.p_ned_m.x(), 40.0 * 5.0 / kF, 1e-9);
}

// A known target seen in the image sets the position (McConville et al. 2020 section 3.2); one seen
// too far from where the estimate expects it is ignored.
TEST(PpaHost, KnownTargetCorrectsThePosition) {
  PpaHost host = makeHost({Eigen::Vector2d(3.0, 4.0)});
  host.initialise({0.5, 3.6, -5});  // the truth is (0, 4): the estimate is 0.5 m north, 0.4 m west
  host.update(frame(5.0, {}, 0, 0, true));
  PpaHostInput input = frame(5.0, {}, 0, 0);
  // The target 3 m ahead of the vehicle: 3 * f / 5 px above the image centre.
  input.target_center_px = Eigen::Vector2d(127.5, 127.5 - 3.0 * kF / 5.0);
  const PpaHostOutput out = host.update(input);
  EXPECT_TRUE(out.corrected);
  EXPECT_NEAR((out.p_ned_m.head<2>() - Eigen::Vector2d(0.0, 4.0)).norm(), 0.0, 1e-9);
  // The correction carries into the following frames.
  EXPECT_NEAR((host.update(frame(5.0, {}, 0, 0)).p_ned_m.head<2>() - Eigen::Vector2d(0, 4)).norm(),
              0.0, 1e-9);
  PpaHost gated = makeHost({Eigen::Vector2d(30.0, 40.0)});
  gated.initialise({0, 0, -5});
  gated.update(frame(5.0, {}, 0, 0, true));
  EXPECT_FALSE(gated.update(input).corrected);
}

}  // namespace
}  // namespace nadir::ppa
