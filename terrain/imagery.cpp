#include "terrain/imagery.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <vector>

#include "terrain/gdal_support.h"

namespace nadir::terrain {
namespace {

void checkStretch(const StretchParams& stretch, const std::string& source) {
  if (!(stretch.low_percent >= 0.0 && stretch.low_percent < stretch.high_percent &&
        stretch.high_percent <= 100.0)) {
    throw TerrainError(source + ": stretch percentiles " + std::to_string(stretch.low_percent) +
                       " .. " + std::to_string(stretch.high_percent) +
                       " must satisfy 0 <= low < high <= 100");
  }
}

}  // namespace

std::optional<cv::Vec3b> ImageryRaster::colourAtPixel(const PixelPoint& pixel,
                                                      Sampling sampling) const {
  if (rgb.empty() || !(pixel.col >= -0.5 && pixel.col <= width() - 0.5 && pixel.row >= -0.5 &&
                       pixel.row <= height() - 0.5)) {
    return std::nullopt;
  }
  const double col = std::clamp(pixel.col, 0.0, static_cast<double>(width() - 1));
  const double row = std::clamp(pixel.row, 0.0, static_cast<double>(height() - 1));
  if (sampling == Sampling::kNearest) {
    return rgb.at<cv::Vec3b>(static_cast<int>(std::lround(row)),
                             static_cast<int>(std::lround(col)));
  }
  const int c0 = std::min(static_cast<int>(col), std::max(width() - 2, 0));
  const int r0 = std::min(static_cast<int>(row), std::max(height() - 2, 0));
  const int c1 = std::min(c0 + 1, width() - 1);
  const int r1 = std::min(r0 + 1, height() - 1);
  const double fc = col - c0;
  const double fr = row - r0;
  const cv::Vec3b& nw = rgb.at<cv::Vec3b>(r0, c0);
  const cv::Vec3b& ne = rgb.at<cv::Vec3b>(r0, c1);
  const cv::Vec3b& sw = rgb.at<cv::Vec3b>(r1, c0);
  const cv::Vec3b& se = rgb.at<cv::Vec3b>(r1, c1);
  cv::Vec3b out;
  for (int k = 0; k < 3; ++k) {
    const double top = nw[k] + fc * (ne[k] - nw[k]);
    const double bottom = sw[k] + fc * (se[k] - sw[k]);
    out[k] = cv::saturate_cast<unsigned char>(top + fr * (bottom - top));
  }
  return out;
}

std::optional<cv::Vec3b> ImageryRaster::colourAt(const core::Geodetic& point,
                                                 Sampling sampling) const {
  return colourAtPixel(georef.pixelFromGeodetic(point), sampling);
}

cv::Mat stretchBand(const cv::Mat& band, const cv::Mat& valid, const StretchParams& stretch,
                    const std::string& source) {
  checkStretch(stretch, source);
  if (band.channels() != 1) {
    throw TerrainError(source + ": a band to stretch must have one channel");
  }
  cv::Mat values;
  band.convertTo(values, CV_32F);
  // Which samples count, as one mask built by whole-raster operations: a raster can
  // hold 2^28 samples.
  cv::Mat use;
  cv::compare(values, values, use, cv::CMP_EQ);
  if (!valid.empty()) use &= valid != 0;
  std::vector<float> samples;
  samples.reserve(static_cast<std::size_t>(cv::countNonZero(use)));
  for (int row = 0; row < values.rows; ++row) {
    const float* in = values.ptr<float>(row);
    const unsigned char* ok = use.ptr<unsigned char>(row);
    for (int col = 0; col < values.cols; ++col) {
      if (ok[col] != 0) samples.push_back(in[col]);
    }
  }
  cv::Mat out(band.size(), CV_8U, cv::Scalar(0));
  if (samples.empty()) return out;
  const auto percentile = [&samples](double percent) {
    const auto index = static_cast<std::size_t>(
        std::lround(percent / 100.0 * static_cast<double>(samples.size() - 1)));
    std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(index),
                     samples.end());
    return static_cast<double>(samples[index]);
  };
  const double low = percentile(stretch.low_percent);
  const double high = percentile(stretch.high_percent);
  const double gain = 255.0 / std::max(high - low, 1e-12);
  for (int row = 0; row < values.rows; ++row) {
    const float* in = values.ptr<float>(row);
    const unsigned char* ok = use.ptr<unsigned char>(row);
    auto* dst = out.ptr<unsigned char>(row);
    for (int col = 0; col < values.cols; ++col) {
      if (ok[col] != 0) dst[col] = cv::saturate_cast<unsigned char>((in[col] - low) * gain);
    }
  }
  return out;
}

