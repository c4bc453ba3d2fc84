// The codecs: each plain struct's fields land in the LCM message's fields (read
// back with the generated types, not the codec), come back exactly through
// decode, and bad bytes or bad values are refused with a message saying what.

#include "lcmtypes/codec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/frames.h"
#include "nadir/baro_t.hpp"
#include "nadir/camera_info_t.hpp"
#include "nadir/camera_info_v1_t.hpp"
#include "nadir/drive_command_t.hpp"
#include "nadir/gate_pattern_t.hpp"
#include "nadir/gps_t.hpp"
#include "nadir/image_t.hpp"
#include "nadir/imu_t.hpp"
#include "nadir/magnetometer_t.hpp"
#include "nadir/nav_state_t.hpp"
#include "nadir/pose_t.hpp"
#include "nadir/range_t.hpp"
#include "nadir/vo_estimate_t.hpp"

namespace nadir::msg {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The bytes read with the generated type, independently of the codec.
template <class Lcm>
Lcm asLcm(const Bytes& bytes) {
  Lcm message;
  EXPECT_EQ(message.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  return message;
}

template <class Lcm>
Bytes bytesOf(const Lcm& message) {
  Bytes bytes(static_cast<std::size_t>(message.getEncodedSize()));
  message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

template <class T, class Lcm>
std::string invalidReason(const Lcm& message) {
  try {
    decode<T>(bytesOf(message));
  } catch (const InvalidMessage& error) {
    return error.what();
  }
  return "";
}

// A pose with every field set and distinct, with a general (non-axis) attitude.
Pose makePose(std::int64_t utime, double base) {
  Pose pose;
  pose.utime = utime;
  pose.p_ned_m = Eigen::Vector3d(base + 10.5, -(base + 20.25), -(base + 120.125));
  pose.v_ned_mps = Eigen::Vector3d(base + 1.5, base - 2.25, 0.375);
  pose.a_ned_mps2 = Eigen::Vector3d(0.125, -0.25, base * 0.01);
  pose.q_world_body = core::quaternionFromRpy({(5.0 + base) * kDeg, -3.0 * kDeg, 40.0 * kDeg});
  pose.omega_body_rps = Eigen::Vector3d(0.01, -0.02, 0.03 + base * 1e-3);
  return pose;
}

cv::Mat gradient(int channels) {
  cv::Mat image(48, 64, channels == 1 ? CV_8UC1 : CV_8UC3);
  for (int r = 0; r < 48; ++r) {
    for (int c = 0; c < 64; ++c) {
      for (int ch = 0; ch < channels; ++ch)
        image.ptr<std::uint8_t>(r)[c * channels + ch] =
            static_cast<std::uint8_t>(r * 4 + c + 50 * ch);
    }
  }
  return image;
}

// ---------------------------------------------------------------- pose_t

// pose_t's fields are the struct's, the wire quaternion w first; decode gives back
// every field, the quaternion as Eigen normalises it.
TEST(Codec, PoseRoundTrip) {
  const Pose pose = makePose(1'700'000'000'123'457, 3.0);
  const nadir::pose_t wire = asLcm<nadir::pose_t>(encode(pose));
  EXPECT_EQ(wire.utime, pose.utime);
  EXPECT_EQ(wire.pos[2], pose.p_ned_m.z());
  EXPECT_EQ(wire.vel[1], pose.v_ned_mps.y());
  EXPECT_EQ(wire.accel[2], pose.a_ned_mps2.z());
  EXPECT_EQ(wire.rotation_rate[2], pose.omega_body_rps.z());
  EXPECT_EQ(wire.orientation[0], pose.q_world_body.w());
  EXPECT_EQ(wire.orientation[3], pose.q_world_body.z());
  const Pose back = decode<Pose>(encode(pose));
  EXPECT_EQ(back.utime, pose.utime);
  EXPECT_EQ(back.p_ned_m, pose.p_ned_m);
  EXPECT_EQ(back.v_ned_mps, pose.v_ned_mps);
  EXPECT_EQ(back.a_ned_mps2, pose.a_ned_mps2);
  EXPECT_EQ(back.omega_body_rps, pose.omega_body_rps);
  EXPECT_EQ(back.q_world_body.coeffs(), pose.q_world_body.normalized().coeffs());
}

// A non-finite position and a quaternion off unit norm by > 1e-3 are refused, naming
// the field; < 1e-3 is normalised. Unset rates from other systems pass.
TEST(Codec, InvalidPoseIsRefused) {
  nadir::pose_t good = asLcm<nadir::pose_t>(encode(makePose(5, 1.0)));

  nadir::pose_t bad = good;
  bad.pos[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(invalidReason<Pose>(bad).find("pos[1]"), std::string::npos) << invalidReason<Pose>(bad);
  bad = good;
  bad.orientation[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(invalidReason<Pose>(bad).find("orientation"), std::string::npos);
  bad = good;
  for (double& c : bad.orientation) c *= 1.002;
  EXPECT_NE(invalidReason<Pose>(bad).find("orientation"), std::string::npos);

  nadir::pose_t nearly = good;
  for (double& c : nearly.orientation) c *= 1.0005;
  const Pose pose = decode<Pose>(bytesOf(nearly));
  EXPECT_NEAR(pose.q_world_body.norm(), 1.0, 1e-15);
  EXPECT_NEAR(pose.q_world_body.w(), good.orientation[0], 1e-15);

  nadir::pose_t no_rates = good;
  no_rates.accel[0] = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(std::isinf(decode<Pose>(bytesOf(no_rates)).a_ned_mps2.x()));
}

// ---------------------------------------------------------------- sensors

// imu_t, range_t, gps_t, baro_t and magnetometer_t carry every field, the enums mapped to the
// wire's.
TEST(Codec, SensorMessagesCarryEveryField) {
  const Imu imu_sample{7, {0.1, -0.2, 0.3}, {0.5, 0.25, -9.80665}};
  const nadir::imu_t imu = asLcm<nadir::imu_t>(encode(imu_sample));
  EXPECT_EQ(imu.utime, 7);
  EXPECT_EQ(imu.angular_velocity_rps[1], -0.2);
  EXPECT_EQ(imu.angular_velocity_rps[2], 0.3);
  EXPECT_EQ(imu.linear_acceleration_mps2[0], 0.5);
  EXPECT_EQ(imu.linear_acceleration_mps2[2], -9.80665);
  EXPECT_EQ(decode<Imu>(encode(imu_sample)).linear_acceleration_mps2,
            imu_sample.linear_acceleration_mps2);

  Range range_sample;
  range_sample.utime = 8;
  range_sample.range_m = 42.5;
  range_sample.status = RangeStatus::TOO_CLOSE;
  range_sample.direction_body = Eigen::Vector3d(0.6, 0.0, 0.8);
  range_sample.min_range_m = 0.1;
  range_sample.max_range_m = 100.0;
  const nadir::range_t range = asLcm<nadir::range_t>(encode(range_sample));
  EXPECT_EQ(range.utime, 8);
  EXPECT_EQ(range.range_m, 42.5);
  EXPECT_EQ(range.min_range_m, 0.1);
  EXPECT_EQ(range.max_range_m, 100.0);
  EXPECT_EQ(range.direction_body[0], 0.6);
  EXPECT_EQ(range.direction_body[2], 0.8);
  EXPECT_EQ(range.status, std::int8_t{nadir::range_t::STATUS_TOO_CLOSE});
  range_sample.status = RangeStatus::VALID;
  EXPECT_EQ(asLcm<nadir::range_t>(encode(range_sample)).status,
            std::int8_t{nadir::range_t::STATUS_VALID});
  range_sample.status = RangeStatus::OUT_OF_RANGE;
  EXPECT_EQ(asLcm<nadir::range_t>(encode(range_sample)).status,
            std::int8_t{nadir::range_t::STATUS_OUT_OF_RANGE});
  EXPECT_EQ(decode<Range>(encode(range_sample)).status, RangeStatus::OUT_OF_RANGE);

  Gps gps_sample;
  gps_sample.utime = 9;
  gps_sample.lat_rad = 0.65;
  gps_sample.lon_rad = -1.97;
  gps_sample.alt_m = 1520.5;
  gps_sample.velocity_ned_mps = Eigen::Vector3d(20.0, -1.0, 0.5);
  gps_sample.horizontal_accuracy_m = 1.5;
  gps_sample.vertical_accuracy_m = 3.0;
  gps_sample.num_satellites = 12;
  gps_sample.fix = GpsFix::FIX_3D;
  const nadir::gps_t gps = asLcm<nadir::gps_t>(encode(gps_sample));
  EXPECT_EQ(gps.utime, 9);
  EXPECT_EQ(gps.latitude_rad, 0.65);
  EXPECT_EQ(gps.longitude_rad, -1.97);
  EXPECT_EQ(gps.altitude_m, 1520.5);
  EXPECT_EQ(gps.velocity_ned_mps[0], 20.0);
  EXPECT_EQ(gps.velocity_ned_mps[2], 0.5);
  EXPECT_EQ(gps.horizontal_accuracy_m, 1.5);
  EXPECT_EQ(gps.vertical_accuracy_m, 3.0);
  EXPECT_EQ(gps.num_satellites, 12);
  EXPECT_EQ(gps.fix_type, std::int8_t{nadir::gps_t::FIX_3D});
  EXPECT_EQ(asLcm<nadir::gps_t>(encode(Gps{})).fix_type, std::int8_t{nadir::gps_t::FIX_NONE});
  EXPECT_EQ(decode<Gps>(encode(gps_sample)).fix, GpsFix::FIX_3D);

  const nadir::baro_t baro = asLcm<nadir::baro_t>(encode(Baro{123456, 1000.0, 89874.6}));
  EXPECT_EQ(baro.utime, 123456);
  EXPECT_EQ(baro.altitude_m, 1000.0);
  EXPECT_EQ(baro.pressure_pa, 89874.6);

  const Bytes mag_bytes = encode(Magnetometer{2345, {20.5, -1.75, 47.25}});
  const nadir::magnetometer_t mag = asLcm<nadir::magnetometer_t>(mag_bytes);
  EXPECT_EQ(mag.utime, 2345);
  EXPECT_EQ(mag.field_ut[0], 20.5);
  EXPECT_EQ(mag.field_ut[1], -1.75);
  EXPECT_EQ(mag.field_ut[2], 47.25);
  EXPECT_EQ(decode<Magnetometer>(mag_bytes).field_body_ut, Eigen::Vector3d(20.5, -1.75, 47.25));
  EXPECT_EQ(typeName(mag_bytes.data(), mag_bytes.size()), "magnetometer_t");
}

// An enum value the type does not define is refused.
TEST(Codec, UndefinedEnumValueIsRefused) {
  nadir::range_t range = asLcm<nadir::range_t>(encode(Range{}));
  range.status = 7;
  EXPECT_NE(invalidReason<Range>(range).find("status 7"), std::string::npos);
}

// ---------------------------------------------------------------- image_t

// Raw gray and RGB images survive encode -> bytes -> decode -> pixels exactly.
TEST(Codec, RawImagesRoundTrip) {
  for (int channels : {1, 3}) {
    const Image image{123'456'789, gradient(channels), 0, {{"exposure_s", {'0', '.', '5'}}}};
    const Bytes bytes = encode(image);
    const nadir::image_t wire = asLcm<nadir::image_t>(bytes);
    EXPECT_EQ(wire.utime, 123'456'789);
    EXPECT_EQ(wire.pixelformat, channels == 1 ? std::int32_t{nadir::image_t::PIXEL_FORMAT_GRAY}
                                              : std::int32_t{nadir::image_t::PIXEL_FORMAT_RGB});
    EXPECT_EQ(wire.row_stride, 64 * channels);
    const Image back = decode<Image>(bytes);
    EXPECT_EQ(cv::norm(back.pixels, image.pixels, cv::NORM_INF), 0.0);
    EXPECT_EQ(back.metadataText("exposure_s"), "0.5");
    EXPECT_EQ(back.metadataText("gain"), "");
  }
}

// A raw image's bytes are the generated encoder's for the same fields, with or
// without metadata, from a whole image or a region of one (rows apart in memory).
TEST(Codec, RawImageBytesAreTheGeneratedEncodersBytes) {
  for (int channels : {1, 3}) {
    const cv::Mat whole = gradient(channels);
    const cv::Mat region = whole(cv::Rect(5, 3, 40, 30));
    for (const cv::Mat& pixels : {whole, region}) {
      for (const bool with_metadata : {false, true}) {
        Image image{-42, pixels, 0, {}};
        if (with_metadata) image.metadata = {{"exposure_s", {'1'}}, {"gain", {'2', '.', '5'}}};
        nadir::image_t expected{};
        expected.utime = -42;
        expected.width = pixels.cols;
        expected.height = pixels.rows;
        expected.row_stride = pixels.cols * channels;
        expected.pixelformat = channels == 1 ? std::int32_t{nadir::image_t::PIXEL_FORMAT_GRAY}
                                             : std::int32_t{nadir::image_t::PIXEL_FORMAT_RGB};
        for (int row = 0; row < pixels.rows; ++row)
          expected.data.insert(expected.data.end(), pixels.ptr<std::uint8_t>(row),
                               pixels.ptr<std::uint8_t>(row) + expected.row_stride);
        expected.size = static_cast<std::int32_t>(expected.data.size());
        for (const auto& [key, value] : image.metadata) {
          nadir::image_metadata_t entry;
          entry.key = key;
          entry.value = value;
          entry.n = static_cast<std::int32_t>(value.size());
          expected.metadata.push_back(entry);
        }
        expected.nmetadata = static_cast<std::int32_t>(expected.metadata.size());
        Bytes expected_bytes(static_cast<std::size_t>(expected.getEncodedSize()));
        ASSERT_GT(
            expected.encode(expected_bytes.data(), 0, static_cast<int>(expected_bytes.size())), 0);
        EXPECT_EQ(encode(image), expected_bytes)
            << channels << " channels, " << pixels.cols << " columns, metadata " << with_metadata;
      }
    }
  }
}

// JPEG images decode to the same size and close to the original pixels.
TEST(Codec, JpegImagesDecode) {
  const Image image{0, gradient(3), 95, {}};
  const Bytes bytes = encode(image);
  const nadir::image_t wire = asLcm<nadir::image_t>(bytes);
  EXPECT_EQ(wire.pixelformat, std::int32_t{nadir::image_t::PIXEL_FORMAT_MJPEG});
  EXPECT_LT(wire.size, 64 * 48 * 3);
  const cv::Mat pixels = decode<Image>(bytes).pixels;
  ASSERT_EQ(pixels.type(), CV_8UC3);
  // JPEG at quality 95 with 4:2:0 chroma: a few counts on average; a swap of R and
  // B would be off by 100 (the channels differ by 50 each).
  EXPECT_LT(cv::norm(pixels, image.pixels, cv::NORM_L1) / pixels.total() / 3, 6.0);
  const cv::Scalar mean_decoded = cv::mean(pixels), mean_original = cv::mean(image.pixels);
  for (int ch = 0; ch < 3; ++ch)
    EXPECT_NEAR(mean_decoded[ch], mean_original[ch], 3.0) << "channel " << ch;
}

// Malformed image_t messages are refused with a message saying what is wrong.
TEST(Codec, MalformedImagesAreRefused) {
  const nadir::image_t message = asLcm<nadir::image_t>(encode(Image{0, gradient(1), 0, {}}));
  nadir::image_t short_data = message;
  short_data.data.resize(100);
  short_data.size = 100;
  EXPECT_NE(invalidReason<Image>(short_data).find("row stride"), std::string::npos);
  nadir::image_t yuv = message;
  yuv.pixelformat = nadir::image_t::PIXEL_FORMAT_YUYV;
  EXPECT_NE(invalidReason<Image>(yuv).find("unsupported pixel format"), std::string::npos);
  nadir::image_t bad_jpeg = message;
  bad_jpeg.pixelformat = nadir::image_t::PIXEL_FORMAT_MJPEG;
  EXPECT_NE(invalidReason<Image>(bad_jpeg).find("JPEG"), std::string::npos);
}

// A JPEG's frame header is read before anything is decoded: a frame size other
// than the message's, a header missing, or more pixels than the bytes can hold
// (a Huffman JPEG spends at least one bit per 8x8 block: 512 pixels a byte) is
// refused without decoding.
TEST(Codec, AJpegIsCheckedBeforeItIsDecoded) {
  const nadir::image_t message = asLcm<nadir::image_t>(encode(Image{0, gradient(1), 90, {}}));
  ASSERT_EQ(message.pixelformat, std::int32_t{nadir::image_t::PIXEL_FORMAT_MJPEG});
  nadir::image_t wider = message;
  wider.width = 65;
  EXPECT_NE(invalidReason<Image>(wider).find("JPEG is 64x48"), std::string::npos)
      << invalidReason<Image>(wider);
  nadir::image_t cut = message;
  cut.data.resize(20);  // the start and part of the first table
  cut.size = 20;
  EXPECT_NE(invalidReason<Image>(cut).find("JPEG data has no frame header"), std::string::npos)
      << invalidReason<Image>(cut);
  // The baseline frame marker FF C0, then length (2), precision (1), height, width.
  nadir::image_t huge = message;
  const std::uint8_t baseline_frame[] = {0xFF, 0xC0};
  const auto sof = std::search(huge.data.begin(), huge.data.end(), std::begin(baseline_frame),
                               std::end(baseline_frame));
  ASSERT_NE(sof, huge.data.end());
  const std::size_t at = static_cast<std::size_t>(sof - huge.data.begin()) + 5;
  ASSERT_EQ(huge.data[at] * 256 + huge.data[at + 1], 48);
  ASSERT_EQ(huge.data[at + 2] * 256 + huge.data[at + 3], 64);
  huge.data[at] = 0x2F;  // 12040 rows
  huge.data[at + 1] = 0x08;
  huge.data[at + 2] = 0x3A;  // 14895 columns
  huge.data[at + 3] = 0x2F;
  huge.width = 14895;
  huge.height = 12040;
  ASSERT_LT(huge.data.size(), 179'335'800u / 512);
  EXPECT_NE(invalidReason<Image>(huge).find(" bytes cannot hold 179335800 pixels"),
            std::string::npos)
      << invalidReason<Image>(huge);
}

// A raw image with metadata cut anywhere (in a field, the pixels, a key or a
// value) or with a byte too many is a DecodeError, as the generated decoder
// refuses it; a pixel count one short or one over shifts the metadata and is
// refused too.
TEST(Codec, CutOrPaddedRawImagesAreDecodeErrors) {
  const Bytes whole = encode(Image{7, gradient(1), 0, {{"exposure_s", {'0', '.', '5'}}}});
  ASSERT_EQ(decode<Image>(whole).metadataText("exposure_s"), "0.5");
  for (std::size_t length = 0; length < whole.size(); ++length) {
    EXPECT_THROW(decode<Image>(whole.data(), length), DecodeError) << "length " << length;
  }
  Bytes padded = whole;
  padded.push_back(0);
  EXPECT_THROW(decode<Image>(padded), DecodeError);
  for (const int delta : {-1, 1}) {
    Bytes shifted = whole;
    const std::uint32_t size = 64 * 48 + static_cast<std::uint32_t>(delta);
    for (int i = 0; i < 4; ++i)
      shifted[32 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(size >> (24 - 8 * i));
    EXPECT_ANY_THROW(decode<Image>(shifted)) << "size off by " << delta;
  }
}

// A count or string length in the bytes that the bytes cannot hold is a
// DecodeError, before anything is allocated for it: image_t's pixel count at
// byte 32 (hash 8, utime 8, four int32) set to 2^31 - 1 and to -5, and
// vo_estimate_t's source length at byte 16 (hash, utime) set to 0 and -1.
TEST(Codec, ImpossibleCountsAreDecodeErrors) {
  const auto withInt32At = [](Bytes bytes, std::size_t offset, std::int32_t value) {
    const auto u = static_cast<std::uint32_t>(value);
    for (int i = 0; i < 4; ++i) bytes[offset + i] = static_cast<std::uint8_t>(u >> (24 - 8 * i));
    return bytes;
  };
  const Bytes image = encode(Image{0, gradient(1), 0, {}});
  ASSERT_EQ(asLcm<nadir::image_t>(image).size, static_cast<std::int32_t>(image.size()) - 40);
  EXPECT_THROW(decode<Image>(withInt32At(image, 32, 0x7fffffff)), DecodeError);
  EXPECT_THROW(decode<Image>(withInt32At(image, 32, -5)), DecodeError);
  VoEstimate estimate;
  estimate.source = "ppa";
  const Bytes vo = encode(estimate);
  EXPECT_EQ(decode<VoEstimate>(withInt32At(vo, 16, 4)).source, "ppa");
  EXPECT_THROW(decode<VoEstimate>(withInt32At(vo, 16, 0)), DecodeError);
  EXPECT_THROW(decode<VoEstimate>(withInt32At(vo, 16, -1)), DecodeError);
}

// ---------------------------------------------------------------- camera_info_t

// camera_info_t's fields are the struct's, and a lens that cannot be one is refused.
TEST(Codec, CameraInfoRoundTripAndRefusals) {
  CameraInfo info;
  info.utime = 42;
  info.camera_name = "down";
  info.width = 1280;
  info.height = 960;
  info.fx = info.fy = 800.0;
  info.cx = 639.5;
  info.cy = 479.5;
  info.distortion_model = Distortion::EQUIDISTANT;
  info.distortion = {0.1, -0.01, 0.001, 0.0};
  info.fps = 31.0;
  info.p_cam_in_body_m = Eigen::Vector3d(0.2, -0.1, 0.05);
  info.q_body_cam = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  const nadir::camera_info_t wire = asLcm<nadir::camera_info_t>(encode(info));
  EXPECT_EQ(wire.distortion_model, std::int8_t{nadir::camera_info_t::DISTORTION_EQUIDISTANT});
  EXPECT_EQ(wire.num_distortion, 4);
  EXPECT_EQ(wire.position_cam_in_body_m[1], -0.1);
  EXPECT_EQ(wire.orientation_body_cam[3], info.q_body_cam.z());
  const CameraInfo back = decode<CameraInfo>(encode(info));
  EXPECT_EQ(back.camera_name, "down");
  EXPECT_EQ(back.cy, 479.5);
  EXPECT_EQ(back.distortion, info.distortion);
  EXPECT_TRUE(back.distorted());
  EXPECT_NEAR((back.T_body_cam().translation() - info.p_cam_in_body_m).norm(), 0.0, 0.0);

  nadir::camera_info_t bad = wire;
  bad.fx = 0.0;
  EXPECT_NE(invalidReason<CameraInfo>(bad).find("focal"), std::string::npos);
  bad = wire;
  bad.width = 0;
  EXPECT_NE(invalidReason<CameraInfo>(bad).find("0x960"), std::string::npos);
  bad = wire;
  bad.orientation_body_cam[0] = 3.0;
  EXPECT_NE(invalidReason<CameraInfo>(bad).find("orientation_body_cam"), std::string::npos);
  bad = wire;
  bad.readout_s = -0.01;
  EXPECT_NE(invalidReason<CameraInfo>(bad).find("negative"), std::string::npos);
}

// The timing fields travel; a camera_info_t of the first layout (logs recorded
// before them) is still a CameraInfo, with an exact, global, instant shutter.
TEST(Codec, CameraInfoTimingAndTheFirstLayout) {
  CameraInfo info;
  info.utime = 7;
  info.camera_name = "down";
  info.width = 640;
  info.height = 480;
  info.fx = info.fy = 500.0;
  info.fps = 20.0;
  info.time_offset_s = 0.004;
  info.timestamp_jitter_s = 0.0005;
  info.exposure_s = 0.005;
  info.readout_s = 0.03;
  const CameraInfo back = decode<CameraInfo>(encode(info));
  EXPECT_EQ(back.time_offset_s, 0.004);
  EXPECT_EQ(back.timestamp_jitter_s, 0.0005);
  EXPECT_EQ(back.exposure_s, 0.005);
  EXPECT_EQ(back.readout_s, 0.03);

  nadir::camera_info_v1_t old{};
  old.utime = 9;
  old.camera_name = "down";
  old.width = 640;
  old.height = 480;
  old.fx = old.fy = 500.0;
  old.cx = 319.5;
  old.cy = 239.5;
  old.fps = 20.0;
  old.orientation_body_cam[0] = 1.0;
  const Bytes bytes = bytesOf(old);
  EXPECT_TRUE(isType<CameraInfo>(bytes.data(), bytes.size()));
  const CameraInfo legacy = decode<CameraInfo>(bytes);
  EXPECT_EQ(legacy.utime, 9);
  EXPECT_EQ(legacy.cx, 319.5);
  EXPECT_EQ(legacy.readout_s, 0.0);
  EXPECT_EQ(legacy.time_offset_s, 0.0);
  EXPECT_NE(nadir::camera_info_v1_t::getHash(), nadir::camera_info_t::getHash());
}

// ---------------------------------------------------------------- vo_estimate_t

// vo_estimate_t keeps its source and status; the pose must be valid only when TRACKING.
TEST(Codec, VoEstimateRoundTrip) {
  VoEstimate estimate;
  estimate.utime = 1'000'000;
  estimate.source = "vo_feature";
  estimate.status = VoStatus::TRACKING;
  estimate.p_ned_m = Eigen::Vector3d(1, 2, -3);
  estimate.num_features = 150;
  estimate.num_resets = 2;
  estimate.processing_time_s = 0.025;
  const nadir::vo_estimate_t wire = asLcm<nadir::vo_estimate_t>(encode(estimate));
  EXPECT_EQ(wire.status, std::int8_t{nadir::vo_estimate_t::STATUS_TRACKING});
  EXPECT_EQ(wire.pose.utime, 1'000'000);
  EXPECT_EQ(wire.pose.pos[2], -3.0);
  const VoEstimate back = decode<VoEstimate>(encode(estimate));
  EXPECT_EQ(back.source, "vo_feature");
  EXPECT_EQ(back.p_ned_m, estimate.p_ned_m);
  EXPECT_EQ(back.num_resets, 2);
  EXPECT_EQ(back.processing_time_s, 0.025);

  nadir::vo_estimate_t unset = wire;
  for (double& w : unset.pose.orientation) w = 0;
  EXPECT_NE(invalidReason<VoEstimate>(unset).find("pose.orientation"), std::string::npos);
  unset.status = nadir::vo_estimate_t::STATUS_INITIALIZING;
  EXPECT_EQ(decode<VoEstimate>(bytesOf(unset)).q_world_body.coeffs(),
            Eigen::Quaterniond::Identity().coeffs());
}

// nav_state_t: the filter's state and its covariances survive the wire, row by
// row; a covariance that is not symmetric, has a negative variance or is not
// finite is refused naming the field.
TEST(Codec, NavStateRoundTripAndRefusals) {
  NavState state;
  state.utime = 2'000'000;
  state.source = "nav";
  state.p_ned_m = Eigen::Vector3d(10, -20, -300);
  state.v_ned_mps = Eigen::Vector3d(25, 1, -0.5);
  state.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  state.position_covariance_m2 << 4, 0.5, 0, 0.5, 9, 0.1, 0, 0.1, 1;
  state.velocity_covariance_m2ps2 = Eigen::Matrix3d::Identity() * 0.01;
  state.attitude_covariance_rad2 = Eigen::Vector3d(1e-6, 2e-6, 3e-6).asDiagonal();
  state.gyro_bias_rps = Eigen::Vector3d(1e-3, -2e-3, 3e-4);
  state.vo_scale = 1.02;
  state.last_gps_utime = 1'500'000;
  state.updates_fused = 7;
  state.updates_refused = 2;
  state.updates_late = 1;
  const nadir::nav_state_t wire = asLcm<nadir::nav_state_t>(encode(state));
  EXPECT_EQ(wire.position_covariance_m2[1], 0.5);  // row-major: (0, 1)
  EXPECT_EQ(wire.position_covariance_m2[5], 0.1);  // (1, 2)
  EXPECT_EQ(wire.pose.vel[0], 25.0);
  const NavState back = decode<NavState>(encode(state));
  EXPECT_EQ(back.source, "nav");
  EXPECT_EQ(back.p_ned_m, state.p_ned_m);
  EXPECT_EQ(back.v_ned_mps, state.v_ned_mps);
  EXPECT_EQ(back.position_covariance_m2, state.position_covariance_m2);
  EXPECT_EQ(back.attitude_covariance_rad2, state.attitude_covariance_rad2);
  EXPECT_EQ(back.gyro_bias_rps, state.gyro_bias_rps);
  EXPECT_EQ(back.vo_scale, 1.02);
  EXPECT_EQ(back.last_gps_utime, 1'500'000);
  EXPECT_EQ(back.updates_refused, 2);

  nadir::nav_state_t bad = wire;
  bad.position_covariance_m2[1] = 0.7;
  EXPECT_NE(invalidReason<NavState>(bad).find("position_covariance_m2 is not symmetric"),
            std::string::npos);
  bad = wire;
  bad.attitude_covariance_rad2[4] = -1e-6;
  EXPECT_NE(invalidReason<NavState>(bad).find("attitude_covariance_rad2 has a negative variance"),
            std::string::npos);
  bad = wire;
  bad.velocity_covariance_m2ps2[0] = std::nan("");
  EXPECT_NE(invalidReason<NavState>(bad).find("velocity_covariance_m2ps2[0] is not finite"),
            std::string::npos);
}

// ---------------------------------------------------------------- types

// Bytes of another type, or too few, are a DecodeError naming both types; the
// fingerprint says which type bytes are.
TEST(Codec, WrongTypeIsADecodeError) {
  const Bytes pose = encode(makePose(0, 0));
  EXPECT_TRUE(isType<Pose>(pose.data(), pose.size()));
  EXPECT_FALSE(isType<Imu>(pose.data(), pose.size()));
  EXPECT_EQ(typeName(pose.data(), pose.size()), "pose_t");
  EXPECT_EQ(std::string(typeNameOf<Heartbeat>()), "heartbeat_t");
  try {
    decode<Imu>(pose);
    FAIL() << "a pose_t was decoded as an imu_t";
  } catch (const DecodeError& error) {
    EXPECT_NE(std::string(error.what()).find("not a imu_t (they are a pose_t)"), std::string::npos)
        << error.what();
  }
  const Bytes truncated(pose.begin(), pose.end() - 4);
  EXPECT_THROW(decode<Pose>(truncated), DecodeError);
  const std::uint8_t three[3] = {1, 2, 3};
  EXPECT_EQ(typeName(three, 3), "");
}

// A bus check comes back whole, its hosts as a set.
TEST(Codec, BusCheckRoundTrip) {
  const BusCheck check{1'700'000'000'000'000, 77, "air", 4242, {"ground", "launch"}};
  const Bytes bytes = encode(check);
  EXPECT_EQ(typeName(bytes.data(), bytes.size()), "bus_check_t");
  const BusCheck back = decode<BusCheck>(bytes);
  EXPECT_EQ(back.utime, check.utime);
  EXPECT_EQ(back.launch_id, 77);
  EXPECT_EQ(back.host, "air");
  EXPECT_EQ(back.pid, 4242);
  EXPECT_EQ(back.heard, (std::set<std::string>{"ground", "launch"}));
}

// A heartbeat and a VO command come back whole.
TEST(Codec, HeartbeatAndCommandRoundTrip) {
  const Heartbeat beat{1'700'000'000'000'000,
                       "ppa",
                       4242,
                       7,
                       true,
                       "812 frames",
                       {{"POSE_PPA", 812}, {"PPA_ODOMETRY", 812}}};
  const Heartbeat back = decode<Heartbeat>(encode(beat));
  EXPECT_EQ(back.node, "ppa");
  EXPECT_EQ(back.pid, 4242);
  EXPECT_EQ(back.sequence, 7);
  EXPECT_TRUE(back.done);
  EXPECT_EQ(back.summary, "812 frames");
  EXPECT_EQ(back.sent, beat.sent);

  VoCommand command;
  command.utime = 5;
  command.target = "vo_feature";
  command.initial_pose = makePose(5, 2.0);
  const VoCommand command_back = decode<VoCommand>(encode(command));
  EXPECT_EQ(command_back.target, "vo_feature");
  ASSERT_TRUE(command_back.initial_pose.has_value());
  EXPECT_EQ(command_back.initial_pose->p_ned_m, command.initial_pose->p_ned_m);
  EXPECT_FALSE(decode<VoCommand>(encode(VoCommand{})).initial_pose.has_value());
}

// A gate pattern's disks and stage costs land in gate_pattern_t's fields and
// come back; a disk count that does not fit the kind is refused.
TEST(Codec, GatePatternRoundTripAndRefusals) {
  GatePattern pattern;
  pattern.utime = 1'000'005'000;
  pattern.kind = PatternKind::GATE;
  pattern.disks_px = {{10.5, 20.0}, {30.0, 20.5}, {10.0, 40.0}, {30.5, 40.5}};
  pattern.squares_intact = true;
  pattern.patterns_in_view = 2;
  pattern.threshold_instructions = 11;
  pattern.flood_instructions = 22;
  pattern.denoise_instructions = 33;
  pattern.coordinates_instructions = 44;
  pattern.chip_time_s = 1.1e-5;
  const Bytes bytes = encode(pattern);
  nadir::gate_pattern_t raw;
  ASSERT_EQ(raw.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  EXPECT_EQ(raw.kind, +nadir::gate_pattern_t::KIND_GATE);
  EXPECT_EQ(raw.num_disks, 4);
  EXPECT_EQ(raw.disks_px[3][0], 30.5);
  EXPECT_EQ(raw.flood_instructions, 22);
  const GatePattern back = decode<GatePattern>(bytes);
  EXPECT_EQ(back.kind, PatternKind::GATE);
  ASSERT_EQ(back.disks_px.size(), 4u);
  EXPECT_EQ(back.disks_px[1], Eigen::Vector2d(30.0, 20.5));
  EXPECT_EQ(back.coordinates_instructions, 44);
  EXPECT_EQ(back.chip_time_s, 1.1e-5);
  EXPECT_TRUE(back.squares_intact);
  EXPECT_EQ(back.patterns_in_view, 2);

  pattern.kind = PatternKind::SLALOM_LEFT;  // three disks, not four
  try {
    decode<GatePattern>(encode(pattern));
    FAIL() << "a slalom board with four disks was accepted";
  } catch (const InvalidMessage& error) {
    EXPECT_NE(std::string(error.what()).find("num_disks 4"), std::string::npos) << error.what();
  }
}

// A drive command comes back whole; a negative speed, a non-finite steering
// angle or an unknown mode is refused naming the field.
TEST(Codec, DriveCommandRoundTripAndRefusals) {
  DriveCommand command;
  command.utime = 2'000'000;
  command.frame_utime = 1'999'500;
  command.steer_rad = -0.25;
  command.speed_mps = 2.4;
  command.mode = DriveCommand::Mode::MANOEUVRE;
  command.lateral_error_rad = 0.01;
  command.deformation = -0.02;
  const Bytes bytes = encode(command);
  nadir::drive_command_t raw;
  ASSERT_EQ(raw.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  EXPECT_EQ(raw.mode, +nadir::drive_command_t::MODE_MANOEUVRE);
  EXPECT_EQ(raw.steer_rad, -0.25);
  const DriveCommand back = decode<DriveCommand>(bytes);
  EXPECT_EQ(back.utime, command.utime);
  EXPECT_EQ(back.frame_utime, command.frame_utime);
  EXPECT_EQ(back.steer_rad, -0.25);
  EXPECT_EQ(back.speed_mps, 2.4);
  EXPECT_EQ(back.mode, DriveCommand::Mode::MANOEUVRE);
  EXPECT_EQ(back.deformation, -0.02);

  const auto refused = [](nadir::drive_command_t bad, const std::string& field) {
    std::vector<std::uint8_t> data(static_cast<std::size_t>(bad.getEncodedSize()));
    bad.encode(data.data(), 0, static_cast<int>(data.size()));
    try {
      decode<DriveCommand>(data);
      ADD_FAILURE() << field << " was accepted";
    } catch (const InvalidMessage& error) {
      EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
    }
  };
  nadir::drive_command_t bad = raw;
  bad.speed_mps = -1.0;
  refused(bad, "speed_mps");
  bad = raw;
  bad.steer_rad = std::numeric_limits<double>::quiet_NaN();
  refused(bad, "steer_rad");
  bad = raw;
  bad.mode = 9;
  refused(bad, "mode");
}

// A waypoint reached comes back whole; an index outside the route is refused.
TEST(Codec, WaypointReachedRoundTripAndRefusal) {
  WaypointReached w;
  w.utime = 52'475'000;
  w.index = 5;
  w.count = 13;
  w.waypoint_ned_m = {100.0, -20.0, -300.0};
  w.believed_ned_m = {99.0, -21.0, -300.5};
  w.true_ned_m = {98.0, -22.0, -301.0};
  w.source = "nav";
  const WaypointReached back = decode<WaypointReached>(encode(w));
  EXPECT_EQ(back.utime, w.utime);
  EXPECT_EQ(back.index, 5);
  EXPECT_EQ(back.count, 13);
  EXPECT_EQ(back.waypoint_ned_m, w.waypoint_ned_m);
  EXPECT_EQ(back.believed_ned_m, w.believed_ned_m);
  EXPECT_EQ(back.true_ned_m, w.true_ned_m);
  EXPECT_EQ(back.source, "nav");
  w.index = 13;
  try {
    decode<WaypointReached>(encode(w));
    FAIL() << "an index past the route was accepted";
  } catch (const InvalidMessage& error) {
    EXPECT_NE(std::string(error.what()).find("index 13"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace nadir::msg
