// DirectVo on synthetic flights over a textured level plane (tests/support/
// textured_plane.h), whose frames are rendered with the exact homography of
// poses the test chose, and the rangefinder's exact range: the estimates are
// compared with those poses.

#include "nodes/vo_direct/direct_vo.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "core/frames.h"
#include "nodes/common/rolling_shutter.h"
#include "tests/support/textured_plane.h"

namespace nadir::vo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
const cv::Size kSize(640, 480);
const cv::Matx33d kK(400, 0, 319.5, 0, 400, 239.5, 0, 0, 1);

// The ground: 0.5 m texels, about 2.5 pixels each from 80 m (the terrain
// renderer's imagery is no sharper than that; a texel per pixel aliases).
test::TexturedPlane smoothPlane() {
  test::TexturedPlane plane;
  plane.metres_per_texel = 0.5;
  return plane;
}

class DirectVoFlight {
 public:
  explicit DirectVoFlight(const test::TexturedPlane& plane = smoothPlane(),
                          DirectVoParams params = {})
      : plane_(plane), texture_(plane.texture()), vo_(params) {
    T_body_cam_.linear() = core::rotationBodyFromDownCamera();
  }

  cv::Mat render(const Eigen::Isometry3d& T_world_body) const {
    return plane_.render(texture_, T_world_body * T_body_cam_, kK, kSize);
  }

  // The frame at T_world_body (or the given image) with the exact range.
  DirectVoOutput step(const Eigen::Isometry3d& T_world_body, const cv::Mat& image = {}) {
    if (!started_) {
      vo_.setStartPose(T_world_body);
      started_ = true;
    }
    VoFrameInput in;
    in.utime = utime_;
    utime_ += 100000;
    in.gray = image.empty() ? render(T_world_body) : image;
    in.K = kK;
    in.R_body_cam = T_body_cam_.linear();
    in.range_m = -T_world_body.translation().z() / T_world_body.linear()(2, 2);
    in.range_ray_cam = T_body_cam_.linear().transpose() * Eigen::Vector3d::UnitZ();
    return vo_.process(in);
  }

  DirectVo& vo() { return vo_; }

 private:
  test::TexturedPlane plane_;
  cv::Mat texture_;
  DirectVo vo_;
  Eigen::Isometry3d T_body_cam_ = Eigen::Isometry3d::Identity();
  std::int64_t utime_ = 0;
  bool started_ = false;
};

double angleDeg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() / kDeg; }

double directionErrorDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) / kDeg;
}

struct RelativeError {
  double rotation_deg;
  double direction_deg;
  double length_ratio;
};

// The second frame's motion from the first, estimated against true.
RelativeError relativeError(const Eigen::Isometry3d& est0, const Eigen::Isometry3d& est1,
                            const Eigen::Isometry3d& true0, const Eigen::Isometry3d& true1) {
  const Eigen::Isometry3d est = est0.inverse() * est1;
  const Eigen::Isometry3d tru = true0.inverse() * true1;
  return {angleDeg(est.linear().transpose() * tru.linear()),
          directionErrorDeg(est.translation(), tru.translation()),
          est.translation().norm() / tru.translation().norm()};
}

const Eigen::Isometry3d kFirst = test::bodyPose({10, -20, -80}, 0.0, 0.0, 30 * kDeg);
const Eigen::Isometry3d kSecond =
    test::bodyPose({12.6, -18.5, -80.4}, 1.0 * kDeg, -0.7 * kDeg, 31.5 * kDeg);

// Two frames of a textured plane 80 m below, 3 m and 1.9 deg apart: the
// direction of the translation within 0.5 deg, the rotation within 0.05 deg
// (the figures the direct VO is held to), the length within 2 % (the range is exact).
TEST(DirectVo, AlignsTwoFramesWithAKnownRelativePose) {
  DirectVoFlight flight;
  const DirectVoOutput a = flight.step(kFirst);
  ASSERT_EQ(a.status, VoStatus::kTracking);
  const DirectVoOutput b = flight.step(kSecond);
  ASSERT_EQ(b.status, VoStatus::kTracking);
  const RelativeError e = relativeError(a.T_world_body, b.T_world_body, kFirst, kSecond);
  std::printf("two frames: rotation %.4f deg, direction %.3f deg, length ratio %.4f\n",
              e.rotation_deg, e.direction_deg, e.length_ratio);
  EXPECT_LT(e.rotation_deg, 0.05);
  EXPECT_LT(e.direction_deg, 0.5);
  EXPECT_NEAR(e.length_ratio, 1.0, 0.02);
}

