// On-sensor gate tracking (Liu et al. 2021) on cluttered synthetic scenes with
// terrain's gate mat pasted in: disk centres with the squares intact and broken.

#include "nodes/ppa/gate_tracker.h"

#include <gtest/gtest.h>

#include <array>
#include <random>

#include "bench/ppa_scenes.h"

namespace nadir::ppa {
namespace {

constexpr int kMatPx = 100;

cv::Mat gateMat() {
  terrain::GroundTarget target;
  target.kind = "gate";
  return test::matImage(target, kMatPx);
}

// The scene with the gate's top-left pixel at (x0, y0); broken: a white cut
// through both squares on the right; specks: dark single pixels inside the
// inner square (noise the de-noising removes).
cv::Mat gateScene(std::uint32_t seed, int x0, int y0, bool broken, bool specks) {
  cv::Mat scene = test::clutterScene(seed, 25, 15);
  cv::Mat mat = gateMat();
  if (specks) {
    std::mt19937 rng(seed);
    for (int i = 0; i < 12; ++i) {
      mat.at<std::uint8_t>(22 + static_cast<int>(rng() % 56), 22 + static_cast<int>(rng() % 56)) =
          20;
    }
  }
  if (broken) {
    // The squares lie 4..19 px in from the mat's edges; cut x 78..99, y 44..55.
    mat(cv::Rect(78, 44, 22, 12)).setTo(cv::Scalar(235));
  }
  test::paste(scene, mat, x0, y0);
  return scene;
}

// The disk centres of a gate at (x0, y0): 0.36 and 0.64 of the mat, at PE centres.
std::array<std::array<double, 2>, 4> diskCentres(int x0, int y0) {
  const double a = 0.36 * kMatPx - 0.5, b = 0.64 * kMatPx - 0.5;
  return {{{x0 + a, y0 + a}, {x0 + b, y0 + a}, {x0 + a, y0 + b}, {x0 + b, y0 + b}}};
}

void expectCentres(const GateResult& result, int x0, int y0) {
  ASSERT_TRUE(result.detected());
  const auto expected = diskCentres(x0, y0);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(result.disk_centres_px[i][0], expected[i][0], 1.5) << "disk " << i;
    EXPECT_NEAR(result.disk_centres_px[i][1], expected[i][1], 1.5) << "disk " << i;
  }
}

GateResult track(GateTracker& tracker, const cv::Mat& scene) {
  Ppa ppa;
  test::expose(ppa, scene);
  return tracker.processFrame(ppa);
}

// With the squares intact the four disks come out of the floods alone, in
// clutter and with dark specks inside (several seeds).
TEST(GateTrackerTest, FindsDisksInsideIntactSquares) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const int x0 = 20 + static_cast<int>((seed * 41) % 120);
    const int y0 = 20 + static_cast<int>((seed * 29) % 120);
    GateTracker tracker{GateTrackerParams{}};
    const GateResult result = track(tracker, gateScene(seed, x0, y0, false, true));
    EXPECT_TRUE(result.squares_intact);
    expectCentres(result, x0, y0);
    EXPECT_LE(result.box.x_min, x0 + 28);
    EXPECT_GE(result.box.x_max, x0 + 71);
    EXPECT_GT(result.instructions, 0u);
  }
}

// Without de-noising the dark specks inside the inner square are disk-like
// components too small to count, so the disks still come out.
TEST(GateTrackerTest, SpecksAreNotDisks) {
  GateTrackerParams params;
  params.denoise_step = 0;
  GateTracker tracker{params};
  const GateResult result = track(tracker, gateScene(2, 70, 60, false, true));
  expectCentres(result, 70, 60);
}

// With a cut through both squares the floods leak in and nothing is left:
// the previous frame's centres, flooded in the dark image, find the moved disks.
TEST(GateTrackerTest, BrokenSquaresUseThePreviousCentres) {
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    GateTracker tracker{GateTrackerParams{}};
    const GateResult first = track(tracker, gateScene(seed, 60, 50, false, false));
    ASSERT_TRUE(first.squares_intact);
    GateResult result = track(tracker, gateScene(seed, 62, 51, true, false));
    EXPECT_FALSE(result.squares_intact);
    expectCentres(result, 62, 51);
    // And on from there, still broken.
    result = track(tracker, gateScene(seed, 65, 49, true, false));
    EXPECT_FALSE(result.squares_intact);
    expectCentres(result, 65, 49);
  }
}

// Broken squares and no previous centres (or after reset()): nothing found.
TEST(GateTrackerTest, BrokenSquaresWithoutHistoryFindNothing) {
  GateTracker tracker{GateTrackerParams{}};
  EXPECT_FALSE(track(tracker, gateScene(4, 60, 50, true, false)).detected());
  ASSERT_TRUE(track(tracker, gateScene(4, 60, 50, false, false)).detected());
  tracker.reset();
  EXPECT_FALSE(track(tracker, gateScene(4, 60, 50, true, false)).detected());
}

// A scene without a gate has no gate.
TEST(GateTrackerTest, NothingWithoutAGate) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    GateTracker tracker{GateTrackerParams{}};
    EXPECT_FALSE(track(tracker, test::clutterScene(seed, 60, 40)).detected()) << "seed " << seed;
  }
}

}  // namespace
}  // namespace nadir::ppa
