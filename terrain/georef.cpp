#include "terrain/georef.h"

#include <tiffio.h>
#include <GeographicLib/Constants.hpp>
#include <GeographicLib/TransverseMercator.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string_view>
#include <vector>

namespace nadir::terrain {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr double kUtmFalseEasting_m = 500'000.0;
constexpr double kUtmSouthFalseNorthing_m = 10'000'000.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// GeoTIFF 1.0 tags and keys.
constexpr uint32_t kTagModelPixelScale = 33550;
constexpr uint32_t kTagModelTiepoint = 33922;
constexpr uint32_t kTagModelTransformation = 34264;
constexpr uint32_t kTagGeoKeyDirectory = 34735;
constexpr uint32_t kTagGdalNodata = 42113;
constexpr int kKeyModelType = 1024;
constexpr int kKeyRasterType = 1025;
constexpr int kKeyGeographicType = 2048;
constexpr int kKeyGeogAngularUnits = 2054;
constexpr int kKeyProjectedCsType = 3072;
constexpr int kKeyProjLinearUnits = 3076;
constexpr int kModelTypeProjected = 1;
constexpr int kModelTypeGeographic = 2;
constexpr int kRasterPixelIsPoint = 2;
constexpr int kUnitDegree = 9102;
constexpr int kUnitMetre = 9001;

double utmCentralMeridian_deg(int zone) { return 6.0 * zone - 183.0; }

std::string utmName(int zone, bool north) {
  return "UTM " + std::to_string(zone) + (north ? "N" : "S");
}

// Collects libtiff's messages for one file instead of printing them.
struct TiffMessages {
  std::string errors;
};

int tiffErrorHandler(TIFF*, void* user_data, const char* module, const char* fmt, va_list ap) {
  auto* messages = static_cast<TiffMessages*>(user_data);
  std::array<char, 512> text{};
  std::vsnprintf(text.data(), text.size(), fmt, ap);
  if (!messages->errors.empty()) messages->errors += "; ";
  if (module != nullptr) messages->errors += std::string(module) + ": ";
  messages->errors += text.data();
  return 1;
}

int tiffWarningHandler(TIFF*, void*, const char*, const char*, va_list) {
  return 1;  // unknown GeoTIFF tags are expected; say nothing
}

struct TiffCloser {
  void operator()(TIFF* tif) const { TIFFClose(tif); }
};
using TiffPtr = std::unique_ptr<TIFF, TiffCloser>;

TiffPtr openTiff(const std::string& path, TiffMessages& messages) {
  TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
  TIFFOpenOptionsSetErrorHandlerExtR(options, tiffErrorHandler, &messages);
  TIFFOpenOptionsSetWarningHandlerExtR(options, tiffWarningHandler, nullptr);
  TiffPtr tif(TIFFOpenExt(path.c_str(), "r", options));
  TIFFOpenOptionsFree(options);
  return tif;
}

// Reads an array tag whether libtiff knows it (registered by someone) or
// created it as an anonymous field on reading. False if absent.
bool getArrayTag(TIFF* tif, uint32_t tag, TIFFDataType type, uint32_t& count, void*& data) {
  const TIFFField* field = TIFFFindField(tif, tag, TIFF_ANY);
  if (field == nullptr || TIFFFieldDataType(field) != type) return false;
  count = 0;
  data = nullptr;
  if (TIFFFieldPassCount(field)) {
    if (TIFFFieldReadCount(field) == TIFF_VARIABLE2) {
      uint32_t n = 0;
      if (TIFFGetField(tif, tag, &n, &data) == 0) return false;
      count = n;
    } else {
      uint16_t n = 0;
      if (TIFFGetField(tif, tag, &n, &data) == 0) return false;
      count = n;
    }
  } else {
    if (TIFFGetField(tif, tag, &data) == 0) return false;
    count = type == TIFF_ASCII && data != nullptr
                ? static_cast<uint32_t>(std::strlen(static_cast<const char*>(data)))
                : static_cast<uint32_t>(TIFFFieldReadCount(field));
  }
  return data != nullptr;
}

std::vector<double> getDoubles(TIFF* tif, uint32_t tag) {
  uint32_t count = 0;
  void* data = nullptr;
  if (!getArrayTag(tif, tag, TIFF_DOUBLE, count, data)) return {};
  const auto* values = static_cast<const double*>(data);
  return {values, values + count};
}

std::vector<uint16_t> getShorts(TIFF* tif, uint32_t tag) {
  uint32_t count = 0;
  void* data = nullptr;
  if (!getArrayTag(tif, tag, TIFF_SHORT, count, data)) return {};
  const auto* values = static_cast<const uint16_t*>(data);
  return {values, values + count};
}

std::string getAscii(TIFF* tif, uint32_t tag) {
  uint32_t count = 0;
  void* data = nullptr;
  if (!getArrayTag(tif, tag, TIFF_ASCII, count, data)) return {};
  const auto* text = static_cast<const char*>(data);
  std::string value(text, count);
  value = value.substr(0, value.find('\0'));
  return value;
}

// GeoKeyDirectory: key id -> SHORT value stored in the directory itself.
struct GeoKeys {
  std::vector<std::pair<int, int>> short_values;
  std::vector<int> other_keys;  // keys whose value lives in another tag

