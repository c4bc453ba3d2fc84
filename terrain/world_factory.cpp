#include "terrain/world_factory.h"

#include <algorithm>
#include <filesystem>
#include <iomanip>

#include <numbers>
#include <sstream>
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
  v.field("dem_path", &dem_path,
          {.doc = "files: elevation GDAL reads (.hgt, GeoTIFF, .asc, a .vrt mosaic)"});
  v.field("default_crs", &default_crs,
          {.doc = "files: CRS of a DEM or imagery file naming none (an .asc without .prj), "
                  "EPSG:n or WKT"});
  v.field("geoid_file", &geoid_file,
          {.doc = "files: geoid grid the DEM heights are above (e.g. "
                  "/usr/share/proj/egm96_15.gtx); empty: they are ellipsoid heights"});
  v.field("extent_m", &extent_m,
          {.doc = "files: half side of the square read around the origin, m; 0: all",
           .min = 0,
           .max = 1e6});
  v.field("resolution_m", &resolution_m,
          {.doc = "files: coarsest ground pixel read, m; 0: the files' own", .min = 0, .max = 1e5});
  v.field("imagery_path", &imagery_path,
          {.doc = "files: RGB raster, or a plain image placed by imagery_bounds_deg"});
  v.field("imagery_red_path", &imagery_red_path, {.doc = "files: red band raster"});
  v.field("imagery_green_path", &imagery_green_path, {.doc = "files: green band raster"});
  v.field("imagery_blue_path", &imagery_blue_path, {.doc = "files: blue band raster"});
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
  ElevationReadOptions dem_options;
  dem_options.crs_if_none = Crs::fromDefinition(params.default_crs, "world.default_crs");
  dem_options.geoid_path = params.geoid_file;
  if (params.origin_at_dem_centre) {
    // The centre of the DEM's whole footprint, its height read below.
    const RasterInfo info = readRasterInfo(params.dem_path, dem_options.crs_if_none);
    built.origin = info.georef.geodeticFromPixel({0.5 * (info.width - 1), 0.5 * (info.height - 1)});
  }
  RasterRegion region;
  region.centre = built.origin;
  region.half_size_m = params.extent_m;
  region.resolution_m = params.resolution_m;
  dem_options.region = region;
  ElevationRaster elevation = readElevation(params.dem_path, dem_options);
  std::optional<ImageryRaster> imagery;
  const bool bands = !params.imagery_red_path.empty() || !params.imagery_green_path.empty() ||
                     !params.imagery_blue_path.empty();
  if (bands) {
    imagery = readImageryBands(params.imagery_red_path, params.imagery_green_path,
                               params.imagery_blue_path, region, {}, dem_options.crs_if_none);
  } else if (!params.imagery_path.empty()) {
    const auto& b = params.imagery_bounds_deg;
    const bool has_bounds = b[0] != 0.0 || b[1] != 0.0 || b[2] != 0.0 || b[3] != 0.0;
    imagery = has_bounds
                  ? readImageWithBounds(params.imagery_path, LatLonBounds{b[0], b[1], b[2], b[3]})
                  : readImageryRgb(params.imagery_path, region, {}, dem_options.crs_if_none);
  }
  if (params.origin_at_dem_centre) {
    const std::optional<double> ground_m = elevation.heightAt(built.origin);
    const PixelPoint centre{0.5 * (elevation.width - 1), 0.5 * (elevation.height - 1)};
    built.origin.alt_m = ground_m ? *ground_m : elevation.heightAtPixelClamped(centre);
  }
  const auto metres = [](double value) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(1) << value;
    return text.str();
  };
  built.description =
      "terrain from " + elevation.source + " (" + elevation.georef.crs.name() + ", " +
      std::to_string(elevation.width) + " x " + std::to_string(elevation.height) + " samples" +
      (elevation.geoid_source.empty()
           ? ", heights taken as ellipsoid heights"
           : ", + geoid " + elevation.geoid_source + " N " + metres(elevation.geoid_min_m) + ".." +
                 metres(elevation.geoid_max_m) + " m") +
      ")" + (imagery ? ", imagery from " + imagery->source : ", shaded relief") + ", origin " +
      std::to_string(built.origin.lat_rad / kDeg) + ", " +
      std::to_string(built.origin.lon_rad / kDeg);
  built.world = std::make_shared<GeoWorld>(std::move(elevation), std::move(imagery),
                                           core::LocalNedFrame(built.origin));
  return built;
}

core::Geodetic approximateOrigin(const WorldParams& params) {
  if (params.kind == "files" && params.origin_at_dem_centre) {
    const RasterInfo info = readRasterInfo(
        params.dem_path, Crs::fromDefinition(params.default_crs, "world.default_crs"));
    return info.georef.geodeticFromPixel({0.5 * (info.width - 1), 0.5 * (info.height - 1)},
                                         params.origin_alt_m);
  }
  return core::geodeticFromDegrees(params.origin_lat_deg, params.origin_lon_deg,
                                   params.origin_alt_m);
}

void markGivenOrigin(WorldParams& params, const std::vector<std::string>& given_keys,
                     const std::string& prefix) {
  const auto given = [&](const std::string& key) {
    return std::find(given_keys.begin(), given_keys.end(), prefix + key) != given_keys.end();
  };
  const bool origin = given("origin_lat_deg") || given("origin_lon_deg") || given("origin_alt_m");
  if (origin && !given("origin_at_dem_centre")) params.origin_at_dem_centre = false;
}

void resolvePathsFrom(WorldParams& params, const std::string& folder) {
  for (std::string* path :
       {&params.dem_path, &params.geoid_file, &params.imagery_path, &params.imagery_red_path,
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
