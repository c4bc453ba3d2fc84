#pragma once
// OpenCV's sample photographs (tests/data/calib/opencv_left, README.md there):
// 13 views of a 9 x 6 inner-corner board with 25 mm squares, 640 x 480 grey.

#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace nadir::calib::test {

inline std::string photoDir() { return std::string(NADIR_TEST_DATA_DIR) + "/calib/opencv_left"; }

inline std::vector<std::string> photoNames() {
  return {"left01", "left02", "left03", "left04", "left05", "left06", "left07",
          "left08", "left09", "left11", "left12", "left13", "left14"};
}

inline cv::Mat loadPhoto(const std::string& name) {
  return cv::imread(photoDir() + "/" + name + ".jpg", cv::IMREAD_GRAYSCALE);
}

// The corners as OpenCV's calibration sample (4.6) finds them: the classic
// detector, then cv::cornerSubPix with an 11 x 11 half-window. Empty if not found.
inline std::vector<cv::Point2f> sampleCorners(const cv::Mat& gray) {
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(
          gray, cv::Size(9, 6), corners,
          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_FAST_CHECK | cv::CALIB_CB_NORMALIZE_IMAGE))
    return {};
  cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.0001));
  return corners;
}

}  // namespace nadir::calib::test