  std::optional<int> get(int key) const {
    for (const auto& [id, value] : short_values) {
      if (id == key) return value;
    }
    return std::nullopt;
  }
  bool elsewhere(int key) const {
    return std::find(other_keys.begin(), other_keys.end(), key) != other_keys.end();
  }
};

GeoKeys parseGeoKeys(const std::vector<uint16_t>& directory, const std::string& path) {
  if (directory.size() < 4 || directory.size() < 4 + 4 * std::size_t{directory[3]}) {
    throw TerrainError(path + ": malformed GeoKeyDirectory tag (" +
                       std::to_string(directory.size()) + " values)");
  }
  GeoKeys keys;
  for (std::size_t i = 0; i < directory[3]; ++i) {
    const uint16_t* entry = &directory[4 + 4 * i];
    if (entry[1] == 0) {
      keys.short_values.emplace_back(entry[0], entry[3]);
    } else {
      keys.other_keys.push_back(entry[0]);
    }
  }
  return keys;
}

Crs crsFromGeoKeys(const GeoKeys& keys, const std::string& path) {
  const std::optional<int> model_type = keys.get(kKeyModelType);
  if (!model_type) {
    throw TerrainError(path + ": GeoTIFF has no GTModelTypeGeoKey (1024)");
  }
  if (*model_type == kModelTypeGeographic) {
    const std::optional<int> geographic_type = keys.get(kKeyGeographicType);
    if (!geographic_type) {
      throw TerrainError(path + ": geographic GeoTIFF without GeographicTypeGeoKey (2048)");
    }
    const std::optional<int> angular_unit = keys.get(kKeyGeogAngularUnits);
    if (angular_unit && *angular_unit != kUnitDegree) {
      throw TerrainError(path + ": angular unit " + std::to_string(*angular_unit) +
                         " is not degrees (9102)");
    }
    return Crs::fromEpsg(*geographic_type, path);
  }
  if (*model_type == kModelTypeProjected) {
    const std::optional<int> projected_type = keys.get(kKeyProjectedCsType);
    if (!projected_type) {
      throw TerrainError(path + ": projected GeoTIFF without ProjectedCSTypeGeoKey (3072)" +
                         (keys.elsewhere(kKeyProjectedCsType) ? " as a SHORT" : ""));
    }
    const std::optional<int> linear_unit = keys.get(kKeyProjLinearUnits);
    if (linear_unit && *linear_unit != kUnitMetre) {
      throw TerrainError(path + ": linear unit " + std::to_string(*linear_unit) +
                         " is not metres (9001)");
    }
    return Crs::fromEpsg(*projected_type, path);
  }
  throw TerrainError(path + ": unsupported GTModelTypeGeoKey " + std::to_string(*model_type) +
                     " (nadir reads 1 projected and 2 geographic)");
}

int cvDepthOf(const GeoTiffInfo& info, const std::string& path) {
  const int bits = info.bits_per_sample;
  switch (info.sample_format) {
    case SAMPLEFORMAT_UINT:
      if (bits == 8) return CV_8U;
      if (bits == 16) return CV_16U;
      break;
    case SAMPLEFORMAT_INT:
      if (bits == 8) return CV_8S;
      if (bits == 16) return CV_16S;
      if (bits == 32) return CV_32S;
      break;
    case SAMPLEFORMAT_IEEEFP:
      if (bits == 32) return CV_32F;
      if (bits == 64) return CV_64F;
      break;
    default:
      break;
  }
  throw TerrainError(path + ": unsupported sample type (" + std::to_string(bits) +
                     " bits, SampleFormat " + std::to_string(info.sample_format) + ")");
}

}  // namespace

