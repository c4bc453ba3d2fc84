// The calibration file: round trips, OpenCV's own sample file, and every
// malformed file named in calibration_file.h refused with the file and the
// field in the message.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "calib/calibration_file.h"
#include "tests/calib/opencv_photos.h"

namespace nadir::calib {
namespace {

namespace fs = std::filesystem;

class CalibrationFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() /
            ("nadir_calib_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string write(const std::string& name, const std::string& text) const {
    const std::string path = (root_ / name).string();
    std::ofstream(path) << text;
    return path;
  }

  // Reading `path` throws std::runtime_error naming the file and `field`.
  void expectRefused(const std::string& path, const std::string& field,
                     const std::string& also = "") const {
    try {
      readCalibrationFile(path);
      ADD_FAILURE() << path << " was read";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find(field), std::string::npos) << what;
      if (!also.empty()) {
        EXPECT_NE(what.find(also), std::string::npos) << what;
      }
    }
  }

  fs::path root_;
};

CalibrationFile exampleFile() {
  CalibrationFile f;
  f.model = LensModel::kRadtan;
  f.image_width = 1280;
  f.image_height = 960;
  f.board_width = 9;
  f.board_height = 6;
  f.square_size_m = 0.03;
  f.nframes = 3;
  f.flags = cv::CALIB_FIX_ASPECT_RATIO | cv::CALIB_FIX_K3;
  f.aspect_ratio = 1.0;
  f.camera_matrix = cv::Matx33d(701.25, 0, 639.125, 0, 701.25, 479.875, 0, 0, 1);
  f.distortion = {-0.2, 0.05, 0.001, -0.0005, 0.0};
  f.avg_reprojection_error_px = 0.123456789;
  f.per_view_errors_px = {0.1, 0.125, 0.15};
  f.extrinsics = {cv::Vec6d(0.1, -0.2, 0.3, 0.01, 0.02, 0.5), cv::Vec6d(0, 0, 0, 0, 0, 1),
                  cv::Vec6d(-1, 2, -3, 4, -5, 6)};
  return f;
}

void expectEqualFiles(const CalibrationFile& a, const CalibrationFile& b) {
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.image_width, b.image_width);
  EXPECT_EQ(a.image_height, b.image_height);
  EXPECT_EQ(a.board_width, b.board_width);
  EXPECT_EQ(a.board_height, b.board_height);
  EXPECT_DOUBLE_EQ(a.square_size_m, b.square_size_m);
  EXPECT_EQ(a.nframes, b.nframes);
  EXPECT_EQ(a.flags, b.flags);
  EXPECT_DOUBLE_EQ(a.aspect_ratio, b.aspect_ratio);
  for (int i = 0; i < 9; ++i) EXPECT_DOUBLE_EQ(a.camera_matrix.val[i], b.camera_matrix.val[i]);
  EXPECT_EQ(a.distortion, b.distortion);
  EXPECT_DOUBLE_EQ(a.avg_reprojection_error_px, b.avg_reprojection_error_px);
  ASSERT_EQ(a.per_view_errors_px.size(), b.per_view_errors_px.size());
  // Stored as 32-bit floats, as the sample stores them.
  for (std::size_t i = 0; i < a.per_view_errors_px.size(); ++i)
    EXPECT_NEAR(a.per_view_errors_px[i], b.per_view_errors_px[i], 1e-7);
  ASSERT_EQ(a.extrinsics.size(), b.extrinsics.size());
  for (std::size_t i = 0; i < a.extrinsics.size(); ++i)
    for (int j = 0; j < 6; ++j) EXPECT_DOUBLE_EQ(a.extrinsics[i][j], b.extrinsics[i][j]);
}

