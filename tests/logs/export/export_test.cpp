// nadir export: a synthetic run.lcmlog with known pixels, calibration, truth and
// IMU is exported in each format and the folders are read back.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/core.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/bus.h"
#include "core/frames.h"
#include "core/lcm_log.h"
#include "core/trajectory.h"
#include "logs/export/export.h"
#include "nadir/camera_info_t.hpp"
#include "nadir/image_t.hpp"
#include "nadir/imu_t.hpp"
#include "nadir/pose_t.hpp"
#include "tests/support/lcm_messages.h"

namespace nadir::dataset {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 64;
constexpr int kHeight = 48;
constexpr int kGrayImages = 4;
constexpr std::int64_t kFirstImageUtime = 12'345;
constexpr std::int64_t kImagePeriodUs = 50'000;
constexpr std::int64_t kTruthPeriodUs = 2'500;  // 400 Hz
constexpr std::int64_t kTruthEndUs = 300'000;
constexpr std::int64_t kImuPeriodUs = 5'000;  // 200 Hz
constexpr double kRoll = 0.1;
// Event timestamps are a receive clock far from the messages' utime: the export must not use them.
constexpr std::int64_t kEventClockOffsetUs = 1'700'000'000'000'000;

// The known trajectory: a straight climbing line, constant roll, yaw turning at 0.5 rad/s.
Eigen::Vector3d truthPosition(double t_s) { return {10.0 * t_s, 2.0 * t_s, -100.0 - 1.0 * t_s}; }
Eigen::Quaterniond truthOrientation(double t_s) {
  return core::quaternionFromRpy({.roll_rad = kRoll, .pitch_rad = 0.0, .yaw_rad = 0.5 * t_s});
}
Eigen::Isometry3d truthPose(double t_s) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = truthOrientation(t_s).toRotationMatrix();
  T.translation() = truthPosition(t_s);
  return T;
}

Eigen::Isometry3d bodyFromCamera() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = core::rotationBodyFromDownCamera();
  T.translation() = Eigen::Vector3d(0.1, 0.0, 0.05);
  return T;
}

std::int64_t imageUtime(int k) { return kFirstImageUtime + k * kImagePeriodUs; }

