// The camera node's message conversions: image_t and camera_info_t round trips and bad input.

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "core/bus.h"
#include "nodes/camera/camera_messages.h"

namespace nadir::camera {
namespace {

render::RenderedImage gradient(int channels) {
  render::RenderedImage rendered;
  rendered.utime = 123'456'789;
  rendered.image.create(48, 64, channels == 1 ? CV_8UC1 : CV_8UC3);
  for (int r = 0; r < 48; ++r) {
    for (int c = 0; c < 64; ++c) {
      for (int ch = 0; ch < channels; ++ch)
        rendered.image.ptr<std::uint8_t>(r)[c * channels + ch] =
            static_cast<std::uint8_t>(r * 4 + c + 50 * ch);
    }
  }
  return rendered;
}

// Raw gray and RGB images survive encode -> bytes -> decode -> pixels exactly.
TEST(CameraMessages, RawImagesRoundTrip) {
  for (int channels : {1, 3}) {
    const render::RenderedImage rendered = gradient(channels);
    const nadir::image_t message = toImageMessage(rendered, 0);
    EXPECT_EQ(message.utime, 123'456'789);
    EXPECT_EQ(message.pixelformat, channels == 1 ? std::int32_t{nadir::image_t::PIXEL_FORMAT_GRAY}
                                                 : std::int32_t{nadir::image_t::PIXEL_FORMAT_RGB});
    EXPECT_EQ(message.row_stride, 64 * channels);
    const std::vector<std::uint8_t> bytes = core::encodeMessage(message);
    nadir::image_t decoded;
    ASSERT_TRUE(core::decodeMessage(bytes.data(), bytes.size(), decoded));
    const cv::Mat pixels = imageFromMessage(decoded);
    EXPECT_EQ(cv::norm(pixels, rendered.image, cv::NORM_INF), 0.0);
  }
}

// JPEG images decode to the same size and close to the original pixels.
TEST(CameraMessages, JpegImagesDecode) {
  const render::RenderedImage rendered = gradient(3);
  const nadir::image_t message = toImageMessage(rendered, 95);
  EXPECT_EQ(message.pixelformat, std::int32_t{nadir::image_t::PIXEL_FORMAT_MJPEG});
  EXPECT_LT(message.size, 64 * 48 * 3);
  const cv::Mat pixels = imageFromMessage(message);
  ASSERT_EQ(pixels.type(), CV_8UC3);
  // JPEG at quality 95 with 4:2:0 chroma: a few counts on average; a swap of R and
  // B would be off by 100 (the channels differ by 50 each).
  EXPECT_LT(cv::norm(pixels, rendered.image, cv::NORM_L1) / pixels.total() / 3, 6.0);
  const cv::Scalar mean_decoded = cv::mean(pixels), mean_original = cv::mean(rendered.image);
  for (int ch = 0; ch < 3; ++ch)
    EXPECT_NEAR(mean_decoded[ch], mean_original[ch], 3.0) << "channel " << ch;
}

// Malformed image_t messages are refused with a message saying what is wrong.
TEST(CameraMessages, MalformedImagesAreRefused) {
  nadir::image_t message = toImageMessage(gradient(1), 0);
  nadir::image_t short_data = message;
  short_data.data.resize(100);
  short_data.size = 100;
  EXPECT_THROW(imageFromMessage(short_data), std::invalid_argument);
  nadir::image_t lying_size = message;
  lying_size.size += 1;
  EXPECT_THROW(imageFromMessage(lying_size), std::invalid_argument);
  nadir::image_t yuv = message;
  yuv.pixelformat = nadir::image_t::PIXEL_FORMAT_YUYV;
  try {
    imageFromMessage(yuv);
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("unsupported pixel format"), std::string::npos);
  }
  nadir::image_t bad_jpeg = message;
  bad_jpeg.pixelformat = nadir::image_t::PIXEL_FORMAT_MJPEG;
  EXPECT_THROW(imageFromMessage(bad_jpeg), std::invalid_argument);
}

// camera_info_t carries the intrinsics and the mount (down camera: R_body_cam columns (0,1,0),
// (-1,0,0), (0,0,1)).
TEST(CameraMessages, CameraInfoCarriesIntrinsicsAndMount) {
  CameraSpec spec;
  spec.fps = 31.0;
  spec.mount_position_m = {0.2, -0.1, 0.05};
  render::CameraIntrinsics k = render::CameraIntrinsics::fromHorizontalFov(1280, 960, 1.4813);
  k.distortion = {-0.1, 0.01, 0.0, 0.0, 0.0};
  const nadir::camera_info_t info = toCameraInfo("down", spec, k, 42);
  EXPECT_EQ(info.utime, 42);
  EXPECT_EQ(info.camera_name, "down");
  EXPECT_EQ(info.width, 1280);
  EXPECT_EQ(info.fx, k.fx);
  EXPECT_EQ(info.cx, 639.5);
  EXPECT_EQ(info.distortion_model, std::int8_t{nadir::camera_info_t::DISTORTION_RADTAN});
  ASSERT_EQ(info.num_distortion, 5);
  EXPECT_EQ(info.distortion[0], -0.1);
  EXPECT_EQ(info.fps, 31.0);
  EXPECT_EQ(info.position_cam_in_body_m[0], 0.2);
  // Rotation of 90 deg about body z: w = cos 45, z = sin 45.
  EXPECT_NEAR(info.orientation_body_cam[0], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(info.orientation_body_cam[3], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(info.orientation_body_cam[1], 0.0, 1e-12);
}

}  // namespace
}  // namespace nadir::camera
