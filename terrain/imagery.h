#pragma once
// Georeferenced 8-bit RGB imagery: an RGB raster, separate single-band
// rasters (e.g. Landsat bands) combined with a percentile stretch, or a plain
// PNG/JPEG with known corner coordinates.

#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>

#include "core/geodesy.h"
#include "core/params.h"
#include "terrain/georef.h"
#include "terrain/raster_file.h"

namespace nadir::terrain {

// Maps each band's [low, high] percentile of its valid samples to [0, 255].
struct StretchParams {
  double low_percent = 2.0;
  double high_percent = 98.0;

  void visit(core::ParamVisitor& v) {
    v.field("low_percent", &low_percent,
            {.doc = "percentile of each band mapped to 0, %", .min = 0, .max = 100});
    v.field("high_percent", &high_percent,
            {.doc = "percentile of each band mapped to 255, %", .min = 0, .max = 100});
  }
};

enum class Sampling { kNearest, kBilinear };

struct ImageryRaster {
  cv::Mat rgb;  // CV_8UC3, R first, row 0 north
  RasterGeoref georef;
  std::string source;  // the file(s) it came from

  int width() const { return rgb.cols; }
  int height() const { return rgb.rows; }

  // Colour at a fractional pixel, nullopt outside the footprint
  // [-0.5, width - 0.5] x [-0.5, height - 0.5] (edge pixels beyond the
  // outermost centres).
  std::optional<cv::Vec3b> colourAtPixel(const PixelPoint& pixel,
                                         Sampling sampling = Sampling::kBilinear) const;
  std::optional<cv::Vec3b> colourAt(const core::Geodetic& point,
                                    Sampling sampling = Sampling::kBilinear) const;
};

// RGB(A) imagery in any raster GDAL reads (raster_file.h): 8-bit samples as
// they are, 16-bit (or other) samples stretched per band (the percentiles of
// the region read). Alpha is dropped. A file naming no CRS is taken to be in
// crs_if_none.
ImageryRaster readImageryRgb(const std::string& path, const RasterRegion& region = {},
                             const StretchParams& stretch = {},
                             const Crs& crs_if_none = Crs::geographic());

// Three single-band rasters on the same grid (else TerrainError naming the
// files), e.g. Landsat bands, combined into RGB, each band stretched. Nodata
// samples are left out of the percentiles and come out black.
ImageryRaster readImageryBands(const std::string& red_path, const std::string& green_path,
                               const std::string& blue_path, const RasterRegion& region = {},
                               const StretchParams& stretch = {},
                               const Crs& crs_if_none = Crs::geographic());

// Outer edges of an image in EPSG:4326, degrees.
struct LatLonBounds {
  double north_deg = 0.0;
  double south_deg = 0.0;
  double west_deg = 0.0;
  double east_deg = 0.0;
};

// A plain image (PNG, JPEG, ...) whose outer edges lie on the given bounds.
ImageryRaster readImageWithBounds(const std::string& path, const LatLonBounds& bounds);

// Stretches one band (any depth, one channel) to CV_8U: the low/high
// percentiles of the samples where valid is non-zero (all if valid is empty)
// map to 0 and 255; invalid samples become 0. source names the file in errors.
cv::Mat stretchBand(const cv::Mat& band, const cv::Mat& valid, const StretchParams& stretch,
                    const std::string& source);

}  // namespace nadir::terrain
