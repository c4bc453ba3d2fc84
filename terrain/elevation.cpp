#include "terrain/elevation.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace nadir::terrain {
namespace {

constexpr float kVoid = std::numeric_limits<float>::quiet_NaN();
constexpr int16_t kSrtmVoid = -32768;

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool isImageOrArchive(const std::string& content) {
  return content.ends_with("image") || content.ends_with("archive");
}

std::uintmax_t fileSize(const std::string& path) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error || !std::ifstream(path).good()) {
    throw TerrainError(path + ": cannot open file");
  }
  return size;
}

// The first "N44W072"-like pattern in the file name (so "N44W072.hgt",
// "SRTM1_N44W072.hgt") -> south-west corner in degrees.
bool parseSrtmName(const std::string& path, int& lat_deg, int& lon_deg) {
  const std::string name = std::filesystem::path(path).filename().string();
  const auto upper = [&name](std::size_t i) {
    return static_cast<char>(std::toupper(static_cast<unsigned char>(name[i])));
  };
  const auto digits = [&name](std::size_t from, std::size_t count) {
    for (std::size_t i = from; i < from + count; ++i) {
      if (!std::isdigit(static_cast<unsigned char>(name[i]))) return false;
    }
    return true;
  };
  for (std::size_t at = 0; at + 7 <= name.size(); ++at) {
    const char ns = upper(at);
    const char ew = upper(at + 3);
    if ((ns != 'N' && ns != 'S') || (ew != 'E' && ew != 'W') || !digits(at + 1, 2) ||
        !digits(at + 4, 3)) {
      continue;
    }
    lat_deg = std::stoi(name.substr(at + 1, 2)) * (ns == 'S' ? -1 : 1);
    lon_deg = std::stoi(name.substr(at + 4, 3)) * (ew == 'W' ? -1 : 1);
    return lat_deg >= -90 && lat_deg < 90 && lon_deg >= -180 && lon_deg < 180;
  }
  return false;
}

// Accumulates inverse-distance weights from the nearest valid samples on
// both sides of every void along one line of the raster.
void accumulateAlongLine(const std::vector<float>& height_m, const std::vector<int32_t>& slot,
                         std::size_t start, std::size_t stride, int count,
                         std::vector<double>& weight_sum, std::vector<double>& value_sum) {
  for (int direction : {1, -1}) {
    int last_valid = -1;
    float last_value = 0.0f;
    for (int step = 0; step < count; ++step) {
      const int k = direction > 0 ? step : count - 1 - step;
      const std::size_t i = start + static_cast<std::size_t>(k) * stride;
      if (!std::isnan(height_m[i])) {
        last_valid = k;
        last_value = height_m[i];
      } else if (last_valid >= 0) {
        const double weight = 1.0 / std::abs(k - last_valid);
        weight_sum[static_cast<std::size_t>(slot[i])] += weight;
        value_sum[static_cast<std::size_t>(slot[i])] += weight * last_value;
      }
    }
  }
}

double parseNumber(std::string_view token, const std::string& path, const std::string& what) {
  double value = 0.0;
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc() || end != token.data() + token.size()) {
    throw TerrainError(path + ": " + what + ": '" + std::string(token) + "' is not a number");
  }
  return value;
}

}  // namespace

std::optional<double> ElevationRaster::heightAtPixel(const PixelPoint& pixel) const {
  if (!(pixel.col >= -0.5 && pixel.col <= width - 0.5 && pixel.row >= -0.5 &&
        pixel.row <= height - 0.5)) {
    return std::nullopt;
  }
  return heightAtPixelClamped(pixel);
}

