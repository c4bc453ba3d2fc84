#include "terrain/elevation.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>
#include <sstream>
#include <string_view>

namespace nadir::terrain {
namespace {

constexpr float kVoid = std::numeric_limits<float>::quiet_NaN();
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr std::uintmax_t kSrtm3Bytes = 1201u * 1201u * 2u;
constexpr std::uintmax_t kSrtm1Bytes = 3601u * 3601u * 2u;

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// A .hgt that GDAL will not read: say why in SRTM's terms.
void explainHgt(const std::string& path) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) return;
  const std::string content = describeFileContent(path);
  if (content.ends_with("image") || content.ends_with("archive")) {
    throw TerrainError(path + ": not an SRTM .hgt file (it is a " + content + ")");
  }
  if (size != kSrtm3Bytes && size != kSrtm1Bytes) {
    throw TerrainError(path + ": " + std::to_string(size) +
                       " bytes is not an SRTM .hgt size (2884802 for 1201 x 1201 or 25934402 "
                       "for 3601 x 3601; truncated?)");
  }
}

// Band 1 of region of a raster, voids NaN.
ElevationRaster readSingleBand(const RasterInfo& info, const RasterRegion& region) {
  const RasterWindow window = rasterWindow(info, region);
  BandSamples samples = std::move(readBands(info, {1}, window, false).front());
  ElevationRaster raster;
  raster.width = window.out_width;
  raster.height = window.out_height;
  raster.georef = window.georef;
  raster.source = info.path;
  samples.values.setTo(kVoid, samples.valid == 0);
  const auto* first = samples.values.ptr<float>();
  raster.height_m.assign(first, first + samples.values.total());
  return raster;
}

// Undulations of the geoid grid at geoid_path under every sample of dem,
// added to its heights. Evaluated exactly every kKnotStep samples and
// bilinearly between: a geoid grid is far coarser than a DEM.
void addGeoid(ElevationRaster& dem, const std::string& geoid_path) {
  constexpr int kKnotStep = 16;
  const RasterInfo info = readRasterInfo(geoid_path);
  if (info.bands != 1) {
    throw TerrainError(geoid_path + ": a geoid grid has one band, this has " +
                       std::to_string(info.bands));
  }
  const PixelGroundSize ground = dem.georef.groundPixelSize(dem.width, dem.height);
  const PixelPoint centre{0.5 * (dem.width - 1), 0.5 * (dem.height - 1)};
  RasterRegion region;
  region.centre = dem.georef.geodeticFromPixel(centre);
  region.half_size_m = 0.75 * std::max(dem.width * ground.col_m, dem.height * ground.row_m);
  RasterInfo shifted = info;
  // A global grid may run from 0 to 360 deg east.
  if (info.georef.crs.kind == Crs::Kind::kGeographic) {
    const double lon_deg = region.centre.lon_rad * kDegPerRad;
    const double west = info.georef.corner_x;
    if (lon_deg < west) shifted.georef.corner_x -= 360.0;
    if (lon_deg > west + info.width * info.georef.pixel_dx) shifted.georef.corner_x += 360.0;
  }
  const ElevationRaster geoid = readSingleBand(shifted, region);

  const auto undulation = [&](int col, int row) {
    const core::Geodetic at = dem.georef.geodeticFromPixel({double(col), double(row)});
    const std::optional<double> n = geoid.heightAt(at);
    if (!n || !std::isfinite(*n)) {
      throw TerrainError(geoid_path + ": does not cover " + dem.source + " (no undulation at " +
                         std::to_string(at.lat_rad * kDegPerRad) + ", " +
                         std::to_string(at.lon_rad * kDegPerRad) + " deg)");
    }
    return *n;
  };
  const auto knots = [](int size) {
    std::vector<int> at;
    for (int i = 0; i < size - 1; i += kKnotStep) at.push_back(i);
    at.push_back(size - 1);
    return at;
  };
  const std::vector<int> cols = knots(dem.width);
  const std::vector<int> rows = knots(dem.height);
  std::vector<double> n_at_knots(cols.size() * rows.size());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t c = 0; c < cols.size(); ++c) {
      n_at_knots[r * cols.size() + c] = undulation(cols[c], rows[r]);
    }
  }
  const auto [low, high] = std::minmax_element(n_at_knots.begin(), n_at_knots.end());
  dem.geoid_min_m = *low;
  dem.geoid_max_m = *high;
  dem.geoid_source = geoid_path;
  std::size_t r = 0;
  for (int row = 0; row < dem.height; ++row) {
    while (r + 2 < rows.size() && rows[r + 1] <= row) ++r;
    const std::size_t r1 = std::min(r + 1, rows.size() - 1);
    const double fr = r1 == r ? 0.0 : double(row - rows[r]) / (rows[r1] - rows[r]);
    std::size_t c = 0;
    for (int col = 0; col < dem.width; ++col) {
      while (c + 2 < cols.size() && cols[c + 1] <= col) ++c;
      const std::size_t c1 = std::min(c + 1, cols.size() - 1);
      const double fc = c1 == c ? 0.0 : double(col - cols[c]) / (cols[c1] - cols[c]);
      const auto knot = [&](std::size_t kr, std::size_t kc) {
        return n_at_knots[kr * cols.size() + kc];
      };
      const double top = knot(r, c) + fc * (knot(r, c1) - knot(r, c));
      const double bottom = knot(r1, c) + fc * (knot(r1, c1) - knot(r1, c));
      dem.height_m[std::size_t(row) * std::size_t(dem.width) + std::size_t(col)] +=
          static_cast<float>(top + fr * (bottom - top));
    }
  }
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