ImageryRaster readImageryRgb(const std::string& path, const RasterRegion& region,
                             const StretchParams& stretch, const Crs& crs_if_none) {
  checkStretch(stretch, path);
  const RasterInfo info = readRasterInfo(path, crs_if_none);
  if (info.bands != 3 && info.bands != 4) {
    throw TerrainError(path + ": has " + std::to_string(info.bands) +
                       " bands; RGB imagery needs 3 (or 4 with alpha)");
  }
  const RasterWindow window = rasterWindow(info, region);
  const std::vector<BandSamples> samples = readBands(info, {1, 2, 3}, window, true);
  ImageryRaster imagery;
  imagery.georef = window.georef;
  imagery.source = path;
  std::vector<cv::Mat> bands;
  if (std::all_of(samples.begin(), samples.end(),
                  [](const BandSamples& band) { return band.values.depth() == CV_8U; })) {
    for (const BandSamples& band : samples) bands.push_back(band.values);
  } else {
    cv::Mat valid = samples[0].valid & samples[1].valid & samples[2].valid;
    for (const BandSamples& band : samples) {
      bands.push_back(stretchBand(band.values, valid, stretch, path));
    }
  }
  cv::merge(bands, imagery.rgb);
  return imagery;
}

ImageryRaster readImageryBands(const std::string& red_path, const std::string& green_path,
                               const std::string& blue_path, const RasterRegion& region,
                               const StretchParams& stretch, const Crs& crs_if_none) {
  checkStretch(stretch, red_path);
  const std::array<std::string, 3> paths{red_path, green_path, blue_path};
  std::array<RasterInfo, 3> infos;
  for (std::size_t k = 0; k < 3; ++k) {
    infos[k] = readRasterInfo(paths[k], crs_if_none);
    if (infos[k].bands != 1) {
      throw TerrainError(paths[k] + ": has " + std::to_string(infos[k].bands) +
                         " bands; expected a single band");
    }
  }
  for (std::size_t k = 1; k < 3; ++k) {
    const RasterGeoref& a = infos[0].georef;
    const RasterGeoref& b = infos[k].georef;
    if (infos[k].width != infos[0].width || infos[k].height != infos[0].height || !a.sameGrid(b)) {
      throw TerrainError(paths[0] + " and " + paths[k] + " do not share their georeferencing: " +
                         std::to_string(infos[0].width) + " x " + std::to_string(infos[0].height) +
                         " px, " + a.crs.name() + ", corner (" + std::to_string(a.corner_x) + ", " +
                         std::to_string(a.corner_y) + "), pixel " + std::to_string(a.pixel_dx) +
                         " vs " + std::to_string(infos[k].width) + " x " +
                         std::to_string(infos[k].height) + " px, " + b.crs.name() + ", corner (" +
                         std::to_string(b.corner_x) + ", " + std::to_string(b.corner_y) +
                         "), pixel " + std::to_string(b.pixel_dx));
    }
  }
  const RasterWindow window = rasterWindow(infos[0], region);
  std::array<BandSamples, 3> samples;
  cv::Mat valid(window.out_height, window.out_width, CV_8U, cv::Scalar(255));
  for (std::size_t k = 0; k < 3; ++k) {
    samples[k] = std::move(readBands(infos[k], {1}, window, false).front());
    valid &= samples[k].valid;
  }
  std::vector<cv::Mat> bands(3);
  for (std::size_t k = 0; k < 3; ++k) {
    bands[k] = stretchBand(samples[k].values, valid, stretch, paths[k]);
  }
  ImageryRaster imagery;
  cv::merge(bands, imagery.rgb);
  imagery.georef = window.georef;
  imagery.source = red_path + "," + green_path + "," + blue_path;
  return imagery;
}

ImageryRaster readImageWithBounds(const std::string& path, const LatLonBounds& bounds) {
  if (!std::ifstream(path).good()) throw TerrainError(path + ": cannot open file");
  if (!(bounds.north_deg > bounds.south_deg && bounds.north_deg <= 90.0 &&
        bounds.south_deg >= -90.0 && bounds.east_deg > bounds.west_deg &&
        bounds.east_deg - bounds.west_deg <= 360.0)) {
    throw TerrainError(
        path + ": bad corner coordinates (north " + std::to_string(bounds.north_deg) + ", south " +
        std::to_string(bounds.south_deg) + ", west " + std::to_string(bounds.west_deg) + ", east " +
        std::to_string(bounds.east_deg) + " deg)");
  }
  cv::Mat bgr;
  // OpenCV tries GDAL on what its own decoders refuse; its words go in the error.
  const GdalErrors errors;
  try {
    bgr = cv::imread(path, cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION);
  } catch (const cv::Exception& e) {
    throw TerrainError(path + ": OpenCV cannot decode it: " + e.what());
  }
  if (bgr.empty()) {
    const std::string content = describeFileContent(path);
    throw TerrainError(path + ": OpenCV cannot decode it as an image" +
                       (content.empty() ? std::string() : " (it is " + content + ")") +
                       errors.said());
  }
  ImageryRaster imagery;
  cv::cvtColor(bgr, imagery.rgb, cv::COLOR_BGR2RGB);
  imagery.source = path;
  imagery.georef.crs = Crs::geographic();
  imagery.georef.corner_x = bounds.west_deg;
  imagery.georef.corner_y = bounds.north_deg;
  imagery.georef.pixel_dx = (bounds.east_deg - bounds.west_deg) / bgr.cols;
  imagery.georef.pixel_dy = -(bounds.north_deg - bounds.south_deg) / bgr.rows;
  return imagery;
}

}  // namespace nadir::terrain