// Written and read back, every field is equal (radtan and fisheye).
TEST_F(CalibrationFileTest, RoundTrip) {
  const CalibrationFile radtan = exampleFile();
  const std::string path = (root_ / "radtan.yml").string();
  writeCalibrationFile(path, radtan);
  expectEqualFiles(readCalibrationFile(path), radtan);

  CalibrationFile fisheye = exampleFile();
  fisheye.model = LensModel::kFisheye;
  fisheye.flags = cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW;
  fisheye.aspect_ratio = 0.0;
  fisheye.distortion = {0.1, -0.02, 0.003, -0.0004};
  const std::string fisheye_path = (root_ / "fisheye.yml").string();
  writeCalibrationFile(fisheye_path, fisheye);
  expectEqualFiles(readCalibrationFile(fisheye_path), fisheye);
}

// OpenCV's sample file reads as written there (no distortion_model: radtan)
// and becomes CameraIntrinsics with its numbers.
TEST_F(CalibrationFileTest, ReadsOpenCvSampleFile) {
  const CalibrationFile f = readCalibrationFile(test::photoDir() + "/left_intrinsics.yml");
  EXPECT_EQ(f.model, LensModel::kRadtan);
  EXPECT_EQ(f.image_width, 640);
  EXPECT_EQ(f.image_height, 480);
  EXPECT_EQ(f.board_width, 9);
  EXPECT_EQ(f.board_height, 6);
  EXPECT_DOUBLE_EQ(f.square_size_m, 2.5000000372529030e-02);
  EXPECT_EQ(f.nframes, 13);
  EXPECT_EQ(f.flags, cv::CALIB_FIX_ASPECT_RATIO);
  EXPECT_DOUBLE_EQ(f.aspect_ratio, 1.0);
  EXPECT_DOUBLE_EQ(f.avg_reprojection_error_px, 3.9259098975581364e-01);
  ASSERT_EQ(f.per_view_errors_px.size(), 13u);
  EXPECT_NEAR(f.per_view_errors_px[1], 1.18204820, 1e-7);
  ASSERT_EQ(f.extrinsics.size(), 13u);
  EXPECT_DOUBLE_EQ(f.extrinsics[12][5], 3.1243767202759759e-01);

  const render::CameraIntrinsics k = toCameraIntrinsics(f);
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.height, 480);
  EXPECT_DOUBLE_EQ(k.fx, 5.3591573396163199e+02);
  EXPECT_DOUBLE_EQ(k.fy, 5.3591573396163199e+02);
  EXPECT_DOUBLE_EQ(k.cx, 3.4228315473308373e+02);
  EXPECT_DOUBLE_EQ(k.cy, 2.3557082909788173e+02);
  const std::array<double, 5> d = {-2.6637260909660682e-01, -3.8588898922304653e-02,
                                   1.7831947042852964e-03, -2.8122100441115472e-04,
                                   2.3839153080878486e-01};
  for (int i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(k.distortion[i], d[i]);
}

// A calibration of the photographs, through the file, projects points as
// cv::projectPoints does with the calibration itself: render's camera model
// and OpenCV agree on what the numbers mean.
TEST_F(CalibrationFileTest, CalibrationThroughFileProjectsAsOpenCv) {
  const BoardSpec board{.inner_cols = 9, .inner_rows = 6, .square_m = 0.025};
  std::vector<View> views;
  for (const std::string& name : test::photoNames()) {
    if (const std::optional<Detection> d = detectBoard(test::loadPhoto(name), board))
      views.push_back({d->corners_px, name});
  }
  CalibOptions options;
  options.max_folds = 0;
  const Calibration c = calibrate(views, board, cv::Size(640, 480), options);
  const std::string path = (root_ / "photos.yml").string();
  writeCalibrationFile(path, toCalibrationFile(c, board));
  const CalibrationFile f = readCalibrationFile(path);
  EXPECT_EQ(f.nframes, static_cast<int>(c.views_used.size()));
  EXPECT_EQ(f.per_view_errors_px.size(), c.views_used.size());
  const render::CameraIntrinsics k = toCameraIntrinsics(f);
  const std::vector<cv::Point3d> points = {{0.1, -0.05, 0.4}, {-0.2, 0.15, 0.5}, {0.0, 0.0, 1.0}};
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), c.camera_matrix, c.distortion,
                    expected);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d uv = k.project({points[i].x, points[i].y, points[i].z});
    EXPECT_NEAR(uv.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(uv.y(), expected[i].y, 1e-9);
  }
}

