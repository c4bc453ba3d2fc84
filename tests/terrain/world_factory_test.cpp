// makeWorld: the world a scenario names, with its origin.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "terrain/checkerboard_world.h"
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

// A files world read as a 6 km square around a given origin, through the
// EGM96 geoid: the world reaches about 3 km each way (not Zion's whole 34 x
// 42 km), the origin is where it was given, and ground heights are the DEM's
// plus EGM96's -22.5 m or so there.
TEST(WorldFactory, FilesWorldWindowAroundAGivenOriginWithAGeoid) {
  WorldParams params;
  params.kind = "files";
  params.dem_path = test::dataPath("zion_srtm.tif");
  params.origin_lat_deg = 37.3;
  params.origin_lon_deg = -113.0;
  params.origin_alt_m = 1500.0;
  params.origin_at_dem_centre = false;
  params.extent_m = 3000.0;
  const BuiltWorld plain = makeWorld(params);
  EXPECT_NEAR(plain.origin.lat_rad / kDeg, 37.3, 1e-12);
  const WorldExtent extent = plain.world->extent();
  EXPECT_GT(extent.north_max_m, 3000.0);
  EXPECT_LT(extent.north_max_m, 3000.0 + 4 * 93.0);
  EXPECT_LT(extent.east_min_m, -3000.0);
  EXPECT_GT(extent.east_min_m, -3000.0 - 4 * 74.0);

  params.geoid_file = "/usr/share/proj/egm96_15.gtx";
  const BuiltWorld lifted = makeWorld(params);
  for (const double north_m : {-2000.0, 0.0, 2500.0}) {
    const double n_m =
        lifted.world->groundUp_m(north_m, 100.0) - plain.world->groundUp_m(north_m, 100.0);
    EXPECT_NEAR(n_m, test::egm96Undulation_m(37.3 + north_m / 111000.0, -113.0 + 100.0 / 88600.0),
                0.05);
  }
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

// A checkerboard world: 9 x 6 inner corners of 0.025 m squares make a board
// of 10 x 7 squares, 0.25 m east by 0.175 m north, centred on the origin; the
// south-west square is dark, its east neighbour light, a square of white
// margin around, mid-grey ground beyond; flat at 0.
TEST(WorldFactory, CheckerboardWorld) {
  WorldParams params;
  params.kind = "checkerboard";
  params.checkerboard = {.inner_cols = 9, .inner_rows = 6, .square_m = 0.025};
  const BuiltWorld built = makeWorld(params);
  EXPECT_NE(built.description.find("9x6"), std::string::npos);
  EXPECT_EQ(built.world->groundUp_m(0.3, -2.0), 0.0);
  const auto& board = dynamic_cast<const CheckerboardWorld&>(*built.world);
  EXPECT_NEAR(board.cornerNorth_m(0), -0.0875 + 0.025, 1e-12);
  EXPECT_NEAR(board.cornerEast_m(8), 0.125 - 0.025, 1e-12);
  // One pixel per 1 mm square of ground, sampled at the centres of squares.
  const auto grey = [&](double north_m, double east_m) {
    cv::Mat rgb;
    built.world->imagery({north_m - 0.0005, east_m - 0.0005, 0.001}, 1, rgb);
    return static_cast<int>(rgb.at<cv::Vec3b>(0, 0)[0]);
  };
  EXPECT_EQ(grey(-0.075, -0.1125), 20);   // south-west square
  EXPECT_EQ(grey(-0.075, -0.0875), 235);  // its east neighbour
  EXPECT_EQ(grey(-0.050, -0.0875), 20);   // and the one north of that
  EXPECT_EQ(grey(-0.100, 0.0), 235);      // the margin south of the board
  EXPECT_EQ(grey(0.0, 0.2), 128);         // the ground beyond
  params.checkerboard.square_m = 0.0;
  EXPECT_THROW(makeWorld(params), core::ParamError);
}

}  // namespace
}  // namespace nadir::terrain
