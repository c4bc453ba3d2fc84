// makeWorld: the world a scenario names, with its origin.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "terrain/georef.h"
#include "terrain/world_factory.h"
#include "terrain_test_util.h"

namespace nadir::terrain {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The default is the procedural world, origin as given.
TEST(WorldFactory, ProceduralByDefault) {
  WorldParams params;
  params.origin_lat_deg = 44.0;
  params.procedural.size_m = 2000.0;
  const BuiltWorld built = makeWorld(params);
  EXPECT_NEAR(built.origin.lat_rad, 44.0 * kDeg, 1e-12);
  EXPECT_EQ(built.world->extent().north_max_m, 1000.0);
  EXPECT_NE(built.description.find("procedural"), std::string::npos);
}

// Zion from files: the origin is the DEM's centre (lon -113.2396..-112.8521,
// lat 37.1321..37.5129), on the ground, so the ground under the origin is at 0.
TEST(WorldFactory, FilesWorldCentresOnTheDem) {
  WorldParams params;
  params.kind = "files";
  params.dem_path = test::dataPath("zion_srtm.tif");
  params.imagery_red_path = test::dataPath("zion_landsat_b4.tif");
  params.imagery_green_path = test::dataPath("zion_landsat_b3.tif");
  params.imagery_blue_path = test::dataPath("zion_landsat_b2.tif");
  const BuiltWorld built = makeWorld(params);
  EXPECT_NEAR(built.origin.lat_rad / kDeg, 0.5 * (37.1321 + 37.5129), 0.002);
  EXPECT_NEAR(built.origin.lon_rad / kDeg, 0.5 * (-113.2396 - 112.8521), 0.002);
  EXPECT_GT(built.origin.alt_m, 1024.0);
  EXPECT_LT(built.origin.alt_m, 2892.0);
  EXPECT_NEAR(built.world->groundUp_m(0.0, 0.0), 0.0, 0.01);
  EXPECT_NEAR(built.world->imageryResolution_m(), 30.0, 1.0);
}

// A files world without a DEM, or with a missing one, is refused naming what is wrong.
TEST(WorldFactory, FilesWorldNeedsAReadableDem) {
  WorldParams params;
  params.kind = "files";
  EXPECT_THROW(makeWorld(params), core::ParamError);
  params.dem_path = test::tempPath("no_such_dem.tif");
  try {
    makeWorld(params);
    FAIL() << "no error for a missing DEM";
  } catch (const TerrainError& error) {
    EXPECT_NE(std::string(error.what()).find("no_such_dem.tif"), std::string::npos);
  }
}

}  // namespace
}  // namespace nadir::terrain
