#include "lcmtypes/codec.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <type_traits>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/frames.h"
#include "nadir/attitude_t.hpp"
#include "nadir/baro_t.hpp"
#include "nadir/body_rates_t.hpp"
#include "nadir/bus_check_t.hpp"
#include "nadir/camera_info_t.hpp"
#include "nadir/camera_info_v1_t.hpp"
#include "nadir/drive_command_t.hpp"
#include "nadir/gate_pattern_t.hpp"
#include "nadir/geodetic_position_t.hpp"
#include "nadir/gps_t.hpp"
#include "nadir/heartbeat_t.hpp"
#include "nadir/image_t.hpp"
#include "nadir/imu_t.hpp"
#include "nadir/magnetometer_t.hpp"
#include "nadir/nav_state_t.hpp"
#include "nadir/pose_t.hpp"
#include "nadir/ppa_odometry_t.hpp"
#include "nadir/range_t.hpp"
#include "nadir/target_detection_t.hpp"
#include "nadir/velocity_t.hpp"
#include "nadir/vo_command_t.hpp"
#include "nadir/vo_estimate_t.hpp"
#include "nadir/waypoint_reached_t.hpp"

namespace nadir::msg {
namespace {

// ---------------------------------------------------------------- bytes

template <class Lcm>
Bytes toBytes(const Lcm& message) {
  Bytes bytes(static_cast<std::size_t>(message.getEncodedSize()));
  if (message.encode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0) {
    throw std::logic_error(std::string("cannot encode ") + Lcm::getTypeName());
  }
  return bytes;
}

std::int64_t fingerprintOf(const void* data, std::size_t size) {
  if (data == nullptr || size < 8) return 0;
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  std::uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | bytes[i];
  return static_cast<std::int64_t>(hash);
}

template <class Lcm>
Lcm fromBytes(const void* data, std::size_t size) {
  if (fingerprintOf(data, size) != Lcm::getHash()) {
    const std::string actual = typeName(data, size);
    throw DecodeError(std::to_string(size) + " bytes are not a " + Lcm::getTypeName() +
                      (actual.empty() ? std::string() : " (they are a " + actual + ")"));
  }
  Lcm message;
  if (message.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) {
    throw DecodeError(std::to_string(size) + " bytes are not a whole " + Lcm::getTypeName() +
                      " (truncated or padded)");
  }
  return message;
}

// ---------------------------------------------------------------- fields

void put3(const Eigen::Vector3d& v, double out[3]) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

Eigen::Vector3d get3(const double in[3]) { return {in[0], in[1], in[2]}; }

void put9(const Eigen::Matrix3d& m, double out[9]) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[3 * r + c] = m(r, c);
}

// Names the message in errors: "pose_t at utime 123".
template <class Lcm>
std::string where(const Lcm& message) {
  return std::string(Lcm::getTypeName()) + " at utime " + std::to_string(message.utime);
}

void requireFinite(const double* values, int count, const std::string& field,
                   const std::string& where) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) {
      throw InvalidMessage(where + ": " + field + "[" + std::to_string(i) + "] is not finite (" +
                           std::to_string(values[i]) + ")");
    }
  }
}

void requireFinite(double value, const std::string& field, const std::string& where) {
  if (!std::isfinite(value)) {
    throw InvalidMessage(where + ": " + field + " is not finite (" + std::to_string(value) + ")");
  }
}

Eigen::Quaterniond rotationFromWire(const double wxyz[4], const std::string& field,
                                    const std::string& where) {
  requireFinite(wxyz, 4, field, where);
  try {
    return core::quaternionFromWire(wxyz);
  } catch (const std::invalid_argument& error) {
    const double norm = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).norm();
    throw InvalidMessage(where + ": " + field + ": " + error.what() + " (norm " +
                         std::to_string(norm) + ", must be within 1e-3 of 1)");
  }
}

// A 3 x 3 covariance, row-major: finite, symmetric and with a non-negative diagonal.
Eigen::Matrix3d covarianceFromWire(const double in[9], const std::string& field,
                                   const std::string& where) {
  requireFinite(in, 9, field, where);
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = in[3 * r + c];
  for (int i = 0; i < 3; ++i) {
    if (m(i, i) < 0.0)
      throw InvalidMessage(where + ": " + field + " has a negative variance (" +
                           std::to_string(m(i, i)) + " at " + std::to_string(i) + ")");
  }
  if ((m - m.transpose()).cwiseAbs().maxCoeff() > 1e-9 * std::max(1.0, m.cwiseAbs().maxCoeff()))
    throw InvalidMessage(where + ": " + field + " is not symmetric");
  return m;
}

// An enum from its wire value, refusing values the type does not define.
template <class Enum>
Enum enumFromWire(int value, int count, const std::string& field, const std::string& where) {
  if (value < 0 || value >= count) {
    throw InvalidMessage(where + ": " + field + " " + std::to_string(value) + " is not defined");
  }
  return static_cast<Enum>(value);
}

// ---------------------------------------------------------------- pose_t

nadir::pose_t poseToLcm(const Pose& pose) {
  nadir::pose_t out{};
  out.utime = pose.utime;
  put3(pose.p_ned_m, out.pos);
  put3(pose.v_ned_mps, out.vel);
  core::quaternionToWire(pose.q_world_body, out.orientation);
  put3(pose.omega_body_rps, out.rotation_rate);
  put3(pose.a_ned_mps2, out.accel);
  return out;
}

// Position and orientation must be valid; the rates are taken as sent (other
// systems' logs leave them unset).
Pose poseFromLcm(const nadir::pose_t& in) {
  const std::string at = where(in);
  requireFinite(in.pos, 3, "pos", at);
  Pose pose;
  pose.utime = in.utime;
  pose.p_ned_m = get3(in.pos);
  pose.v_ned_mps = get3(in.vel);
  pose.a_ned_mps2 = get3(in.accel);
  pose.q_world_body = rotationFromWire(in.orientation, "orientation", at);
  pose.omega_body_rps = get3(in.rotation_rate);
  return pose;
}

