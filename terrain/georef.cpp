#include "terrain/georef.h"

#include <ogr_spatialref.h>
#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/TransverseMercator.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <string_view>

#include "terrain/gdal_support.h"

namespace nadir::terrain {

namespace {

std::string wktOf(const OGRSpatialReference& srs) {
  char* text = nullptr;
  srs.exportToWkt(&text);
  std::string wkt = text == nullptr ? "" : text;
  CPLFree(text);
  return wkt;
}

}  // namespace

// PROJ's two transformations between WGS-84 and one CRS (srs, whose WKT is
// wkt). OGR's transformations keep state, so each call holds a lock.
class CrsTransform {
 public:
  CrsTransform(OGRSpatialReference srs, std::string wkt, const std::string& source)
      : srs_(std::move(srs)), wkt_(std::move(wkt)) {
    srs_.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    OGRSpatialReference wgs84;
    wgs84.SetWellKnownGeogCS("WGS84");
    wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    const char* code = srs_.GetAuthorityCode(nullptr);
    const char* authority = srs_.GetAuthorityName(nullptr);
    if (code != nullptr && authority != nullptr && std::string_view(authority) == "EPSG") {
      epsg_ = std::atoi(code);
    }
    GdalErrors errors;
    to_crs_.reset(OGRCreateCoordinateTransformation(&wgs84, &srs_));
    to_geodetic_.reset(OGRCreateCoordinateTransformation(&srs_, &wgs84));
    if (!to_crs_ || !to_geodetic_) {
      throw TerrainError(source + ": PROJ has no transformation between WGS 84 and " + name() +
                         errors.said());
    }
  }

  CrsPoint fromGeodetic(double lat_deg, double lon_deg) const {
    double x = lon_deg, y = lat_deg;
    const std::lock_guard lock(mutex_);
    if (!to_crs_->Transform(1, &x, &y)) return {kNaN, kNaN};
    return {x, y};
  }
  void toGeodetic(const CrsPoint& point, double& lat_deg, double& lon_deg) const {
    double x = point.x, y = point.y;
    const std::lock_guard lock(mutex_);
    if (!to_geodetic_->Transform(1, &x, &y)) x = y = kNaN;
    lon_deg = x;
    lat_deg = y;
  }
  bool sameAs(const CrsTransform& other) const {
    const char* options[] = {"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES",
                             "CRITERION=EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS", nullptr};
    return srs_.IsSame(&other.srs_, options) != 0;
  }
  int epsg() const { return epsg_; }
  std::string name() const {
    const char* name = srs_.GetName();
    const std::string label = name == nullptr ? "unnamed CRS" : name;
    return epsg_ > 0 ? "EPSG:" + std::to_string(epsg_) + " (" + label + ")" : label;
  }
  const std::string& wkt() const { return wkt_; }