cv::Mat grayPattern(int k) {
  cv::Mat image(kHeight, kWidth, CV_8UC1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      image.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((3 * x + 5 * y + 40 * k) % 256);
  return image;
}

// Smooth, so JPEG keeps it within a few grey levels.
cv::Mat jpegPattern() {
  cv::Mat image(kHeight, kWidth, CV_8UC1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      image.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(60 + 2 * x + y);
  return image;
}

nadir::image_t grayMessage(const cv::Mat& pixels, std::int64_t utime) {
  nadir::image_t message{};
  message.utime = utime;
  message.width = pixels.cols;
  message.height = pixels.rows;
  message.row_stride = pixels.cols * pixels.channels();
  message.pixelformat = pixels.channels() == 1 ? std::int32_t{nadir::image_t::PIXEL_FORMAT_GRAY}
                                               : std::int32_t{nadir::image_t::PIXEL_FORMAT_RGB};
  message.data.assign(pixels.data, pixels.data + pixels.total() * pixels.elemSize());
  message.size = static_cast<std::int32_t>(message.data.size());
  return message;
}

nadir::image_t jpegMessage(const cv::Mat& pixels, std::int64_t utime) {
  nadir::image_t message{};
  message.utime = utime;
  message.width = pixels.cols;
  message.height = pixels.rows;
  message.pixelformat = nadir::image_t::PIXEL_FORMAT_MJPEG;
  cv::imencode(".jpg", pixels, message.data, {cv::IMWRITE_JPEG_QUALITY, 95});
  message.size = static_cast<std::int32_t>(message.data.size());
  return message;
}

nadir::camera_info_t cameraInfo() {
  nadir::camera_info_t info{};
  info.utime = 0;
  info.camera_name = "down";
  info.width = kWidth;
  info.height = kHeight;
  info.fx = 50.0;
  info.fy = 51.0;
  info.cx = 31.5;
  info.cy = 23.5;
  info.distortion_model = nadir::camera_info_t::DISTORTION_RADTAN;
  info.distortion = {0.01, -0.002, 0.0005, -0.0003, 0.0};
  info.num_distortion = 5;
  info.fps = 20.0;
  const Eigen::Isometry3d T = bodyFromCamera();
  for (int i = 0; i < 3; ++i) info.position_cam_in_body_m[i] = T.translation()[i];
  core::quaternionToWire(Eigen::Quaterniond(T.rotation()), info.orientation_body_cam);
  return info;
}

nadir::pose_t truthMessage(std::int64_t utime) {
  const double t = static_cast<double>(utime) * 1e-6;
  nadir::pose_t pose{};
  pose.utime = utime;
  const Eigen::Vector3d p = truthPosition(t);
  for (int i = 0; i < 3; ++i) pose.pos[i] = p[i];
  pose.vel[0] = 10.0;
  pose.vel[1] = 2.0;
  pose.vel[2] = -1.0;
  core::quaternionToWire(truthOrientation(t), pose.orientation);
  return pose;
}

nadir::imu_t imuMessage(std::int64_t utime) {
  nadir::imu_t imu{};
  imu.utime = utime;
  imu.angular_velocity_rps[2] = 0.5;
  imu.linear_acceleration_mps2[0] = static_cast<double>(utime) * 1e-6;
  imu.linear_acceleration_mps2[2] = -9.81;
  return imu;
}

struct LogContents {
  bool images = true;
  std::string camera_channel = "CAMERA_DOWN";
  bool camera_info = true;
};

template <class Msg>
void writeMessage(core::LcmLogWriter& writer, const std::string& channel, const Msg& message) {
  const std::vector<std::uint8_t> bytes = ::nadir::test::encodeMessage(message);
  writer.write(message.utime + kEventClockOffsetUs, channel, bytes.data(), bytes.size());
}

// Writes the synthetic run in time order. Returns the file size after each image event.
std::vector<std::int64_t> writeRun(const fs::path& path, const LogContents& contents = {}) {
  std::vector<std::int64_t> size_after_image;
  core::LcmLogWriter writer(path.string());
  if (contents.camera_info) writeMessage(writer, contents.camera_channel + "_INFO", cameraInfo());
  int next_image = 0;
  for (std::int64_t t = 0; t <= kTruthEndUs; t += kTruthPeriodUs) {
    writeMessage(writer, "POSE_TRUTH", truthMessage(t));
    if (t % kImuPeriodUs == 0) writeMessage(writer, "IMU", imuMessage(t));
    while (contents.images && next_image <= kGrayImages && imageUtime(next_image) <= t) {
      const std::int64_t utime = imageUtime(next_image);
      writeMessage(writer, contents.camera_channel,
                   next_image < kGrayImages ? grayMessage(grayPattern(next_image), utime)
                                            : jpegMessage(jpegPattern(), utime));
      writer.flush();
      size_after_image.push_back(static_cast<std::int64_t>(fs::file_size(path)));
      ++next_image;
    }
  }
  writer.flush();
  return size_after_image;
}

constexpr int kTruthSamples = static_cast<int>(kTruthEndUs / kTruthPeriodUs) + 1;
constexpr int kImuSamples = static_cast<int>(kTruthEndUs / kImuPeriodUs) + 1;
constexpr int kImages = kGrayImages + 1;

std::vector<std::string> readLines(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<double> numbers(std::string line, char separator) {
  for (char& c : line)
    if (c == separator) c = ' ';
  std::istringstream in(line);
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

std::set<std::string> filesIn(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename());
  return names;
}

std::string secondsText(std::int64_t utime) {
  char text[32];
  std::snprintf(text, sizeof(text), "%lld.%06lld", static_cast<long long>(utime / 1'000'000),
                static_cast<long long>(utime % 1'000'000));
  return text;
}

// The exported image k equals the source pixels (JPEG: within its loss).
void expectImage(const fs::path& path, int k) {
  const cv::Mat read = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(read.empty()) << path;
  ASSERT_EQ(read.type(), CV_8UC1) << path;
  ASSERT_EQ(read.cols, kWidth);
  ASSERT_EQ(read.rows, kHeight);
  if (k < kGrayImages) {
    EXPECT_EQ(cv::norm(read, grayPattern(k), cv::NORM_INF), 0.0) << path;
  } else {
    EXPECT_LE(cv::norm(read, jpegPattern(), cv::NORM_INF), 6.0) << path;
    EXPECT_LE(cv::norm(read, jpegPattern(), cv::NORM_L1) / (kWidth * kHeight), 1.5) << path;
  }
}

// A TUM trajectory line "t tx ty tz qx qy qz qw" against the camera's known pose at t.
void expectCameraPoseLine(const std::string& line, std::int64_t utime) {
  const std::vector<double> v = numbers(line, ' ');
  ASSERT_EQ(v.size(), 8u) << line;
  EXPECT_EQ(line.substr(0, line.find(' ')), secondsText(utime));
  const Eigen::Isometry3d expected =
      truthPose(static_cast<double>(utime) * 1e-6) * bodyFromCamera();
  EXPECT_NEAR(v[1], expected.translation().x(), 1e-9) << line;
  EXPECT_NEAR(v[2], expected.translation().y(), 1e-9) << line;
  EXPECT_NEAR(v[3], expected.translation().z(), 1e-9) << line;
  const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
  EXPECT_NEAR(q.angularDistance(Eigen::Quaterniond(expected.rotation())), 0.0, 1e-9) << line;
}

class ExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() /
            ("nadir_dataset_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    log_ = root_ / "run.lcmlog";
  }
  void TearDown() override { fs::remove_all(root_); }

  ExportSummary exportAs(Format format, const std::string& out_name) {
    ExportOptions options;
    options.log_path = log_.string();
    options.out_dir = (root_ / out_name).string();
    options.format = format;
    return exportRun(options);
  }

  fs::path root_;
  fs::path log_;
};

// EuRoC: source-equal PNGs, ns data.csv, sensor.yaml intrinsics and T_BS, IMU, body truth.
TEST_F(ExportTest, EurocWritesImagesCalibrationImuAndBodyTruth) {
  writeRun(log_);
  const ExportSummary summary = exportAs(Format::kEuroc, "euroc");
  EXPECT_EQ(summary.images, kImages);
  EXPECT_EQ(summary.poses, kTruthSamples);
  EXPECT_EQ(summary.imu_samples, kImuSamples);
  EXPECT_TRUE(summary.damage.empty()) << summary.damage;
  const fs::path mav = root_ / "euroc" / "mav0";

  const std::vector<std::string> csv = readLines(mav / "cam0" / "data.csv");
  ASSERT_EQ(csv.size(), static_cast<std::size_t>(kImages + 1));
  EXPECT_EQ(csv[0], "#timestamp [ns],filename");
  std::set<std::string> expected_files;
  for (int k = 0; k < kImages; ++k) {
    const std::string ns = std::to_string(imageUtime(k) * 1000);
    EXPECT_EQ(csv[static_cast<std::size_t>(k) + 1], ns + "," + ns + ".png");
    expected_files.insert(ns + ".png");
    expectImage(mav / "cam0" / "data" / (ns + ".png"), k);
  }
  EXPECT_EQ(filesIn(mav / "cam0" / "data"), expected_files);
  EXPECT_EQ(readLines(root_ / "euroc" / "timestamps.txt").front(),
            std::to_string(kFirstImageUtime * 1000));

  const std::string yaml = readText(mav / "cam0" / "sensor.yaml");
  EXPECT_NE(yaml.find("intrinsics: [50, 51, 31.5, 23.5]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("resolution: [64, 48]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("camera_model: pinhole"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("distortion_model: radial-tangential"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("distortion_coefficients: [0.01, -0.002, 0.0005, -0.0003]"),
            std::string::npos)
      << yaml;
  EXPECT_NE(yaml.find("rate_hz: 20"), std::string::npos) << yaml;
  const std::size_t data_at = yaml.find("data: [");
  ASSERT_NE(data_at, std::string::npos);
  const std::string matrix_text = yaml.substr(data_at + 7, yaml.find(']', data_at) - data_at - 7);
  const std::vector<double> m = numbers(matrix_text, ',');
  ASSERT_EQ(m.size(), 16u) << matrix_text;
  const Eigen::Matrix4d expected_T = bodyFromCamera().matrix();
  for (int i = 0; i < 16; ++i)
    EXPECT_NEAR(m[static_cast<std::size_t>(i)], expected_T(i / 4, i % 4), 1e-12);

  const std::vector<std::string> imu = readLines(mav / "imu0" / "data.csv");
  ASSERT_EQ(imu.size(), static_cast<std::size_t>(kImuSamples + 1));
  const std::vector<double> imu3 = numbers(imu[4], ',');  // sample 3, at 15 ms
  ASSERT_EQ(imu3.size(), 7u);
  EXPECT_EQ(imu3[0], 15'000'000.0);
  EXPECT_DOUBLE_EQ(imu3[3], 0.5);
  EXPECT_DOUBLE_EQ(imu3[4], 0.015);
  EXPECT_DOUBLE_EQ(imu3[6], -9.81);

  const std::vector<std::string> truth =
      readLines(mav / "state_groundtruth_estimate0" / "data.csv");
  ASSERT_EQ(truth.size(), static_cast<std::size_t>(kTruthSamples + 1));
  EXPECT_EQ(truth[0].rfind("#timestamp, p_RS_R_x [m]", 0), 0u);
  for (int i : {0, 7, kTruthSamples - 1}) {
    const std::vector<double> row = numbers(truth[static_cast<std::size_t>(i) + 1], ',');
    ASSERT_EQ(row.size(), 17u);
    const double t = i * kTruthPeriodUs * 1e-6;
    EXPECT_EQ(row[0], static_cast<double>(i * kTruthPeriodUs * 1000));
    const Eigen::Vector3d p = truthPosition(t);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(row[1 + static_cast<std::size_t>(j)], p[j], 1e-9);
    const Eigen::Quaterniond q(row[4], row[5], row[6], row[7]);  // w x y z
    EXPECT_NEAR(q.angularDistance(truthOrientation(t)), 0.0, 1e-9);
    EXPECT_EQ(row[8], 10.0);
    EXPECT_EQ(row[9], 2.0);
    EXPECT_EQ(row[10], -1.0);
  }
  EXPECT_TRUE(fs::exists(root_ / "euroc" / "README.md"));
}

// TUM mono: images/NNNNN.png, times.txt, DSO camera.txt, camera truth at the image times.
TEST_F(ExportTest, TumMonoWritesDsoLayoutAndInterpolatedCameraTruth) {
  writeRun(log_);
  const ExportSummary summary = exportAs(Format::kTumMono, "tum_mono");
  EXPECT_EQ(summary.images, kImages);
  EXPECT_EQ(summary.poses, kImages);
  const fs::path out = root_ / "tum_mono";
  std::set<std::string> expected_files;
  const std::vector<std::string> times = readLines(out / "times.txt");
  ASSERT_EQ(times.size(), static_cast<std::size_t>(kImages));
  for (int k = 0; k < kImages; ++k) {
    char name[16];
    std::snprintf(name, sizeof(name), "%05d", k);
    expected_files.insert(std::string(name) + ".png");
    EXPECT_EQ(times[static_cast<std::size_t>(k)],
              std::string(name) + " " + secondsText(imageUtime(k)) + " 0");
    expectImage(out / "images" / (std::string(name) + ".png"), k);
  }
  EXPECT_EQ(filesIn(out / "images"), expected_files);
  EXPECT_EQ(readLines(out / "camera.txt"),
            (std::vector<std::string>{"RadTan 50 51 31.5 23.5 0.01 -0.002 0.0005 -0.0003", "64 48",
                                      "crop", "64 48"}));
  std::vector<std::string> truth = readLines(out / "groundtruth.txt");
  std::erase_if(truth, [](const std::string& line) { return line.starts_with("#"); });
  ASSERT_EQ(truth.size(), static_cast<std::size_t>(kImages));
  for (int k = 0; k < kImages; ++k)
    expectCameraPoseLine(truth[static_cast<std::size_t>(k)], imageUtime(k));
}

// TUM RGB-D: rgb/<s>.png, rgb.txt, calibration line, camera truth at the image times.
TEST_F(ExportTest, TumWritesRgbListCalibrationAndCameraTruth) {
  writeRun(log_);
  const ExportSummary summary = exportAs(Format::kTum, "tum");
  EXPECT_EQ(summary.images, kImages);
  EXPECT_EQ(summary.poses, kImages);
  EXPECT_EQ(summary.imu_samples, 0);
  const fs::path out = root_ / "tum";
  std::vector<std::string> list = readLines(out / "rgb.txt");
  std::erase_if(list, [](const std::string& line) { return line.starts_with("#"); });
  ASSERT_EQ(list.size(), static_cast<std::size_t>(kImages));
  std::set<std::string> expected_files;
  for (int k = 0; k < kImages; ++k) {
    const std::string seconds = secondsText(imageUtime(k));
    EXPECT_EQ(list[static_cast<std::size_t>(k)], seconds + " rgb/" + seconds + ".png");
    expected_files.insert(seconds + ".png");
    expectImage(out / "rgb" / (seconds + ".png"), k);
  }
  EXPECT_EQ(filesIn(out / "rgb"), expected_files);
  std::vector<std::string> truth = readLines(out / "groundtruth.txt");
  std::erase_if(truth, [](const std::string& line) { return line.starts_with("#"); });
  ASSERT_EQ(truth.size(), static_cast<std::size_t>(kImages));
  for (int k = 0; k < kImages; ++k)
    expectCameraPoseLine(truth[static_cast<std::size_t>(k)], imageUtime(k));
  std::vector<std::string> calibration = readLines(out / "calibration.txt");
  std::erase_if(calibration, [](const std::string& line) { return line.starts_with("#"); });
  EXPECT_EQ(calibration,
            (std::vector<std::string>{"50 51 31.5 23.5 0.01 -0.002 0.0005 -0.0003 0"}));
}

// REP-103's axes, written out by hand: R_enu_ned swaps north and east and turns
// down into up; R_frd_flu turns left into right and up into down.
Eigen::Matrix3d enuFromNed() {
  Eigen::Matrix3d R;
  R << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  return R;
}
Eigen::Matrix3d frdFromFlu() { return Eigen::Vector3d(1, -1, -1).asDiagonal(); }

// --frame enu: EuRoC's truth is the FLU body in ENU (position, attitude and
// velocity), its IMU is in FLU (a level IMU's specific force +9.81 up), cam0's
// T_BS is T_flu_cam; the TUM truth is the camera in ENU, says so in its frame
// line and reads back in nadir's axes.
TEST_F(ExportTest, EnuAxesTurnEveryPoseVectorAndExtrinsic) {
  writeRun(log_);
  ExportOptions options;
  options.log_path = log_.string();
  options.out_dir = (root_ / "euroc_enu").string();
  options.axes = core::Axes::kEnu;
  exportRun(options);
  const fs::path mav = root_ / "euroc_enu" / "mav0";
  const std::vector<std::string> truth =
      readLines(mav / "state_groundtruth_estimate0" / "data.csv");
  ASSERT_EQ(truth.size(), static_cast<std::size_t>(kTruthSamples + 1));
  for (int i : {0, 7, kTruthSamples - 1}) {
    const std::vector<double> row = numbers(truth[static_cast<std::size_t>(i) + 1], ',');
    ASSERT_EQ(row.size(), 17u);
    const double t = i * kTruthPeriodUs * 1e-6;
    const Eigen::Vector3d p_ned = truthPosition(t);
    EXPECT_NEAR(row[1], p_ned.y(), 1e-9);
    EXPECT_NEAR(row[2], p_ned.x(), 1e-9);
    EXPECT_NEAR(row[3], -p_ned.z(), 1e-9);
    const Eigen::Matrix3d R_enu_flu =
        enuFromNed() * truthOrientation(t).toRotationMatrix() * frdFromFlu();
    const Eigen::Quaterniond q(row[4], row[5], row[6], row[7]);  // w x y z
    EXPECT_NEAR(q.angularDistance(Eigen::Quaterniond(R_enu_flu)), 0.0, 1e-9);
    EXPECT_EQ(row[8], 2.0);   // east
    EXPECT_EQ(row[9], 10.0);  // north
    EXPECT_EQ(row[10], 1.0);  // up
  }
  const std::vector<double> imu3 = numbers(readLines(mav / "imu0" / "data.csv")[4], ',');
  ASSERT_EQ(imu3.size(), 7u);
  EXPECT_DOUBLE_EQ(imu3[3], -0.5);   // a yaw rate to the right is one to the left's minus
  EXPECT_DOUBLE_EQ(imu3[4], 0.015);  // forward stays forward
  EXPECT_DOUBLE_EQ(imu3[6], 9.81);   // the specific force points up
  const std::string yaml = readText(mav / "cam0" / "sensor.yaml");
  const std::size_t data_at = yaml.find("data: [");
  ASSERT_NE(data_at, std::string::npos);
  const std::vector<double> m =
      numbers(yaml.substr(data_at + 7, yaml.find(']', data_at) - data_at - 7), ',');
  ASSERT_EQ(m.size(), 16u);
  Eigen::Matrix4d expected_T = Eigen::Matrix4d::Identity();
  expected_T.topLeftCorner<3, 3>() = frdFromFlu().transpose() * bodyFromCamera().rotation();
  expected_T.topRightCorner<3, 1>() = Eigen::Vector3d(0.1, 0.0, -0.05);
  for (int i = 0; i < 16; ++i)
    EXPECT_NEAR(m[static_cast<std::size_t>(i)], expected_T(i / 4, i % 4), 1e-12);

  options.out_dir = (root_ / "tum_enu").string();
  options.format = Format::kTum;
  exportRun(options);
  const fs::path groundtruth = root_ / "tum_enu" / "groundtruth.txt";
  std::vector<std::string> lines = readLines(groundtruth);
  EXPECT_NE(std::find(lines.begin(), lines.end(), "# frame: world=enu body=camera"), lines.end());
  std::erase_if(lines, [](const std::string& line) { return line.starts_with("#"); });
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kImages));
  const std::vector<double> v = numbers(lines[2], ' ');
  ASSERT_EQ(v.size(), 8u);
  const Eigen::Isometry3d T_ned_cam =
      truthPose(static_cast<double>(imageUtime(2)) * 1e-6) * bodyFromCamera();
  EXPECT_NEAR(v[1], T_ned_cam.translation().y(), 1e-9);
  EXPECT_NEAR(v[2], T_ned_cam.translation().x(), 1e-9);
  EXPECT_NEAR(v[3], -T_ned_cam.translation().z(), 1e-9);
  EXPECT_NEAR(Eigen::Quaterniond(v[7], v[4], v[5], v[6])
                  .angularDistance(Eigen::Quaterniond(enuFromNed() * T_ned_cam.rotation())),
              0.0, 1e-9);
  const core::Trajectory read = core::readTum(groundtruth.string());
  ASSERT_EQ(read.size(), static_cast<std::size_t>(kImages));
  EXPECT_LT((read[2].p_ned_m - T_ned_cam.translation()).norm(), 1e-9);
  EXPECT_LT(read[2].q_world_body.angularDistance(Eigen::Quaterniond(T_ned_cam.rotation())), 1e-9);
}

// With the IMU's noise known (the run's scenario), EuRoC's imu0/sensor.yaml
// carries it, orbslam3.yaml is monocular-inertial and openvins/ holds OpenVINS's
// three files: read back with OpenCV's FileStorage (what both read them with),
// the camera is the calibration, T_b_c1 and T_imu_cam are T_body_cam and the
// noise the scenario's. Without it the settings are monocular, there is no
// openvins/, and a note says why.
TEST_F(ExportTest, EurocCarriesTheImuNoiseAndSettingsForOrbSlam3AndOpenVins) {
  writeRun(log_);
  ExportOptions options;
  options.log_path = log_.string();
  options.out_dir = (root_ / "euroc_noise").string();
  options.imu_noise = ImuNoise{.gyroscope_noise_density = 2e-4,
                               .gyroscope_random_walk = 2e-5,
                               .accelerometer_noise_density = 2e-3,
                               .accelerometer_random_walk = 3e-4};
  exportRun(options);
  const fs::path out = root_ / "euroc_noise";
  const std::string imu_yaml = readText(out / "mav0" / "imu0" / "sensor.yaml");
  for (const char* line :
       {"gyroscope_noise_density: 0.0002", "gyroscope_random_walk: 2e-05",
        "accelerometer_noise_density: 0.002", "accelerometer_random_walk: 0.0003"}) {
    EXPECT_NE(imu_yaml.find(line), std::string::npos) << line << "\n" << imu_yaml;
  }
  cv::FileStorage settings((out / "orbslam3.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(settings.isOpened());
  EXPECT_EQ(static_cast<std::string>(settings["File.version"]), "1.0");
  EXPECT_EQ(static_cast<std::string>(settings["Camera.type"]), "PinHole");
  EXPECT_EQ(static_cast<double>(settings["Camera1.fx"]), 50.0);
  EXPECT_EQ(static_cast<double>(settings["Camera1.cy"]), 23.5);
  EXPECT_EQ(static_cast<double>(settings["Camera1.p2"]), -0.0003);
  EXPECT_EQ(static_cast<int>(settings["Camera.width"]), 64);
  EXPECT_EQ(static_cast<int>(settings["Camera.fps"]), 20);
  EXPECT_EQ(static_cast<double>(settings["IMU.NoiseGyro"]), 2e-4);
  EXPECT_EQ(static_cast<double>(settings["IMU.AccWalk"]), 3e-4);
  EXPECT_EQ(static_cast<double>(settings["IMU.Frequency"]), 200.0);
  cv::Mat T_b_c1;
  settings["IMU.T_b_c1"] >> T_b_c1;
  ASSERT_EQ(T_b_c1.rows, 4);
  ASSERT_EQ(T_b_c1.cols, 4);
  const Eigen::Matrix4d expected_T = bodyFromCamera().matrix();
  for (int i = 0; i < 16; ++i) {
    EXPECT_NEAR(T_b_c1.at<float>(i / 4, i % 4), expected_T(i / 4, i % 4), 1e-6) << i;
  }

  // OpenVINS's Kalibr chains, read back as OpenVINS reads them (OpenCV's FileStorage).
  cv::FileStorage imu_chain((out / "openvins" / "kalibr_imu_chain.yaml").string(),
                            cv::FileStorage::READ);
  ASSERT_TRUE(imu_chain.isOpened());
  EXPECT_EQ(static_cast<double>(imu_chain["imu0"]["gyroscope_noise_density"]), 2e-4);
  EXPECT_EQ(static_cast<double>(imu_chain["imu0"]["accelerometer_random_walk"]), 3e-4);
  EXPECT_EQ(static_cast<double>(imu_chain["imu0"]["update_rate"]), 200.0);
  cv::FileStorage cam_chain((out / "openvins" / "kalibr_imucam_chain.yaml").string(),
                            cv::FileStorage::READ);
  ASSERT_TRUE(cam_chain.isOpened());
  const cv::FileNode T_imu_cam = cam_chain["cam0"]["T_imu_cam"];
  ASSERT_EQ(T_imu_cam.size(), 4u);
  for (int r = 0; r < 4; ++r) {
    ASSERT_EQ(T_imu_cam[r].size(), 4u);
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(static_cast<double>(T_imu_cam[r][c]), expected_T(r, c), 1e-12) << r << c;
    }
  }
  EXPECT_EQ(static_cast<std::string>(cam_chain["cam0"]["distortion_model"]), "radtan");
  EXPECT_EQ(static_cast<double>(cam_chain["cam0"]["intrinsics"][0]), 50.0);
  cv::FileStorage estimator((out / "openvins" / "estimator_config.yaml").string(),
                            cv::FileStorage::READ);
  ASSERT_TRUE(estimator.isOpened());
  EXPECT_EQ(static_cast<int>(estimator["max_cameras"]), 1);
  EXPECT_EQ(static_cast<std::string>(estimator["relative_config_imucam"]),
            "kalibr_imucam_chain.yaml");

  options.out_dir = (root_ / "euroc_no_noise").string();
  options.imu_noise.reset();
  const ExportSummary summary = exportRun(options);
  cv::FileStorage mono((root_ / "euroc_no_noise" / "orbslam3.yaml").string(),
                       cv::FileStorage::READ);
  ASSERT_TRUE(mono.isOpened());
  EXPECT_TRUE(mono["IMU.NoiseGyro"].empty());
  EXPECT_FALSE(fs::exists(root_ / "euroc_no_noise" / "openvins"));
  EXPECT_EQ(static_cast<double>(mono["Camera1.fx"]), 50.0);
  EXPECT_NE(std::find_if(summary.notes.begin(), summary.notes.end(),
                         [](const std::string& note) {
                           return note.find("monocular only") != std::string::npos;
                         }),
            summary.notes.end());
}

// RGB images keep their colours: red stays red in the PNG.
TEST_F(ExportTest, RgbImagesKeepTheirChannelOrder) {
  {
    core::LcmLogWriter writer(log_.string());
    writeMessage(writer, "CAMERA_DOWN_INFO", cameraInfo());
    const cv::Mat rgb(kHeight, kWidth, CV_8UC3, cv::Scalar(200, 100, 50));  // R, G, B
    writeMessage(writer, "CAMERA_DOWN", grayMessage(rgb, 1000));
  }
  const ExportSummary summary = exportAs(Format::kEuroc, "euroc");
  ASSERT_EQ(summary.images, 1);
  const cv::Mat read = cv::imread((root_ / "euroc/mav0/cam0/data/1000000.png").string());
  ASSERT_EQ(read.type(), CV_8UC3);
  EXPECT_EQ(read.at<cv::Vec3b>(5, 5), cv::Vec3b(50, 100, 200));  // imread gives B, G, R
}

// An output folder that holds anything is refused and left as it was.
TEST_F(ExportTest, RefusesNonEmptyOutputFolder) {
  writeRun(log_);
  const fs::path out = root_ / "taken";
  fs::create_directories(out);
  std::ofstream(out / "keep.txt") << "mine";
  try {
    exportAs(Format::kEuroc, "taken");
    FAIL() << "a non-empty output folder was accepted";
  } catch (const ExportError& error) {
    EXPECT_NE(std::string(error.what()).find(out.string()), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("not empty"), std::string::npos) << error.what();
  }
  EXPECT_EQ(filesIn(out), std::set<std::string>{"keep.txt"});
  // An existing empty folder is fine.
  fs::create_directories(root_ / "empty");
  EXPECT_EQ(exportAs(Format::kEuroc, "empty").images, kImages);
}

// No images on the channel: the error names log, channel and the image channels; no output.
TEST_F(ExportTest, NoImagesNamesTheChannelsThatHaveThem) {
  writeRun(log_, {.camera_channel = "CAMERA_FRONT"});
  try {
    exportAs(Format::kEuroc, "out");
    FAIL() << "a log without images on CAMERA_DOWN was exported";
  } catch (const ExportError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find(log_.string()), std::string::npos) << what;
    EXPECT_NE(what.find("CAMERA_DOWN"), std::string::npos) << what;
    EXPECT_NE(what.find("CAMERA_FRONT (5 images)"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(root_ / "out"));
}

// A log with no image_t at all lists the channels it has.
TEST_F(ExportTest, LogWithoutAnyImagesListsItsChannels) {
  writeRun(log_, {.images = false});
  try {
    exportAs(Format::kTum, "out");
    FAIL() << "a log without images was exported";
  } catch (const ExportError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("no channel in the log carries image_t"), std::string::npos) << what;
    EXPECT_NE(what.find("POSE_TRUTH"), std::string::npos) << what;
    EXPECT_NE(what.find("IMU"), std::string::npos) << what;
  }
}

// Without camera_info_t there is no calibration: refused, naming the info channel.
TEST_F(ExportTest, MissingCameraInfoIsRefused) {
  writeRun(log_, {.camera_info = false});
  try {
    exportAs(Format::kTumMono, "out");
    FAIL() << "a log without camera_info_t was exported";
  } catch (const ExportError& error) {
    EXPECT_NE(std::string(error.what()).find("CAMERA_DOWN_INFO"), std::string::npos)
        << error.what();
  }
  EXPECT_FALSE(fs::exists(root_ / "out"));
}

// A missing log is named in the error.
TEST_F(ExportTest, MissingLogIsNamed) {
  try {
    exportAs(Format::kEuroc, "out");
    FAIL() << "a missing log was accepted";
  } catch (const ExportError& error) {
    EXPECT_NE(std::string(error.what()).find(log_.string()), std::string::npos) << error.what();
  }
}

// A log cut inside the third image exports what precedes the cut and reports the damage.
TEST_F(ExportTest, TruncatedLogExportsWhatPrecedesTheDamage) {
  const std::vector<std::int64_t> size_after_image = writeRun(log_);
  const std::int64_t cut = size_after_image[2] - 100;  // inside image 2's event
  fs::resize_file(log_, static_cast<std::uintmax_t>(cut));
  const ExportSummary summary = exportAs(Format::kEuroc, "euroc");
  EXPECT_EQ(summary.images, 2);
  EXPECT_NE(summary.damage.find("truncated"), std::string::npos) << summary.damage;
  const std::vector<std::string> csv = readLines(root_ / "euroc/mav0/cam0/data.csv");
  ASSERT_EQ(csv.size(), 3u);
  expectImage(root_ / "euroc/mav0/cam0/data" / (std::to_string(imageUtime(1) * 1000) + ".png"), 1);
  // Truth ran up to image 2's time (it is logged before the image at that step).
  const std::vector<std::string> truth =
      readLines(root_ / "euroc/mav0/state_groundtruth_estimate0/data.csv");
  EXPECT_EQ(summary.poses, static_cast<std::int64_t>(truth.size()) - 1);
  const std::vector<double> last = numbers(truth.back(), ',');
  EXPECT_LE(last[0], static_cast<double>(imageUtime(2) * 1000 + kTruthPeriodUs * 1000));
  EXPECT_GE(last[0], static_cast<double>(imageUtime(2) * 1000 - kTruthPeriodUs * 1000));
}

// Images whose utime does not advance are skipped with a note (file names would collide).
TEST_F(ExportTest, RepeatedImageTimesAreSkippedWithANote) {
  {
    core::LcmLogWriter writer(log_.string());
    writeMessage(writer, "CAMERA_DOWN_INFO", cameraInfo());
    writeMessage(writer, "CAMERA_DOWN", grayMessage(grayPattern(0), 1000));
    writeMessage(writer, "CAMERA_DOWN", grayMessage(grayPattern(1), 1000));
    writeMessage(writer, "CAMERA_DOWN", grayMessage(grayPattern(2), 500));
    writeMessage(writer, "CAMERA_DOWN", grayMessage(grayPattern(3), 2000));
  }
  const ExportSummary summary = exportAs(Format::kTumMono, "mono");
  EXPECT_EQ(summary.images, 2);
  expectImage(root_ / "mono/images/00001.png", 3);
  bool noted = false;
  for (const auto& note : summary.notes) noted = noted || note.find("2 images") == 0;
  EXPECT_TRUE(noted);
}

// Format names round-trip and an unknown one lists the known ones.
TEST(ExportFormat, NamesRoundTrip) {
  for (Format f : {Format::kEuroc, Format::kTumMono, Format::kTum})
    EXPECT_EQ(parseFormat(formatName(f)), f);
  try {
    parseFormat("kitti");
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("euroc, tum-mono, tum"), std::string::npos);
  }
}

}  // namespace
}  // namespace nadir::dataset
