#pragma once
// Rasters read through GDAL: GeoTIFF, VRT mosaics of several files, SRTM
// .hgt, ESRI ASCII grids, GTX geoid grids and the other formats listed in
// docs/terrain.md, in any CRS PROJ knows. A raster is read whole or as the
// window under a ground square, at its own resolution or coarser (from the
// file's overviews where it has them).

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/geodesy.h"
#include "terrain/georef.h"

namespace nadir::terrain {

// What a raster file says about itself.
struct RasterInfo {
  std::string path;
  std::string driver;  // GDAL's short name: GTiff, VRT, SRTMHGT, AAIGrid, GTX ...
  int width = 0;
  int height = 0;
  int bands = 0;
  int depth = 0;  // OpenCV depth of band 1's samples (CV_8U, CV_16S, CV_32F ...)
  RasterGeoref georef;
  bool crs_given = true;    // false: the file names no CRS; the caller's default is used
  bool has_nodata = false;  // band 1's nodata value
  double nodata = 0.0;
  int overviews = 0;  // band 1's reduced-resolution copies
};

// The most samples one read may give by default (1 GiB of float heights).
inline constexpr std::int64_t kMaxRasterSamples = std::int64_t{1} << 28;

// The part of a raster to read and how finely.
struct RasterRegion {
  // The north-up ground square with sides 2 half_size_m around centre, on
  // the tangent plane at centre; 0: the whole raster.
  core::Geodetic centre;
  double half_size_m = 0.0;
  // The coarsest ground pixel wanted, m; 0: the file's own. A finer file is
  // read as means of k x k blocks of its pixels, k the largest whole number
  // with k pixels no wider than this (the raster's last partial blocks are
  // left out), in the samples' type (an integer DEM's means are rounded), from
  // the file's overviews where it has them.
  double resolution_m = 0.0;
  // The most samples a band read may give; a read that would give more is refused.
  std::int64_t max_samples = kMaxRasterSamples;
};

// A rectangle of full-resolution pixels and the out_width x out_height
// samples it is read into, with their georeferencing.
struct RasterWindow {
  int col = 0;
  int row = 0;
  int width = 0;
  int height = 0;
  int out_width = 0;
  int out_height = 0;
  RasterGeoref georef;
};

// One band as read: values (CV_8U or CV_32F) and valid, CV_8U, 255 where the
// sample is data (not the nodata value, not NaN), else 0.
struct BandSamples {
  cv::Mat values;
  cv::Mat valid;
};

// Opens path with GDAL. A file that names no CRS (an ESRI grid without .prj)
// is taken to be in crs_if_none. Throws TerrainError naming path for a file
// GDAL cannot read, one without georeferencing, or a rotated or south-up one.
RasterInfo readRasterInfo(const std::string& path, const Crs& crs_if_none = Crs::geographic());

// The window of info's raster under region, with a margin of two pixels,
// clipped to the raster. Throws TerrainError naming the file if the square
// misses the raster or the read would give more than region.max_samples.
RasterWindow rasterWindow(const RasterInfo& info, const RasterRegion& region);

// Bands (1-based) of window: 8-bit bands as CV_8U when eight_bit is true,
// every other band as CV_32F; a coarser read averages the valid samples.
std::vector<BandSamples> readBands(const RasterInfo& info, const std::vector<int>& bands,
                                   const RasterWindow& window, bool eight_bit);

}  // namespace nadir::terrain