// ---------------------------------------------------------------- image_t

struct JpegFrameSize {
  int width = 0;
  int height = 0;
};

// The frame size a JPEG declares in its start-of-frame marker, read before
// anything is decoded; nothing when the bytes hold no whole one before the scan.
std::optional<JpegFrameSize> jpegFrameSize(const std::vector<std::uint8_t>& jpeg) {
  const std::size_t size = jpeg.size();
  if (size < 4 || jpeg[0] != 0xFF || jpeg[1] != 0xD8) return std::nullopt;
  std::size_t at = 2;
  while (at + 4 <= size) {
    if (jpeg[at] != 0xFF) return std::nullopt;
    const std::uint8_t marker = jpeg[at + 1];
    if (marker == 0xFF) {  // a fill byte before the marker
      ++at;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length
      at += 2;
      continue;
    }
    if (marker == 0xDA || marker == 0xD9) return std::nullopt;  // the scan, the end
    const std::size_t length = (std::size_t{jpeg[at + 2]} << 8) | jpeg[at + 3];
    if (length < 2 || at + 2 + length > size) return std::nullopt;
    const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
                       marker != 0xCC;  // C4, C8, CC: Huffman tables, reserved, arithmetic
    if (frame) {
      if (length < 7) return std::nullopt;
      const std::uint8_t* header = jpeg.data() + at + 4;  // precision, height, width
      return JpegFrameSize{(header[3] << 8) | header[4], (header[1] << 8) | header[2]};
    }
    at += 2 + length;
  }
  return std::nullopt;
}

// A Huffman-coded JPEG spends at least one bit on each 8x8 block of each
// component, so n bytes hold at most 512 n pixels; a few hundred bytes that
// declare more would have a node decode gigapixels of nothing.
constexpr std::int64_t kMaxJpegPixelsPerByte = 512;

// An image_t's fields as an Image; its pixel bytes are data (size bytes),
// which are message.data unless they were decoded apart (decode<Image>).
Image imageFromLcm(const nadir::image_t& message, const std::uint8_t* data, std::size_t size) {
  const auto fail = [&](const std::string& what) {
    return InvalidMessage("image_t " + std::to_string(message.width) + "x" +
                          std::to_string(message.height) + " at utime " +
                          std::to_string(message.utime) + ": " + what);
  };
  Image image;
  image.utime = message.utime;
  for (const nadir::image_metadata_t& entry : message.metadata) {
    image.metadata.emplace_back(entry.key, entry.value);
  }
  if (message.width <= 0 || message.height <= 0) throw fail("no pixels");
  if (message.pixelformat == nadir::image_t::PIXEL_FORMAT_MJPEG) {
    const std::vector<std::uint8_t>& jpeg = message.data;
    const std::optional<JpegFrameSize> frame = jpegFrameSize(jpeg);
    if (!frame) throw fail("JPEG data has no frame header");
    if (frame->width != message.width || frame->height != message.height) {
      throw fail("JPEG is " + std::to_string(frame->width) + "x" + std::to_string(frame->height));
    }
    if (std::int64_t{message.width} * message.height >
        kMaxJpegPixelsPerByte * static_cast<std::int64_t>(jpeg.size())) {
      throw fail("a JPEG of " + std::to_string(jpeg.size()) + " bytes cannot hold " +
                 std::to_string(std::int64_t{message.width} * message.height) + " pixels");
    }
    cv::Mat decoded = cv::imdecode(jpeg, cv::IMREAD_UNCHANGED);
    if (decoded.empty()) throw fail("JPEG data does not decode");
    if (decoded.cols != message.width || decoded.rows != message.height) {
      throw fail("JPEG is " + std::to_string(decoded.cols) + "x" + std::to_string(decoded.rows));
    }
    if (decoded.channels() == 3) cv::cvtColor(decoded, decoded, cv::COLOR_BGR2RGB);
    image.pixels = decoded;
    return image;
  }
  int channels = 0;
  switch (message.pixelformat) {
    case nadir::image_t::PIXEL_FORMAT_GRAY:
      channels = 1;
      break;
    case nadir::image_t::PIXEL_FORMAT_RGB:
    case nadir::image_t::PIXEL_FORMAT_BGR:
      channels = 3;
      break;
    default:
      throw fail("unsupported pixel format " + std::to_string(message.pixelformat));
  }
  if (message.row_stride < message.width * channels ||
      static_cast<std::int64_t>(message.row_stride) * message.height >
          static_cast<std::int64_t>(size)) {
    throw fail("row stride " + std::to_string(message.row_stride) + " does not fit " +
               std::to_string(size) + " bytes");
  }
  const cv::Mat view(message.height, message.width, channels == 1 ? CV_8UC1 : CV_8UC3,
                     const_cast<std::uint8_t*>(data), static_cast<std::size_t>(message.row_stride));
  image.pixels = view.clone();
  if (message.pixelformat == nadir::image_t::PIXEL_FORMAT_BGR)
    cv::cvtColor(image.pixels, image.pixels, cv::COLOR_BGR2RGB);
  return image;
}

Image imageFromLcm(const nadir::image_t& message) {
  if (message.size != static_cast<std::int32_t>(message.data.size())) {
    throw InvalidMessage("image_t " + std::to_string(message.width) + "x" +
                         std::to_string(message.height) + " at utime " +
                         std::to_string(message.utime) + ": size field " +
                         std::to_string(message.size) + " but " +
                         std::to_string(message.data.size()) + " bytes of data");
  }
  return imageFromLcm(message, message.data.data(), message.data.size());
}

// ---------------------------------------------------------------- the type table

