// FeatureVo on synthetic flights: a random-texture ground plane 150 m below,
// rendered into each 1280x960 frame with the exact homography of the camera
// pose (tests/support/textured_ground.h), along a known trajectory (straight
// and level, then a gentle banked turn).

#include "nodes/vo_feature/feature_vo.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "core/frames.h"
#include "tests/support/textured_ground.h"

namespace nadir::vo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kWidth = 1280;
constexpr int kHeight = 960;
constexpr double kAltitudeM = 150.0;  // ground at world z = 0, the camera at z = -150
constexpr double kDtS = 0.1;
constexpr double kSpeedMps = 20.0;
const cv::Matx33d kK(800, 0, 640, 0, 800, 480, 0, 0, 1);

using test::bodyPose;

cv::Mat render(const Eigen::Isometry3d& T_world_cam) {
  return test::renderGround(T_world_cam, kK, cv::Size(kWidth, kHeight));
}

// Straight and level north for turn_at_frame frames, then a right turn at
// 3 deg/s with the roll eased in to 6 deg over 10 frames.
struct FlightPlan {
  int turn_at_frame = 60;
  double speed_mps = kSpeedMps;
  double dt_s = kDtS;
  Eigen::Vector3d start_m = Eigen::Vector3d(-150.0, -60.0, -kAltitudeM);
};

std::vector<Eigen::Isometry3d> trajectory(int frames, const FlightPlan& plan) {
  std::vector<Eigen::Isometry3d> poses;
  Eigen::Vector3d p = plan.start_m;
  double yaw = 0.0;
  for (int i = 0; i < frames; ++i) {
    const int turn = i - plan.turn_at_frame;
    const double roll = turn <= 0 ? 0.0 : 6.0 * kDeg * std::min(1.0, turn / 10.0);
    poses.push_back(bodyPose(p, roll, 0.0, yaw));
    if (turn > 0) yaw += 3.0 * kDeg * plan.dt_s * std::min(1.0, turn / 10.0);
    p += plan.speed_mps * plan.dt_s * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
  }
  return poses;
}

struct FlightRun {
  std::vector<Eigen::Isometry3d> truth;
  std::vector<VoFrameOutput> out;
  double ms_per_frame = 0.0;
  double scale_ratio = 1.0;  // map height / measured height at the last key-frame
  FeatureVoMapStats map_stats;
};

// Frames [noise_begin, noise_end) are pure noise (the camera blinded).
FlightRun fly(int frames, int noise_begin = -1, int noise_end = -1,
              const FeatureVoParams& params = {}, const FlightPlan& plan = {}) {
  if (noise_end < noise_begin) noise_end = noise_begin + 1;
  FlightRun run;
  run.truth = trajectory(frames, plan);
  FeatureVo vo(params);
  vo.setStartPose(run.truth.front());
  const Eigen::Matrix3d R_body_cam = core::rotationBodyFromDownCamera();
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  T_body_cam.linear() = R_body_cam;
  cv::RNG rng(7);
  double total_ms = 0.0;
  for (int i = 0; i < frames; ++i) {
    VoFrameInput in;
    in.utime = static_cast<std::int64_t>(std::llround(i * plan.dt_s * 1e6));
    in.K = kK;
    in.R_body_cam = R_body_cam;
    // The rangefinder along the body's down axis, over the flat ground at z = 0.
    const Eigen::Isometry3d& T_world_body = run.truth[static_cast<std::size_t>(i)];
    in.range_m = -T_world_body.translation().z() / T_world_body.linear()(2, 2);
    in.range_ray_cam = R_body_cam.transpose() * Eigen::Vector3d::UnitZ();
    if (i >= noise_begin && i < noise_end) {
      in.gray = cv::Mat(kHeight, kWidth, CV_8U);
      rng.fill(in.gray, cv::RNG::UNIFORM, 0, 256);
    } else {
      in.gray = render(run.truth[static_cast<std::size_t>(i)] * T_body_cam);
    }
    const auto t0 = std::chrono::steady_clock::now();
    run.out.push_back(vo.process(in));
    total_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  run.ms_per_frame = total_ms / frames;
  run.scale_ratio = vo.lastScaleRatio();
  run.map_stats = vo.mapStats();
  return run;
}

int firstTracking(const FlightRun& run) {
  for (std::size_t i = 0; i < run.out.size(); ++i)
    if (run.out[i].status == VoStatus::kTracking) return static_cast<int>(i);
  return -1;
}

double pathLength(const std::vector<Eigen::Vector3d>& p) {
  double length = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i) length += (p[i] - p[i - 1]).norm();
  return length;
}