 private:
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  OGRSpatialReference srs_;
  std::unique_ptr<OGRCoordinateTransformation> to_crs_;
  std::unique_ptr<OGRCoordinateTransformation> to_geodetic_;
  mutable std::mutex mutex_;
  int epsg_ = 0;
  std::string wkt_;
};

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr double kUtmFalseEasting_m = 500'000.0;
constexpr double kUtmSouthFalseNorthing_m = 10'000'000.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double utmCentralMeridian_deg(int zone) { return 6.0 * zone - 183.0; }

std::string utmName(int zone, bool north) {
  return "UTM " + std::to_string(zone) + (north ? "N" : "S");
}

OGRSpatialReference wgs84Geographic() {
  OGRSpatialReference wgs84;
  wgs84.SetWellKnownGeogCS("WGS84");
  return wgs84;
}

// PROJ's transformations for srs, shared by every Crs of the same WKT: a world
// reads its DEM, imagery and geoid, often in one CRS, and PROJ takes tens of
// milliseconds to build a transformation. Held weakly: one lives only while a
// Crs uses it.
std::shared_ptr<const CrsTransform> sharedTransform(OGRSpatialReference srs,
                                                    const std::string& source) {
  std::string wkt = wktOf(srs);
  if (wkt.empty()) return std::make_shared<const CrsTransform>(std::move(srs), wkt, source);
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<const CrsTransform>> built;
  {
    const std::lock_guard lock(mutex);
    const auto found = built.find(wkt);
    if (found != built.end()) {
      if (auto transform = found->second.lock()) return transform;
    }
  }
  auto transform = std::make_shared<const CrsTransform>(std::move(srs), wkt, source);
  const std::lock_guard lock(mutex);
  std::erase_if(built, [](const auto& entry) { return entry.second.expired(); });
  built[wkt] = transform;
  return transform;
}

// The fast path for WGS-84 geographic and UTM (in metres), else PROJ's.
Crs crsOf(OGRSpatialReference srs, const std::string& source) {
  if (srs.IsCompound()) srs.StripVertical();
  const OGRSpatialReference wgs84 = wgs84Geographic();
  const char* same_datum[] = {"CRITERION=EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS", nullptr};
  if (srs.IsGeographic()) {
    if (srs.IsSame(&wgs84, same_datum) &&
        std::abs(srs.GetAngularUnits() * kDegPerRad - 1.0) < 1e-12) {
      return Crs::geographic();
    }
  } else if (srs.IsProjected()) {
    int north = 0;
    const int zone = srs.GetUTMZone(&north);
    if (zone >= 1 && zone <= 60 && srs.GetLinearUnits() == 1.0 &&
        srs.IsSameGeogCS(&wgs84, same_datum)) {
      return Crs::utm(zone, north != 0);
    }
  } else {
    throw TerrainError(source + ": CRS '" + std::string(srs.GetName() ? srs.GetName() : "") +
                       "' is neither geographic nor projected; nadir needs a horizontal CRS");
  }
  Crs crs;
  crs.kind = Crs::Kind::kOther;
  crs.other = sharedTransform(std::move(srs), source);
  return crs;
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
  GdalErrors errors;
  OGRSpatialReference srs;
  if (epsg <= 0 || srs.importFromEPSG(epsg) != OGRERR_NONE) {
    throw TerrainError(source + ": EPSG:" + std::to_string(epsg) + " is not a CRS PROJ knows" +
                       errors.said());
  }
  return crsOf(std::move(srs), source);
}

Crs Crs::fromDefinition(const std::string& definition, const std::string& source) {
  GdalErrors errors;
  OGRSpatialReference srs;
  if (definition.empty() ||
      srs.SetFromUserInput(definition.c_str(),
                           OGRSpatialReference::SET_FROM_USER_INPUT_LIMITATIONS_get()) !=
          OGRERR_NONE) {
    std::string shown = definition.substr(0, 60);
    if (definition.size() > 60) shown += "...";
    throw TerrainError(source + ": not a CRS definition: '" + shown + "'" + errors.said());
  }
  return crsOf(std::move(srs), source);
}

int Crs::epsg() const {
  switch (kind) {
    case Kind::kGeographic:
      return 4326;
    case Kind::kUtm:
      return (utm_north ? 32600 : 32700) + utm_zone;
    case Kind::kOther:
      return other->epsg();
  }
  return 0;
}

std::string Crs::name() const {
  switch (kind) {
    case Kind::kGeographic:
      return "EPSG:4326 (WGS 84)";
    case Kind::kUtm:
      return "EPSG:" + std::to_string(epsg()) + " (" + utmName(utm_zone, utm_north) + ")";
    case Kind::kOther:
      return other->name();
  }
  return {};
}

std::string Crs::wkt() const {
  if (kind == Kind::kOther) return other->wkt();
  OGRSpatialReference srs = wgs84Geographic();
  if (kind == Kind::kUtm) srs.SetUTM(utm_zone, utm_north ? 1 : 0);
  return wktOf(srs);
}

bool Crs::operator==(const Crs& rhs) const {
  if (kind != rhs.kind) return false;
  if (kind == Kind::kUtm) return utm_zone == rhs.utm_zone && utm_north == rhs.utm_north;
  if (kind == Kind::kOther) return other == rhs.other || other->sameAs(*rhs.other);
  return true;
}

CrsPoint Crs::fromGeodetic(const core::Geodetic& point) const {
  const double lat_deg = point.lat_rad * kDegPerRad;
  const double lon_deg = point.lon_rad * kDegPerRad;
  if (kind == Kind::kGeographic) return {lon_deg, lat_deg};
  if (!(std::abs(lat_deg) <= 90.0) || !std::isfinite(lon_deg)) return {kNaN, kNaN};
  if (kind == Kind::kOther) return other->fromGeodetic(lat_deg, lon_deg);
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
  if (kind == Kind::kOther) {
    other->toGeodetic(point, lat_deg, lon_deg);
  } else {
    GeographicLib::TransverseMercator::UTM().Reverse(
        utmCentralMeridian_deg(utm_zone), point.x - kUtmFalseEasting_m,
        point.y - (utm_north ? 0.0 : kUtmSouthFalseNorthing_m), lat_deg, lon_deg);
  }
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
  if (crs.kind == Crs::Kind::kOther) {
    // Geodesic distances to the next pixel east and south.
    const core::Geodetic east = geodeticFromPixel({centre.col + 1.0, centre.row});
    const core::Geodetic south = geodeticFromPixel({centre.col, centre.row + 1.0});
    const GeographicLib::Geodesic& geodesic = GeographicLib::Geodesic::WGS84();
    double col_m = kNaN, row_m = kNaN;
    geodesic.Inverse(at.lat_rad * kDegPerRad, at.lon_rad * kDegPerRad, east.lat_rad * kDegPerRad,
                     east.lon_rad * kDegPerRad, col_m);
    geodesic.Inverse(at.lat_rad * kDegPerRad, at.lon_rad * kDegPerRad, south.lat_rad * kDegPerRad,
                     south.lon_rad * kDegPerRad, row_m);
    return {col_m, row_m};
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

}  // namespace nadir::terrain