// Each nadir type's name by fingerprint, for typeName().
struct KnownType {
  std::int64_t hash;
  const char* name;
};

template <class... Lcm>
std::vector<KnownType> knownTypes() {
  return {KnownType{Lcm::getHash(), Lcm::getTypeName()}...};
}

// The generated type of each plain struct.
template <class T>
struct LcmOf;
template <>
struct LcmOf<Pose> {
  using type = nadir::pose_t;
};
template <>
struct LcmOf<Imu> {
  using type = nadir::imu_t;
};
template <>
struct LcmOf<Range> {
  using type = nadir::range_t;
};
template <>
struct LcmOf<Gps> {
  using type = nadir::gps_t;
};
template <>
struct LcmOf<Baro> {
  using type = nadir::baro_t;
};
template <>
struct LcmOf<Magnetometer> {
  using type = nadir::magnetometer_t;
};
template <>
struct LcmOf<GeodeticPosition> {
  using type = nadir::geodetic_position_t;
};
template <>
struct LcmOf<Attitude> {
  using type = nadir::attitude_t;
};
template <>
struct LcmOf<Velocity> {
  using type = nadir::velocity_t;
};
template <>
struct LcmOf<BodyRates> {
  using type = nadir::body_rates_t;
};
template <>
struct LcmOf<CameraInfo> {
  using type = nadir::camera_info_t;
};
template <>
struct LcmOf<Image> {
  using type = nadir::image_t;
};
template <>
struct LcmOf<VoEstimate> {
  using type = nadir::vo_estimate_t;
};
template <>
struct LcmOf<NavState> {
  using type = nadir::nav_state_t;
};
template <>
struct LcmOf<PpaOdometry> {
  using type = nadir::ppa_odometry_t;
};
template <>
struct LcmOf<TargetDetection> {
  using type = nadir::target_detection_t;
};
template <>
struct LcmOf<VoCommand> {
  using type = nadir::vo_command_t;
};
template <>
struct LcmOf<GatePattern> {
  using type = nadir::gate_pattern_t;
};
template <>
struct LcmOf<DriveCommand> {
  using type = nadir::drive_command_t;
};
template <>
struct LcmOf<WaypointReached> {
  using type = nadir::waypoint_reached_t;
};
template <>
struct LcmOf<Heartbeat> {
  using type = nadir::heartbeat_t;
};
template <>
struct LcmOf<BusCheck> {
  using type = nadir::bus_check_t;
};

}  // namespace

// ---------------------------------------------------------------- helpers of the structs

Eigen::Isometry3d CameraInfo::T_body_cam() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q_body_cam.toRotationMatrix();
  T.translation() = p_cam_in_body_m;
  return T;
}

bool CameraInfo::distorted() const {
  return std::any_of(distortion.begin(), distortion.end(), [](double k) { return k != 0.0; });
}

std::string Image::metadataText(const std::string& key) const {
  for (const auto& [name, value] : metadata) {
    if (name == key) return std::string(value.begin(), value.end());
  }
  return {};
}

// ---------------------------------------------------------------- encode

Bytes encode(const Pose& message) { return toBytes(poseToLcm(message)); }

Bytes encode(const Imu& message) {
  nadir::imu_t out{};
  out.utime = message.utime;
  put3(message.angular_velocity_rps, out.angular_velocity_rps);
  put3(message.linear_acceleration_mps2, out.linear_acceleration_mps2);
  return toBytes(out);
}

Bytes encode(const Range& message) {
  nadir::range_t out{};
  out.utime = message.utime;
  out.range_m = message.range_m;
  out.min_range_m = message.min_range_m;
  out.max_range_m = message.max_range_m;
  put3(message.direction_body, out.direction_body);
  switch (message.status) {
    case RangeStatus::VALID:
      out.status = nadir::range_t::STATUS_VALID;
      break;
    case RangeStatus::TOO_CLOSE:
      out.status = nadir::range_t::STATUS_TOO_CLOSE;
      break;
    case RangeStatus::OUT_OF_RANGE:
      out.status = nadir::range_t::STATUS_OUT_OF_RANGE;
      break;
  }
  return toBytes(out);
}

Bytes encode(const Gps& message) {
  nadir::gps_t out{};
  out.utime = message.utime;
  out.latitude_rad = message.lat_rad;
  out.longitude_rad = message.lon_rad;
  out.altitude_m = message.alt_m;
  put3(message.velocity_ned_mps, out.velocity_ned_mps);
  out.horizontal_accuracy_m = message.horizontal_accuracy_m;
  out.vertical_accuracy_m = message.vertical_accuracy_m;
  out.num_satellites = static_cast<std::int16_t>(
      std::clamp<int>(message.num_satellites, 0, std::numeric_limits<std::int16_t>::max()));
  // GpsFix lists gps_t's FIX_* values in their order.
  out.fix_type = static_cast<std::int8_t>(message.fix);
  return toBytes(out);
}

Bytes encode(const Baro& message) {
  nadir::baro_t out{};
  out.utime = message.utime;
  out.altitude_m = message.altitude_m;
  out.pressure_pa = message.pressure_pa;
  return toBytes(out);
}

Bytes encode(const Magnetometer& message) {
  nadir::magnetometer_t out{};
  out.utime = message.utime;
  put3(message.field_body_ut, out.field_ut);
  return toBytes(out);
}

Bytes encode(const GeodeticPosition& message) {
  nadir::geodetic_position_t out{};
  out.utime = message.utime;
  out.latitude_rad = message.lat_rad;
  out.longitude_rad = message.lon_rad;
  out.altitude_m = message.alt_m;
  out.altitude_rel_m = message.alt_rel_m;
  return toBytes(out);
}

Bytes encode(const Attitude& message) {
  nadir::attitude_t out{};
  out.utime = message.utime;
  core::quaternionToWire(message.q_world_body, out.orientation);
  out.roll_rad = message.roll_rad;
  out.pitch_rad = message.pitch_rad;
  out.yaw_rad = message.yaw_rad;
  return toBytes(out);
}