// Initialises within a few frames at metric scale, tracks the whole flight, ends within 2 % of the
// distance.
TEST(FeatureVo, TracksStraightAndTurningFlightAtMetricScale) {
  constexpr int kFrames = 120;
  const FlightRun run = fly(kFrames);
  const int first = firstTracking(run);
  ASSERT_GE(first, 1);
  EXPECT_LE(first, 10);
  std::vector<Eigen::Vector3d> est, tru;
  for (int i = first; i < kFrames; ++i) {
    EXPECT_EQ(run.out[static_cast<std::size_t>(i)].status, VoStatus::kTracking) << "frame " << i;
    est.push_back(run.out[static_cast<std::size_t>(i)].T_world_body.translation());
    tru.push_back(run.truth[static_cast<std::size_t>(i)].translation());
  }
  const double length_est = pathLength(est);
  const double length_true = pathLength(tru);
  const double flown = pathLength([&] {
    std::vector<Eigen::Vector3d> all;
    for (const auto& T : run.truth) all.push_back(T.translation());
    return all;
  }());
  const double end_error =
      (run.out.back().T_world_body.translation() - run.truth.back().translation()).norm();
  const double yaw_error_deg = Eigen::AngleAxisd(run.out.back().T_world_body.linear().transpose() *
                                                 run.truth.back().linear())
                                   .angle() /
                               kDeg;
  int keyframes = 0;
  for (const auto& o : run.out) keyframes += o.new_keyframe ? 1 : 0;
  std::printf(
      "feature_vo: init at frame %d, length %.2f / %.2f m, end error %.2f m of %.1f m flown, "
      "attitude error %.2f deg, %d key-frames, map/measured height %.4f, %.1f ms per 1280x960 "
      "frame\n",
      first, length_est, length_true, end_error, flown, yaw_error_deg, keyframes, run.scale_ratio,
      run.ms_per_frame);
  EXPECT_NEAR(length_est / length_true, 1.0, 0.03);
  EXPECT_LT(end_error, 0.02 * flown);
  EXPECT_LT(yaw_error_deg, 1.0);
  EXPECT_EQ(run.out.back().resets, 0);
}

// The map's diagnostics count the key-frames that saw each point it drops:
// on a flight without a loss every point is made from two key-frames (the
// two-view start or a triangulation), so none was seen by fewer than two,
// and the bins add up to the points dropped. A map of 4 key-frames drops
// points within the flight.
TEST(FeatureVo, CountsTheKeyframesThatSawEachDroppedPoint) {
  FeatureVoParams params;
  params.local_window = 3;
  params.map_keyframes = 4;
  const FlightRun run = fly(120, -1, -1, params);
  const FeatureVoMapStats& stats = run.map_stats;
  ASSERT_GT(stats.points_dropped, 0);
  EXPECT_EQ(stats.points_by_keyframes[0], 0);
  EXPECT_EQ(stats.points_by_keyframes[1], 0);
  std::int64_t total = 0;
  for (const std::int64_t n : stats.points_by_keyframes) total += n;
  EXPECT_EQ(total, stats.points_dropped);
}

