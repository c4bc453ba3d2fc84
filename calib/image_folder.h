#pragma once
// A folder of calibration photographs.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace nadir::calib {

// The image files directly in folder (png, jpg, jpeg, bmp, tif, tiff, pgm,
// ppm; any case), sorted by name. Throws std::runtime_error naming the folder
// when it is not a folder or holds no such file.
std::vector<std::string> imageFiles(const std::string& folder);

// The image as 8-bit grey; empty when the file cannot be read as an image.
cv::Mat readGrayImage(const std::string& path);

}  // namespace nadir::calib
