#include "terrain/world_factory.h"

#include <filesystem>

#include <numbers>
#include <stdexcept>

#include "terrain/elevation.h"
#include "terrain/geo_world.h"
#include "terrain/georef.h"
#include "terrain/imagery.h"

namespace nadir::terrain {

void WorldParams::visit(core::ParamVisitor& v) {
  v.field("kind", &kind,
          {.doc = "procedural, files, checkerboard or arena",
           .choices = {"procedural", "files", "checkerboard", "arena"}});
  core::visitGroup(v, "procedural", "the procedural world (kind: procedural)", procedural);
  core::visitGroup(v, "checkerboard", "a calibration board on flat ground (kind: checkerboard)",
                   checkerboard);
  core::visitGroup(v, "arena", "the flat floor of an indoor robot arena (kind: arena)", arena);
  v.field("dem_path", &dem_path, {.doc = "files: elevation (.hgt, GeoTIFF, .asc)"});
  v.field("imagery_path", &imagery_path,
          {.doc = "files: RGB GeoTIFF, or a plain image placed by imagery_bounds_deg"});
  v.field("imagery_red_path", &imagery_red_path, {.doc = "files: red band GeoTIFF"});
  v.field("imagery_green_path", &imagery_green_path, {.doc = "files: green band GeoTIFF"});
  v.field("imagery_blue_path", &imagery_blue_path, {.doc = "files: blue band GeoTIFF"});
  v.field("imagery_bounds_deg", &imagery_bounds_deg,
          {.doc = "plain image corners: north, south, west, east, deg; zeros for GeoTIFFs",
           .min = -180,
           .max = 180,
           .list_size = 4});
  v.field("origin_lat_deg", &origin_lat_deg,
          {.doc = "world frame origin latitude, deg", .min = -90, .max = 90});
  v.field("origin_lon_deg", &origin_lon_deg,
          {.doc = "world frame origin longitude, deg", .min = -180, .max = 180});
  v.field("origin_alt_m", &origin_alt_m,
          {.doc = "world frame origin height above the WGS-84 ellipsoid, m",
           .min = -1000,
           .max = 20000});
  v.field("origin_at_dem_centre", &origin_at_dem_centre,
          {.doc = "files: put the origin at the DEM's centre, on its ground"});
}

BuiltWorld makeWorld(const WorldParams& params) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  BuiltWorld built;
  built.origin =
      core::geodeticFromDegrees(params.origin_lat_deg, params.origin_lon_deg, params.origin_alt_m);
  if (params.kind == "procedural") {
    auto world = std::make_shared<ProceduralWorld>(params.procedural);
    built.description = "procedural world, seed " + std::to_string(params.procedural.seed) + ", " +
                        std::to_string(static_cast<int>(params.procedural.size_m)) + " m square";
    built.world = world;
    return built;
  }
  if (params.kind == "checkerboard") {
    const CheckerboardParams& board = params.checkerboard;
    built.world = std::make_shared<CheckerboardWorld>(board);
    built.description = "checkerboard, " + std::to_string(board.inner_cols) + "x" +
                        std::to_string(board.inner_rows) + " inner corners, " +
                        std::to_string(board.square_m) + " m squares";
    return built;
  }
  if (params.kind == "arena") {
    built.world = std::make_shared<ArenaWorld>(params.arena);
    built.description = "arena floor, " +
                        std::to_string(static_cast<int>(2.0 * params.arena.half_size_m)) +
                        " m square";
    return built;
  }
  if (params.dem_path.empty()) throw core::ParamError("world.dem_path: a files world needs a DEM");
  ElevationRaster elevation = readElevation(params.dem_path);
  std::optional<ImageryRaster> imagery;
  const bool bands = !params.imagery_red_path.empty() || !params.imagery_green_path.empty() ||
                     !params.imagery_blue_path.empty();
  if (bands) {
    imagery = readGeoTiffBands(params.imagery_red_path, params.imagery_green_path,
                               params.imagery_blue_path);
  } else if (!params.imagery_path.empty()) {
    const auto& b = params.imagery_bounds_deg;
    const bool has_bounds = b[0] != 0.0 || b[1] != 0.0 || b[2] != 0.0 || b[3] != 0.0;
    imagery = has_bounds
                  ? readImageWithBounds(params.imagery_path, LatLonBounds{b[0], b[1], b[2], b[3]})
                  : readGeoTiffRgb(params.imagery_path);
  }
  if (params.origin_at_dem_centre) {
    const PixelPoint centre{0.5 * (elevation.width - 1), 0.5 * (elevation.height - 1)};
    built.origin =
        elevation.georef.geodeticFromPixel(centre, elevation.heightAtPixelClamped(centre));
  }
  built.description = "terrain from " + elevation.source +
                      (imagery ? ", imagery from " + imagery->source : ", shaded relief") +
                      ", origin " + std::to_string(built.origin.lat_rad / kDeg) + ", " +
                      std::to_string(built.origin.lon_rad / kDeg);
  built.world = std::make_shared<GeoWorld>(std::move(elevation), std::move(imagery),
                                           core::LocalNedFrame(built.origin));
  return built;
}

void resolvePathsFrom(WorldParams& params, const std::string& folder) {
  for (std::string* path : {&params.dem_path, &params.imagery_path, &params.imagery_red_path,
                            &params.imagery_green_path, &params.imagery_blue_path}) {
    if (path->empty() || std::filesystem::path(*path).is_absolute()) continue;
    *path = (std::filesystem::path(folder) / *path).lexically_normal().string();
  }
}

void requireFlightWorld(const WorldParams& params) {
  if (params.kind == "checkerboard") {
    throw std::invalid_argument(
        "world.kind is checkerboard: a calibration board a few decimetres across, not ground "
        "to fly over; look at it with nadir calib --virtual");
  }
}

}  // namespace nadir::terrain
