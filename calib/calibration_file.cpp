#include "calib/calibration_file.h"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

namespace nadir::calib {
namespace {

class Reader {
 public:
  explicit Reader(const std::string& path) : path_(path) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw std::runtime_error("calibration file '" + path_ + "': " + field + ": " + what);
  }

  cv::FileNode node(const cv::FileStorage& fs, const std::string& field, bool required) const {
    cv::FileNode n = fs[field];
    if (n.empty() && required) fail(field, "missing");
    return n;
  }

  int integer(const cv::FileStorage& fs, const std::string& field, bool required) const {
    const cv::FileNode n = node(fs, field, required);
    if (n.empty()) return 0;
    if (!n.isInt()) fail(field, "not a whole number");
    return static_cast<int>(n);
  }

  double real(const cv::FileStorage& fs, const std::string& field) const {
    const cv::FileNode n = node(fs, field, false);
    if (n.empty()) return 0.0;
    if (!n.isInt() && !n.isReal()) fail(field, "not a number");
    const double value = static_cast<double>(n);
    if (!std::isfinite(value)) fail(field, "not a finite number");
    return value;
  }

  // A matrix of doubles; an empty Mat when the field is absent and optional.
  cv::Mat matrix(const cv::FileStorage& fs, const std::string& field, bool required) const {
    const cv::FileNode n = node(fs, field, required);
    cv::Mat m;
    if (n.empty()) return m;
    try {
      n >> m;
    } catch (const cv::Exception&) {
      fail(field, "not an OpenCV matrix (!!opencv-matrix with rows, cols, dt and data)");
    }
    if (m.empty() || m.channels() != 1) fail(field, "not an OpenCV matrix of numbers");
    m.convertTo(m, CV_64F);
    for (int r = 0; r < m.rows; ++r) {
      for (int c = 0; c < m.cols; ++c) {
        if (!std::isfinite(m.at<double>(r, c))) fail(field, "holds a value that is not finite");
      }
    }
    return m;
  }

 private:
  std::string path_;
};

std::string sizeText(const cv::Mat& m) {
  return std::to_string(m.rows) + "x" + std::to_string(m.cols);
}

}  // namespace

void writeCalibrationFile(const std::string& path, const CalibrationFile& file) {
  // Checked here so that the message is ours, not OpenCV's log line.
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!dir.empty() && !std::filesystem::is_directory(dir, ec))
    throw std::runtime_error("calibration file '" + path + "': cannot be written: no directory " +
                             dir.string());
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::WRITE);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("calibration file '" + path + "': cannot be written: " + e.what());
  }
  if (!fs.isOpened())
    throw std::runtime_error("calibration file '" + path + "': cannot be written");
  // The sample's keys in the sample's order; distortion_model is nadir's.
  fs << "nframes" << file.nframes;
  fs << "image_width" << file.image_width;
  fs << "image_height" << file.image_height;
  fs << "board_width" << file.board_width;
  fs << "board_height" << file.board_height;
  fs << "square_size" << file.square_size_m;
  if (file.model == LensModel::kRadtan && (file.flags & cv::CALIB_FIX_ASPECT_RATIO))
    fs << "aspectRatio" << file.aspect_ratio;
  fs << "flags" << file.flags;
  fs << "distortion_model" << lensModelName(file.model);
  fs << "camera_matrix" << cv::Mat(file.camera_matrix);
  fs << "distortion_coefficients" << cv::Mat(file.distortion, true);
  fs << "avg_reprojection_error" << file.avg_reprojection_error_px;
  if (!file.per_view_errors_px.empty()) {
    cv::Mat errors;
    cv::Mat(file.per_view_errors_px, true).convertTo(errors, CV_32F);  // the sample's type
    fs << "per_view_reprojection_errors" << errors;
  }
  if (!file.extrinsics.empty()) {
    cv::Mat extrinsics(static_cast<int>(file.extrinsics.size()), 6, CV_64F);
    for (int r = 0; r < extrinsics.rows; ++r) {
      for (int c = 0; c < 6; ++c) extrinsics.at<double>(r, c) = file.extrinsics[r][c];
    }
    fs << "extrinsic_parameters" << extrinsics;
  }
  fs.release();
}