Crs Crs::utm(int zone, bool north) {
  if (zone < 1 || zone > 60) {
    throw TerrainError("UTM zone " + std::to_string(zone) + " is outside 1..60");
  }
  Crs crs;
  crs.kind = Kind::kUtm;
  crs.utm_zone = zone;
  crs.utm_north = north;
  return crs;
}

Crs Crs::fromEpsg(int epsg, const std::string& source) {
  if (epsg == 4326) return geographic();
  if (epsg >= 32601 && epsg <= 32660) return utm(epsg - 32600, true);
  if (epsg >= 32701 && epsg <= 32760) return utm(epsg - 32700, false);
  throw TerrainError(source + ": unsupported CRS EPSG:" + std::to_string(epsg) +
                     " (nadir reads EPSG:4326 and WGS-84 UTM, EPSG:326zz and 327zz)");
}

int Crs::epsg() const {
  if (kind == Kind::kGeographic) return 4326;
  return (utm_north ? 32600 : 32700) + utm_zone;
}

std::string Crs::name() const {
  if (kind == Kind::kGeographic) return "EPSG:4326 (WGS 84)";
  return "EPSG:" + std::to_string(epsg()) + " (" + utmName(utm_zone, utm_north) + ")";
}

CrsPoint Crs::fromGeodetic(const core::Geodetic& point) const {
  const double lat_deg = point.lat_rad * kDegPerRad;
  const double lon_deg = point.lon_rad * kDegPerRad;
  if (kind == Kind::kGeographic) return {lon_deg, lat_deg};
  if (!(std::abs(lat_deg) <= 90.0) || !std::isfinite(lon_deg)) return {kNaN, kNaN};
  CrsPoint out;
  GeographicLib::TransverseMercator::UTM().Forward(utmCentralMeridian_deg(utm_zone), lat_deg,
                                                   lon_deg, out.x, out.y);
  out.x += kUtmFalseEasting_m;
  if (!utm_north) out.y += kUtmSouthFalseNorthing_m;
  return out;
}

core::Geodetic Crs::toGeodetic(const CrsPoint& point, double alt_m) const {
  if (kind == Kind::kGeographic) {
    return {point.y * kRadPerDeg, point.x * kRadPerDeg, alt_m};
  }
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  GeographicLib::TransverseMercator::UTM().Reverse(
      utmCentralMeridian_deg(utm_zone), point.x - kUtmFalseEasting_m,
      point.y - (utm_north ? 0.0 : kUtmSouthFalseNorthing_m), lat_deg, lon_deg);
  return {lat_deg * kRadPerDeg, lon_deg * kRadPerDeg, alt_m};
}

PixelGroundSize RasterGeoref::groundPixelSize(int width, int height) const {
  const PixelPoint centre{0.5 * (width - 1), 0.5 * (height - 1)};
  const core::Geodetic at = geodeticFromPixel(centre);
  if (crs.kind == Crs::Kind::kGeographic) {
    const double a = GeographicLib::Constants::WGS84_a();
    const double f = GeographicLib::Constants::WGS84_f();
    const double e2 = f * (2.0 - f);
    const double sin_lat = std::sin(at.lat_rad);
    const double w = std::sqrt(1.0 - e2 * sin_lat * sin_lat);
    const double prime_vertical_m = a / w;
    const double meridional_m = a * (1.0 - e2) / (w * w * w);
    return {std::abs(pixel_dx) * kRadPerDeg * prime_vertical_m * std::cos(at.lat_rad),
            std::abs(pixel_dy) * kRadPerDeg * meridional_m};
  }
  double x = 0.0, y = 0.0, gamma = 0.0, scale = 1.0;
  GeographicLib::TransverseMercator::UTM().Forward(utmCentralMeridian_deg(crs.utm_zone),
                                                   at.lat_rad * kDegPerRad, at.lon_rad * kDegPerRad,
                                                   x, y, gamma, scale);
  return {std::abs(pixel_dx) / scale, std::abs(pixel_dy) / scale};
}

