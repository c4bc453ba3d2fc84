#pragma once
// The calibration file: OpenCV's YAML as its calibration sample
// (samples/cpp/calibration.cpp, saveCameraParams) writes it, through
// cv::FileStorage, plus distortion_model: radtan or fisheye (a file without
// it is radtan, as the sample's are).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/board.h"
#include "calib/calibrate.h"
#include "render/camera_model.h"

namespace nadir::calib {

// The file's fields; the YAML key of each is in its comment.
struct CalibrationFile {
  LensModel model = LensModel::kRadtan;  // distortion_model
  int image_width = 0;                   // image_width, px
  int image_height = 0;                  // image_height, px
  int board_width = 0;                   // board_width: inner corners per row; 0 = unknown
  int board_height = 0;                  // board_height: inner corners per column
  double square_size_m = 0.0;            // square_size
  int nframes = 0;                       // nframes: views used
  int flags = 0;                         // flags: OpenCV solver flags
  double aspect_ratio = 0.0;             // aspectRatio: written when CALIB_FIX_ASPECT_RATIO is set
  cv::Matx33d camera_matrix = cv::Matx33d::eye();  // camera_matrix
  // distortion_coefficients: radtan k1 k2 p1 p2 [k3 [k4 k5 k6 [s1..s4 [tx ty]]]], fisheye k1..k4.
  std::vector<double> distortion;
  double avg_reprojection_error_px = 0.0;  // avg_reprojection_error
  std::vector<double> per_view_errors_px;  // per_view_reprojection_errors
  // extrinsic_parameters: one row per view, rvec then tvec (m), board -> camera.
  std::vector<cv::Vec6d> extrinsics;
};

// Throws std::runtime_error naming the file when it cannot be written.
void writeCalibrationFile(const std::string& path, const CalibrationFile& file);
// Throws std::runtime_error naming the file and the field when the file is
// missing, not YAML, lacks image_width, image_height, camera_matrix or
// distortion_coefficients, or holds a value out of range: a camera_matrix not
// 3x3, a focal length <= 0, an image size <= 0, a distortion count the model
// does not have, an unknown distortion_model.
CalibrationFile readCalibrationFile(const std::string& path);

// The file of a calibration made on this board.
CalibrationFile toCalibrationFile(const Calibration& calibration, const BoardSpec& board);

// The camera model nadir renders and undistorts with. It has only k1 k2 p1 p2
// k3: throws std::invalid_argument for a fisheye file, or radtan coefficients
// beyond k3 that are not zero.
render::CameraIntrinsics toCameraIntrinsics(const CalibrationFile& file);

}  // namespace nadir::calib
