#pragma once
// Builds the World a scenario or node asks for: the procedural world, or real
// terrain from a DEM and imagery files around a geodetic origin.

#include <memory>
#include <string>
#include <vector>

#include "core/geodesy.h"
#include "core/params.h"
#include "terrain/arena_world.h"
#include "terrain/checkerboard_world.h"
#include "terrain/procedural_world.h"
#include "terrain/world.h"

namespace nadir::terrain {

struct WorldParams {
  // "procedural", "files", "checkerboard" (a calibration board on flat ground)
  // or "arena" (the flat floor of an indoor robot arena).
  std::string kind = "procedural";
  ProceduralWorldParams procedural;
  CheckerboardParams checkerboard;
  ArenaParams arena;
  // files: a DEM GDAL reads (.hgt, GeoTIFF, .asc, a .vrt mosaic ...).
  std::string dem_path;
  // files: the CRS of a DEM or imagery file that names none (an .asc
  // without .prj, an image with only a world file).
  std::string default_crs = "EPSG:4326";
  // files: a geoid grid the DEM's heights are above; empty: they are taken
  // as heights above the ellipsoid.
  std::string geoid_file;
  // files: half the side of the square read around the origin, m; 0: all of
  // the files.
  double extent_m = 0.0;
  // files: the coarsest ground pixel wanted, m; 0: the files' own.
  double resolution_m = 0.0;
  // files: imagery as one RGB GeoTIFF, or a plain image with imagery_bounds_deg;
  // empty with the band paths below; all empty: the DEM's shaded relief.
  std::string imagery_path;
  std::string imagery_red_path;
  std::string imagery_green_path;
  std::string imagery_blue_path;
  // Plain image corners: north, south, west, east latitude/longitude, deg.
  std::vector<double> imagery_bounds_deg = {0.0, 0.0, 0.0, 0.0};
  // The world frame's origin (WGS-84, deg and m above the ellipsoid). With
  // files and origin_at_dem_centre, the DEM's centre at its ground height;
  // a scenario that gives the origin but not origin_at_dem_centre turns it
  // off (markGivenOrigin).
  double origin_lat_deg = 0.0;
  double origin_lon_deg = 0.0;
  double origin_alt_m = 0.0;
  bool origin_at_dem_centre = true;

  void visit(core::ParamVisitor& v);
};

struct BuiltWorld {
  std::shared_ptr<const World> world;
  // The geodetic origin of the world frame.
  core::Geodetic origin;
  std::string description;
};

// Throws TerrainError (files) or core::ParamError (bad values) naming what is wrong.
BuiltWorld makeWorld(const WorldParams& params);

// The origin's latitude and longitude as makeWorld will put it, reading no
// more of a DEM than its header (the height is origin_alt_m).
core::Geodetic approximateOrigin(const WorldParams& params);

// Throws std::invalid_argument when the world is not ground to fly or drive
// over (a checkerboard world is a calibration board a few decimetres across:
// nadir calib --virtual looks at it).
void requireFlightWorld(const WorldParams& params);

// After loading a scenario whose text names the keys in given_keys (dotted,
// "world.origin_lat_deg"): an origin given without origin_at_dem_centre is
// the origin to use, also for a files world.
void markGivenOrigin(WorldParams& params, const std::vector<std::string>& given_keys,
                     const std::string& prefix = "world.");

// Makes the world's relative file paths relative to `folder` (the folder of
// the file that named them).
void resolvePathsFrom(WorldParams& params, const std::string& folder);

}  // namespace nadir::terrain