bool RasterGeoref::sameGrid(const RasterGeoref& other) const {
  const auto close_rel = [](double a, double b) {
    return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
  };
  return crs == other.crs && close_rel(pixel_dx, other.pixel_dx) &&
         close_rel(pixel_dy, other.pixel_dy) &&
         std::abs(corner_x - other.corner_x) <= 1e-6 * std::abs(pixel_dx) &&
         std::abs(corner_y - other.corner_y) <= 1e-6 * std::abs(pixel_dy);
}

std::string describeFileContent(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 64> bytes{};
  in.read(bytes.data(), bytes.size());
  const auto n = static_cast<std::size_t>(in.gcount());
  const std::string head(bytes.data(), n);
  const auto starts = [&head](std::string_view magic) { return head.starts_with(magic); };
  if (n == 0) return "empty";
  if (starts("\x89PNG")) return "PNG image";
  if (starts("\xFF\xD8\xFF")) return "JPEG image";
  if (starts(std::string_view("II*\0", 4)) || starts(std::string_view("MM\0*", 4))) {
    return "TIFF image";
  }
  if (starts(std::string_view("II+\0", 4)) || starts(std::string_view("MM\0+", 4))) {
    return "BigTIFF image";
  }
  if (starts("GIF8")) return "GIF image";
  if (starts("\x1F\x8B")) return "gzip archive";
  if (starts("PK\x03\x04")) return "zip archive";
  bool printable = true;
  for (const char c : head) {
    const auto u = static_cast<unsigned char>(c);
    if (!(u == '\n' || u == '\r' || u == '\t' || (u >= 0x20 && u < 0x7F))) printable = false;
  }
  if (printable) {
    std::string first_line = head.substr(0, head.find_first_of("\r\n"));
    if (first_line.size() > 24) first_line = first_line.substr(0, 24) + "...";
    return "text starting '" + first_line + "'";
  }
  return {};
}

