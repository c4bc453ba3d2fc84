#include "calib/image_folder.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

namespace nadir::calib {

std::vector<std::string> imageFiles(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::exists(folder, error)) throw std::runtime_error(folder + ": no such folder");
  if (!fs::is_directory(folder, error))
    throw std::runtime_error(folder + ": not a folder of images");
  std::vector<std::string> files;
  fs::directory_iterator entries(folder, error);
  if (error) throw std::runtime_error(folder + ": cannot be read: " + error.message());
  for (const fs::directory_entry& entry : entries) {
    if (!entry.is_regular_file()) continue;
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    for (const char* known : {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm"}) {
      if (extension == known) {
        files.push_back(entry.path().string());
        break;
      }
    }
  }
  if (files.empty())
    throw std::runtime_error(folder +
                             ": no image in the folder (png, jpg, bmp, tif, pgm or ppm files)");
  std::sort(files.begin(), files.end());
  return files;
}

cv::Mat readGrayImage(const std::string& path) {
  try {
    return cv::imread(path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception&) {
    return {};
  }
}

}  // namespace nadir::calib