// The local map: the BA optimises 3 key-frames (the new one and its two most
// co-visible), yet a ground point stays in view for 9 s (the 180 m footprint
// at 20 m/s) and so is seen by many more key-frames; those enter the BA as
// fixed observers. Its points seen by five or more key-frames are there, each
// with every key-frame of the map that saw it.
TEST(FeatureVo, LocalBundleAdjustmentOptimisesAPointAgainstEveryKeyframeThatSawIt) {
  FeatureVoParams params;
  params.local_window = 3;
  params.background_ba = false;
  const FlightRun run = fly(120, -1, -1, params);
  const FeatureVoMapStats& stats = run.map_stats;
  EXPECT_EQ(stats.ba_free_keyframes, 3);
  EXPECT_GE(stats.ba_fixed_keyframes, 2);
  std::int64_t seen_by_five_or_more = 0;
  for (std::size_t k = 5; k < stats.ba_points_by_observations.size(); ++k)
    seen_by_five_or_more += stats.ba_points_by_observations[k];
  std::printf(
      "feature_vo local BA: %d key-frames optimised, %d fixed, %lld points with 5 or more "
      "observations\n",
      stats.ba_free_keyframes, stats.ba_fixed_keyframes,
      static_cast<long long>(seen_by_five_or_more));
  EXPECT_GT(seen_by_five_or_more, 50);
  EXPECT_EQ(stats.ba_points_missing_observations, 0);
}

// No tilt: 60 s of straight and level flight at 10 m/s, 150 m over flat
// ground, at 5 frames/s. Against the truth at every tracked frame from 2 s
// after the two-view start (its first frames, on a 4 m baseline, are off by
// up to 0.13 deg before the first local BAs), the estimate's tilt (the angle
// between its down axis and the true one: roll and pitch error together)
// stays under 0.1 deg and its height error under 0.5 m.
TEST(FeatureVo, LevelFlightKeepsItsTiltAndHeight) {
  constexpr int kFrames = 300;
  FlightPlan plan;
  plan.turn_at_frame = kFrames;
  plan.speed_mps = 10.0;
  plan.dt_s = 0.2;
  plan.start_m = Eigen::Vector3d(-300.0, 0.0, -kAltitudeM);
  FeatureVoParams params;
  params.background_ba = false;
  const FlightRun run = fly(kFrames, -1, -1, params, plan);
  const int first = firstTracking(run);
  ASSERT_GE(first, 1);
  constexpr int kSettleFrames = 10;
  double worst_tilt_deg = 0.0;
  double worst_height_m = 0.0;
  for (int i = first; i < kFrames; ++i) {
    const VoFrameOutput& out = run.out[static_cast<std::size_t>(i)];
    ASSERT_EQ(out.status, VoStatus::kTracking) << "frame " << i;
    if (i < first + kSettleFrames) continue;
    const Eigen::Isometry3d& truth = run.truth[static_cast<std::size_t>(i)];
    const Eigen::Vector3d down_est = out.T_world_body.linear() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d down_true = truth.linear() * Eigen::Vector3d::UnitZ();
    const double tilt_deg =
        std::atan2(down_est.cross(down_true).norm(), down_est.dot(down_true)) / kDeg;
    const double height_m = std::abs(out.T_world_body.translation().z() - truth.translation().z());
    worst_tilt_deg = std::max(worst_tilt_deg, tilt_deg);
    worst_height_m = std::max(worst_height_m, height_m);
  }
  std::printf("feature_vo level flight: worst tilt %.3f deg, worst height error %.3f m\n",
              worst_tilt_deg, worst_height_m);
  EXPECT_LT(worst_tilt_deg, 0.1);
  EXPECT_LT(worst_height_m, 0.5);
}