// The same with the second frame 30 % brighter (gain 1.3; the texture spans
// 20-190 so nothing clips): the affine brightness model absorbs it, and its
// log gain is log(1.3) more than without the change, within 0.03 (resampling
// the texture changes the contrast a little by itself; measured 0.019 off).
TEST(DirectVo, AlignsTwoFramesThroughA30PercentGainChange) {
  test::TexturedPlane plane = smoothPlane();
  plane.lowest = 112.0;
  plane.highest = 138.0;
  double log_gain[2] = {0.0, 0.0};
  for (int bright = 0; bright < 2; ++bright) {
    DirectVoFlight flight(plane);
    const DirectVoOutput a = flight.step(kFirst);
    ASSERT_EQ(a.status, VoStatus::kTracking);
    cv::Mat second;
    flight.render(kSecond).convertTo(second, CV_8U, bright ? 1.3 : 1.0);
    const DirectVoOutput b = flight.step(kSecond, second);
    ASSERT_EQ(b.status, VoStatus::kTracking);
    const RelativeError e = relativeError(a.T_world_body, b.T_world_body, kFirst, kSecond);
    std::printf(
        "gain %.1f: rotation %.4f deg, direction %.3f deg, length ratio %.4f, log gain %.4f\n",
        bright ? 1.3 : 1.0, e.rotation_deg, e.direction_deg, e.length_ratio, b.affine.a);
    EXPECT_LT(e.rotation_deg, 0.05);
    EXPECT_LT(e.direction_deg, 0.5);
    EXPECT_NEAR(e.length_ratio, 1.0, 0.02);
    log_gain[bright] = b.affine.a;
  }
  EXPECT_NEAR(log_gain[1] - log_gain[0], std::log(1.3), 0.03);
}

// Hovering 80 m up and rolling at 45 deg/s for 1 s (-22.5 to +22.5 deg) at
// 31 frames/s: every frame tracked, no re-initialisation, the attitude within
// 0.5 deg at every frame.
TEST(DirectVo, FollowsAPureRollAt45DegreesPerSecond) {
  DirectVoFlight flight;
  double worst_deg = 0.0;
  for (int i = 0; i <= 31; ++i) {
    const double roll = (-22.5 + 45.0 * i / 31.0) * kDeg;
    const Eigen::Isometry3d truth = test::bodyPose({0, 0, -80}, roll, 0.0, 0.3);
    const DirectVoOutput out = flight.step(truth);
    ASSERT_EQ(out.status, VoStatus::kTracking) << "frame " << i;
    ASSERT_EQ(out.resets, 0) << "frame " << i;
    worst_deg =
        std::max(worst_deg, angleDeg(out.T_world_body.linear().transpose() * truth.linear()));
  }
  std::printf("roll 45 deg/s: worst attitude error %.3f deg, %lld key-frames\n", worst_deg,
              static_cast<long long>(flight.vo().timing().keyframes));
  EXPECT_LT(worst_deg, 0.5);
}

// Straight and level at 19.3 m/s, 10 frames/s; frames 20-27 are noise (the
// camera blinded). They are LOST; the map is made again after them from the
// extrapolated pose (one reset), and no estimate is more than 1 m off the
// truth, during or after.
TEST(DirectVo, ReinitialisesAfterEightBlindFramesWithoutAJump) {
  DirectVoFlight flight;
  cv::RNG rng(7);
  double worst_m = 0.0;
  int lost = 0;
  DirectVoOutput out;
  for (int i = 0; i < 50; ++i) {
    // 1.93 m a frame along a heading of 11.5 deg: no whole-pixel shifts
    // between frames, which a real camera never gives either.
    const Eigen::Isometry3d truth = test::bodyPose(
        {-50.0 + 1.93 * i * std::cos(0.2), 5.0 + 1.93 * i * std::sin(0.2), -80.0}, 0.0, 0.0, 0.2);
    cv::Mat image;
    if (i >= 20 && i < 28) {
      image = cv::Mat(kSize, CV_8U);
      rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    }
    out = flight.step(truth, image);
    if (out.status == VoStatus::kLost) ++lost;
    if (i >= 20 && i < 28) {
      EXPECT_NE(out.status, VoStatus::kTracking) << "blind frame " << i;
    }
    if (i >= 30) {
      EXPECT_EQ(out.status, VoStatus::kTracking) << "frame " << i;
    }
    worst_m = std::max(worst_m, (out.T_world_body.translation() - truth.translation()).norm());
  }
  std::printf("8 blind frames: %d lost, %d resets, worst position error %.3f m\n", lost, out.resets,
              worst_m);
  EXPECT_EQ(out.resets, 1);
  EXPECT_LT(worst_m, 1.0);
}