Bytes encode(const Velocity& message) {
  nadir::velocity_t out{};
  out.utime = message.utime;
  put3(message.v_ned_mps, out.velocity_ned_mps);
  return toBytes(out);
}

Bytes encode(const BodyRates& message) {
  nadir::body_rates_t out{};
  out.utime = message.utime;
  put3(message.omega_body_dps, out.angular_velocity_dps);
  return toBytes(out);
}

Bytes encode(const CameraInfo& message) {
  nadir::camera_info_t out{};
  out.utime = message.utime;
  out.camera_name = message.camera_name;
  out.width = message.width;
  out.height = message.height;
  out.fx = message.fx;
  out.fy = message.fy;
  out.cx = message.cx;
  out.cy = message.cy;
  // Distortion lists camera_info_t's DISTORTION_* values in their order.
  out.distortion_model = static_cast<std::int8_t>(message.distortion_model);
  out.distortion = message.distortion;
  out.num_distortion = static_cast<std::int32_t>(out.distortion.size());
  out.fps = message.fps;
  put3(message.p_cam_in_body_m, out.position_cam_in_body_m);
  core::quaternionToWire(message.q_body_cam, out.orientation_body_cam);
  out.time_offset_s = message.time_offset_s;
  out.timestamp_jitter_s = message.timestamp_jitter_s;
  out.exposure_s = message.exposure_s;
  out.readout_s = message.readout_s;
  return toBytes(out);
}

Bytes encode(const Image& message) {
  const cv::Mat& pixels = message.pixels;
  const bool gray = pixels.channels() == 1;
  nadir::image_t out{};
  out.utime = message.utime;
  out.width = pixels.cols;
  out.height = pixels.rows;
  for (const auto& [key, value] : message.metadata) {
    nadir::image_metadata_t entry;
    entry.key = key;
    entry.value = value;
    entry.n = static_cast<std::int32_t>(value.size());
    out.metadata.push_back(std::move(entry));
  }
  out.nmetadata = static_cast<std::int32_t>(out.metadata.size());
  if (message.jpeg_quality > 0) {
    cv::Mat bgr;
    if (!gray) cv::cvtColor(pixels, bgr, cv::COLOR_RGB2BGR);
    std::vector<std::uint8_t> jpeg;
    cv::imencode(".jpg", gray ? pixels : bgr, jpeg,
                 {cv::IMWRITE_JPEG_QUALITY, std::min(message.jpeg_quality, 100)});
    out.row_stride = 0;
    out.pixelformat = nadir::image_t::PIXEL_FORMAT_MJPEG;
    out.data = std::move(jpeg);
    out.size = static_cast<std::int32_t>(out.data.size());
    return toBytes(out);
  }
  // Raw pixels go from the image straight into the bytes, copied once: the
  // message is encoded without them, and they are put in where data goes,
  // right after the fingerprint, utime and five int32 fields.
  out.row_stride = pixels.cols * pixels.channels();
  out.pixelformat = gray ? std::int32_t{nadir::image_t::PIXEL_FORMAT_GRAY}
                         : std::int32_t{nadir::image_t::PIXEL_FORMAT_RGB};
  out.size = 0;
  const Bytes without_pixels = toBytes(out);
  constexpr std::size_t kDataOffset = 8 + 8 + 5 * 4;
  const std::size_t row_bytes = static_cast<std::size_t>(out.row_stride);
  const std::size_t data_bytes = row_bytes * static_cast<std::size_t>(pixels.rows);
  Bytes bytes;
  bytes.reserve(without_pixels.size() + data_bytes);
  bytes.insert(bytes.end(), without_pixels.begin(), without_pixels.begin() + kDataOffset);
  for (int shift = 24, i = 0; i < 4; shift -= 8, ++i)  // size, big-endian
    bytes[kDataOffset - 4 + static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>(static_cast<std::uint32_t>(data_bytes) >> shift);
  for (int row = 0; row < pixels.rows; ++row)
    bytes.insert(bytes.end(), pixels.ptr<std::uint8_t>(row),
                 pixels.ptr<std::uint8_t>(row) + row_bytes);
  bytes.insert(bytes.end(), without_pixels.begin() + kDataOffset, without_pixels.end());
  return bytes;
}

Bytes encode(const VoEstimate& message) {
  nadir::vo_estimate_t out{};
  out.utime = message.utime;
  out.source = message.source;
  // VoStatus lists vo_estimate_t's STATUS_* values in their order.
  out.status = static_cast<std::int8_t>(message.status);
  out.pose.utime = message.utime;
  put3(message.p_ned_m, out.pose.pos);
  core::quaternionToWire(message.q_world_body, out.pose.orientation);
  out.num_features = message.num_features;
  out.num_resets = message.num_resets;
  out.processing_time_s = message.processing_time_s;
  return toBytes(out);
}

Bytes encode(const NavState& message) {
  nadir::nav_state_t out{};
  out.utime = message.utime;
  out.source = message.source;
  out.pose.utime = message.utime;
  put3(message.p_ned_m, out.pose.pos);
  put3(message.v_ned_mps, out.pose.vel);
  core::quaternionToWire(message.q_world_body, out.pose.orientation);
  put9(message.position_covariance_m2, out.position_covariance_m2);
  put9(message.velocity_covariance_m2ps2, out.velocity_covariance_m2ps2);
  put9(message.attitude_covariance_rad2, out.attitude_covariance_rad2);
  put3(message.gyro_bias_rps, out.gyro_bias_rps);
  put3(message.accel_bias_mps2, out.accel_bias_mps2);
  out.baro_bias_m = message.baro_bias_m;
  out.ground_down_m = message.ground_down_m;
  out.vo_scale = message.vo_scale;
  out.last_gps_utime = message.last_gps_utime;
  out.updates_fused = message.updates_fused;
  out.updates_refused = message.updates_refused;
  out.updates_late = message.updates_late;
  return toBytes(out);
}

Bytes encode(const PpaOdometry& message) {
  nadir::ppa_odometry_t out{};
  out.utime = message.utime;
  out.frame_index = message.frame_index;
  out.translation_x_px = message.translation_x_px;
  out.translation_y_px = message.translation_y_px;
  out.rotation_rad = message.rotation_rad;
  out.scale = message.scale;
  out.strength = message.strength;
  out.new_keyframe = message.new_keyframe;
  out.keyframe_edge_count = message.keyframe_edge_count;
  out.instruction_count = message.instruction_count;
  return toBytes(out);
}

Bytes encode(const TargetDetection& message) {
  nadir::target_detection_t out{};
  out.utime = message.utime;
  // TargetKind lists target_detection_t's KIND_* values in their order.
  out.kind = static_cast<std::int8_t>(message.kind);
  out.detected = message.detected;
  out.x_min_px = message.x_min_px;
  out.y_min_px = message.y_min_px;
  out.x_max_px = message.x_max_px;
  out.y_max_px = message.y_max_px;
  out.center_x_px = message.center_x_px;
  out.center_y_px = message.center_y_px;
  out.num_boundaries = message.num_boundaries;
  for (const Eigen::Vector2d& point : message.points_px) {
    out.points_px.push_back({point.x(), point.y()});
  }
  out.num_points = static_cast<std::int32_t>(out.points_px.size());
  return toBytes(out);
}

Bytes encode(const VoCommand& message) {
  nadir::vo_command_t out{};
  out.utime = message.utime;
  out.target = message.target;
  out.command = nadir::vo_command_t::COMMAND_RESET;
  out.has_initial_pose = message.initial_pose.has_value();
  if (message.initial_pose) out.initial_pose = poseToLcm(*message.initial_pose);
  return toBytes(out);
}

Bytes encode(const Heartbeat& message) {
  nadir::heartbeat_t out{};
  out.utime = message.utime;
  out.node = message.node;
  out.pid = message.pid;
  out.sequence = message.sequence;
  out.done = message.done;
  out.summary = message.summary;
  for (const auto& [channel, count] : message.sent) {
    out.channels.push_back(channel);
    out.messages_sent.push_back(count);
  }
  out.num_channels = static_cast<std::int32_t>(out.channels.size());
  return toBytes(out);
}

Bytes encode(const BusCheck& message) {
  nadir::bus_check_t out{};
  out.utime = message.utime;
  out.launch_id = message.launch_id;
  out.host = message.host;
  out.pid = message.pid;
  out.heard.assign(message.heard.begin(), message.heard.end());
  out.num_heard = static_cast<std::int32_t>(out.heard.size());
  return toBytes(out);
}

// ---------------------------------------------------------------- decode

template <>
Pose decode<Pose>(const void* data, std::size_t size) {
  return poseFromLcm(fromBytes<nadir::pose_t>(data, size));
}

template <>
Imu decode<Imu>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::imu_t>(data, size);
  return {in.utime, get3(in.angular_velocity_rps), get3(in.linear_acceleration_mps2)};
}

