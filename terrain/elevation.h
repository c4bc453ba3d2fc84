#pragma once
// Digital elevation models (DEMs), read through GDAL into one north-up raster
// of heights above the WGS-84 ellipsoid: SRTM .hgt tiles, GeoTIFF DEMs
// (Copernicus, USGS 3DEP), ESRI ASCII grids, VRT mosaics of tiles, in any CRS.
//
// DEM heights are almost always above a geoid (EGM96, EGM2008, NAVD88), which
// lies up to about 100 m from the ellipsoid. Given a geoid grid
// (Debian's proj-data has /usr/share/proj/egm96_15.gtx) its undulation N is
// added: h = H + N. Without one the file's heights are taken as ellipsoid
// heights, which over a scenario of a few tens of km raises or lowers all of
// the ground by nearly the same offset.

#include <optional>
#include <string>
#include <vector>

#include "core/geodesy.h"
#include "terrain/georef.h"
#include "terrain/raster_file.h"

namespace nadir::terrain {

struct ElevationRaster {
  int width = 0;
  int height = 0;
  std::vector<float> height_m;  // row-major, row 0 north; no NaN after reading
  RasterGeoref georef;
  std::string source;    // the file it came from
  int filled_voids = 0;  // samples that were voids/nodata and were filled
  // The geoid grid whose undulation was added (empty: none), and the range
  // of undulations added, m.
  std::string geoid_source;
  double geoid_min_m = 0.0;
  double geoid_max_m = 0.0;

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

struct ElevationReadOptions {
  // The part to read (default: all of it) and how finely.
  RasterRegion region;
  // The CRS of a grid that names none (an ESRI ASCII grid without .prj).
  Crs crs_if_none = Crs::geographic();
  // A geoid grid (GTX or GeoTIFF of undulations, m) the heights are above;
  // empty: heights are taken as ellipsoid heights.
  std::string geoid_path;
};

// Reads path through GDAL (raster_file.h), except ESRI ASCII grids (.asc, or
// text starting "ncols"), which nadir reads itself, strictly, and whole:
// ncols, nrows, xllcorner|xllcenter, yllcorner|yllcenter, cellsize (or dx
// and dy), optional NODATA_value, then nrows rows north first; their CRS is
// the .prj beside them, else crs_if_none. Nodata samples (and NaN) are voids,
// filled with fillVoids. Throws TerrainError naming the file for a file that
// cannot be read, a DEM with more than one band, one without georeferencing
// or whose every sample is a void, and a geoid grid that does not cover it.
ElevationRaster readElevation(const std::string& path, const ElevationReadOptions& options = {});

// Fills NaN samples from the nearest valid samples left, right, above and
// below, weighted by inverse distance (exact along a straight slope, where
// GDAL 3.6's GDALFillNodata is off by half a pixel's rise: docs/terrain.md);
// voids with no valid sample in their row or column are filled in later
// passes from filled neighbours. Returns how many samples were filled.
// Throws TerrainError naming source if no sample is valid.
int fillVoids(std::vector<float>& height_m, int width, int height, const std::string& source);

}  // namespace nadir::terrain
