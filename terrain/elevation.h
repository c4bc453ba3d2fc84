#pragma once
// Digital elevation models (DEMs): SRTM .hgt tiles, GeoTIFF DEMs and ESRI
// ASCII grids, read into one north-up raster of heights.
//
// Heights are taken as heights above the WGS-84 ellipsoid. SRTM and most DEMs
// are really heights above the EGM96/EGM2008 geoid, which lies up to ~100 m
// from the ellipsoid (a few tens of metres in the US), but Debian ships no
// geoid model. Over a scenario of a few tens of km the difference is a nearly
// constant offset that raises or lowers all of the ground together.

#include <optional>
#include <string>
#include <vector>

#include "core/geodesy.h"
#include "terrain/georef.h"

namespace nadir::terrain {

struct ElevationRaster {
  int width = 0;
  int height = 0;
  std::vector<float> height_m;  // row-major, row 0 north; no NaN after reading
  RasterGeoref georef;
  std::string source;    // the file it came from
  int filled_voids = 0;  // samples that were voids/nodata and were filled

  float at(int col, int row) const {
    return height_m[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                    static_cast<std::size_t>(col)];
  }

  // Bilinear height at a fractional pixel, nullopt outside the raster's
  // footprint [-0.5, width - 0.5] x [-0.5, height - 0.5]; between the outer
  // edge and the outermost pixel centres the edge samples are used.
  std::optional<double> heightAtPixel(const PixelPoint& pixel) const;
  // Same, but outside the footprint the nearest edge value (NaN for a NaN
  // pixel).
  double heightAtPixelClamped(const PixelPoint& pixel) const;
  // Bilinear height under a geodetic position (its alt_m is ignored).
  std::optional<double> heightAt(const core::Geodetic& point) const;
};

// SRTM .hgt: big-endian int16, 1201 x 1201 (3") or 3601 x 3601 (1"); the
// tile's south-west corner from the first N44W072-like part of the file name
// (N44W072 -> 44 N, 72 W; S12E034 -> 12 S, 34 E), pixel (0,0)
// centred on its north-west corner; -32768 is a void.
ElevationRaster readSrtmHgt(const std::string& path);

// GeoTIFF DEM, one band of int8/uint8/int16/uint16/int32/float32/float64.
// GDAL_NODATA samples (and NaN) are voids.
ElevationRaster readGeoTiffElevation(const std::string& path);

// ESRI ASCII grid: ncols, nrows, xllcorner|xllcenter, yllcorner|yllcenter,
// cellsize (or dx and dy), optional NODATA_value, then nrows rows north
// first. The CRS is not in the file: EPSG:4326 unless given.
ElevationRaster readEsriAsciiGrid(const std::string& path, const Crs& crs = Crs::geographic());

// Any of the above, by extension (.hgt, .tif/.tiff, .asc), else by content.
// A file whose content is not what its name says is an error.
ElevationRaster readElevation(const std::string& path);

// Fills NaN samples from the nearest valid samples left, right, above and
// below, weighted by inverse distance (exact along a straight slope); voids
// with no valid sample in their row or column are filled in later passes from
// filled neighbours. Returns how many samples were filled. Throws
// TerrainError naming source if no sample is valid.
int fillVoids(std::vector<float>& height_m, int width, int height, const std::string& source);

}  // namespace nadir::terrain
