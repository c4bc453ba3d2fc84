// The on-sensor visual odometry against frames warped with cv::warpAffine from
// a synthetic texture: the transforms put into the warp are the expected output.

#include "nodes/ppa/visual_odometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "bench/ppa_scenes.h"

namespace nadir::ppa {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kOrigin = 384.0;  // the key-frame's window in the 1024 px texture

struct Truth {
  double tx = 0, ty = 0, theta = 0, scale = 1;
};

class VisualOdometryTest : public ::testing::Test {
 protected:
  VisualOdometryResult feed(const Truth& truth) {
    test::expose(ppa_, test::viewOf(texture_, kOrigin, kOrigin, truth.tx, truth.ty, truth.theta,
                                    truth.scale));
    return vo_.processFrame(ppa_);
  }

  // Frames from the key-frame to `end` in `steps` equal steps (as at a high
  // frame rate); returns the last result.
  VisualOdometryResult ramp(const Truth& end, int steps) {
    VisualOdometryResult result = feed({});
    EXPECT_TRUE(result.new_keyframe);
    for (int i = 1; i <= steps; ++i) {
      const double f = static_cast<double>(i) / steps;
      result = feed({end.tx * f, end.ty * f, end.theta * f, std::pow(end.scale, f)});
      EXPECT_FALSE(result.new_keyframe) << "frame " << i;
    }
    return result;
  }