// ESRI ASCII grid, strictly: GDAL's AAIGrid driver reads a missing or
// non-numeric value as 0 and ignores extra values, so nadir keeps its own
// reader and refuses such a file. Voids are NaN.
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
  return dem;
}

// The CRS of an ASCII grid: its .prj sidecar if it has one, else crs_if_none.
Crs asciiGridCrs(const std::string& path, const Crs& crs_if_none) {
  for (const char* ext : {".prj", ".PRJ"}) {
    const std::string prj = std::filesystem::path(path).replace_extension(ext).string();
    std::ifstream in(prj);
    if (!in) continue;
    std::stringstream text;
    text << in.rdbuf();
    return Crs::fromDefinition(text.str(), prj);
  }
  return crs_if_none;
}

bool looksLikeAsciiGrid(const std::string& path) {
  if (!describeFileContent(path).starts_with("text")) return false;
  std::ifstream in(path);
  std::string first;
  in >> first;
  std::transform(first.begin(), first.end(), first.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return first == "ncols" || first == "nrows";
}

// The part of a DEM read whole that region asks for (averaged when coarser).
ElevationRaster windowOf(ElevationRaster whole, const RasterRegion& region) {
  RasterInfo info;
  info.path = whole.source;
  info.width = whole.width;
  info.height = whole.height;
  info.georef = whole.georef;
  const RasterWindow window = rasterWindow(info, region);
  const cv::Mat all(whole.height, whole.width, CV_32F, whole.height_m.data());
  cv::Mat part = all(cv::Rect(window.col, window.row, window.width, window.height)).clone();
  if (window.out_width != window.width || window.out_height != window.height) {
    cv::resize(part, part, cv::Size(window.out_width, window.out_height), 0, 0, cv::INTER_AREA);
  }
  ElevationRaster dem = std::move(whole);
  dem.width = window.out_width;
  dem.height = window.out_height;
  dem.georef = window.georef;
  dem.height_m.assign(part.begin<float>(), part.end<float>());
  return dem;
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

ElevationRaster readElevation(const std::string& path, const ElevationReadOptions& options) {
  const std::string ext = lowerExtension(path);
  ElevationRaster dem;
  const bool read_whole =
      ext == ".asc" ||
      (ext != ".hgt" && std::filesystem::is_regular_file(path) && looksLikeAsciiGrid(path));
  if (read_whole) {
    dem = readEsriAsciiGrid(path, asciiGridCrs(path, options.crs_if_none));
  } else {
    if (ext == ".hgt") explainHgt(path);
    RasterInfo info;
    try {
      info = readRasterInfo(path, options.crs_if_none);
    } catch (const TerrainError& e) {
      if (ext == ".hgt") {
        throw TerrainError(std::string(e.what()) +
                           "; an SRTM tile's file name starts with its south-west corner, e.g. "
                           "N44W072.hgt");
      }
      throw;
    }
    if (info.bands != 1) {
      throw TerrainError(path + ": has " + std::to_string(info.bands) + " bands; a DEM has one");
    }
    dem = readSingleBand(info, options.region);
  }
  dem.filled_voids = fillVoids(dem.height_m, dem.width, dem.height, path);
  if (read_whole && (options.region.half_size_m > 0.0 || options.region.resolution_m > 0.0)) {
    dem = windowOf(std::move(dem), options.region);
  }
  if (!options.geoid_path.empty()) addGeoid(dem, options.geoid_path);
  return dem;
}

}  // namespace nadir::terrain