GeoTiffInfo readGeoTiffInfo(const std::string& path) {
  if (!std::ifstream(path).good()) {
    throw TerrainError(path + ": cannot open file");
  }
  const std::string content = describeFileContent(path);
  if (content != "TIFF image" && content != "BigTIFF image") {
    throw TerrainError(path + ": not a TIFF file" +
                       (content.empty() ? std::string() : " (it is " + content + ")"));
  }
  TiffMessages messages;
  const TiffPtr tif = openTiff(path, messages);
  if (!tif) {
    throw TerrainError(path + ": libtiff cannot read it: " + messages.errors);
  }

  GeoTiffInfo info;
  uint32_t width = 0;
  uint32_t height = 0;
  uint16_t samples = 1;
  uint16_t bits = 1;
  uint16_t format = SAMPLEFORMAT_UINT;
  TIFFGetField(tif.get(), TIFFTAG_IMAGEWIDTH, &width);
  TIFFGetField(tif.get(), TIFFTAG_IMAGELENGTH, &height);
  TIFFGetFieldDefaulted(tif.get(), TIFFTAG_SAMPLESPERPIXEL, &samples);
  TIFFGetFieldDefaulted(tif.get(), TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tif.get(), TIFFTAG_SAMPLEFORMAT, &format);
  if (width == 0 || height == 0 || width > (1u << 30) / std::max<uint32_t>(height, 1)) {
    throw TerrainError(path + ": unusable image size " + std::to_string(width) + " x " +
                       std::to_string(height));
  }
  info.width = static_cast<int>(width);
  info.height = static_cast<int>(height);
  info.samples_per_pixel = samples;
  info.bits_per_sample = bits;
  info.sample_format = format;

  const std::vector<uint16_t> directory = getShorts(tif.get(), kTagGeoKeyDirectory);
  if (directory.empty()) {
    throw TerrainError(path + ": no GeoTIFF georeferencing (GeoKeyDirectory tag 34735 missing)");
  }
  const GeoKeys keys = parseGeoKeys(directory, path);
  info.georef.crs = crsFromGeoKeys(keys, path);
  info.pixel_is_point = keys.get(kKeyRasterType).value_or(1) == kRasterPixelIsPoint;

  // Raster space: (0,0) is the outer corner of the first pixel for
  // PixelIsArea and its centre for PixelIsPoint.
  const double raster_offset = info.pixel_is_point ? 0.5 : 0.0;
  const std::vector<double> scale = getDoubles(tif.get(), kTagModelPixelScale);
  const std::vector<double> tiepoint = getDoubles(tif.get(), kTagModelTiepoint);
  const std::vector<double> transform = getDoubles(tif.get(), kTagModelTransformation);
  double scale_x = 0.0, scale_y = 0.0, x_at_origin = 0.0, y_at_origin = 0.0;
  if (scale.size() >= 2 && tiepoint.size() >= 6) {
    scale_x = scale[0];
    scale_y = -scale[1];
    x_at_origin = tiepoint[3] - tiepoint[0] * scale_x;
    y_at_origin = tiepoint[4] - tiepoint[1] * scale_y;
  } else if (transform.size() >= 16) {
    if (transform[1] != 0.0 || transform[4] != 0.0) {
      throw TerrainError(path + ": rotated raster (ModelTransformation has shear terms)");
    }
    scale_x = transform[0];
    scale_y = transform[5];
    x_at_origin = transform[3];
    y_at_origin = transform[7];
  } else {
    throw TerrainError(path +
                       ": no ModelPixelScale (33550) + ModelTiepoint (33922) or "
                       "ModelTransformation (34264) tag");
  }
  if (!(scale_x > 0.0) || !(scale_y < 0.0) || !std::isfinite(x_at_origin) ||
      !std::isfinite(y_at_origin)) {
    throw TerrainError(path + ": not a north-up raster (pixel size " + std::to_string(scale_x) +
                       ", " + std::to_string(scale_y) + ")");
  }
  info.georef.pixel_dx = scale_x;
  info.georef.pixel_dy = scale_y;
  info.georef.corner_x = x_at_origin - raster_offset * scale_x;
  info.georef.corner_y = y_at_origin - raster_offset * scale_y;

  const std::string nodata = getAscii(tif.get(), kTagGdalNodata);
  if (!nodata.empty()) {
    char* end = nullptr;
    const double value = std::strtod(nodata.c_str(), &end);
    if (end != nodata.c_str()) {
      info.has_nodata = true;
      info.nodata = value;
    }
  }
  return info;
}

cv::Mat readGeoTiffPixels(const std::string& path, const GeoTiffInfo& info) {
  const int depth = cvDepthOf(info, path);
  cv::Mat pixels;
  try {
    pixels = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw TerrainError(path + ": OpenCV cannot decode it: " + e.what());
  }
  if (pixels.empty()) {
    throw TerrainError(path + ": OpenCV cannot decode the pixels (truncated or unsupported TIFF)");
  }
  if (pixels.cols != info.width || pixels.rows != info.height ||
      pixels.channels() != info.samples_per_pixel || pixels.depth() != depth) {
    throw TerrainError(path + ": OpenCV decoded " + std::to_string(pixels.cols) + " x " +
                       std::to_string(pixels.rows) + " x " + std::to_string(pixels.channels()) +
                       " of type " + cv::typeToString(pixels.type()) + ", the TIFF header says " +
                       std::to_string(info.width) + " x " + std::to_string(info.height) + " x " +
                       std::to_string(info.samples_per_pixel) + " of type " +
                       cv::typeToString(CV_MAKETYPE(depth, 1)));
  }
  // OpenCV hands colour back as BGR(A); restore the file's order.
  if (pixels.channels() == 3 || pixels.channels() == 4) {
    cv::Mat file_order(pixels.size(), pixels.type());
    const std::array<int, 8> from_to{0, 2, 1, 1, 2, 0, 3, 3};
    cv::mixChannels(&pixels, 1, &file_order, 1, from_to.data(),
                    static_cast<std::size_t>(pixels.channels()));
    pixels = file_order;
  }
  return pixels;
}

}  // namespace nadir::terrain