// A fisheye file reads, but cannot become render::CameraIntrinsics (radtan only).
TEST_F(CalibrationFileTest, FisheyeFileDoesNotConvert) {
  CalibrationFile fisheye = exampleFile();
  fisheye.model = LensModel::kFisheye;
  fisheye.distortion = {0.1, -0.02, 0.003, -0.0004};
  const std::string path = (root_ / "fisheye.yml").string();
  writeCalibrationFile(path, fisheye);
  const CalibrationFile f = readCalibrationFile(path);
  EXPECT_EQ(f.model, LensModel::kFisheye);
  try {
    toCameraIntrinsics(f);
    FAIL() << "a fisheye file became CameraIntrinsics";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fisheye"), std::string::npos) << e.what();
  }
  CalibrationFile rational = exampleFile();
  rational.distortion = {-0.2, 0.05, 0, 0, 0, 0.01, 0, 0};
  EXPECT_THROW(toCameraIntrinsics(rational), std::invalid_argument);
}

const char* const kValid = R"(%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ -0.1, 0.01, 0., 0., 0. ]
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// Each malformed file is refused naming the file and the field: missing, not
// YAML, no camera_matrix, a 2x3 camera_matrix, fx or fy <= 0, an image size
// <= 0, plus an unknown distortion_model and a fisheye file with 5 coefficients.
TEST_F(CalibrationFileTest, MalformedFilesNameFileAndField) {
  // The template itself reads.
  EXPECT_DOUBLE_EQ(readCalibrationFile(write("valid.yml", kValid)).camera_matrix(0, 0), 500.0);

  expectRefused((root_ / "missing.yml").string(), "no such file");
  expectRefused(write("text.yml", "this is not a calibration\n"), "YAML");
  expectRefused(write("empty.yml", ""), "YAML");
  expectRefused(write("no_k.yml", replaced(kValid, "camera_matrix:", "other_matrix:")),
                "camera_matrix", "missing");
  expectRefused(write("k_2x3.yml", replaced(replaced(kValid, "rows: 3", "rows: 2"),
                                            "data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]",
                                            "data: [ 500., 0., 320., 0., 500., 240. ]")),
                "camera_matrix", "2x3");
  expectRefused(write("fx0.yml", replaced(kValid, "[ 500., 0., 320.", "[ 0., 0., 320.")),
                "camera_matrix", "fx");
  expectRefused(write("fy_neg.yml", replaced(kValid, "0., 500., 240.", "0., -500., 240.")),
                "camera_matrix", "fy");
  expectRefused(write("w0.yml", replaced(kValid, "image_width: 640", "image_width: 0")),
                "image_width");
  expectRefused(write("h_neg.yml", replaced(kValid, "image_height: 480", "image_height: -480")),
                "image_height");
  expectRefused(write("no_w.yml", replaced(kValid, "image_width: 640\n", "")), "image_width",
                "missing");
  expectRefused(
      write("model.yml", replaced(kValid, "image_width", "distortion_model: kb4\nimage_width")),
      "distortion_model", "kb4");
  expectRefused(write("fisheye5.yml",
                      replaced(kValid, "image_width", "distortion_model: fisheye\nimage_width")),
                "distortion_coefficients", "fisheye");
}

// Writing where no file can be made is an error naming the path.
TEST_F(CalibrationFileTest, UnwritablePathRefused) {
  const std::string path = (root_ / "no_such_dir" / "out.yml").string();
  try {
    writeCalibrationFile(path, exampleFile());
    FAIL() << "wrote " << path;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nadir::calib
