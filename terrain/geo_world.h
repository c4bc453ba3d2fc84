#pragma once
// Real terrain as a World: a DEM and (optionally) imagery on the WGS-84
// ellipsoid, seen from the scenario's local NED frame.

#include <optional>
#include <vector>

#include "core/geodesy.h"
#include "terrain/elevation.h"
#include "terrain/georef.h"
#include "terrain/imagery.h"
#include "terrain/world.h"

namespace nadir::terrain {

// Pixel coordinates in georef of the centres of a size_px x size_px grid over
// square (row 0 north, column 0 west) on the tangent plane (down = 0) of
// frame, row-major into pixels. Exact (tangent plane -> geodetic -> raster)
// at knots every kMaxKnotStep_px pixels and at most kKnotSpacing_m apart,
// cubic (Lagrange through 4 knots, per axis) in between. The mapping bends
// only with the earth's curvature, so the error is tiny: measured worst 1e-8 m
// on the ground for squares up to 20 km, 6e-5 m for a 100 km square at 80 deg
// latitude (tests/terrain/geo_world_test.cpp checks < 1 mm).
void rasterPixelsOfSquare(const core::LocalNedFrame& frame, const RasterGeoref& georef,
                          const GroundSquare& square, int size_px, std::vector<PixelPoint>& pixels);
inline constexpr double kKnotSpacing_m = 5000.0;
inline constexpr int kMaxKnotStep_px = 32;

// The DEM drawn as terrain: hypsometric tint (green lowlands to brown and
// white tops over the DEM's own height range) times a hillshade lit from the
// north-west at 45 deg, on the DEM's grid.
ImageryRaster shadedRelief(const ElevationRaster& elevation);

class GeoWorld : public World {
 public:
  // Without imagery the ground shows shadedRelief(elevation). Throws
  // TerrainError naming the files if the DEM is empty or the rasters do not
  // overlap.
  GeoWorld(ElevationRaster elevation, std::optional<ImageryRaster> imagery,
           const core::LocalNedFrame& frame);

  // The point (north, east, 0) of the tangent plane is converted to latitude
  // and longitude, the DEM's height h is sampled there (bilinear), and the
  // result is -down of (lat, lon, h) in NED: it includes the earth's
  // curvature (about d^2 / 2R, 7.8 m at 10 km from the origin). Outside
  // extent() the value at the nearest point of extent(); NaN for NaN input.
  double groundUp_m(double north_m, double east_m) const override;
  // Bilinear colour of the imagery under each pixel centre of the tangent
  // plane square (rasterPixelsOfSquare); beyond the imagery's edge the edge
  // pixels.
  void imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const override;
  double imageryResolution_m() const override { return imagery_resolution_m_; }
  double elevationResolution_m() const override { return elevation_resolution_m_; }
  // The largest north/east box inside the footprints of both rasters.
  WorldExtent extent() const override { return extent_; }

  const ElevationRaster& elevation() const { return elevation_; }
  bool hasImagery() const { return has_imagery_; }
  const core::LocalNedFrame& frame() const { return frame_; }

 private:
  ElevationRaster elevation_;
  ImageryRaster imagery_;  // the given imagery or the DEM's shaded relief
  bool has_imagery_ = false;
  core::LocalNedFrame frame_;
  WorldExtent extent_;
  double imagery_resolution_m_ = 0.0;
  double elevation_resolution_m_ = 0.0;
};

}  // namespace nadir::terrain