CalibrationFile readCalibrationFile(const std::string& path) {
  const Reader reader(path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error("calibration file '" + path + "': no such file");
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(
        "calibration file '" + path +
        "': not a YAML file OpenCV can read (it must start with %YAML:1.0): " + e.what());
  }
  if (!fs.isOpened()) throw std::runtime_error("calibration file '" + path + "': cannot be opened");

  CalibrationFile file;
  const cv::FileNode model = fs["distortion_model"];
  if (!model.empty()) {
    if (!model.isString()) reader.fail("distortion_model", "not a string (radtan or fisheye)");
    const std::string name = static_cast<std::string>(model);
    const std::optional<LensModel> m = lensModelFromName(name);
    if (!m) reader.fail("distortion_model", name + " is neither radtan nor fisheye");
    file.model = *m;
  }

  file.image_width = reader.integer(fs, "image_width", true);
  if (file.image_width <= 0)
    reader.fail("image_width", std::to_string(file.image_width) + " is not a positive size");
  file.image_height = reader.integer(fs, "image_height", true);
  if (file.image_height <= 0)
    reader.fail("image_height", std::to_string(file.image_height) + " is not a positive size");
  file.board_width = reader.integer(fs, "board_width", false);
  file.board_height = reader.integer(fs, "board_height", false);
  file.square_size_m = reader.real(fs, "square_size");
  file.nframes = reader.integer(fs, "nframes", false);
  file.flags = reader.integer(fs, "flags", false);
  file.aspect_ratio = reader.real(fs, "aspectRatio");

  const cv::Mat k = reader.matrix(fs, "camera_matrix", true);
  if (k.rows != 3 || k.cols != 3) reader.fail("camera_matrix", sizeText(k) + ", not 3x3");
  file.camera_matrix = cv::Matx33d(k);
  if (!(file.camera_matrix(0, 0) > 0.0))
    reader.fail("camera_matrix", "fx = " + std::to_string(file.camera_matrix(0, 0)) +
                                     " is not a positive focal length");
  if (!(file.camera_matrix(1, 1) > 0.0))
    reader.fail("camera_matrix", "fy = " + std::to_string(file.camera_matrix(1, 1)) +
                                     " is not a positive focal length");

  const cv::Mat d = reader.matrix(fs, "distortion_coefficients", true);
  if (d.rows != 1 && d.cols != 1)
    reader.fail("distortion_coefficients", sizeText(d) + ", not a row or a column");
  file.distortion.assign(d.begin<double>(), d.end<double>());
  const std::size_t n = file.distortion.size();
  if (file.model == LensModel::kFisheye && n != 4)
    reader.fail("distortion_coefficients",
                std::to_string(n) + " coefficients; the fisheye model has 4 (k1..k4)");
  if (file.model == LensModel::kRadtan && n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
    reader.fail("distortion_coefficients",
                std::to_string(n) + " coefficients; OpenCV's model has 4, 5, 8, 12 or 14");

  file.avg_reprojection_error_px = reader.real(fs, "avg_reprojection_error");
  const cv::Mat errors = reader.matrix(fs, "per_view_reprojection_errors", false);
  if (!errors.empty()) file.per_view_errors_px.assign(errors.begin<double>(), errors.end<double>());
  const cv::Mat extrinsics = reader.matrix(fs, "extrinsic_parameters", false);
  if (!extrinsics.empty()) {
    if (extrinsics.cols != 6)
      reader.fail("extrinsic_parameters", sizeText(extrinsics) + ", not 6 columns (rvec, tvec)");
    for (int r = 0; r < extrinsics.rows; ++r) {
      cv::Vec6d row;
      for (int c = 0; c < 6; ++c) row[c] = extrinsics.at<double>(r, c);
      file.extrinsics.push_back(row);
    }
  }
  return file;
}

CalibrationFile toCalibrationFile(const Calibration& calibration, const BoardSpec& board) {
  CalibrationFile file;
  file.model = calibration.model;
  file.image_width = calibration.image_size.width;
  file.image_height = calibration.image_size.height;
  file.board_width = board.inner_cols;
  file.board_height = board.inner_rows;
  file.square_size_m = board.square_m;
  file.nframes = static_cast<int>(calibration.views_used.size());
  file.flags = calibration.opencv_flags;
  file.aspect_ratio = calibration.aspect_ratio;
  file.camera_matrix = calibration.camera_matrix;
  file.distortion = calibration.distortion;
  file.avg_reprojection_error_px = calibration.rms_px;
  file.per_view_errors_px = calibration.per_view_rms_px;
  for (std::size_t v = 0; v < calibration.rvecs.size(); ++v) {
    const cv::Vec3d& r = calibration.rvecs[v];
    const cv::Vec3d& t = calibration.tvecs[v];
    file.extrinsics.emplace_back(r[0], r[1], r[2], t[0], t[1], t[2]);
  }
  return file;
}

render::CameraIntrinsics toCameraIntrinsics(const CalibrationFile& file) {
  if (file.model == LensModel::kFisheye)
    throw std::invalid_argument(
        "toCameraIntrinsics: a fisheye calibration (k1..k4, equidistant) cannot become "
        "render::CameraIntrinsics, which has only the radtan model k1 k2 p1 p2 k3");
  if (file.distortion.size() < 4)
    throw std::invalid_argument("toCameraIntrinsics: " + std::to_string(file.distortion.size()) +
                                " distortion coefficients; radtan needs at least k1 k2 p1 p2");
  for (std::size_t i = 5; i < file.distortion.size(); ++i) {
    if (file.distortion[i] != 0.0)
      throw std::invalid_argument(
          "toCameraIntrinsics: distortion coefficient " + std::to_string(i) +
          " (beyond k3: rational, thin-prism or tilt terms) is not zero; render::CameraIntrinsics "
          "has only k1 k2 p1 p2 k3");
  }
  render::CameraIntrinsics k;
  k.width = file.image_width;
  k.height = file.image_height;
  k.fx = file.camera_matrix(0, 0);
  k.fy = file.camera_matrix(1, 1);
  k.cx = file.camera_matrix(0, 2);
  k.cy = file.camera_matrix(1, 2);
  for (std::size_t i = 0; i < 5; ++i)
    k.distortion[i] = i < file.distortion.size() ? file.distortion[i] : 0.0;
  return k;
}

}  // namespace nadir::calib
