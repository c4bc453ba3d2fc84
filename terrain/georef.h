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
#include <stdexcept>
#include <string>

#include <opencv2/core/mat.hpp>

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

// The coordinate reference systems nadir reads: WGS-84 geographic (EPSG:4326,
// x = longitude, y = latitude, degrees) and WGS-84 UTM (EPSG:326zz north,
// 327zz south, metres).
struct Crs {
  enum class Kind { kGeographic, kUtm };
  Kind kind = Kind::kGeographic;
  int utm_zone = 0;  // 1..60 for kUtm
  bool utm_north = true;

  static Crs geographic() { return Crs{}; }
  // Throws TerrainError for a zone outside 1..60.
  static Crs utm(int zone, bool north);
  // EPSG:4326, 32601..32660, 32701..32760; anything else is a TerrainError
  // naming source (the file the code came from) and the code.
  static Crs fromEpsg(int epsg, const std::string& source);

  int epsg() const;
  std::string name() const;  // "EPSG:4326 (WGS 84)", "EPSG:32612 (UTM 12N)"

  // Geodetic -> CRS. UTM always uses this CRS's zone and hemisphere, with
  // GeographicLib's TransverseMercator::UTM() (what GeographicLib::UTMUPS
  // computes when given the zone, but without UTMUPS's range check, so a
  // point beyond the zone still maps, to an easting outside the usual range).
  // NaN coordinates for a latitude beyond +-90 deg.
  CrsPoint fromGeodetic(const core::Geodetic& point) const;
  // CRS -> geodetic with height alt_m.
  core::Geodetic toGeodetic(const CrsPoint& point, double alt_m = 0.0) const;

  bool operator==(const Crs& other) const = default;
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

// What a GeoTIFF says about itself (libtiff, GeoTIFF 1.0 tags).
struct GeoTiffInfo {
  int width = 0;
  int height = 0;
  int samples_per_pixel = 0;
  int bits_per_sample = 0;
  int sample_format = 1;  // 1 unsigned, 2 signed integer, 3 IEEE float
  RasterGeoref georef;
  bool pixel_is_point = false;  // GTRasterTypeGeoKey = 2
  bool has_nodata = false;      // GDAL_NODATA tag present
  double nodata = 0.0;
};

// Reads the header and georeferencing (ModelPixelScale + ModelTiepoint or a
// north-up ModelTransformation, GeoKeyDirectory, GDAL_NODATA) of a GeoTIFF.
// A PixelIsPoint tiepoint is a pixel centre, a PixelIsArea one a pixel
// corner. Throws TerrainError naming path if the file is not a TIFF, has no
// or unsupported georeferencing (CRS, rotation, south-up).
GeoTiffInfo readGeoTiffInfo(const std::string& path);

// The pixels of a GeoTIFF (cv::imread, IMREAD_UNCHANGED), checked against
// info: same size, channel count and sample type. Multi-channel images are
// returned in file order (R first), not OpenCV's BGR.
cv::Mat readGeoTiffPixels(const std::string& path, const GeoTiffInfo& info);

// "PNG image", "JPEG image", "TIFF image", "text" ... from a file's first
// bytes, for error messages; empty if unrecognised.
std::string describeFileContent(const std::string& path);

}  // namespace nadir::terrain