// Straight and level over ground as faint as the thesis's farmland seen
// through coarse imagery (a texture spanning 18 intensity levels, under
// sensor noise of 3 levels RMS): the image fixes the pose too loosely, and the
// VO says so (LOST on most frames) where, without the check on the pose's
// uncertainty, it reports every frame tracked while its estimate drifts. The
// same flight and noise over the ordinary texture is tracked throughout.
struct FaintFlight {
  int tracked = 0, lost = 0;
  double worst_tracked_m = 0.0;
};

FaintFlight flyOverNoisyGround(const test::TexturedPlane& plane, const DirectVoParams& params) {
  DirectVoFlight flight(plane, params);
  cv::RNG rng(11);
  FaintFlight result;
  for (int i = 0; i < 30; ++i) {
    const Eigen::Isometry3d truth = test::bodyPose(
        {-50.0 + 1.93 * i * std::cos(0.2), 5.0 + 1.93 * i * std::sin(0.2), -80.0}, 0.0, 0.0, 0.2);
    cv::Mat image, noise(kSize, CV_32F), noisy;
    flight.render(truth).convertTo(image, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
    cv::Mat(image + noise).convertTo(noisy, CV_8U);
    const DirectVoOutput out = flight.step(truth, noisy);
    if (i == 0) continue;  // the map is made on the first frame
    if (out.status == VoStatus::kLost) ++result.lost;
    if (out.status != VoStatus::kTracking) continue;
    ++result.tracked;
    result.worst_tracked_m = std::max(
        result.worst_tracked_m, (out.T_world_body.translation() - truth.translation()).norm());
  }
  return result;
}

TEST(DirectVo, ReportsLostOverGroundTooFaintToFixThePose) {
  const FaintFlight ordinary = flyOverNoisyGround(smoothPlane(), {});
  test::TexturedPlane faint = smoothPlane();
  faint.lowest = 116.0;
  faint.highest = 134.0;
  const FaintFlight checked = flyOverNoisyGround(faint, {});
  DirectVoParams unchecked_params;
  unchecked_params.lost_pose_sigma_mrad = 1e6;
  const FaintFlight unchecked = flyOverNoisyGround(faint, unchecked_params);
  std::printf(
      "of 29 frames: ordinary %d tracked (worst %.2f m); faint %d tracked, %d lost; "
      "faint without the check %d tracked (worst %.2f m)\n",
      ordinary.tracked, ordinary.worst_tracked_m, checked.tracked, checked.lost, unchecked.tracked,
      unchecked.worst_tracked_m);
  EXPECT_EQ(ordinary.tracked, 29);
  EXPECT_GE(checked.lost, 20);
  EXPECT_GT(unchecked.worst_tracked_m, 5.0 * ordinary.worst_tracked_m);
  EXPECT_GE(unchecked.tracked, 25);
}

// The speed check: at 19.3 m/s and 10 frames/s, a limit of 30 m/s tracks
// every frame, a limit of 10 m/s none (each frame moved 1.93 m in 0.1 s).
TEST(DirectVo, AFrameMovedFasterThanTheSpeedLimitIsLost) {
  for (const double limit_mps : {30.0, 10.0}) {
    DirectVoParams params;
    params.lost_speed_mps = limit_mps;
    DirectVoFlight flight(smoothPlane(), params);
    int tracked = 0;
    for (int i = 0; i < 10; ++i) {
      const DirectVoOutput out = flight.step(
          test::bodyPose({-50.0 + 1.93 * i * std::cos(0.2), 5.0 + 1.93 * i * std::sin(0.2), -80.0},
                         0.0, 0.0, 0.2));
      if (i > 0 && out.status == VoStatus::kTracking) ++tracked;
    }
    EXPECT_EQ(tracked, limit_mps > 19.3 ? 9 : 0) << "limit " << limit_mps << " m/s";
  }
}

// A rolling-shutter frame (each row rendered from the pose at its own time:
// rolling at 45 deg/s and flying at 19.3 m/s, 30 ms readout, 80 m over the
// textured plane) rectified with the true motion is the global-shutter frame
// at its stamp: the mean difference over the interior falls from that of the
// raw frame (the 1.35 deg roll during the readout shifts the bottom row
// against the top by about 9 px) to the interpolation's.
TEST(RollingShutter, RectifiedFrameIsTheGlobalShutterFrame) {
  const test::TexturedPlane plane = smoothPlane();
  const cv::Mat texture = plane.texture();
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
  T_world_cam0.linear() = core::rotationBodyFromDownCamera();
  T_world_cam0.translation() = Eigen::Vector3d(3.0, -7.0, -80.0);
  CameraTwist twist;
  twist.omega_cam_rps = Eigen::Vector3d(0.0, 45.0 * kDeg, 0.0);
  twist.v_cam_mps = Eigen::Vector3d(19.3, 0.0, 0.0);
  constexpr double kReadout_s = 0.03;
  const auto poseAt = [&](double t) {
    Eigen::Isometry3d T = T_world_cam0;
    T.linear() = T_world_cam0.linear() *
                 Eigen::AngleAxisd(twist.omega_cam_rps.norm() * t, twist.omega_cam_rps.normalized())
                     .toRotationMatrix();
    T.translation() += T_world_cam0.linear() * twist.v_cam_mps * t;
    return T;
  };
  const cv::Mat global = plane.render(texture, T_world_cam0, kK, kSize);
  cv::Mat rolling(kSize, CV_8U);
  for (int r = 0; r < kSize.height; ++r) {
    const double t = (r - 0.5 * (kSize.height - 1)) / kSize.height * kReadout_s;
    plane.render(texture, poseAt(t), kK, kSize).row(r).copyTo(rolling.row(r));
  }
  const cv::Mat rectified = rectifyRollingShutter(rolling, kK, kReadout_s, twist, 80.0);
  const cv::Rect interior(40, 40, kSize.width - 80, kSize.height - 80);
  const auto meanDiff = [&](const cv::Mat& a) {
    cv::Mat diff;
    cv::absdiff(a(interior), global(interior), diff);
    return cv::mean(diff)[0];
  };
  const double raw = meanDiff(rolling), fixed = meanDiff(rectified);
  std::printf("mean difference from the global shutter: raw %.2f, rectified %.2f counts\n", raw,
              fixed);
  EXPECT_GT(raw, 10.0);
  EXPECT_LT(fixed, 2.0);
  EXPECT_THROW(rectifyRollingShutter(rolling, kK, kReadout_s, twist, 0.0), std::invalid_argument);
}

// Climbing from 60 to 120 m at 6 m/s while flying at 19.3 m/s, 10 frames/s,
// nose up 10 deg: the ground recedes from frame to frame (the case a level
// flight never tests). Every frame tracked, the attitude within 0.3 deg and the
// position within 1 % of the distance flown at every frame.
TEST(DirectVo, FollowsAClimb) {
  DirectVoFlight flight;
  double worst_deg = 0.0, worst_share = 0.0;
  for (int i = 0; i <= 100; ++i) {
    const double along = 1.93 * i;
    const Eigen::Isometry3d truth =
        test::bodyPose({-100.0 + along * std::cos(0.2), along * std::sin(0.2), -60.0 - 0.6 * i},
                       0.0, 10.0 * kDeg, 0.2);
    const DirectVoOutput out = flight.step(truth);
    ASSERT_EQ(out.status, VoStatus::kTracking) << "frame " << i;
    worst_deg =
        std::max(worst_deg, angleDeg(out.T_world_body.linear().transpose() * truth.linear()));
    if (i > 0)
      worst_share = std::max(
          worst_share, (out.T_world_body.translation() - truth.translation()).norm() / (2.02 * i));
    if (getenv("DBG"))
      std::printf("%d rot %.3f pos %.3f\n", i,
                  angleDeg(out.T_world_body.linear().transpose() * truth.linear()),
                  (out.T_world_body.translation() - truth.translation()).norm());
  }
  std::printf(
      "climb: worst attitude error %.3f deg, worst position error %.2f %% of the distance\n",
      worst_deg, 100.0 * worst_share);
  EXPECT_LT(worst_deg, 0.3);
  EXPECT_LT(worst_share, 0.01);
}

// A reset to a given pose: the next estimates continue from it and it counts.
TEST(DirectVo, ResetsToARequestedPose) {
  DirectVoFlight flight;
  for (int i = 0; i < 5; ++i) flight.step(test::bodyPose({2.0 * i, 0.0, -80.0}, 0.0, 0.0, 0.0));
  const Eigen::Isometry3d elsewhere = test::bodyPose({500.0, -300.0, -80.0}, 0.0, 0.0, 0.0);
  flight.vo().requestReset(elsewhere);
  const DirectVoOutput out = flight.step(test::bodyPose({10.0, 0.0, -80.0}, 0.0, 0.0, 0.0));
  EXPECT_EQ(out.resets, 1);
  EXPECT_LT((out.T_world_body.translation() - elsewhere.translation()).norm(), 1e-9);
  const DirectVoOutput next = flight.step(test::bodyPose({12.0, 0.0, -80.0}, 0.0, 0.0, 0.0));
  EXPECT_EQ(next.status, VoStatus::kTracking);
  EXPECT_NEAR((next.T_world_body.translation() - elsewhere.translation()).x(), 2.0, 0.1);
}

// A frame that is not 8-bit gray is refused with a clear error.
TEST(DirectVo, RefusesAColourFrame) {
  DirectVo vo({});
  VoFrameInput in;
  in.gray = cv::Mat(48, 64, CV_8UC3);
  EXPECT_THROW(vo.process(in), std::invalid_argument);
}

}  // namespace
}  // namespace nadir::vo