template <>
Range decode<Range>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::range_t>(data, size);
  Range out;
  out.utime = in.utime;
  out.range_m = in.range_m;
  out.status = enumFromWire<RangeStatus>(in.status, 3, "status", where(in));
  out.direction_body = get3(in.direction_body);
  out.min_range_m = in.min_range_m;
  out.max_range_m = in.max_range_m;
  if (out.status == RangeStatus::VALID) requireFinite(in.range_m, "range_m", where(in));
  return out;
}

template <>
Gps decode<Gps>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::gps_t>(data, size);
  Gps out;
  out.utime = in.utime;
  out.lat_rad = in.latitude_rad;
  out.lon_rad = in.longitude_rad;
  out.alt_m = in.altitude_m;
  out.velocity_ned_mps = get3(in.velocity_ned_mps);
  out.horizontal_accuracy_m = in.horizontal_accuracy_m;
  out.vertical_accuracy_m = in.vertical_accuracy_m;
  out.num_satellites = in.num_satellites;
  out.fix = enumFromWire<GpsFix>(in.fix_type, 5, "fix_type", where(in));
  return out;
}

template <>
Baro decode<Baro>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::baro_t>(data, size);
  return {in.utime, in.altitude_m, in.pressure_pa};
}

template <>
Magnetometer decode<Magnetometer>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::magnetometer_t>(data, size);
  return {in.utime, get3(in.field_ut)};
}

template <>
GeodeticPosition decode<GeodeticPosition>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::geodetic_position_t>(data, size);
  const std::string at = where(in);
  requireFinite(in.latitude_rad, "latitude_rad", at);
  requireFinite(in.longitude_rad, "longitude_rad", at);
  requireFinite(in.altitude_m, "altitude_m", at);
  if (std::abs(in.latitude_rad) > std::numbers::pi / 2) {
    throw InvalidMessage(at + ": latitude_rad " + std::to_string(in.latitude_rad) +
                         " is beyond a pole");
  }
  return {in.utime, in.latitude_rad, in.longitude_rad, in.altitude_m, in.altitude_rel_m};
}

template <>
Attitude decode<Attitude>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::attitude_t>(data, size);
  return {in.utime, rotationFromWire(in.orientation, "orientation", where(in)), in.roll_rad,
          in.pitch_rad, in.yaw_rad};
}

template <>
Velocity decode<Velocity>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::velocity_t>(data, size);
  return {in.utime, get3(in.velocity_ned_mps)};
}

template <>
BodyRates decode<BodyRates>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::body_rates_t>(data, size);
  return {in.utime, get3(in.angular_velocity_dps)};
}

