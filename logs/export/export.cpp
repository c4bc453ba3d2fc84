#include "logs/export/export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/clock.h"
#include "core/lcm_log.h"
#include "core/trajectory.h"
#include "lcmtypes/codec.h"

namespace nadir::dataset {
namespace fs = std::filesystem;

namespace {

// Truth is interpolated only between samples at most this far apart: a wider
// gap means truth is missing there (a damaged log), not a slow truth stream.
constexpr std::int64_t kMaxTruthGapUs = 500'000;

struct Calibration {
  msg::CameraInfo info;
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
};

// What the first pass over the log finds: everything but the pixels.
struct Scan {
  std::optional<Calibration> calibration;
  std::optional<std::int64_t> calibration_changed_utime;
  std::vector<msg::Pose> truth;  // T_world_body (world local NED, body FRD)
  std::vector<msg::Imu> imu;
  std::int64_t camera_images = 0;
  std::int64_t camera_other_messages = 0;
  std::map<std::string, std::int64_t> image_channels;
  std::map<std::string, std::int64_t> info_channels;
  std::map<std::string, std::int64_t> all_channels;
  std::map<std::string, std::int64_t> undecodable;
  std::int64_t truth_duplicates = 0;
  std::int64_t imu_duplicates = 0;
  std::string damage;
};

// Decodes one event as T; nothing if it is not a valid T.
template <class T>
std::optional<T> decodeEvent(const core::LogEvent& event) {
  try {
    return msg::decode<T>(event.data);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::string plural(std::int64_t count, const std::string& word) {
  return std::to_string(count) + " " + word + (count == 1 ? "" : "s");
}

std::string channelList(const std::map<std::string, std::int64_t>& channels,
                        const std::string& word) {
  std::string text;
  for (const auto& [channel, count] : channels) {
    if (!text.empty()) text += ", ";
    text += channel + " (" + plural(count, word) + ")";
  }
  return text;
}

bool sameCalibration(const msg::CameraInfo& a, const msg::CameraInfo& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy && a.distortion_model == b.distortion_model &&
         a.distortion == b.distortion && a.p_cam_in_body_m == b.p_cam_in_body_m &&
         a.q_body_cam.coeffs() == b.q_body_cam.coeffs();
}

// Sorts by utime and keeps the first of samples that share a time; returns how many went.
template <class T>
std::int64_t sortByTime(std::vector<T>& samples) {
  std::stable_sort(samples.begin(), samples.end(),
                   [](const T& a, const T& b) { return a.utime < b.utime; });
  const auto end = std::unique(samples.begin(), samples.end(),
                               [](const T& a, const T& b) { return a.utime == b.utime; });
  const auto dropped = static_cast<std::int64_t>(std::distance(end, samples.end()));
  samples.erase(end, samples.end());
  return dropped;
}

std::unique_ptr<core::LcmLogReader> openLog(const std::string& path) {
  try {
    return std::make_unique<core::LcmLogReader>(path);
  } catch (const core::LogError& error) {
    throw ExportError(error.what());
  }
}

Scan scanLog(const ExportOptions& options, const std::string& info_channel) {
  Scan scan;
  auto reader = openLog(options.log_path);
  try {
    while (auto event = reader->next()) {
      ++scan.all_channels[event->channel];
      const bool image = msg::isType<msg::Image>(event->data.data(), event->data.size());
      if (image) ++scan.image_channels[event->channel];
      if (msg::isType<msg::CameraInfo>(event->data.data(), event->data.size())) {
        ++scan.info_channels[event->channel];
      }
      if (event->channel == options.camera_channel) {
        if (image) {
          ++scan.camera_images;
        } else {
          ++scan.camera_other_messages;
        }
      }
      if (event->channel == info_channel) {
        const std::optional<msg::CameraInfo> info = decodeEvent<msg::CameraInfo>(*event);
        if (!info) {
          ++scan.undecodable[info_channel];
        } else if (!scan.calibration) {
          scan.calibration = Calibration{*info, info->T_body_cam()};
        } else if (!scan.calibration_changed_utime &&
                   !sameCalibration(scan.calibration->info, *info)) {
          scan.calibration_changed_utime = info->utime;
        }
      }
      if (event->channel == options.truth_channel) {
        if (std::optional<msg::Pose> pose = decodeEvent<msg::Pose>(*event)) {
          // EuRoC's ground truth holds the velocity; other systems may leave it unset.
          if (!pose->v_ned_mps.allFinite()) pose->v_ned_mps.setZero();
          scan.truth.push_back(*pose);
        } else {
          ++scan.undecodable[options.truth_channel];
        }
      }
      if (event->channel == options.imu_channel) {
        if (const std::optional<msg::Imu> imu = decodeEvent<msg::Imu>(*event)) {
          scan.imu.push_back(*imu);
        } else {
          ++scan.undecodable[options.imu_channel];
        }
      }
    }
  } catch (const core::LogError& error) {
    throw ExportError(error.what());
  }
  scan.damage = reader->damageReport();
  scan.truth_duplicates = sortByTime(scan.truth);
  scan.imu_duplicates = sortByTime(scan.imu);
  return scan;
}

// ------------------------------------------------------------------ text output

std::string number(double value) {
  char text[64];
  // + 0.0 writes a negative zero (an axis turned from 0) as 0.
  std::snprintf(text, sizeof(text), "%.12g", value + 0.0);
  return text;
}

// utime as seconds with exactly six decimals (no rounding through a double).
std::string secondsText(std::int64_t utime) {
  const bool negative = utime < 0;
  const std::uint64_t magnitude =
      negative ? 0 - static_cast<std::uint64_t>(utime) : static_cast<std::uint64_t>(utime);
  char text[48];
  std::snprintf(text, sizeof(text), "%s%llu.%06llu", negative ? "-" : "",
                static_cast<unsigned long long>(magnitude / 1'000'000),
                static_cast<unsigned long long>(magnitude % 1'000'000));
  return text;
}

std::string nanosecondsText(std::int64_t utime) { return std::to_string(utime * 1000); }

class TextFile {
 public:
  explicit TextFile(fs::path path) : path_(std::move(path)), out_(path_) {
    if (!out_) throw ExportError("cannot create " + path_.string());
  }
  TextFile& operator<<(const std::string& text) {
    out_ << text;
    return *this;
  }
  void close() {
    out_.close();
    if (out_.fail()) throw ExportError("cannot write " + path_.string());
  }

 private:
  fs::path path_;
  std::ofstream out_;
};

void writeText(const fs::path& path, const std::string& text) {
  TextFile file(path);
  file << text;
  file.close();
}

void createFolder(const fs::path& path) {
  std::error_code error;
  fs::create_directories(path, error);
  if (error) throw ExportError("cannot create folder " + path.string() + ": " + error.message());
}

// A rotation or transform's entry: rounding leaves 1e-16 where it has an
// exact 0; the 0 is written.
std::string matrixEntry(double value) { return number(std::abs(value) < 1e-12 ? 0.0 : value); }

// A 4x4 matrix as EuRoC's sensor.yaml writes it (row-major data list).
std::string yamlMatrix(const Eigen::Isometry3d& T, const std::string& indent) {
  const Eigen::Matrix4d M = T.matrix();
  std::string text = indent + "cols: 4\n" + indent + "rows: 4\n" + indent + "data: [";
  for (int r = 0; r < 4; ++r) {
    if (r > 0) text += ",\n" + indent + "       ";
    for (int c = 0; c < 4; ++c) text += (c > 0 ? ", " : "") + matrixEntry(M(r, c));
  }
  return text + "]\n";
}

std::string listOf(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i > 0 ? ", " : "") + number(values[i]);
  return text + "]";
}

// The first `count` coefficients (zero-padded); a note if non-zero ones are cut.
std::vector<double> firstCoefficients(const msg::CameraInfo& info, std::size_t count,
                                      const std::string& format_name,
                                      std::vector<std::string>& notes) {
  std::vector<double> coefficients(count, 0.0);
  for (std::size_t i = 0; i < info.distortion.size(); ++i) {
    if (i < count) {
      coefficients[i] = info.distortion[i];
    } else if (info.distortion[i] != 0.0) {
      notes.push_back(format_name + " takes " + std::to_string(count) +
                      " distortion coefficients: coefficient " + std::to_string(i + 1) + " (" +
                      number(info.distortion[i]) + ") is not in the calibration file");
    }
  }
  return coefficients;
}

struct ImageRecord {
  std::int64_t utime = 0;
  std::string file;  // relative to the folder that holds the index file
  double exposure_ms = 0.0;
};

double exposureMs(const msg::Image& image) {
  try {
    const double seconds = std::stod(image.metadataText("exposure_s"));
    if (std::isfinite(seconds) && seconds > 0) return seconds * 1000.0;
  } catch (const std::exception&) {
  }
  return 0.0;
}

// ------------------------------------------------------------------ the layouts

struct Layout {
  fs::path image_dir;  // where the PNGs go
  std::function<std::string(std::int64_t utime, std::int64_t index)> name;
};

Layout layoutFor(Format format, const fs::path& out) {
  switch (format) {
    case Format::kEuroc:
      return {out / "mav0" / "cam0" / "data",
              [](std::int64_t utime, std::int64_t) { return nanosecondsText(utime) + ".png"; }};
    case Format::kTumMono:
      return {out / "images", [](std::int64_t, std::int64_t index) {
                char text[32];
                std::snprintf(text, sizeof(text), "%05lld.png", static_cast<long long>(index));
                return std::string(text);
              }};
    case Format::kTum:
      return {out / "rgb",
              [](std::int64_t utime, std::int64_t) { return secondsText(utime) + ".png"; }};
  }
  throw std::logic_error("unknown export format");
}

struct Context {
  const ExportOptions& options;
  const Scan& scan;
  const Calibration& calibration;
  fs::path out;
  std::vector<ImageRecord> images;
  ExportSummary& summary;
};

std::string sourceLine(const Context& context) {
  return "nadir export of " + context.options.camera_channel + " from " + context.options.log_path;
}

double cameraRateHz(const Context& context) {
  if (context.calibration.info.fps > 0) return context.calibration.info.fps;
  if (context.images.size() < 2) return 0.0;
  const double span_s =
      static_cast<double>(context.images.back().utime - context.images.front().utime) * 1e-6;
  return span_s > 0 ? static_cast<double>(context.images.size() - 1) / span_s : 0.0;
}

double medianRateHz(const std::vector<msg::Imu>& samples) {
  if (samples.size() < 2) return 0.0;
  std::vector<std::int64_t> dts;
  dts.reserve(samples.size() - 1);
  for (std::size_t i = 1; i < samples.size(); ++i)
    dts.push_back(samples[i].utime - samples[i - 1].utime);
  std::nth_element(dts.begin(), dts.begin() + static_cast<std::ptrdiff_t>(dts.size() / 2),
                   dts.end());
  const std::int64_t median = dts[dts.size() / 2];
  return median > 0 ? 1e6 / static_cast<double>(median) : 0.0;
}

// Ground truth of the camera at each image time: T_world_cam = T_world_body * T_body_cam.
void writeTumTrajectory(Context& context, const fs::path& path) {
  TextFile file(path);
  const core::Axes axes = context.options.axes;
  file << "# ground truth: pose of the camera in the world, T_world_cam, interpolated at the "
          "image times; " +
              core::frameWords(axes, core::BodyAxes::kCamera) + "\n";
  file << "# " + sourceLine(context) + ", truth from " + context.options.truth_channel + "\n";
  file << "# frame: " + core::frameTag(axes, core::BodyAxes::kCamera) + "\n";
  file << "# timestamp tx ty tz qx qy qz qw\n";
  std::int64_t missing = 0;
  core::Trajectory truth;
  for (const msg::Pose& sample : context.scan.truth) {
    truth.push_back({core::secondsFromUtime(sample.utime), sample.p_ned_m, sample.q_world_body});
  }
  for (const ImageRecord& image : context.images) {
    const auto body = core::interpolate(truth, core::secondsFromUtime(image.utime),
                                        core::secondsFromUtime(kMaxTruthGapUs));
    if (!body) {
      ++missing;
      continue;
    }
    Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
    T_world_body.linear() = body->q_world_body.toRotationMatrix();
    T_world_body.translation() = body->p_ned_m;
    const Eigen::Isometry3d T_world_cam = T_world_body * context.calibration.T_body_cam;
    const Eigen::Vector3d p = core::worldVectorIn(axes, T_world_cam.translation());
    const Eigen::Quaterniond q =
        core::attitudeIn(axes, Eigen::Quaterniond(T_world_cam.rotation()), core::BodyAxes::kCamera);
    file << secondsText(image.utime) + " " + number(p.x()) + " " + number(p.y()) + " " +
                number(p.z()) + " " + number(q.x()) + " " + number(q.y()) + " " + number(q.z()) +
                " " + number(q.w()) + "\n";
    ++context.summary.poses;
  }
  file.close();
  if (missing > 0 && !context.scan.truth.empty()) {
    context.summary.notes.push_back(plural(missing, "image") + " outside the truth's time span " +
                                    "(or in a gap in it) have no line in " +
                                    path.filename().string());
  }
}

std::string framesReadme(const Context& context, const std::string& layout,
                         const std::string& truth) {
  const auto& info = context.calibration.info;
  const bool enu = context.options.axes == core::Axes::kEnu;
  const Eigen::Isometry3d T_body_cam =
      core::bodyToSensorIn(context.options.axes, context.calibration.T_body_cam);
  const Eigen::Vector3d p_body_cam = T_body_cam.translation();
  const Eigen::Quaterniond q_body_cam(T_body_cam.rotation());
  return "# " + sourceLine(context) + "\n\n" + layout + "\n\n## Frames and units\n\n" +
         (enu ? "- World: local ENU at the scenario's origin (x east, y north, z up: REP-103), "
                "metres (nadir's own is NED: written with --frame enu).\n"
                "- Body: FLU (x forward, y left, z up: REP-103); the IMU is mounted on it, "
                "aligned, at its origin.\n"
              : "- World: nadir's local NED at the scenario's origin (x north, y east, z down), "
                "metres.\n"
                "- Body: FRD (x forward, y right, z down); the IMU is mounted on it, aligned, at "
                "its origin.\n") +
         "- Camera: OpenCV optical (x right, y down the image, z along the optical axis).\n"
         "- Quaternions are Hamilton.\n- " +
         truth +
         "\n\n## Camera\n\n"
         "- " +
         std::to_string(info.width) + "x" + std::to_string(info.height) + " px, fx " +
         number(info.fx) + ", fy " + number(info.fy) + ", cx " + number(info.cx) + ", cy " +
         number(info.cy) + " (pixel centres; the top-left pixel's centre is (0, 0))\n" +
         "- distortion coefficients (model " +
         std::to_string(static_cast<int>(info.distortion_model)) +
         ": 0 none, 1 radial-tangential k1 k2 p1 p2 [k3], 2 equidistant k1 k2 k3 k4): " +
         listOf(info.distortion) + "\n- T_body_cam: camera at " + number(p_body_cam.x()) + ", " +
         number(p_body_cam.y()) + ", " + number(p_body_cam.z()) +
         " m in the body frame, R_body_cam (w x y z) " +
         listOf({q_body_cam.w(), q_body_cam.x(), q_body_cam.y(), q_body_cam.z()}) +
         "\n\nCounts: " + plural(context.summary.images, "image") + ", " +
         plural(context.summary.poses, "ground-truth pose") + ", " +
         plural(context.summary.imu_samples, "IMU sample") + ".\n";
}

// EuRoC's (and Kalibr's) noise lines of an IMU's sensor.yaml.
std::string imuNoiseYaml(const std::optional<ImuNoise>& noise) {
  if (!noise) {
    return "# The noise densities and random walks are the scenario's sensors.imu parameters; "
           "no scenario.yaml was beside the log.\n";
  }
  return "# The scenario's sensors.imu, continuous time.\ngyroscope_noise_density: " +
         number(noise->gyroscope_noise_density) +
         "     # [ rad / s / sqrt(Hz) ]\ngyroscope_random_walk: " +
         number(noise->gyroscope_random_walk) +
         "       # [ rad / s^2 / sqrt(Hz) ]\naccelerometer_noise_density: " +
         number(noise->accelerometer_noise_density) +
         "  # [ m / s^2 / sqrt(Hz) ]\naccelerometer_random_walk: " +
         number(noise->accelerometer_random_walk) + "    # [ m / s^3 / sqrt(Hz) ]\n";
}

// ORB-SLAM3's settings (file version 1.0) for this camera and IMU: monocular-
// inertial when the IMU's noise is known, monocular otherwise. The ORB
// extractor's figures are ORB-SLAM3's EuRoC ones, its feature count scaled with
// the image area from EuRoC's 752 x 480 (1000 features), 1000 to 3000.
std::string orbSlam3Settings(const Context& context) {
  const auto& info = context.calibration.info;
  const bool fisheye = info.distortion_model == msg::Distortion::EQUIDISTANT;
  std::vector<std::string> unused;
  const std::vector<double> k = firstCoefficients(info, 4, "ORB-SLAM3", unused);
  std::string text = "%YAML:1.0\n# " + sourceLine(context) +
                     "\n# ORB-SLAM3 (v1.0 settings): ./Examples/" +
                     (context.options.imu_noise ? "Monocular-Inertial/mono_inertial_euroc"
                                                : "Monocular/mono_euroc") +
                     " ORBvoc.txt orbslam3.yaml . timestamps.txt\n\nFile.version: \"1.0\"\n\n"
                     "Camera.type: \"" +
                     (fisheye ? "KannalaBrandt8" : "PinHole") + "\"\n";
  text += "Camera1.fx: " + number(info.fx) + "\nCamera1.fy: " + number(info.fy) +
          "\nCamera1.cx: " + number(info.cx) + "\nCamera1.cy: " + number(info.cy) + "\n";
  const char* names[4] = {"k1", "k2", fisheye ? "k3" : "p1", fisheye ? "k4" : "p2"};
  for (int i = 0; i < 4; ++i) {
    text +=
        std::string("Camera1.") + names[i] + ": " + number(k[static_cast<std::size_t>(i)]) + "\n";
  }
  if (!fisheye && info.distortion.size() > 4 && info.distortion[4] != 0.0) {
    text += "Camera1.k3: " + number(info.distortion[4]) + "\n";
  }
  const double features = std::clamp(
      1000.0 * static_cast<double>(info.width) * info.height / (752.0 * 480.0), 1000.0, 3000.0);
  text += "Camera.width: " + std::to_string(info.width) +
          "\nCamera.height: " + std::to_string(info.height) +
          "\nCamera.fps: " + number(std::round(cameraRateHz(context))) + "\nCamera.RGB: 1\n\n";
  if (const auto& noise = context.options.imu_noise) {
    const Eigen::Matrix4d T =
        core::bodyToSensorIn(context.options.axes, context.calibration.T_body_cam).matrix();
    text +=
        "# T_b_c1: the camera in the body (= IMU) frame\nIMU.T_b_c1: !!opencv-matrix\n"
        "  rows: 4\n  cols: 4\n  dt: f\n  data: [";
    for (int i = 0; i < 16; ++i) text += (i > 0 ? ", " : "") + matrixEntry(T(i / 4, i % 4));
    text += "]\nIMU.NoiseGyro: " + number(noise->gyroscope_noise_density) +
            "\nIMU.NoiseAcc: " + number(noise->accelerometer_noise_density) +
            "\nIMU.GyroWalk: " + number(noise->gyroscope_random_walk) +
            "\nIMU.AccWalk: " + number(noise->accelerometer_random_walk) +
            "\nIMU.Frequency: " + number(std::round(medianRateHz(context.scan.imu))) + "\n\n";
  }
  text += "ORBextractor.nFeatures: " + std::to_string(static_cast<int>(std::round(features))) +
          "\nORBextractor.scaleFactor: 1.2\nORBextractor.nLevels: 8\n"
          "ORBextractor.iniThFAST: 20\nORBextractor.minThFAST: 7\n\n"
          "Viewer.KeyFrameSize: 0.05\nViewer.KeyFrameLineWidth: 1.0\nViewer.GraphLineWidth: 0.9\n"
          "Viewer.PointSize: 2.0\nViewer.CameraSize: 0.08\nViewer.CameraLineWidth: 3.0\n"
          "Viewer.ViewpointX: 0.0\nViewer.ViewpointY: -0.7\nViewer.ViewpointZ: -3.5\n"
          "Viewer.ViewpointF: 500.0\n";
  return text;
}

// A 4x4 or 3x3 matrix as Kalibr writes one: a YAML list of rows.
std::string kalibrRows(const Eigen::MatrixXd& M, const std::string& indent) {
  std::string text;
  for (Eigen::Index r = 0; r < M.rows(); ++r) {
    text += indent + "- [";
    for (Eigen::Index c = 0; c < M.cols(); ++c) text += (c > 0 ? ", " : "") + matrixEntry(M(r, c));
    text += "]\n";
  }
  return text;
}

// OpenVINS's three files for this camera and IMU (monocular; its EuRoC
// configuration otherwise): Kalibr's IMU and camera-IMU chains and the
// estimator's settings that name them. OpenVINS reads ROS topics: the EuRoC
// folder goes into a bag first, camera on /cam0/image_raw, IMU on /imu0.
void writeOpenVins(const Context& context, const ImuNoise& noise) {
  const fs::path dir = context.out / "openvins";
  createFolder(dir);
  const auto& info = context.calibration.info;
  const bool fisheye = info.distortion_model == msg::Distortion::EQUIDISTANT;
  std::vector<std::string> unused;
  const std::vector<double> k = firstCoefficients(info, 4, "Kalibr", unused);
  const std::string header = "%YAML:1.0\n# " + sourceLine(context) + "\n\n";
  writeText(dir / "kalibr_imu_chain.yaml",
            header + "imu0:\n  T_i_b:\n" + kalibrRows(Eigen::Matrix4d::Identity(), "    ") +
                "  accelerometer_noise_density: " + number(noise.accelerometer_noise_density) +
                "\n  accelerometer_random_walk: " + number(noise.accelerometer_random_walk) +
                "\n  gyroscope_noise_density: " + number(noise.gyroscope_noise_density) +
                "\n  gyroscope_random_walk: " + number(noise.gyroscope_random_walk) +
                "\n  rostopic: /imu0\n  time_offset: 0.0\n  update_rate: " +
                number(std::round(medianRateHz(context.scan.imu))) +
                "\n  model: \"kalibr\"\n  Tw:\n" + kalibrRows(Eigen::Matrix3d::Identity(), "    ") +
                "  R_IMUtoGYRO:\n" + kalibrRows(Eigen::Matrix3d::Identity(), "    ") + "  Ta:\n" +
                kalibrRows(Eigen::Matrix3d::Identity(), "    ") + "  R_IMUtoACC:\n" +
                kalibrRows(Eigen::Matrix3d::Identity(), "    ") + "  Tg:\n" +
                kalibrRows(Eigen::Matrix3d::Zero(), "    "));
  const Eigen::Matrix4d T_imu_cam =
      core::bodyToSensorIn(context.options.axes, context.calibration.T_body_cam).matrix();
  writeText(dir / "kalibr_imucam_chain.yaml",
            header + "cam0:\n  T_imu_cam:  # R_CtoI, p_CinI: the camera in the body (= IMU)\n" +
                kalibrRows(T_imu_cam, "    ") +
                "  cam_overlaps: []\n  camera_model: pinhole\n  distortion_coeffs: " + listOf(k) +
                "\n  distortion_model: " + (fisheye ? "equidistant" : "radtan") +
                "\n  intrinsics: [" + number(info.fx) + ", " + number(info.fy) + ", " +
                number(info.cx) + ", " + number(info.cy) + "]  # fu, fv, cu, cv\n  resolution: [" +
                std::to_string(info.width) + ", " + std::to_string(info.height) +
                "]\n  rostopic: /cam0/image_raw\n");
  writeText(
      dir / "estimator_config.yaml",
      header +
          "verbosity: \"INFO\"\n\nuse_fej: true\nuse_imuavg: true\nuse_rk4int: true\n\n"
          "use_stereo: false\nmax_cameras: 1\n\ncalib_cam_extrinsics: true\n"
          "calib_cam_intrinsics: true\ncalib_cam_timeoffset: true\n\nmax_clones: 11\n"
          "max_slam: 50\nmax_slam_in_update: 25\nmax_msckf_in_update: 40\ndt_slam_delay: 1\n\n"
          "gravity_mag: 9.80665  # nadir's gravity\n\nfeat_rep_msckf: \"GLOBAL_3D\"\n"
          "feat_rep_slam: \"ANCHORED_MSCKF_INVERSE_DEPTH\"\n"
          "feat_rep_aruco: \"ANCHORED_MSCKF_INVERSE_DEPTH\"\n\ntry_zupt: false\n"
          "zupt_chi2_multipler: 0\nzupt_max_velocity: 0.1\nzupt_noise_multiplier: 10\n"
          "zupt_max_disparity: 0.5\nzupt_only_at_beginning: false\n\ninit_window_time: 2.0\n"
          "init_imu_thresh: 1.5\ninit_max_disparity: 10.0\ninit_max_features: 75\n\n"
          "init_dyn_use: false\ninit_dyn_min_movement: 0\ninit_dyn_mle_opt_calib: false\n"
          "init_dyn_mle_max_iter: 50\ninit_dyn_mle_max_time: 0.05\ninit_dyn_mle_max_threads: 2\n"
          "init_dyn_num_pose: 6\ninit_dyn_min_deg: 10.0\ninit_dyn_inflation_ori: 10\n"
          "init_dyn_inflation_vel: 100\ninit_dyn_inflation_bg: 10\ninit_dyn_inflation_ba: 100\n"
          "init_dyn_min_rec_cond: 1e-12\ninit_dyn_bias_g: [0.0, 0.0, 0.0]\n"
          "init_dyn_bias_a: [0.0, 0.0, 0.0]\n\nrecord_timing_information: false\n"
          "record_timing_filepath: \"/tmp/traj_timing.txt\"\n\nsave_total_state: false\n"
          "filepath_est: \"/tmp/ov_estimate.txt\"\nfilepath_std: \"/tmp/ov_estimate_std.txt\"\n"
          "filepath_gt: \"/tmp/ov_groundtruth.txt\"\n\nuse_klt: true\nnum_pts: 200\n"
          "fast_threshold: 20\ngrid_x: 5\ngrid_y: 5\nmin_px_dist: 10\nknn_ratio: 0.70\n"
          "track_frequency: " +
          number(std::round(cameraRateHz(context))) +
          "\ndownsample_cameras: false\nnum_opencv_threads: 2\n"
          "histogram_method: \"HISTOGRAM\"\n\nuse_aruco: false\nnum_aruco: 1024\n"
          "downsize_aruco: true\n\nup_msckf_sigma_px: 1\nup_msckf_chi2_multipler: 1\n"
          "up_slam_sigma_px: 1\nup_slam_chi2_multipler: 1\nup_aruco_sigma_px: 1\n"
          "up_aruco_chi2_multipler: 1\n\nuse_mask: false\n\n"
          "relative_config_imu: \"kalibr_imu_chain.yaml\"\n"
          "relative_config_imucam: \"kalibr_imucam_chain.yaml\"\n");
}

void writeEuroc(Context& context) {
  const fs::path mav = context.out / "mav0";
  const auto& info = context.calibration.info;
  auto& notes = context.summary.notes;
  const core::Axes axes = context.options.axes;
  const bool enu = axes == core::Axes::kEnu;
  const std::string body = enu ? "FLU" : "FRD";
  const std::string world = enu ? "local ENU" : "local NED";

  // cam0
  {
    TextFile csv(mav / "cam0" / "data.csv");
    csv << "#timestamp [ns],filename\n";
    for (const ImageRecord& image : context.images)
      csv << nanosecondsText(image.utime) + "," + image.file + "\n";
    csv.close();
    std::string model = "radial-tangential";
    std::vector<double> coefficients;
    if (info.distortion_model == msg::Distortion::EQUIDISTANT) {
      model = "equidistant";
      coefficients = firstCoefficients(info, 4, "EuRoC's equidistant model", notes);
    } else {
      coefficients = firstCoefficients(info, 4, "EuRoC's radial-tangential model", notes);
    }
    writeText(mav / "cam0" / "sensor.yaml",
              "# " + sourceLine(context) +
                  "\n# General sensor definitions.\nsensor_type: camera\ncomment: nadir camera '" +
                  info.camera_name + "' on " + context.options.camera_channel +
                  "\n\n# Sensor extrinsics wrt. the body-frame: T_body_cam, body " + body +
                  " (= imu0), camera OpenCV optical.\nT_BS:\n" +
                  yamlMatrix(core::bodyToSensorIn(axes, context.calibration.T_body_cam), "  ") +
                  "\n# Camera specific definitions.\nrate_hz: " + number(cameraRateHz(context)) +
                  "\nresolution: [" + std::to_string(info.width) + ", " +
                  std::to_string(info.height) + "]\ncamera_model: pinhole\nintrinsics: [" +
                  number(info.fx) + ", " + number(info.fy) + ", " + number(info.cx) + ", " +
                  number(info.cy) + "] #fu, fv, cu, cv\ndistortion_model: " + model +
                  "\ndistortion_coefficients: " + listOf(coefficients) + "\n");
  }

  // imu0: the IMU frame is the body frame.
  {
    createFolder(mav / "imu0");
    TextFile csv(mav / "imu0" / "data.csv");
    csv << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
           "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
    for (const msg::Imu& s : context.scan.imu) {
      const Eigen::Vector3d w = core::bodyVectorIn(axes, s.angular_velocity_rps);
      const Eigen::Vector3d a = core::bodyVectorIn(axes, s.linear_acceleration_mps2);
      csv << nanosecondsText(s.utime) + "," + number(w.x()) + "," + number(w.y()) + "," +
                 number(w.z()) + "," + number(a.x()) + "," + number(a.y()) + "," + number(a.z()) +
                 "\n";
      ++context.summary.imu_samples;
    }
    csv.close();
    writeText(mav / "imu0" / "sensor.yaml",
              "# " + sourceLine(context) + ", IMU from " + context.options.imu_channel +
                  "\n#Default imu sensor yaml file\nsensor_type: imu\ncomment: nadir IMU, body " +
                  body + ", specific force (a level vehicle at rest reads 0, 0, " +
                  (enu ? "9.81" : "-9.81") +
                  ")\n\n"
                  "# Sensor extrinsics wrt. the body-frame.\nT_BS:\n" +
                  yamlMatrix(Eigen::Isometry3d::Identity(), "  ") +
                  "rate_hz: " + number(medianRateHz(context.scan.imu)) + "\n\n" +
                  imuNoiseYaml(context.options.imu_noise));
    if (context.scan.imu.empty()) {
      notes.push_back("no imu_t on " + context.options.imu_channel +
                      ": mav0/imu0/data.csv has only its header");
    }
  }

  // state_groundtruth_estimate0: the body at the truth rate.
  {
    createFolder(mav / "state_groundtruth_estimate0");
    TextFile csv(mav / "state_groundtruth_estimate0" / "data.csv");
    csv << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
           "q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
           "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
           "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
    for (const msg::Pose& s : context.scan.truth) {
      const Eigen::Vector3d p = core::worldVectorIn(axes, s.p_ned_m);
      const Eigen::Quaterniond q = core::attitudeIn(axes, s.q_world_body, core::BodyAxes::kVehicle);
      const Eigen::Vector3d v = core::worldVectorIn(axes, s.v_ned_mps);
      csv << nanosecondsText(s.utime) + "," + number(p.x()) + "," + number(p.y()) + "," +
                 number(p.z()) + "," + number(q.w()) + "," + number(q.x()) + "," + number(q.y()) +
                 "," + number(q.z()) + "," + number(v.x()) + "," + number(v.y()) + "," +
                 number(v.z()) + ",0,0,0,0,0,0\n";
      ++context.summary.poses;
    }
    csv.close();
    writeText(mav / "state_groundtruth_estimate0" / "sensor.yaml",
              "# " + sourceLine(context) + ", truth from " + context.options.truth_channel +
                  "\nsensor_type: visual-inertial\ncomment: nadir simulator truth: the body (" +
                  body + ", = imu0) in the world (" + world +
                  "); biases are not logged and are written as 0\n\n# Sensor extrinsics wrt. the "
                  "body-frame.\nT_BS:\n" +
                  yamlMatrix(Eigen::Isometry3d::Identity(), "  "));
  }

  writeText(
      mav / "body.yaml",
      "# " + sourceLine(context) +
          (enu ? "\ncomment: the body frame is FLU (x forward, y left, z up: REP-103; nadir's "
                 "FRD body turned about x), which is also the IMU frame (imu0)\n"
               : "\ncomment: the body frame is nadir's FRD body frame (x forward, y right, z "
                 "down), which is also the IMU frame (imu0)\n"));

  writeText(context.out / "orbslam3.yaml", orbSlam3Settings(context));
  if (context.options.imu_noise) {
    writeOpenVins(context, *context.options.imu_noise);
  } else {
    notes.push_back(
        "the IMU's noise is not known (no scenario.yaml beside the log): orbslam3.yaml is "
        "monocular only, imu0/sensor.yaml has no noise figures and no openvins/ is written");
  }

  // One timestamp per line, as ORB-SLAM3's EuRoC examples take them.
  {
    TextFile times(context.out / "timestamps.txt");
    for (const ImageRecord& image : context.images) times << nanosecondsText(image.utime) + "\n";
    times.close();
  }

  writeText(
      context.out / "README.md",
      framesReadme(
          context,
          "EuRoC MAV (ASL) layout:\n\n"
          "```\nmav0/cam0/data/<timestamp_ns>.png   images\n"
          "mav0/cam0/data.csv                  #timestamp [ns],filename\n"
          "mav0/cam0/sensor.yaml               T_BS (= T_body_cam), rate_hz, resolution, "
          "intrinsics, distortion\n"
          "mav0/imu0/data.csv                  timestamp [ns], gyro (rad/s), specific force "
          "(m/s^2), body " +
              body +
              "\n"
              "mav0/state_groundtruth_estimate0/data.csv   timestamp [ns], p, q (w x y z), v, "
              "b_w, b_a\n"
              "timestamps.txt                      image timestamps [ns], one a line "
              "(ORB-SLAM3's EuRoC_TimeStamps)\n```\n\n"
              "Timestamps are the messages' utime in nanoseconds (utime * 1000): sim time, "
              "from 0 at the start of a simulated run.",
          "Ground truth (state_groundtruth_estimate0) is the body, T_world_body, at the "
          "truth rate; velocity in the world frame; biases are not logged and are 0. "
          "The body frame is the IMU frame (imu0's T_BS is the identity) and cam0's T_BS "
          "is T_body_cam."));
}

std::string dsoCalibration(const Context& context) {
  const auto& info = context.calibration.info;
  const std::string size = std::to_string(info.width) + " " + std::to_string(info.height) + "\n";
  const std::string k =
      number(info.fx) + " " + number(info.fy) + " " + number(info.cx) + " " + number(info.cy);
  auto& notes = context.summary.notes;
  switch (info.distortion_model) {
    case msg::Distortion::RADTAN: {
      const auto d = firstCoefficients(info, 4, "DSO's RadTan model", notes);
      // "crop": DSO undistorts to a pinhole image of the same size ("none" would skip that).
      return "RadTan " + k + " " + number(d[0]) + " " + number(d[1]) + " " + number(d[2]) + " " +
             number(d[3]) + "\n" + size + "crop\n" + size;
    }
    case msg::Distortion::EQUIDISTANT: {
      const auto d = firstCoefficients(info, 4, "DSO's EquiDistant model", notes);
      return "EquiDistant " + k + " " + number(d[0]) + " " + number(d[1]) + " " + number(d[2]) +
             " " + number(d[3]) + "\n" + size + "crop\n" + size;
    }
    default:
      return "Pinhole " + k + " 0\n" + size + "none\n" + size;
  }
}

void writeTumMono(Context& context) {
  TextFile times(context.out / "times.txt");
  for (std::size_t i = 0; i < context.images.size(); ++i) {
    char index[32];
    std::snprintf(index, sizeof(index), "%05zu", i);
    times << std::string(index) + " " + secondsText(context.images[i].utime) + " " +
                 number(context.images[i].exposure_ms) + "\n";
  }
  times.close();
  writeText(context.out / "camera.txt", dsoCalibration(context));
  writeTumTrajectory(context, context.out / "groundtruth.txt");
  writeText(context.out / "README.md",
            framesReadme(context,
                         "TUM monocular layout (DSO's dataset reader):\n\n"
                         "```\nimages/00000.png ...   images in time order\n"
                         "times.txt              index timestamp [s] exposure [ms] (0: unknown)\n"
                         "camera.txt             DSO calibration: model fx fy cx cy [coefficients]"
                         " / input w h / crop|none / output w h\n"
                         "groundtruth.txt        timestamp [s] tx ty tz qx qy qz qw\n```\n\n"
                         "Run DSO with files=images calib=camera.txt mode=1 (no photometric "
                         "calibration). Timestamps are the messages' utime in seconds with six "
                         "decimals: sim time, from 0 at the start of a simulated run.",
                         "Ground truth (groundtruth.txt) is the camera, T_world_cam = T_world_body "
                         "* T_body_cam, at each image time (linear position, SLERP orientation "
                         "between the truth samples around it), as DSO's result.txt reports "
                         "camera poses."));
}

void writeTum(Context& context) {
  TextFile list(context.out / "rgb.txt");
  list << "# color images\n# " + sourceLine(context) + "\n# timestamp filename\n";
  for (const ImageRecord& image : context.images)
    list << secondsText(image.utime) + " " + image.file + "\n";
  list.close();
  const auto& info = context.calibration.info;
  std::vector<double> d;
  if (info.distortion_model == msg::Distortion::EQUIDISTANT) {
    d = firstCoefficients(info, 4, "equidistant", context.summary.notes);
    d.push_back(0.0);
    context.summary.notes.push_back(
        "calibration.txt: the camera is equidistant (k1 k2 k3 k4), not TUM's radial-tangential");
  } else {
    d = firstCoefficients(info, 5, "TUM's calibration line", context.summary.notes);
  }
  writeText(
      context.out / "calibration.txt",
      "# " + sourceLine(context) + "\n# " + std::to_string(info.width) + "x" +
          std::to_string(info.height) + " px; model " +
          (info.distortion_model == msg::Distortion::EQUIDISTANT ? "equidistant"
                                                                 : "radial-tangential (OpenCV)") +
          "\n# fx fy cx cy d0 d1 d2 d3 d4\n" + number(info.fx) + " " + number(info.fy) + " " +
          number(info.cx) + " " + number(info.cy) + " " + number(d[0]) + " " + number(d[1]) + " " +
          number(d[2]) + " " + number(d[3]) + " " + number(d[4]) + "\n");
  writeTumTrajectory(context, context.out / "groundtruth.txt");
  writeText(context.out / "README.md",
            framesReadme(context,
                         "TUM RGB-D layout (colour only; evo's tum trajectory format):\n\n"
                         "```\nrgb/<timestamp>.png   images\n"
                         "rgb.txt               timestamp [s] filename\n"
                         "groundtruth.txt       timestamp [s] tx ty tz qx qy qz qw\n"
                         "calibration.txt       fx fy cx cy d0 d1 d2 d3 d4 (TUM's table)\n```\n\n"
                         "Timestamps are the messages' utime in seconds with six decimals: sim "
                         "time, from 0 at the start of a simulated run.",
                         "Ground truth (groundtruth.txt) is the camera's optical centre and "
                         "orientation, T_world_cam = T_world_body * T_body_cam, as in TUM RGB-D, "
                         "at each image time (linear position, SLERP orientation between the "
                         "truth samples around it)."));
}

// ------------------------------------------------------------------ images

void writeImages(Context& context, const Layout& layout) {
  createFolder(layout.image_dir);
  auto reader = openLog(context.options.log_path);
  const auto& info = context.calibration.info;
  std::int64_t undecodable = 0;
  std::int64_t out_of_order = 0;
  std::int64_t wrong_size = 0;
  std::optional<std::int64_t> last_utime;
  std::string first_error;
  try {
    while (auto event = reader->next()) {
      if (event->channel != context.options.camera_channel) continue;
      if (!msg::isType<msg::Image>(event->data.data(), event->data.size())) continue;
      msg::Image message;
      try {
        message = msg::decode<msg::Image>(event->data);
      } catch (const msg::DecodeError& error) {
        if (first_error.empty()) {
          first_error = "event " + std::to_string(event->event_number) + ": " + error.what();
        }
        ++undecodable;
        continue;
      } catch (const msg::InvalidMessage& error) {
        if (first_error.empty()) first_error = error.what();
        ++undecodable;
        continue;
      }
      cv::Mat& pixels = message.pixels;
      // Every layout needs strictly increasing times (EuRoC and TUM name files by them).
      if (last_utime && message.utime <= *last_utime) {
        ++out_of_order;
        continue;
      }
      last_utime = message.utime;
      if (pixels.cols != info.width || pixels.rows != info.height) ++wrong_size;
      const auto index = static_cast<std::int64_t>(context.images.size());
      const std::string name = layout.name(message.utime, index);
      const fs::path path = layout.image_dir / name;
      if (pixels.channels() == 3) cv::cvtColor(pixels, pixels, cv::COLOR_RGB2BGR);
      bool written = false;
      try {
        written = cv::imwrite(path.string(), pixels);
      } catch (const cv::Exception& error) {
        throw ExportError("cannot write " + path.string() + ": " + error.what());
      }
      if (!written) throw ExportError("cannot write " + path.string());
      ImageRecord record;
      record.utime = message.utime;
      record.file = context.options.format == Format::kTum ? "rgb/" + name : name;
      record.exposure_ms = exposureMs(message);
      context.images.push_back(record);
      ++context.summary.images;
      if (context.options.progress)
        context.options.progress(context.summary.images, context.scan.camera_images);
    }
  } catch (const core::LogError& error) {
    throw ExportError(error.what());
  }
  auto& notes = context.summary.notes;
  if (undecodable > 0) {
    notes.push_back(plural(undecodable, "image") + " on " + context.options.camera_channel +
                    " did not decode and were skipped (first: " + first_error + ")");
  }
  if (out_of_order > 0) {
    notes.push_back(plural(out_of_order, "image") + " on " + context.options.camera_channel +
                    " had a utime not after the previous image's and were skipped");
  }
  if (wrong_size > 0) {
    notes.push_back(plural(wrong_size, "image") + " differ in size from the camera_info_t's " +
                    std::to_string(info.width) + "x" + std::to_string(info.height));
  }
}

void checkOutputFolder(const fs::path& out) {
  std::error_code error;
  if (!fs::exists(out, error)) return;
  if (!fs::is_directory(out, error)) {
    throw ExportError(out.string() + " exists and is not a folder: refusing to overwrite it");
  }
  if (!fs::is_empty(out, error)) {
    throw ExportError("output folder " + out.string() +
                      " exists and is not empty: refusing to overwrite it (remove it or choose "
                      "another output folder)");
  }
}

}  // namespace

Format parseFormat(const std::string& name) {
  if (name == "euroc") return Format::kEuroc;
  if (name == "tum-mono") return Format::kTumMono;
  if (name == "tum") return Format::kTum;
  throw std::invalid_argument("unknown export format '" + name + "' (known: euroc, tum-mono, tum)");
}

std::string formatName(Format format) {
  switch (format) {
    case Format::kEuroc:
      return "euroc";
    case Format::kTumMono:
      return "tum-mono";
    case Format::kTum:
      return "tum";
  }
  return "unknown";
}

ExportSummary exportRun(const ExportOptions& options) {
  const fs::path log_path(options.log_path);
  std::error_code error;
  if (options.log_path.empty()) throw ExportError("no LCM log given");
  if (!fs::exists(log_path, error)) throw ExportError("no LCM log at " + options.log_path);
  if (fs::is_directory(log_path, error)) {
    throw ExportError(options.log_path + " is a folder, not an LCM log");
  }
  if (options.out_dir.empty()) throw ExportError("no output folder given");
  if (options.camera_channel.empty()) throw ExportError("no camera channel given");
  const fs::path out(options.out_dir);
  checkOutputFolder(out);
  const std::string info_channel =
      options.info_channel.empty() ? options.camera_channel + "_INFO" : options.info_channel;

  const Scan scan = scanLog(options, info_channel);
  if (scan.camera_images == 0) {
    std::string message = options.log_path + ": no image_t on channel " + options.camera_channel;
    if (scan.camera_other_messages > 0) {
      message +=
          " (it carries " + plural(scan.camera_other_messages, "message") + " of another type)";
    }
    if (!scan.image_channels.empty()) {
      message += "; channels with image_t: " + channelList(scan.image_channels, "image");
    } else {
      message += "; no channel in the log carries image_t";
      if (!scan.all_channels.empty()) {
        message += " (channels: " + channelList(scan.all_channels, "message") + ")";
      }
    }
    throw ExportError(message);
  }
  if (!scan.calibration) {
    std::string message = options.log_path + ": no camera_info_t on " + info_channel +
                          " (the dataset's calibration comes from it)";
    if (scan.undecodable.contains(info_channel)) {
      message += "; " + plural(scan.undecodable.at(info_channel), "message") + " there " +
                 "did not decode as a valid camera_info_t";
    }
    if (!scan.info_channels.empty()) {
      message += "; channels with camera_info_t: " + channelList(scan.info_channels, "message");
    }
    throw ExportError(message);
  }

  createFolder(out);
  ExportSummary summary;
  summary.out_dir = options.out_dir;
  summary.damage = scan.damage;
  Context context{options, scan, *scan.calibration, out, {}, summary};
  writeImages(context, layoutFor(options.format, out));
  switch (options.format) {
    case Format::kEuroc:
      writeEuroc(context);
      break;
    case Format::kTumMono:
      writeTumMono(context);
      break;
    case Format::kTum:
      writeTum(context);
      break;
  }

  auto& notes = summary.notes;
  if (scan.calibration_changed_utime) {
    notes.push_back("the camera_info_t on " + info_channel + " changed at utime " +
                    std::to_string(*scan.calibration_changed_utime) +
                    "; the export's calibration is the first one");
  }
  if (scan.truth.empty()) {
    notes.push_back("no pose_t on " + options.truth_channel + ": no ground truth written");
  }
  if (scan.truth_duplicates > 0) {
    notes.push_back(plural(scan.truth_duplicates, "pose_t") + " on " + options.truth_channel +
                    " repeated an earlier time and were dropped");
  }
  if (scan.imu_duplicates > 0 && options.format == Format::kEuroc) {
    notes.push_back(plural(scan.imu_duplicates, "imu_t") + " on " + options.imu_channel +
                    " repeated an earlier time and were dropped");
  }
  for (const auto& [channel, count] : scan.undecodable) {
    if (channel == info_channel && scan.calibration) continue;
    notes.push_back(plural(count, "message") + " on " + channel +
                    " did not decode (or held non-finite values) and were skipped");
  }
  return summary;
}

}  // namespace nadir::dataset
