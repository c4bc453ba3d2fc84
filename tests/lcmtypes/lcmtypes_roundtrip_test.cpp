// Round-trip, fingerprint, malformed-input and wire-format tests of the nadir LCM types.
//
// Field values are chosen to exercise the codec (sign, width, precision, multi-byte UTF-8),
// not to be physically meaningful. Every field gets a non-zero value, and each decode goes
// into a fresh zero-initialised instance, so a field the codec drops fails its check.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "nadir/attitude_t.hpp"
#include "nadir/baro_t.hpp"
#include "nadir/body_rates_t.hpp"
#include "nadir/camera_info_t.hpp"
#include "nadir/geodetic_position_t.hpp"
#include "nadir/gps_t.hpp"
#include "nadir/image_metadata_t.hpp"
#include "nadir/image_t.hpp"
#include "nadir/imu_t.hpp"
#include "nadir/pose_t.hpp"
#include "nadir/ppa_odometry_t.hpp"
#include "nadir/range_t.hpp"
#include "nadir/target_detection_t.hpp"
#include "nadir/velocity_t.hpp"
#include "nadir/vo_command_t.hpp"
#include "nadir/vo_estimate_t.hpp"

namespace {

using Bytes = std::vector<uint8_t>;

// Encodes msg into a buffer of exactly getEncodedSize() bytes.
template <typename T>
Bytes Encode(const T& msg) {
  Bytes buf(static_cast<std::size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return buf;
}

// Decodes the first `length` bytes of buf into a fresh instance; returns decode()'s result.
// The bytes are copied into a buffer of exactly `length` bytes, so reading past it is a
// real out-of-bounds access (visible under a sanitizer), not a read of the rest of buf.
template <typename T>
int DecodePrefix(const Bytes& buf, std::size_t length) {
  const Bytes prefix(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(length));
  T out{};
  return out.decode(prefix.data(), 0, static_cast<int>(prefix.size()));
}

// Encodes msg, decodes the bytes into a separate fresh instance and returns that instance.
template <typename T>
T RoundTrip(const T& msg) {
  const Bytes buf = Encode(msg);
  T decoded{};
  EXPECT_EQ(decoded.decode(buf.data(), 0, static_cast<int>(buf.size())),
            static_cast<int>(buf.size()));
  return decoded;
}

// The bytes of a UTF-8 string, for byte[] fields holding text.
Bytes TextBytes(std::string_view text) { return Bytes(text.begin(), text.end()); }

template <std::size_t N>
void ExpectArrayEq(const double (&actual)[N], const std::array<double, N>& expected) {
  for (std::size_t i = 0; i < N; ++i) {
    EXPECT_EQ(actual[i], expected[i]) << "element " << i;
  }
}

// A pose whose fields all differ from each other (for base >= 0) and are not floats.
nadir::pose_t MakePose(int64_t utime, double base) {
  nadir::pose_t pose{};
  pose.utime = utime;
  pose.pos[0] = base + 0.1;
  pose.pos[1] = base + 0.2;
  pose.pos[2] = -(base + 0.3);
  pose.vel[0] = base + 1.1;
  pose.vel[1] = -(base + 1.2);
  pose.vel[2] = base + 1.3;
  pose.orientation[0] = base + 2.1;
  pose.orientation[1] = -(base + 2.2);
  pose.orientation[2] = base + 2.3;
  pose.orientation[3] = -(base + 2.4);
  pose.rotation_rate[0] = base + 3.1;
  pose.rotation_rate[1] = base + 3.2;
  pose.rotation_rate[2] = -(base + 3.3);
  pose.accel[0] = -(base + 4.1);
  pose.accel[1] = base + 4.2;
  pose.accel[2] = base + 4.3;
  return pose;
}

void ExpectPoseEq(const nadir::pose_t& expected, const nadir::pose_t& actual) {
  EXPECT_EQ(actual.utime, expected.utime);
  ExpectArrayEq(actual.pos, {expected.pos[0], expected.pos[1], expected.pos[2]});
  ExpectArrayEq(actual.vel, {expected.vel[0], expected.vel[1], expected.vel[2]});
  ExpectArrayEq(actual.orientation, {expected.orientation[0], expected.orientation[1],
                                     expected.orientation[2], expected.orientation[3]});
  ExpectArrayEq(actual.rotation_rate,
                {expected.rotation_rate[0], expected.rotation_rate[1], expected.rotation_rate[2]});
  ExpectArrayEq(actual.accel, {expected.accel[0], expected.accel[1], expected.accel[2]});
}

nadir::image_metadata_t MakeMetadata(std::string key, std::string_view value) {
  nadir::image_metadata_t entry{};
  entry.key = std::move(key);
  entry.value = TextBytes(value);
  entry.n = static_cast<int32_t>(entry.value.size());
  return entry;
}

// An image with raw pixel data (including 0x00 and 0xFF bytes) and three metadata entries.
nadir::image_t MakeImage() {
  nadir::image_t image{};
  image.utime = INT64_C(1'700'000'000'123'456);
  image.width = 3;
  image.height = 2;
  image.row_stride = 5;
  image.pixelformat = nadir::image_t::PIXEL_FORMAT_GRAY;
  image.data = {0x00, 0x01, 0x7F, 0x80, 0xFF, 0xFE, 0x42, 0x99, 0x10, 0xA5};
  image.size = static_cast<int32_t>(image.data.size());
  image.metadata = {MakeMetadata("exposure_µs", "4000"), MakeMetadata("température_°C", "21.5"),
                    MakeMetadata("名前", "カメラ🛸")};
  image.nmetadata = static_cast<int32_t>(image.metadata.size());
  return image;
}

// Checks that fields sent by MakeMetadata(key, value) arrived unchanged.
void ExpectMetadataEq(const nadir::image_metadata_t& actual, const std::string& key,
                      std::string_view value) {
  EXPECT_EQ(actual.key, key);
  EXPECT_EQ(actual.n, static_cast<int32_t>(value.size()));
  EXPECT_EQ(actual.value, TextBytes(value));
}

// Appends the 8 bytes of v, most significant first.
void AppendBigEndian(Bytes& out, uint64_t v) {
  for (int shift = 56; shift >= 0; shift -= 8) {
    out.push_back(static_cast<uint8_t>(v >> shift));
  }
}

// --- Fingerprints ---------------------------------------------------------------------------

// image_t's fingerprint equals bot_core.image_t's (it covers image_metadata_t recursively).
TEST(LcmTypesFingerprint, ImageMatchesBotCore) {
  EXPECT_EQ(nadir::image_t::getHash(), INT64_C(0x14739ffe13d5f5f0));
}

// pose_t's fingerprint equals bot_core.pose_t's.
TEST(LcmTypesFingerprint, PoseMatchesBotCore) {
  EXPECT_EQ(nadir::pose_t::getHash(), INT64_C(0x2e16efb052b0105e));
}

// --- Round trips: every field of every type -------------------------------------------------

// pose_t: every field survives encode/decode.
TEST(LcmTypesRoundTrip, Pose) {
  const nadir::pose_t msg = MakePose(INT64_C(5'000'000'001), 7.0);
  const nadir::pose_t decoded = RoundTrip(msg);
  ExpectPoseEq(MakePose(INT64_C(5'000'000'001), 7.0), decoded);
}

// image_metadata_t on its own: UTF-8 key and a multi-byte value survive encode/decode.
TEST(LcmTypesRoundTrip, ImageMetadata) {
  const nadir::image_metadata_t decoded = RoundTrip(MakeMetadata("gain_dB_é", "12.5 ± 0.1"));
  ExpectMetadataEq(decoded, "gain_dB_é", "12.5 ± 0.1");
}

// image_t: scalars, every pixel byte and every nested metadata entry survive encode/decode.
TEST(LcmTypesRoundTrip, Image) {
  const nadir::image_t decoded = RoundTrip(MakeImage());
  EXPECT_EQ(decoded.utime, INT64_C(1'700'000'000'123'456));
  EXPECT_EQ(decoded.width, 3);
  EXPECT_EQ(decoded.height, 2);
  EXPECT_EQ(decoded.row_stride, 5);
  EXPECT_EQ(decoded.pixelformat, 1497715271);  // PIXEL_FORMAT_GRAY
  EXPECT_EQ(decoded.size, 10);
  EXPECT_EQ(decoded.data, (Bytes{0x00, 0x01, 0x7F, 0x80, 0xFF, 0xFE, 0x42, 0x99, 0x10, 0xA5}));
  EXPECT_EQ(decoded.nmetadata, 3);
  ASSERT_EQ(decoded.metadata.size(), 3u);
  ExpectMetadataEq(decoded.metadata[0], "exposure_µs", "4000");
  ExpectMetadataEq(decoded.metadata[1], "température_°C", "21.5");
  ExpectMetadataEq(decoded.metadata[2], "名前", "カメラ🛸");
}

// camera_info_t: UTF-8 name, intrinsics, variable-length distortion and mounting survive.
TEST(LcmTypesRoundTrip, CameraInfo) {
  nadir::camera_info_t msg{};
  msg.utime = INT64_C(1'700'000'000'000'001);
  msg.camera_name = "caméra_bas";
  msg.width = 640;
  msg.height = 480;
  msg.fx = 415.69219381653056;
  msg.fy = 415.7;
  msg.cx = 319.5;
  msg.cy = 239.1;
  msg.distortion_model = nadir::camera_info_t::DISTORTION_EQUIDISTANT;
  msg.distortion = {-0.0123, 0.004567, -1.0 / 3.0, 1e-310};  // 1e-310 is subnormal.
  msg.num_distortion = static_cast<int32_t>(msg.distortion.size());
  msg.fps = 29.97;
  msg.position_cam_in_body_m[0] = 0.1;
  msg.position_cam_in_body_m[1] = -0.02;
  msg.position_cam_in_body_m[2] = 0.3;
  msg.orientation_body_cam[0] = 0.7071067811865476;
  msg.orientation_body_cam[1] = -0.01;
  msg.orientation_body_cam[2] = 0.02;
  msg.orientation_body_cam[3] = 0.7070360705084289;

  const nadir::camera_info_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(1'700'000'000'000'001));
  EXPECT_EQ(decoded.camera_name, "caméra_bas");
  EXPECT_EQ(decoded.width, 640);
  EXPECT_EQ(decoded.height, 480);
  EXPECT_EQ(decoded.fx, 415.69219381653056);
  EXPECT_EQ(decoded.fy, 415.7);
  EXPECT_EQ(decoded.cx, 319.5);
  EXPECT_EQ(decoded.cy, 239.1);
  EXPECT_EQ(decoded.distortion_model, 2);  // DISTORTION_EQUIDISTANT
  EXPECT_EQ(decoded.num_distortion, 4);
  EXPECT_EQ(decoded.distortion, (std::vector<double>{-0.0123, 0.004567, -1.0 / 3.0, 1e-310}));
  EXPECT_EQ(decoded.fps, 29.97);
  ExpectArrayEq(decoded.position_cam_in_body_m, {0.1, -0.02, 0.3});
  ExpectArrayEq(decoded.orientation_body_cam,
                {0.7071067811865476, -0.01, 0.02, 0.7070360705084289});
}

// imu_t: every field survives encode/decode.
TEST(LcmTypesRoundTrip, Imu) {
  nadir::imu_t msg{};
  msg.utime = INT64_C(9'007'199'254'740'993);  // 2^53 + 1: not representable as a double.
  msg.angular_velocity_rps[0] = 0.01;
  msg.angular_velocity_rps[1] = -0.02;
  msg.angular_velocity_rps[2] = 0.03;
  msg.linear_acceleration_mps2[0] = 0.11;
  msg.linear_acceleration_mps2[1] = -0.12;
  msg.linear_acceleration_mps2[2] = -9.80665;

  const nadir::imu_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(9'007'199'254'740'993));
  ExpectArrayEq(decoded.angular_velocity_rps, {0.01, -0.02, 0.03});
  ExpectArrayEq(decoded.linear_acceleration_mps2, {0.11, -0.12, -9.80665});
}

// range_t: every field survives encode/decode.
TEST(LcmTypesRoundTrip, Range) {
  nadir::range_t msg{};
  msg.utime = INT64_C(4'294'967'297);  // 2^32 + 1
  msg.range_m = 12.345678901234567;
  msg.min_range_m = 0.05;
  msg.max_range_m = 40.1;
  msg.direction_body[0] = 0.1;
  msg.direction_body[1] = -0.2;
  msg.direction_body[2] = 0.9746794344808963;
  msg.status = nadir::range_t::STATUS_OUT_OF_RANGE;

  const nadir::range_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(4'294'967'297));
  EXPECT_EQ(decoded.range_m, 12.345678901234567);
  EXPECT_EQ(decoded.min_range_m, 0.05);
  EXPECT_EQ(decoded.max_range_m, 40.1);
  ExpectArrayEq(decoded.direction_body, {0.1, -0.2, 0.9746794344808963});
  EXPECT_EQ(decoded.status, 2);  // STATUS_OUT_OF_RANGE
}

// gps_t: every field survives encode/decode, including a negative int16.
TEST(LcmTypesRoundTrip, Gps) {
  nadir::gps_t msg{};
  msg.utime = INT64_C(1'234'567'890'123'456);
  msg.latitude_rad = 0.8527087756759584;
  msg.longitude_rad = -0.0022689280275926286;
  msg.altitude_m = 123.456;
  msg.velocity_ned_mps[0] = 1.1;
  msg.velocity_ned_mps[1] = -2.2;
  msg.velocity_ned_mps[2] = 0.3;
  msg.horizontal_accuracy_m = 0.7;
  msg.vertical_accuracy_m = 1.3;
  msg.num_satellites = -12345;
  msg.fix_type = nadir::gps_t::FIX_RTK;

  const nadir::gps_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(1'234'567'890'123'456));
  EXPECT_EQ(decoded.latitude_rad, 0.8527087756759584);
  EXPECT_EQ(decoded.longitude_rad, -0.0022689280275926286);
  EXPECT_EQ(decoded.altitude_m, 123.456);
  ExpectArrayEq(decoded.velocity_ned_mps, {1.1, -2.2, 0.3});
  EXPECT_EQ(decoded.horizontal_accuracy_m, 0.7);
  EXPECT_EQ(decoded.vertical_accuracy_m, 1.3);
  EXPECT_EQ(decoded.num_satellites, -12345);
  EXPECT_EQ(decoded.fix_type, 4);  // FIX_RTK
}

// vo_estimate_t: UTF-8 source, scalars and the nested pose survive encode/decode.
TEST(LcmTypesRoundTrip, VoEstimate) {
  nadir::vo_estimate_t msg{};
  msg.utime = INT64_C(6'000'000'000'007);
  msg.source = "vo_direct_ü";
  msg.status = nadir::vo_estimate_t::STATUS_LOST;
  msg.pose = MakePose(INT64_C(6'000'000'000'008), 20.0);
  msg.num_features = 321;
  msg.num_resets = 17;
  msg.processing_time_s = 0.0123;

  const nadir::vo_estimate_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(6'000'000'000'007));
  EXPECT_EQ(decoded.source, "vo_direct_ü");
  EXPECT_EQ(decoded.status, 2);  // STATUS_LOST
  ExpectPoseEq(MakePose(INT64_C(6'000'000'000'008), 20.0), decoded.pose);
  EXPECT_EQ(decoded.num_features, 321);
  EXPECT_EQ(decoded.num_resets, 17);
  EXPECT_EQ(decoded.processing_time_s, 0.0123);
}

// ppa_odometry_t: every field survives encode/decode, including boolean true and a
// negative int64.
TEST(LcmTypesRoundTrip, PpaOdometry) {
  nadir::ppa_odometry_t msg{};
  msg.utime = INT64_C(7'000'000'000'011);
  msg.frame_index = INT64_C(5'000'000'123);
  msg.translation_x_px = -3.25;
  msg.translation_y_px = 1.1;
  msg.rotation_rad = -0.0314;
  msg.scale = 1.0001;
  msg.strength = 0.87;
  msg.new_keyframe = true;
  msg.keyframe_edge_count = 4321;
  msg.instruction_count = INT64_C(-81'985'529'216'486'895);  // -0x0123456789ABCDEF

  const nadir::ppa_odometry_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(7'000'000'000'011));
  EXPECT_EQ(decoded.frame_index, INT64_C(5'000'000'123));
  EXPECT_EQ(decoded.translation_x_px, -3.25);
  EXPECT_EQ(decoded.translation_y_px, 1.1);
  EXPECT_EQ(decoded.rotation_rad, -0.0314);
  EXPECT_EQ(decoded.scale, 1.0001);
  EXPECT_EQ(decoded.strength, 0.87);
  EXPECT_EQ(decoded.new_keyframe, 1);
  EXPECT_EQ(decoded.keyframe_edge_count, 4321);
  EXPECT_EQ(decoded.instruction_count, INT64_C(-81'985'529'216'486'895));
}

// target_detection_t: scalars and every element of the N x 2 point array survive.
TEST(LcmTypesRoundTrip, TargetDetection) {
  nadir::target_detection_t msg{};
  msg.utime = INT64_C(8'000'000'000'013);
  msg.kind = nadir::target_detection_t::KIND_GATE;
  msg.detected = true;
  msg.x_min_px = -4;
  msg.y_min_px = 7;
  msg.x_max_px = 250;
  msg.y_max_px = 199;
  msg.center_x_px = 123.1;
  msg.center_y_px = 103.2;
  msg.num_boundaries = 3;
  msg.points_px = {{10.1, 20.2}, {-30.3, 40.4}, {50.5, -60.6}, {70.7, 80.8}};
  msg.num_points = static_cast<int32_t>(msg.points_px.size());

  const nadir::target_detection_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(8'000'000'000'013));
  EXPECT_EQ(decoded.kind, 1);  // KIND_GATE
  EXPECT_EQ(decoded.detected, 1);
  EXPECT_EQ(decoded.x_min_px, -4);
  EXPECT_EQ(decoded.y_min_px, 7);
  EXPECT_EQ(decoded.x_max_px, 250);
  EXPECT_EQ(decoded.y_max_px, 199);
  EXPECT_EQ(decoded.center_x_px, 123.1);
  EXPECT_EQ(decoded.center_y_px, 103.2);
  EXPECT_EQ(decoded.num_boundaries, 3);
  EXPECT_EQ(decoded.num_points, 4);
  EXPECT_EQ(decoded.points_px, (std::vector<std::vector<double>>{
                                   {10.1, 20.2}, {-30.3, 40.4}, {50.5, -60.6}, {70.7, 80.8}}));
}

// vo_command_t: UTF-8 target, command, boolean true and the nested pose survive.
TEST(LcmTypesRoundTrip, VoCommand) {
  nadir::vo_command_t msg{};
  msg.utime = INT64_C(9'000'000'000'017);
  msg.target = "ppa_θ";
  msg.command = -5;  // Not a defined command: the codec must carry any int8, sign included.
  msg.has_initial_pose = true;
  msg.initial_pose = MakePose(INT64_C(9'000'000'000'019), 30.0);

  const nadir::vo_command_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(9'000'000'000'017));
  EXPECT_EQ(decoded.target, "ppa_θ");
  EXPECT_EQ(decoded.command, -5);
  EXPECT_EQ(decoded.has_initial_pose, 1);
  ExpectPoseEq(MakePose(INT64_C(9'000'000'000'019), 30.0), decoded.initial_pose);
}

// baro_t: every field survives encode/decode.
TEST(LcmTypesRoundTrip, Baro) {
  nadir::baro_t msg{};
  msg.utime = INT64_C(1'700'000'000'000'003);
  msg.altitude_m = -412.25;  // Below the ellipsoid (the Dead Sea shore).
  msg.pressure_pa = 106454.3;

  const nadir::baro_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(1'700'000'000'000'003));
  EXPECT_EQ(decoded.altitude_m, -412.25);
  EXPECT_EQ(decoded.pressure_pa, 106454.3);
}

// geodetic_position_t: every field survives encode/decode, including a negative relative altitude.
TEST(LcmTypesRoundTrip, GeodeticPosition) {
  nadir::geodetic_position_t msg{};
  msg.utime = INT64_C(1'700'000'000'000'005);
  msg.latitude_rad = -0.5931997761031083;
  msg.longitude_rad = 2.6297467049469577;
  msg.altitude_m = 1523.875;
  msg.altitude_rel_m = -3.125;

  const nadir::geodetic_position_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(1'700'000'000'000'005));
  EXPECT_EQ(decoded.latitude_rad, -0.5931997761031083);
  EXPECT_EQ(decoded.longitude_rad, 2.6297467049469577);
  EXPECT_EQ(decoded.altitude_m, 1523.875);
  EXPECT_EQ(decoded.altitude_rel_m, -3.125);
}

// attitude_t: the quaternion (w first) and the three Euler angles survive encode/decode.
TEST(LcmTypesRoundTrip, Attitude) {
  nadir::attitude_t msg{};
  msg.utime = INT64_C(1'700'000'000'000'007);
  msg.orientation[0] = 0.7071067811865476;
  msg.orientation[1] = -0.01;
  msg.orientation[2] = 0.02;
  msg.orientation[3] = 0.7070360705084289;
  msg.roll_rad = -0.031;
  msg.pitch_rad = 0.0125;
  msg.yaw_rad = 1.5707963267948966;

  const nadir::attitude_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(1'700'000'000'000'007));
  ExpectArrayEq(decoded.orientation, {0.7071067811865476, -0.01, 0.02, 0.7070360705084289});
  EXPECT_EQ(decoded.roll_rad, -0.031);
  EXPECT_EQ(decoded.pitch_rad, 0.0125);
  EXPECT_EQ(decoded.yaw_rad, 1.5707963267948966);
}

// velocity_t: every field survives encode/decode.
TEST(LcmTypesRoundTrip, Velocity) {
  nadir::velocity_t msg{};
  msg.utime = INT64_C(1'700'000'000'000'009);
  msg.velocity_ned_mps[0] = 21.5;
  msg.velocity_ned_mps[1] = -3.75;
  msg.velocity_ned_mps[2] = 0.1;

  const nadir::velocity_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(1'700'000'000'000'009));
  ExpectArrayEq(decoded.velocity_ned_mps, {21.5, -3.75, 0.1});
}

// body_rates_t: every field survives encode/decode.
TEST(LcmTypesRoundTrip, BodyRates) {
  nadir::body_rates_t msg{};
  msg.utime = INT64_C(1'700'000'000'000'011);
  msg.angular_velocity_dps[0] = 45.0;
  msg.angular_velocity_dps[1] = -1.5;
  msg.angular_velocity_dps[2] = 28.64788975654116;

  const nadir::body_rates_t decoded = RoundTrip(msg);
  EXPECT_EQ(decoded.utime, INT64_C(1'700'000'000'000'011));
  ExpectArrayEq(decoded.angular_velocity_dps, {45.0, -1.5, 28.64788975654116});
}

// --- Malformed input ------------------------------------------------------------------------

// Bytes one short of a full message are rejected (negative result) for several types.
TEST(LcmTypesMalformed, TruncatedByOneByteIsRejected) {
  const Bytes pose = Encode(MakePose(1, 1.0));
  EXPECT_LT(DecodePrefix<nadir::pose_t>(pose, pose.size() - 1), 0);

  nadir::imu_t imu{};
  imu.utime = 1;
  const Bytes imu_bytes = Encode(imu);
  EXPECT_LT(DecodePrefix<nadir::imu_t>(imu_bytes, imu_bytes.size() - 1), 0);

  nadir::vo_estimate_t estimate{};
  estimate.source = "ppa";
  estimate.pose = MakePose(2, 2.0);
  const Bytes estimate_bytes = Encode(estimate);
  EXPECT_LT(DecodePrefix<nadir::vo_estimate_t>(estimate_bytes, estimate_bytes.size() - 1), 0);

  nadir::target_detection_t target{};
  target.points_px = {{1.0, 2.0}, {3.0, 4.0}};
  target.num_points = 2;
  const Bytes target_bytes = Encode(target);
  EXPECT_LT(DecodePrefix<nadir::target_detection_t>(target_bytes, target_bytes.size() - 1), 0);

  const Bytes image = Encode(MakeImage());
  EXPECT_LT(DecodePrefix<nadir::image_t>(image, image.size() - 1), 0);
}

// Every proper prefix of an image_t (cut in a scalar, the pixel data, a key or a value)
// is rejected.
TEST(LcmTypesMalformed, EveryTruncatedImageIsRejected) {
  const Bytes image = Encode(MakeImage());
  for (std::size_t length = 0; length < image.size(); ++length) {
    EXPECT_LT(DecodePrefix<nadir::image_t>(image, length), 0) << "length " << length;
  }
  EXPECT_EQ(DecodePrefix<nadir::image_t>(image, image.size()), static_cast<int>(image.size()));
}

// Bytes carrying another type's fingerprint, or a corrupted one, are rejected.
TEST(LcmTypesMalformed, WrongFingerprintIsRejected) {
  // pose_t bytes are longer than an imu_t's, so only the fingerprint check can reject them.
  const Bytes pose = Encode(MakePose(1, 1.0));
  ASSERT_GT(pose.size(), static_cast<std::size_t>(nadir::imu_t{}.getEncodedSize()));
  EXPECT_LT(DecodePrefix<nadir::imu_t>(pose, pose.size()), 0);

  const Bytes image = Encode(MakeImage());
  EXPECT_LT(DecodePrefix<nadir::image_metadata_t>(image, image.size()), 0);
  EXPECT_LT(DecodePrefix<nadir::pose_t>(image, image.size()), 0);

  Bytes corrupted = pose;
  corrupted[7] ^= 0x01;  // Last byte of the fingerprint.
  EXPECT_LT(DecodePrefix<nadir::pose_t>(corrupted, corrupted.size()), 0);
}

// --- Wire format ----------------------------------------------------------------------------

// imu_t encodes as its big-endian fingerprint, then big-endian int64 and IEEE-754 doubles.
TEST(LcmTypesWireFormat, ImuIsBigEndian) {
  nadir::imu_t msg{};
  msg.utime = INT64_C(0x0102030405060708);
  msg.angular_velocity_rps[0] = 1.0;
  msg.angular_velocity_rps[1] = -2.0;
  msg.angular_velocity_rps[2] = 0.5;
  msg.linear_acceleration_mps2[0] = 0.25;
  msg.linear_acceleration_mps2[1] = 2.0;
  msg.linear_acceleration_mps2[2] = -0.5;

  Bytes expected;
  AppendBigEndian(expected, static_cast<uint64_t>(nadir::imu_t::getHash()));
  const Bytes body = {
      0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,  // utime
      0x3F, 0xF0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  //  1.0
      0xC0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // -2.0
      0x3F, 0xE0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  //  0.5
      0x3F, 0xD0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  //  0.25
      0x40, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  //  2.0
      0xBF, 0xE0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // -0.5
  };
  expected.insert(expected.end(), body.begin(), body.end());

  EXPECT_EQ(Encode(msg), expected);
}

// pose_t bytes start with bot_core's fingerprint 0x2e16efb052b0105e, most significant first.
TEST(LcmTypesWireFormat, PoseStartsWithFingerprint) {
  const Bytes pose = Encode(MakePose(1, 1.0));
  ASSERT_EQ(pose.size(), 8u + 8u + 16u * 8u);
  EXPECT_EQ(Bytes(pose.begin(), pose.begin() + 8),
            (Bytes{0x2E, 0x16, 0xEF, 0xB0, 0x52, 0xB0, 0x10, 0x5E}));
}

// vo_command_t: a string is a big-endian int32 length counting the NUL, then the bytes and
// the NUL; a boolean is one byte; a nested pose_t follows without its own fingerprint.
TEST(LcmTypesWireFormat, VoCommandStringBooleanAndNestedPose) {
  nadir::vo_command_t msg{};
  msg.target = "ab";
  msg.command = 0x7E;
  msg.has_initial_pose = true;
  msg.initial_pose.utime = INT64_C(0x1112131415161718);

  const Bytes buf = Encode(msg);
  ASSERT_EQ(buf.size(), 8u + 8u + (4u + 3u) + 1u + 1u + (8u + 16u * 8u));
  EXPECT_EQ(Bytes(buf.begin() + 16, buf.begin() + 33),
            (Bytes{0x00, 0x00, 0x00, 0x03, 'a', 'b', 0x00,             // target
                   0x7E,                                               // command
                   0x01,                                               // has_initial_pose
                   0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x18}));  // initial_pose.utime
}

}  // namespace