namespace {

// The fields both layouts of camera_info_t share.
template <class Lcm>
CameraInfo cameraInfoFromLcm(const Lcm& in) {
  const std::string at = where(in);
  if (in.width <= 0 || in.height <= 0) {
    throw InvalidMessage(at + ": " + std::to_string(in.width) + "x" + std::to_string(in.height) +
                         " is not an image size");
  }
  for (const auto& [name, value] :
       {std::pair{"fx", in.fx}, std::pair{"fy", in.fy}, std::pair{"cx", in.cx},
        std::pair{"cy", in.cy}, std::pair{"fps", in.fps}}) {
    requireFinite(value, name, at);
  }
  if (in.fx <= 0 || in.fy <= 0) throw InvalidMessage(at + ": a focal length is not positive");
  requireFinite(in.distortion.data(), static_cast<int>(in.distortion.size()), "distortion", at);
  requireFinite(in.position_cam_in_body_m, 3, "position_cam_in_body_m", at);
  CameraInfo out;
  out.utime = in.utime;
  out.camera_name = in.camera_name;
  out.width = in.width;
  out.height = in.height;
  out.fx = in.fx;
  out.fy = in.fy;
  out.cx = in.cx;
  out.cy = in.cy;
  out.distortion_model = enumFromWire<Distortion>(in.distortion_model, 3, "distortion_model", at);
  out.distortion = in.distortion;
  out.fps = in.fps;
  out.p_cam_in_body_m = get3(in.position_cam_in_body_m);
  out.q_body_cam = rotationFromWire(in.orientation_body_cam, "orientation_body_cam", at);
  return out;
}

}  // namespace

template <>
CameraInfo decode<CameraInfo>(const void* data, std::size_t size) {
  // Logs recorded before the timing fields hold the first layout.
  if (fingerprintOf(data, size) == nadir::camera_info_v1_t::getHash())
    return cameraInfoFromLcm(fromBytes<nadir::camera_info_v1_t>(data, size));
  const auto in = fromBytes<nadir::camera_info_t>(data, size);
  CameraInfo out = cameraInfoFromLcm(in);
  const std::string at = where(in);
  for (const auto& [name, value] :
       {std::pair{"time_offset_s", in.time_offset_s},
        std::pair{"timestamp_jitter_s", in.timestamp_jitter_s},
        std::pair{"exposure_s", in.exposure_s}, std::pair{"readout_s", in.readout_s}}) {
    requireFinite(value, name, at);
  }
  if (in.timestamp_jitter_s < 0 || in.exposure_s < 0 || in.readout_s < 0)
    throw InvalidMessage(at + ": a negative jitter, exposure or readout time");
  out.time_offset_s = in.time_offset_s;
  out.timestamp_jitter_s = in.timestamp_jitter_s;
  out.exposure_s = in.exposure_s;
  out.readout_s = in.readout_s;
  return out;
}

template <>
Image decode<Image>(const void* data, std::size_t size) {
  // Raw pixels are copied once, from the bytes into the image: the generated
  // decoder reads every other field from a copy of the bytes without them
  // (the size field 0), and the pixels come straight from where data lies.
  // Bytes that do not decode that way go the whole way, for its errors.
  constexpr std::size_t kSizeOffset = 8 + 8 + 4 * 4, kDataOffset = kSizeOffset + 4;
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  if (size >= kDataOffset && fingerprintOf(data, size) == nadir::image_t::getHash() &&
      !isJpegImage(data, size)) {
    std::uint32_t size_field = 0;
    for (std::size_t i = 0; i < 4; ++i) size_field = (size_field << 8) | bytes[kSizeOffset + i];
    const std::size_t pixel_bytes = size_field;
    if (size_field <= 0x7FFFFFFFu && pixel_bytes <= size - kDataOffset) {
      std::vector<std::uint8_t> without_pixels(bytes, bytes + kDataOffset);
      std::fill(without_pixels.begin() + kSizeOffset, without_pixels.end(), 0);
      without_pixels.insert(without_pixels.end(), bytes + kDataOffset + pixel_bytes, bytes + size);
      std::optional<nadir::image_t> message;
      try {
        message = fromBytes<nadir::image_t>(without_pixels.data(), without_pixels.size());
      } catch (const DecodeError&) {
      }
      if (message) return imageFromLcm(*message, bytes + kDataOffset, pixel_bytes);
    }
  }
  return imageFromLcm(fromBytes<nadir::image_t>(data, size));
}

template <>
VoEstimate decode<VoEstimate>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::vo_estimate_t>(data, size);
  const std::string at = where(in);
  VoEstimate out;
  out.utime = in.utime;
  out.source = in.source;
  out.status = enumFromWire<VoStatus>(in.status, 3, "status", at);
  out.num_features = in.num_features;
  out.num_resets = in.num_resets;
  out.processing_time_s = in.processing_time_s;
  out.p_ned_m = get3(in.pose.pos);
  if (out.status == VoStatus::TRACKING) {
    requireFinite(in.pose.pos, 3, "pose.pos", at);
    out.q_world_body = rotationFromWire(in.pose.orientation, "pose.orientation", at);
  } else {
    try {
      out.q_world_body = core::quaternionFromWire(in.pose.orientation);
    } catch (const std::invalid_argument&) {
      out.q_world_body = Eigen::Quaterniond::Identity();
    }
  }
  return out;
}

