#pragma once
// Georeferencing of north-up rasters: the coordinate reference system (CRS) a
// file is in, and the mapping between pixels, CRS coordinates and WGS-84
// geodetic positions.
//
// Pixel convention: fractional pixel coordinates (col, row) with integer
// values at pixel CENTRES; pixel (0,0) covers col, row in [-0.5, 0.5], row 0
// is the north edge. A raster of width x height pixels covers
// [-0.5, width - 0.5] x [-0.5, height - 0.5].

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "core/geodesy.h"

namespace nadir::terrain {

// Any failure to read or interpret terrain data. The message names the file.
class TerrainError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A point in a CRS: longitude, latitude in degrees (geographic) or easting,
// northing in metres (UTM).
struct CrsPoint {
  double x = 0.0;
  double y = 0.0;
};

// Fractional pixel coordinates, integers at pixel centres.
struct PixelPoint {
  double col = 0.0;
  double row = 0.0;
};

class CrsTransform;  // PROJ's transformations for a CRS without a fast path

// A coordinate reference system: any CRS that GDAL and PROJ know (EPSG code,
// WKT, PROJ string). WGS-84 geographic (x = longitude, y = latitude, degrees)
// and WGS-84 UTM are computed by GeographicLib; every other CRS (NAD83 UTM,
// ETRS89 / LAEA, ...) goes through PROJ. Axes are always x east, y north
// (longitude first), whatever order the CRS's definition gives.
struct Crs {
  enum class Kind { kGeographic, kUtm, kOther };
  Kind kind = Kind::kGeographic;
  int utm_zone = 0;  // 1..60 for kUtm
  bool utm_north = true;
  std::shared_ptr<const CrsTransform> other;  // kOther only

  static Crs geographic() { return Crs{}; }
  // Throws TerrainError for a zone outside 1..60.
  static Crs utm(int zone, bool north);
  // Any EPSG code PROJ knows; 4326 and 32601..32660, 32701..32760 get the
  // fast paths. An unknown code, or a CRS that is not geographic or
  // projected (a vertical CRS, say) is a TerrainError naming source.
  static Crs fromEpsg(int epsg, const std::string& source);
  // A CRS from its WKT (as GDAL gives it for a raster), or from anything
  // OGRSpatialReference::SetFromUserInput takes ("EPSG:26912", a PROJ string).
  static Crs fromDefinition(const std::string& definition, const std::string& source);

  int epsg() const;  // the CRS's EPSG code, 0 if it has none
  std::string name()
      const;  // "EPSG:4326 (WGS 84)", "EPSG:32612 (UTM 12N)", "EPSG:26912 (NAD83 / UTM zone 12N)"
  std::string wkt() const;  // OGC WKT 1, for writing files

  // Geodetic (WGS-84) -> CRS. UTM always uses this CRS's zone and hemisphere,
  // with GeographicLib's TransverseMercator::UTM() (what GeographicLib::UTMUPS
  // computes when given the zone, but without UTMUPS's range check, so a point
  // beyond the zone still maps, to an easting outside the usual range). NaN
  // coordinates for a latitude beyond +-90 deg or a point PROJ cannot map.
  CrsPoint fromGeodetic(const core::Geodetic& point) const;
  // CRS -> geodetic (WGS-84) with height alt_m.
  core::Geodetic toGeodetic(const CrsPoint& point, double alt_m = 0.0) const;

  // Same kind, zone and hemisphere; for kOther, the same CRS by PROJ's
  // judgement (axis order and names aside).
  bool operator==(const Crs& other) const;
};

// Ground size of one pixel, metres.
struct PixelGroundSize {
  double col_m = 0.0;  // along a row (west-east)
  double row_m = 0.0;  // along a column (north-south)
};

// Georeferencing of a north-up raster: CRS coordinates are affine in pixel
// coordinates, without rotation.
struct RasterGeoref {
  Crs crs;
  // CRS coordinates of the outer (north-west) corner of pixel (0,0), i.e. of
  // pixel coordinates (-0.5, -0.5).
  double corner_x = 0.0;
  double corner_y = 0.0;
  // Pixel size in CRS units; pixel_dy < 0 for a north-up raster.
  double pixel_dx = 1.0;
  double pixel_dy = -1.0;

  CrsPoint crsFromPixel(const PixelPoint& pixel) const {
    return {corner_x + (pixel.col + 0.5) * pixel_dx, corner_y + (pixel.row + 0.5) * pixel_dy};
  }
  PixelPoint pixelFromCrs(const CrsPoint& point) const {
    return {(point.x - corner_x) / pixel_dx - 0.5, (point.y - corner_y) / pixel_dy - 0.5};
  }
  CrsPoint crsFromGeodetic(const core::Geodetic& point) const { return crs.fromGeodetic(point); }
  core::Geodetic geodeticFromCrs(const CrsPoint& point, double alt_m = 0.0) const {
    return crs.toGeodetic(point, alt_m);
  }
  PixelPoint pixelFromGeodetic(const core::Geodetic& point) const {
    return pixelFromCrs(crs.fromGeodetic(point));
  }
  core::Geodetic geodeticFromPixel(const PixelPoint& pixel, double alt_m = 0.0) const {
    return crs.toGeodetic(crsFromPixel(pixel), alt_m);
  }

  // Ground size of a pixel at the centre of a width x height raster
  // (geographic: from the ellipsoid's radii of curvature there; UTM: the grid
  // size divided by the point scale factor).
  PixelGroundSize groundPixelSize(int width, int height) const;

  // Same CRS and grid: corners within 1e-6 of a pixel, pixel sizes within 1e-9
  // relative.
  bool sameGrid(const RasterGeoref& other) const;
};

// "PNG image", "JPEG image", "TIFF image", "text" ... from a file's first
// bytes, for error messages; empty if unrecognised.
std::string describeFileContent(const std::string& path);

}  // namespace nadir::terrain