double ElevationRaster::heightAtPixelClamped(const PixelPoint& pixel) const {
  if (std::isnan(pixel.col) || std::isnan(pixel.row)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double col = std::clamp(pixel.col, 0.0, static_cast<double>(width - 1));
  const double row = std::clamp(pixel.row, 0.0, static_cast<double>(height - 1));
  const int c0 = std::min(static_cast<int>(col), std::max(width - 2, 0));
  const int r0 = std::min(static_cast<int>(row), std::max(height - 2, 0));
  const int c1 = std::min(c0 + 1, width - 1);
  const int r1 = std::min(r0 + 1, height - 1);
  const double fc = col - c0;
  const double fr = row - r0;
  const double top = at(c0, r0) + fc * (at(c1, r0) - at(c0, r0));
  const double bottom = at(c0, r1) + fc * (at(c1, r1) - at(c0, r1));
  return top + fr * (bottom - top);
}

std::optional<double> ElevationRaster::heightAt(const core::Geodetic& point) const {
  return heightAtPixel(georef.pixelFromGeodetic(point));
}

int fillVoids(std::vector<float>& height_m, int width, int height, const std::string& source) {
  std::vector<std::size_t> voids;
  for (std::size_t i = 0; i < height_m.size(); ++i) {
    if (std::isnan(height_m[i])) voids.push_back(i);
  }
  const int filled = static_cast<int>(voids.size());
  if (voids.empty()) return 0;
  if (voids.size() == height_m.size()) {
    throw TerrainError(source + ": every elevation sample is a void (nodata)");
  }
  std::vector<int32_t> slot(height_m.size(), -1);
  const auto w = static_cast<std::size_t>(width);
  const auto h = static_cast<std::size_t>(height);
  while (!voids.empty()) {
    for (std::size_t k = 0; k < voids.size(); ++k) slot[voids[k]] = static_cast<int32_t>(k);
    std::vector<double> weight_sum(voids.size(), 0.0);
    std::vector<double> value_sum(voids.size(), 0.0);
    // Only lines holding a void are scanned.
    std::vector<char> row_has_void(h, 0);
    std::vector<char> col_has_void(w, 0);
    for (const std::size_t i : voids) {
      row_has_void[i / w] = 1;
      col_has_void[i % w] = 1;
    }
    for (std::size_t row = 0; row < h; ++row) {
      if (row_has_void[row]) {
        accumulateAlongLine(height_m, slot, row * w, 1, width, weight_sum, value_sum);
      }
    }
    for (std::size_t col = 0; col < w; ++col) {
      if (col_has_void[col]) {
        accumulateAlongLine(height_m, slot, col, w, height, weight_sum, value_sum);
      }
    }
    // Commit after the pass so that a pass only uses samples valid before it.
    std::vector<std::size_t> remaining;
    for (std::size_t k = 0; k < voids.size(); ++k) {
      if (weight_sum[k] > 0.0) {
        height_m[voids[k]] = static_cast<float>(value_sum[k] / weight_sum[k]);
      } else {
        remaining.push_back(voids[k]);
      }
    }
    voids.swap(remaining);
  }
  return filled;
}

ElevationRaster readSrtmHgt(const std::string& path) {
  const std::uintmax_t size = fileSize(path);
  const std::string content = describeFileContent(path);
  if (isImageOrArchive(content)) {
    throw TerrainError(path + ": not an SRTM .hgt file (it is a " + content + ")");
  }
  int samples = 0;
  if (size == 1201u * 1201u * 2u) {
    samples = 1201;
  } else if (size == 3601u * 3601u * 2u) {
    samples = 3601;
  } else {
    throw TerrainError(path + ": " + std::to_string(size) +
                       " bytes is not an SRTM .hgt size (2884802 for 1201 x 1201 or 25934402 "
                       "for 3601 x 3601; truncated?)" +
                       (content.starts_with("text") ? " (it is " + content + ")" : ""));
  }
  int lat_deg = 0;
  int lon_deg = 0;
  if (!parseSrtmName(path, lat_deg, lon_deg)) {
    throw TerrainError(path +
                       ": cannot tell the tile's corner from the file name (expected e.g. "
                       "N44W072.hgt)");
  }

  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (in.gcount() != static_cast<std::streamsize>(bytes.size())) {
    throw TerrainError(path + ": read only " + std::to_string(in.gcount()) + " of " +
                       std::to_string(size) + " bytes");
  }

  ElevationRaster dem;
  dem.width = samples;
  dem.height = samples;
  dem.source = path;
  dem.height_m.resize(static_cast<std::size_t>(samples) * static_cast<std::size_t>(samples));
  for (std::size_t i = 0; i < dem.height_m.size(); ++i) {
    const auto value =
        static_cast<int16_t>(static_cast<uint16_t>(bytes[2 * i] << 8 | bytes[2 * i + 1]));
    dem.height_m[i] = value == kSrtmVoid ? kVoid : static_cast<float>(value);
  }
  const double spacing_deg = 1.0 / (samples - 1);
  dem.georef.crs = Crs::geographic();
  dem.georef.pixel_dx = spacing_deg;
  dem.georef.pixel_dy = -spacing_deg;
  // Pixel (0,0) is centred on the tile's north-west corner.
  dem.georef.corner_x = lon_deg - 0.5 * spacing_deg;
  dem.georef.corner_y = lat_deg + 1 + 0.5 * spacing_deg;
  dem.filled_voids = fillVoids(dem.height_m, dem.width, dem.height, path);
  return dem;
}

ElevationRaster readGeoTiffElevation(const std::string& path) {
  const GeoTiffInfo info = readGeoTiffInfo(path);
  if (info.samples_per_pixel != 1) {
    throw TerrainError(path + ": has " + std::to_string(info.samples_per_pixel) +
                       " bands; a DEM has one");
  }
  const cv::Mat pixels = readGeoTiffPixels(path, info);
  cv::Mat values;
  pixels.convertTo(values, CV_64F);
  // The nodata value as it reads back from a sample of the file's type.
  const double nodata = info.sample_format == 3 && info.bits_per_sample == 32
                            ? static_cast<double>(static_cast<float>(info.nodata))
                            : info.nodata;

  ElevationRaster dem;
  dem.width = info.width;
  dem.height = info.height;
  dem.georef = info.georef;
  dem.source = path;
  dem.height_m.resize(static_cast<std::size_t>(dem.width) * static_cast<std::size_t>(dem.height));
  for (int row = 0; row < dem.height; ++row) {
    const double* in = values.ptr<double>(row);
    float* out = &dem.height_m[static_cast<std::size_t>(row) * static_cast<std::size_t>(dem.width)];
    for (int col = 0; col < dem.width; ++col) {
      const bool is_void =
          std::isnan(in[col]) ||
          (info.has_nodata && (in[col] == nodata || (std::isnan(nodata) && std::isnan(in[col]))));
      out[col] = is_void ? kVoid : static_cast<float>(in[col]);
    }
  }
  dem.filled_voids = fillVoids(dem.height_m, dem.width, dem.height, path);
  return dem;
}

ElevationRaster readEsriAsciiGrid(const std::string& path, const Crs& crs) {
  if (!std::ifstream(path).good()) throw TerrainError(path + ": cannot open file");
  const std::string content = describeFileContent(path);
  if (!content.starts_with("text")) {
    throw TerrainError(
        path + ": not an ESRI ASCII grid" +
        (content.empty() ? std::string(" (binary data)") : " (it is " + content + ")"));
  }
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();

  std::size_t pos = 0;
  const auto next_token = [&text, &pos]() -> std::string_view {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    const std::size_t begin = pos;
    while (pos < text.size() && !std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    return std::string_view(text).substr(begin, pos - begin);
  };

  // Header: "key value" pairs until the first numeric token.
  std::optional<double> ncols, nrows, xll, yll, cellsize, dx, dy, nodata;
  bool x_is_centre = false;
  bool y_is_centre = false;
  std::size_t data_start = 0;
  while (true) {
    const std::size_t before = pos;
    const std::string_view token = next_token();
    if (token.empty() || !std::isalpha(static_cast<unsigned char>(token.front()))) {
      data_start = before;
      break;
    }
    std::string key(token);
    std::transform(key.begin(), key.end(), key.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const double value = parseNumber(next_token(), path, key);
    if (key == "ncols") {
      ncols = value;
    } else if (key == "nrows") {
      nrows = value;
    } else if (key == "xllcorner" || key == "xllcenter" || key == "xllcentre") {
      xll = value;
      x_is_centre = key != "xllcorner";
    } else if (key == "yllcorner" || key == "yllcenter" || key == "yllcentre") {
      yll = value;
      y_is_centre = key != "yllcorner";
    } else if (key == "cellsize") {
      cellsize = value;
    } else if (key == "dx") {
      dx = value;
    } else if (key == "dy") {
      dy = value;
    } else if (key == "nodata_value") {
      nodata = value;
    } else {
      throw TerrainError(path + ": unknown ESRI ASCII grid header key '" + key + "'");
    }
  }
  if (!ncols || !nrows || !xll || !yll || !(cellsize || (dx && dy))) {
    throw TerrainError(path +
                       ": not an ESRI ASCII grid (needs ncols, nrows, xllcorner|xllcenter, "
                       "yllcorner|yllcenter and cellsize)");
  }
  const double size_x = cellsize ? *cellsize : *dx;
  const double size_y = cellsize ? *cellsize : *dy;
  if (*ncols < 1 || *nrows < 1 || *ncols != std::floor(*ncols) || *nrows != std::floor(*nrows) ||
      *ncols * *nrows > double{1 << 30} || !(size_x > 0) || !(size_y > 0)) {
    throw TerrainError(path + ": bad ESRI ASCII grid header (ncols " + std::to_string(*ncols) +
                       ", nrows " + std::to_string(*nrows) + ", cell size " +
                       std::to_string(size_x) + " x " + std::to_string(size_y) + ")");
  }

  ElevationRaster dem;
  dem.width = static_cast<int>(*ncols);
  dem.height = static_cast<int>(*nrows);
  dem.source = path;
  dem.georef.crs = crs;
  dem.georef.pixel_dx = size_x;
  dem.georef.pixel_dy = -size_y;
  dem.georef.corner_x = *xll - (x_is_centre ? 0.5 * size_x : 0.0);
  dem.georef.corner_y = *yll + dem.height * size_y - (y_is_centre ? 0.5 * size_y : 0.0);

  const std::size_t count =
      static_cast<std::size_t>(dem.width) * static_cast<std::size_t>(dem.height);
  dem.height_m.reserve(count);
  pos = data_start;
  while (dem.height_m.size() < count) {
    const std::string_view token = next_token();
    if (token.empty()) {
      throw TerrainError(path + ": expected " + std::to_string(count) + " values (" +
                         std::to_string(dem.height) + " rows of " + std::to_string(dem.width) +
                         "), found " + std::to_string(dem.height_m.size()));
    }
    const double value =
        parseNumber(token, path, "value " + std::to_string(dem.height_m.size() + 1));
    dem.height_m.push_back(
        (nodata && value == *nodata) || std::isnan(value) ? kVoid : static_cast<float>(value));
  }
  if (!next_token().empty()) {
    throw TerrainError(path + ": more than the " + std::to_string(count) +
                       " values the header announces");
  }
  dem.filled_voids = fillVoids(dem.height_m, dem.width, dem.height, path);
  return dem;
}

ElevationRaster readElevation(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".hgt") return readSrtmHgt(path);
  if (ext == ".tif" || ext == ".tiff") return readGeoTiffElevation(path);
  if (ext == ".asc") return readEsriAsciiGrid(path);

  const std::uintmax_t size = fileSize(path);
  const std::string content = describeFileContent(path);
  if (content == "TIFF image") return readGeoTiffElevation(path);
  if (content.starts_with("text")) {
    std::ifstream in(path);
    std::string first;
    in >> first;
    std::transform(first.begin(), first.end(), first.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (first == "ncols" || first == "nrows") return readEsriAsciiGrid(path);
  }
  if (size == 1201u * 1201u * 2u || size == 3601u * 3601u * 2u) return readSrtmHgt(path);
  throw TerrainError(path + ": unknown elevation format" +
                     (content.empty() ? std::string() : " (it is " + content + ")") +
                     "; nadir reads SRTM .hgt, GeoTIFF and ESRI ASCII grids");
}

}  // namespace nadir::terrain