template <>
NavState decode<NavState>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::nav_state_t>(data, size);
  const std::string at = where(in);
  NavState out;
  out.utime = in.utime;
  out.source = in.source;
  requireFinite(in.pose.pos, 3, "pose.pos", at);
  requireFinite(in.pose.vel, 3, "pose.vel", at);
  out.p_ned_m = get3(in.pose.pos);
  out.v_ned_mps = get3(in.pose.vel);
  out.q_world_body = rotationFromWire(in.pose.orientation, "pose.orientation", at);
  out.position_covariance_m2 =
      covarianceFromWire(in.position_covariance_m2, "position_covariance_m2", at);
  out.velocity_covariance_m2ps2 =
      covarianceFromWire(in.velocity_covariance_m2ps2, "velocity_covariance_m2ps2", at);
  out.attitude_covariance_rad2 =
      covarianceFromWire(in.attitude_covariance_rad2, "attitude_covariance_rad2", at);
  requireFinite(in.gyro_bias_rps, 3, "gyro_bias_rps", at);
  requireFinite(in.accel_bias_mps2, 3, "accel_bias_mps2", at);
  out.gyro_bias_rps = get3(in.gyro_bias_rps);
  out.accel_bias_mps2 = get3(in.accel_bias_mps2);
  out.baro_bias_m = in.baro_bias_m;
  out.ground_down_m = in.ground_down_m;
  out.vo_scale = in.vo_scale;
  out.last_gps_utime = in.last_gps_utime;
  out.updates_fused = in.updates_fused;
  out.updates_refused = in.updates_refused;
  out.updates_late = in.updates_late;
  return out;
}

template <>
PpaOdometry decode<PpaOdometry>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::ppa_odometry_t>(data, size);
  PpaOdometry out;
  out.utime = in.utime;
  out.frame_index = in.frame_index;
  out.translation_x_px = in.translation_x_px;
  out.translation_y_px = in.translation_y_px;
  out.rotation_rad = in.rotation_rad;
  out.scale = in.scale;
  out.strength = in.strength;
  out.new_keyframe = in.new_keyframe;
  out.keyframe_edge_count = in.keyframe_edge_count;
  out.instruction_count = in.instruction_count;
  return out;
}

template <>
TargetDetection decode<TargetDetection>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::target_detection_t>(data, size);
  TargetDetection out;
  out.utime = in.utime;
  out.kind = enumFromWire<TargetKind>(in.kind, 2, "kind", where(in));
  out.detected = in.detected;
  out.x_min_px = in.x_min_px;
  out.y_min_px = in.y_min_px;
  out.x_max_px = in.x_max_px;
  out.y_max_px = in.y_max_px;
  out.center_x_px = in.center_x_px;
  out.center_y_px = in.center_y_px;
  out.num_boundaries = in.num_boundaries;
  for (const std::vector<double>& point : in.points_px)
    out.points_px.emplace_back(point[0], point[1]);
  return out;
}

Bytes encode(const GatePattern& message) {
  nadir::gate_pattern_t out{};
  out.utime = message.utime;
  // PatternKind lists gate_pattern_t's KIND_* values in their order.
  out.kind = static_cast<std::int8_t>(message.kind);
  for (const Eigen::Vector2d& disk : message.disks_px) out.disks_px.push_back({disk.x(), disk.y()});
  out.num_disks = static_cast<std::int32_t>(out.disks_px.size());
  out.squares_intact = message.squares_intact;
  out.patterns_in_view = message.patterns_in_view;
  out.threshold_instructions = message.threshold_instructions;
  out.flood_instructions = message.flood_instructions;
  out.denoise_instructions = message.denoise_instructions;
  out.coordinates_instructions = message.coordinates_instructions;
  out.chip_time_s = message.chip_time_s;
  return toBytes(out);
}

Bytes encode(const DriveCommand& message) {
  nadir::drive_command_t out{};
  out.utime = message.utime;
  out.frame_utime = message.frame_utime;
  out.steer_rad = message.steer_rad;
  out.speed_mps = message.speed_mps;
  // DriveCommand::Mode lists drive_command_t's MODE_* values in their order.
  out.mode = static_cast<std::int8_t>(message.mode);
  out.lateral_error_rad = message.lateral_error_rad;
  out.deformation = message.deformation;
  return toBytes(out);
}

Bytes encode(const WaypointReached& message) {
  nadir::waypoint_reached_t out{};
  out.utime = message.utime;
  out.index = message.index;
  out.count = message.count;
  put3(message.waypoint_ned_m, out.waypoint_ned);
  put3(message.believed_ned_m, out.believed_ned);
  put3(message.true_ned_m, out.true_ned);
  out.source = message.source;
  return toBytes(out);
}

template <>
WaypointReached decode<WaypointReached>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::waypoint_reached_t>(data, size);
  const std::string at = where(in);
  requireFinite(in.waypoint_ned, 3, "waypoint_ned", at);
  requireFinite(in.believed_ned, 3, "believed_ned", at);
  requireFinite(in.true_ned, 3, "true_ned", at);
  if (in.index < 0 || in.index >= in.count) {
    throw InvalidMessage(at + ": index " + std::to_string(in.index) + " is not in [0, count " +
                         std::to_string(in.count) + ")");
  }
  WaypointReached out;
  out.utime = in.utime;
  out.index = in.index;
  out.count = in.count;
  out.waypoint_ned_m = get3(in.waypoint_ned);
  out.believed_ned_m = get3(in.believed_ned);
  out.true_ned_m = get3(in.true_ned);
  out.source = in.source;
  return out;
}

template <>
GatePattern decode<GatePattern>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::gate_pattern_t>(data, size);
  const std::string at = where(in);
  GatePattern out;
  out.utime = in.utime;
  out.kind = enumFromWire<PatternKind>(in.kind, 4, "kind", at);
  for (const std::vector<double>& disk : in.disks_px) {
    requireFinite(disk.data(), 2, "disks_px", at);
    out.disks_px.emplace_back(disk[0], disk[1]);
  }
  const std::size_t wanted = out.kind == PatternKind::GATE   ? 4
                             : out.kind == PatternKind::NONE ? out.disks_px.size()
                                                             : 3;
  if (out.disks_px.size() != wanted) {
    throw InvalidMessage(at + ": num_disks " + std::to_string(out.disks_px.size()) +
                         " does not fit the pattern's kind (" + std::to_string(wanted) + ")");
  }
  out.squares_intact = in.squares_intact;
  out.patterns_in_view = in.patterns_in_view;
  out.threshold_instructions = in.threshold_instructions;
  out.flood_instructions = in.flood_instructions;
  out.denoise_instructions = in.denoise_instructions;
  out.coordinates_instructions = in.coordinates_instructions;
  out.chip_time_s = in.chip_time_s;
  requireFinite(in.chip_time_s, "chip_time_s", at);
  return out;
}