  cv::Mat texture_ = test::patchTexture(1024, 7);
  Ppa ppa_;
  VisualOdometryParams params_;
  VisualOdometry vo_{params_};
};

// The first frame becomes the key-frame, at the identity, with a dense edge image.
TEST_F(VisualOdometryTest, FirstFrameBecomesTheKeyframe) {
  const VisualOdometryResult result = feed({});
  EXPECT_TRUE(result.new_keyframe);
  EXPECT_EQ(result.translation_x_px, 0.0);
  EXPECT_EQ(result.translation_y_px, 0.0);
  EXPECT_EQ(result.rotation_rad, 0.0);
  EXPECT_EQ(result.scale, 1.0);
  EXPECT_DOUBLE_EQ(result.strength, 1.0);
  EXPECT_GT(result.keyframe_edge_count, 3000);
  EXPECT_EQ(result.keyframe_edge_count, result.edge_count);
  EXPECT_GT(result.instructions, 0u);
}

// The same view again aligns at the identity with every key-frame edge shared.
TEST_F(VisualOdometryTest, SameViewAlignsAtIdentity) {
  feed({});
  const VisualOdometryResult result = feed({});
  EXPECT_FALSE(result.new_keyframe);
  EXPECT_EQ(result.translation_x_px, 0.0);
  EXPECT_EQ(result.translation_y_px, 0.0);
  EXPECT_EQ(result.rotation_rad, 0.0);
  EXPECT_EQ(result.scale, 1.0);
  EXPECT_DOUBLE_EQ(result.strength, 1.0);
  EXPECT_EQ(result.iterations, 1);
}

// A translation of (+3, -2) px reached over 10 frames is recovered to the pixel.
TEST_F(VisualOdometryTest, RecoversTranslation) {
  const VisualOdometryResult result = ramp({3.0, -2.0, 0.0, 1.0}, 10);
  EXPECT_NEAR(result.translation_x_px, 3.0, 0.5);
  EXPECT_NEAR(result.translation_y_px, -2.0, 0.5);
  EXPECT_NEAR(result.rotation_rad, 0.0, params_.rotation_step_rad + 1e-9);
  EXPECT_NEAR(result.scale, 1.0, params_.scale_step + 1e-9);
  EXPECT_GT(result.strength, 0.6);
}

// A translation of (-4, +5) px over 10 frames, on another texture.
TEST_F(VisualOdometryTest, RecoversTranslationOtherTexture) {
  texture_ = test::patchTexture(1024, 11);
  const VisualOdometryResult result = ramp({-4.0, 5.0, 0.0, 1.0}, 10);
  EXPECT_NEAR(result.translation_x_px, -4.0, 0.5);
  EXPECT_NEAR(result.translation_y_px, 5.0, 0.5);
}

// A rotation of 2 deg clockwise over 10 frames is recovered within one step (0.29 deg).
TEST_F(VisualOdometryTest, RecoversRotation) {
  const VisualOdometryResult result = ramp({0.0, 0.0, 2.0 * kDeg, 1.0}, 10);
  EXPECT_NEAR(result.rotation_rad, 2.0 * kDeg, params_.rotation_step_rad);
  EXPECT_NEAR(result.translation_x_px, 0.0, 1.0);
  EXPECT_NEAR(result.translation_y_px, 0.0, 1.0);
  EXPECT_NEAR(result.scale, 1.0, params_.scale_step + 1e-9);
}

// An anti-clockwise rotation of 2 deg likewise.
TEST_F(VisualOdometryTest, RecoversAnticlockwiseRotation) {
  const VisualOdometryResult result = ramp({0.0, 0.0, -2.0 * kDeg, 1.0}, 10);
  EXPECT_NEAR(result.rotation_rad, -2.0 * kDeg, params_.rotation_step_rad);
}

// A scaling of 3 % over 10 frames is recovered within one step (0.5 %).
TEST_F(VisualOdometryTest, RecoversScaling) {
  const VisualOdometryResult result = ramp({0.0, 0.0, 0.0, 1.03}, 10);
  EXPECT_NEAR(result.scale, 1.03, 0.005);
  EXPECT_NEAR(result.rotation_rad, 0.0, params_.rotation_step_rad + 1e-9);
  EXPECT_NEAR(result.translation_x_px, 0.0, 1.0);
  EXPECT_NEAR(result.translation_y_px, 0.0, 1.0);
}

// A shrinking of 3 % likewise.
TEST_F(VisualOdometryTest, RecoversShrinking) {
  const VisualOdometryResult result = ramp({0.0, 0.0, 0.0, 1.0 / 1.03}, 10);
  EXPECT_NEAR(result.scale, 1.0 / 1.03, 0.005);
}

// All four together: (+3, -2) px, 2 deg, 3 %.
TEST_F(VisualOdometryTest, RecoversCombinedTransform) {
  const VisualOdometryResult result = ramp({3.0, -2.0, 2.0 * kDeg, 1.03}, 10);
  EXPECT_NEAR(result.translation_x_px, 3.0, 1.0);
  EXPECT_NEAR(result.translation_y_px, -2.0, 1.0);
  EXPECT_NEAR(result.rotation_rad, 2.0 * kDeg, params_.rotation_step_rad);
  EXPECT_NEAR(result.scale, 1.03, 0.005);
}

// Out and back (3 deg and 3 % away, then home): the transform returns to the
// identity with the strength of an unmoved frame, so nothing compounded.
TEST_F(VisualOdometryTest, OutAndBackReturnsToIdentity) {
  ramp({4.0, 3.0, 3.0 * kDeg, 1.03}, 12);
  VisualOdometryResult result;
  for (int i = 11; i >= 0; --i) {
    const double f = i / 12.0;
    result = feed({4.0 * f, 3.0 * f, 3.0 * kDeg * f, std::pow(1.03, f)});
    ASSERT_FALSE(result.new_keyframe);
  }
  EXPECT_EQ(result.translation_x_px, 0.0);
  EXPECT_EQ(result.translation_y_px, 0.0);
  EXPECT_EQ(result.rotation_rad, 0.0);
  EXPECT_EQ(result.scale, 1.0);
  EXPECT_DOUBLE_EQ(result.strength, 1.0);
}

// Flying on at 2 px a frame, the overlap drops and a new key-frame is taken:
// the switching frame reports its transform against the old key-frame, and
// chaining the transforms over the key-frames gives the distance flown.
TEST_F(VisualOdometryTest, NewKeyframeWhenOverlapDrops) {
  feed({});
  double keyframe_x = 0.0;  // where the current key-frame is, px along x
  int switches = 0;
  double previous_strength = 1.0;
  for (int i = 1; i <= 100; ++i) {
    const double x = 2.0 * i;
    const VisualOdometryResult result = feed({x, 0.0, 0.0, 1.0});
    EXPECT_NEAR(keyframe_x + result.translation_x_px, x, 2.0) << "frame " << i;
    EXPECT_NEAR(result.translation_y_px, 0.0, 1.0) << "frame " << i;
    if (result.new_keyframe) {
      ++switches;
      EXPECT_LT(result.strength, params_.keyframe_strength);
      EXPECT_LT(result.strength, previous_strength);
      // The aligned translation against the old key-frame: about 70 % of the view is left.
      EXPECT_GT(result.translation_x_px, 40.0);
      keyframe_x += result.translation_x_px;
      previous_strength = 1.0;
    } else {
      EXPECT_GE(result.strength, params_.keyframe_strength);
      previous_strength = result.strength;
    }
  }
  EXPECT_GE(switches, 1);
}

// With analog noise of 1 count on every transfer (edges stay above it) the
// combined transform is still recovered.
TEST_F(VisualOdometryTest, ToleratesAnalogNoise) {
  PpaParams noisy;
  noisy.analog_noise_sigma = 1.0;
  noisy.noise_seed = 3;
  ppa_ = Ppa(noisy);
  const VisualOdometryResult result = ramp({3.0, -2.0, 2.0 * kDeg, 1.03}, 10);
  EXPECT_NEAR(result.translation_x_px, 3.0, 1.0);
  EXPECT_NEAR(result.translation_y_px, -2.0, 1.0);
  EXPECT_NEAR(result.rotation_rad, 2.0 * kDeg, params_.rotation_step_rad);
  EXPECT_NEAR(result.scale, 1.03, 0.005);
}

// A featureless view has no edges: it is a key-frame with no edges, of strength 0.
TEST_F(VisualOdometryTest, FeaturelessViewHasNoStrength) {
  test::expose(ppa_, cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(128)));
  VisualOdometryResult result = vo_.processFrame(ppa_);
  EXPECT_TRUE(result.new_keyframe);
  EXPECT_EQ(result.keyframe_edge_count, 0);
  EXPECT_EQ(result.strength, 0.0);
  result = vo_.processFrame(ppa_);
  EXPECT_TRUE(result.new_keyframe);
  EXPECT_EQ(result.strength, 0.0);
}

// reset() forgets the key-frame: the next frame is a key-frame again.
TEST_F(VisualOdometryTest, ResetStartsOver) {
  ramp({2.0, 0.0, 0.0, 1.0}, 4);
  vo_.reset();
  const VisualOdometryResult result = feed({2.0, 0.0, 0.0, 1.0});
  EXPECT_TRUE(result.new_keyframe);
  EXPECT_EQ(result.translation_x_px, 0.0);
}

// Invalid parameters are refused with the key named.
TEST(VisualOdometryParamsTest, RejectsBadValues) {
  VisualOdometryParams params;
  params.keyframe_strength = 1.5;
  EXPECT_THROW(VisualOdometry{params}, core::ParamError);
  params = {};
  params.max_iterations = 0;
  EXPECT_THROW(VisualOdometry{params}, core::ParamError);
}

}  // namespace
}  // namespace nadir::ppa