// A frame of pure noise mid-flight is LOST; the next frames track again and the pose does not jump.
TEST(FeatureVo, NoiseFrameIsLostThenRecoversWithoutJump) {
  constexpr int kFrames = 80;
  constexpr int kNoise = 40;
  const FlightRun run = fly(kFrames, kNoise, kNoise + 1);
  EXPECT_EQ(run.out[kNoise].status, VoStatus::kLost);
  int recovered = -1;
  for (int i = kNoise + 1; i < kFrames; ++i)
    if (run.out[static_cast<std::size_t>(i)].status == VoStatus::kTracking) {
      recovered = i;
      break;
    }
  ASSERT_GT(recovered, kNoise);
  EXPECT_LE(recovered, kNoise + 3);
  // Every published step around the lost frame is within 1 m of the true 2 m step.
  for (int i = kNoise - 1; i < kFrames; ++i) {
    const double step = (run.out[static_cast<std::size_t>(i)].T_world_body.translation() -
                         run.out[static_cast<std::size_t>(i) - 1].T_world_body.translation())
                            .norm();
    EXPECT_NEAR(step, kSpeedMps * kDtS, 1.0) << "frame " << i;
  }
  for (int i = recovered; i < kFrames; ++i)
    EXPECT_EQ(run.out[static_cast<std::size_t>(i)].status, VoStatus::kTracking) << "frame " << i;
  double flown = 0.0;
  for (int i = 1; i < kFrames; ++i)
    flown += (run.truth[static_cast<std::size_t>(i)].translation() -
              run.truth[static_cast<std::size_t>(i) - 1].translation())
                 .norm();
  const double end_error =
      (run.out.back().T_world_body.translation() - run.truth.back().translation()).norm();
  std::printf("feature_vo lost case: recovered at frame %d, end error %.2f m of %.1f m flown\n",
              recovered, end_error, flown);
  EXPECT_LT(end_error, 0.02 * flown);
}

// Blinded longer than lost_frames_before_reset, the VO drops its map and starts
// a new one in the same world frame: from the rangefinder's ground plane at
// once, or by two-view initialisation. Either way the published pose never
// jumps (each step within 1 m of the true 2 m step: the motion model carries
// it through), tracking resumes, and the end error stays within 3 % of the
// distance flown.
void expectReinitialisesWithoutJump(bool from_range) {
  constexpr int kFrames = 110;
  constexpr int kBlindBegin = 40;
  constexpr int kBlindEnd = 48;  // 8 lost frames, more than the default 5
  FeatureVoParams params;
  params.reinit_from_range = from_range;
  params.background_ba = false;
  const FlightRun run = fly(kFrames, kBlindBegin, kBlindEnd, params);
  EXPECT_EQ(run.out.back().resets, 1);
  int resumed = -1;
  for (int i = kBlindEnd; i < kFrames; ++i)
    if (run.out[static_cast<std::size_t>(i)].status == VoStatus::kTracking) {
      resumed = i;
      break;
    }
  ASSERT_GE(resumed, kBlindEnd);
  EXPECT_LE(resumed, kBlindEnd + 10);
  for (int i = resumed; i < kFrames; ++i)
    EXPECT_EQ(run.out[static_cast<std::size_t>(i)].status, VoStatus::kTracking) << "frame " << i;
  for (int i = kBlindBegin - 1; i < kFrames; ++i) {
    const double step = (run.out[static_cast<std::size_t>(i)].T_world_body.translation() -
                         run.out[static_cast<std::size_t>(i) - 1].T_world_body.translation())
                            .norm();
    EXPECT_NEAR(step, kSpeedMps * kDtS, 1.0) << "frame " << i;
  }
  const double flown = kSpeedMps * kDtS * (kFrames - 1);
  const double end_error =
      (run.out.back().T_world_body.translation() - run.truth.back().translation()).norm();
  std::printf(
      "feature_vo re-initialised (%s): tracking again at frame %d, end error %.2f m of "
      "%.1f m flown\n",
      from_range ? "from the range" : "two-view", resumed, end_error, flown);
  EXPECT_LT(end_error, 0.03 * flown);
}

TEST(FeatureVo, RepeatedLossReinitialisesFromTheRangeWithoutJump) {
  expectReinitialisesWithoutJump(true);
}

TEST(FeatureVo, RepeatedLossReinitialisesTwoViewWithoutJump) {
  expectReinitialisesWithoutJump(false);
}

}  // namespace
}  // namespace nadir::vo