template <>
DriveCommand decode<DriveCommand>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::drive_command_t>(data, size);
  const std::string at = where(in);
  DriveCommand out;
  out.utime = in.utime;
  out.frame_utime = in.frame_utime;
  requireFinite(in.steer_rad, "steer_rad", at);
  requireFinite(in.speed_mps, "speed_mps", at);
  if (in.speed_mps < 0.0) {
    throw InvalidMessage(at + ": speed_mps " + std::to_string(in.speed_mps) + " is negative");
  }
  out.steer_rad = in.steer_rad;
  out.speed_mps = in.speed_mps;
  out.mode = enumFromWire<DriveCommand::Mode>(in.mode, 5, "mode", at);
  out.lateral_error_rad = in.lateral_error_rad;
  out.deformation = in.deformation;
  return out;
}

template <>
VoCommand decode<VoCommand>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::vo_command_t>(data, size);
  VoCommand out;
  out.utime = in.utime;
  out.target = in.target;
  out.command = enumFromWire<VoCommand::Kind>(in.command, 1, "command", where(in));
  if (in.has_initial_pose) out.initial_pose = poseFromLcm(in.initial_pose);
  return out;
}

template <>
Heartbeat decode<Heartbeat>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::heartbeat_t>(data, size);
  Heartbeat out{in.utime, in.node, in.pid, in.sequence, in.done != 0, in.summary, {}};
  for (std::size_t i = 0; i < in.channels.size(); ++i)
    out.sent[in.channels[i]] = in.messages_sent[i];
  return out;
}

template <>
BusCheck decode<BusCheck>(const void* data, std::size_t size) {
  const auto in = fromBytes<nadir::bus_check_t>(data, size);
  return {in.utime, in.launch_id, in.host, in.pid, {in.heard.begin(), in.heard.end()}};
}

// ---------------------------------------------------------------- types

template <class T>
bool isType(const void* data, std::size_t size) {
  if constexpr (std::is_same_v<T, CameraInfo>) {
    if (fingerprintOf(data, size) == nadir::camera_info_v1_t::getHash()) return true;
  }
  return fingerprintOf(data, size) == LcmOf<T>::type::getHash();
}

template <class T>
const char* typeNameOf() {
  return LcmOf<T>::type::getTypeName();
}

#define NADIR_MSG_TYPE(T)                            \
  template bool isType<T>(const void*, std::size_t); \
  template const char* typeNameOf<T>();
NADIR_MSG_TYPE(Pose)
NADIR_MSG_TYPE(Imu)
NADIR_MSG_TYPE(Range)
NADIR_MSG_TYPE(Gps)
NADIR_MSG_TYPE(Baro)
NADIR_MSG_TYPE(Magnetometer)
NADIR_MSG_TYPE(GeodeticPosition)
NADIR_MSG_TYPE(Attitude)
NADIR_MSG_TYPE(Velocity)
NADIR_MSG_TYPE(BodyRates)
NADIR_MSG_TYPE(CameraInfo)
NADIR_MSG_TYPE(Image)
NADIR_MSG_TYPE(VoEstimate)
NADIR_MSG_TYPE(NavState)
NADIR_MSG_TYPE(PpaOdometry)
NADIR_MSG_TYPE(TargetDetection)
NADIR_MSG_TYPE(VoCommand)
NADIR_MSG_TYPE(GatePattern)
NADIR_MSG_TYPE(DriveCommand)
NADIR_MSG_TYPE(WaypointReached)
NADIR_MSG_TYPE(Heartbeat)
NADIR_MSG_TYPE(BusCheck)
#undef NADIR_MSG_TYPE

std::string typeName(const void* data, std::size_t size) {
  static const std::vector<KnownType> kTypes =
      knownTypes<nadir::pose_t, nadir::imu_t, nadir::range_t, nadir::gps_t, nadir::baro_t,
                 nadir::magnetometer_t, nadir::geodetic_position_t, nadir::attitude_t,
                 nadir::velocity_t, nadir::body_rates_t, nadir::camera_info_t,
                 nadir::camera_info_v1_t, nadir::image_t, nadir::vo_estimate_t, nadir::nav_state_t,
                 nadir::ppa_odometry_t, nadir::target_detection_t, nadir::vo_command_t,
                 nadir::gate_pattern_t, nadir::drive_command_t, nadir::waypoint_reached_t,
                 nadir::heartbeat_t, nadir::bus_check_t>();
  const std::int64_t hash = fingerprintOf(data, size);
  for (const KnownType& type : kTypes) {
    if (type.hash == hash) return type.name;
  }
  return {};
}

bool isJpegImage(const void* data, std::size_t size) {
  // image_t: fingerprint, utime (int64), width, height, row_stride, pixelformat (int32s).
  constexpr std::size_t kPixelFormatOffset = 8 + 8 + 3 * 4;
  if (!isType<Image>(data, size) || size < kPixelFormatOffset + 4) return false;
  const auto* bytes = static_cast<const std::uint8_t*>(data) + kPixelFormatOffset;
  std::uint32_t format = 0;
  for (int i = 0; i < 4; ++i) format = (format << 8) | bytes[i];
  return static_cast<std::int32_t>(format) == nadir::image_t::PIXEL_FORMAT_MJPEG;
}

}  // namespace nadir::msg
