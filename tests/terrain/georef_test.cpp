#include "terrain/georef.h"
#include "terrain/raster_file.h"

#include <gtest/gtest.h>
#include <tiffio.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/geodesy.h"

#include "terrain_test_util.h"

namespace nadir::terrain {

namespace {

using test::dataPath;
using test::geoKeys;
using test::tempPath;
using test::writeGeoTiff;

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
// WGS-84 meridian arc from the equator to 45 deg (numerical integration of
// a (1 - e^2) / (1 - e^2 sin^2)^1.5, done by hand outside the code).
constexpr double kMeridianArc45_m = 4984944.378;

// A geographic 16-bit GeoTIFF whose tiepoint maps raster (0,0) to
// (7 E, 46 N), 0.01 deg pixels, with the given GTRasterTypeGeoKey.
void writeSmallGeographicTiff(const std::string& path, uint16_t raster_type) {
  writeGeoTiff(path, cv::Mat(3, 4, CV_16S, cv::Scalar(5)), {0.01, 0.01, 0.0},
               {0, 0, 0, 7.0, 46.0, 0}, geoKeys({{1024, 2}, {1025, raster_type}, {2048, 4326}}));
}

TEST(Crs, FromEpsgKnowsGeographicAndUtm) {
  // EPSG:4326 is geographic, 32612 UTM 12 north, 32733 UTM 33 south.
  EXPECT_EQ(Crs::fromEpsg(4326, "f").kind, Crs::Kind::kGeographic);
  const Crs north = Crs::fromEpsg(32612, "f");
  EXPECT_EQ(north.kind, Crs::Kind::kUtm);
  EXPECT_EQ(north.utm_zone, 12);
  EXPECT_TRUE(north.utm_north);
  const Crs south = Crs::fromEpsg(32733, "f");
  EXPECT_EQ(south.utm_zone, 33);
  EXPECT_FALSE(south.utm_north);
  EXPECT_EQ(south.epsg(), 32733);
  EXPECT_EQ(north.name(), "EPSG:32612 (UTM 12N)");
}

TEST(Crs, UnknownOrNonHorizontalEpsgNamesSourceAndCode) {
  // EPSG:99999 does not exist and EPSG:5773 (EGM96 height) is vertical: both
  // are refused with the file and the code named.
  for (const int code : {99999, 5773}) {
    try {
      Crs::fromEpsg(code, "some/file.tif");
      ADD_FAILURE() << code << ": no exception";
    } catch (const TerrainError& e) {
      EXPECT_NE(std::string(e.what()).find("some/file.tif"), std::string::npos) << e.what();
      if (code == 99999) {
        EXPECT_NE(std::string(e.what()).find("99999"), std::string::npos) << e.what();
      } else {
        EXPECT_NE(std::string(e.what()).find("neither geographic nor projected"), std::string::npos)
            << e.what();
      }
    }
  }
  EXPECT_THROW(Crs::fromDefinition("not a crs", "f"), TerrainError);
}

TEST(Crs, WebMercatorThroughProj) {
  // EPSG:3857 has no fast path; its equations are x = a lon, y = a ln tan(pi/4
  // + lat/2) on the sphere of radius a = 6378137 m: at (45 N, 10 E),
  // x = 1113194.908 m and y = 5621521.486 m (worked out by hand).
  const Crs mercator = Crs::fromEpsg(3857, "f");
  EXPECT_EQ(mercator.kind, Crs::Kind::kOther);
  EXPECT_EQ(mercator.epsg(), 3857);
  EXPECT_NE(mercator.name().find("Pseudo-Mercator"), std::string::npos) << mercator.name();
  const CrsPoint p = mercator.fromGeodetic(core::geodeticFromDegrees(45.0, 10.0, 0.0));
  EXPECT_NEAR(p.x, 1113194.908, 1e-3);
  EXPECT_NEAR(p.y, 5621521.486, 1e-3);
  const core::Geodetic back = mercator.toGeodetic(p);
  EXPECT_NEAR(back.lat_rad * kDegPerRad, 45.0, 1e-9);
  EXPECT_NEAR(back.lon_rad * kDegPerRad, 10.0, 1e-9);
}

TEST(Crs, Nad83UtmIsWithinTheDatumShiftOfWgs84Utm) {
  // NAD83 / UTM 12N (EPSG:26912, USGS 3DEP's CRS in Utah) goes through PROJ.
  // NAD83 and WGS 84 differ by about 1-2 m in the western US, so a point's
  // coordinates in NAD83 UTM 12N are within 3 m of WGS-84 UTM 12N's
  // (GeographicLib), and the way back returns the point.
  const Crs nad83 = Crs::fromEpsg(26912, "f");
  EXPECT_EQ(nad83.kind, Crs::Kind::kOther);
  EXPECT_EQ(nad83.name(), "EPSG:26912 (NAD83 / UTM zone 12N)");
  EXPECT_EQ(Crs::fromDefinition("EPSG:26912", "f"), nad83);
  EXPECT_FALSE(nad83 == Crs::utm(12, true));
  const core::Geodetic zion = core::geodeticFromDegrees(37.3, -113.0, 0.0);
  const CrsPoint a = nad83.fromGeodetic(zion);
  const CrsPoint b = Crs::utm(12, true).fromGeodetic(zion);
  EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 3.0) << a.x - b.x << ", " << a.y - b.y;
  const core::Geodetic back = nad83.toGeodetic(a, 12.0);
  EXPECT_NEAR(back.lat_rad * kDegPerRad, 37.3, 1e-9);
  EXPECT_NEAR(back.lon_rad * kDegPerRad, -113.0, 1e-9);
  EXPECT_EQ(back.alt_m, 12.0);
  // A 30 m NAD83 UTM pixel is 30 m / k on the ground (k, the UTM point scale,
  // within 0.9996..1.0004 near the zone's centre).
  RasterGeoref georef;
  georef.crs = nad83;
  georef.corner_x = a.x;
  georef.corner_y = a.y;
  georef.pixel_dx = 30.0;
  georef.pixel_dy = -30.0;
  const PixelGroundSize size = georef.groundPixelSize(3, 3);
  EXPECT_NEAR(size.col_m, 30.0, 30.0 * 4e-4);
  EXPECT_NEAR(size.row_m, 30.0, 30.0 * 4e-4);
}

TEST(Crs, OneCrsBuildsItsTransformationsOnce) {
  // Every Crs of one CRS shares one PROJ transformation while any of them
  // lives; another CRS has its own.
  const Crs first = Crs::fromEpsg(26912, "first");
  const Crs second = Crs::fromDefinition("EPSG:26912", "second");
  const Crs mercator = Crs::fromEpsg(3857, "third");
  ASSERT_NE(first.other, nullptr);
  EXPECT_EQ(first.other.get(), second.other.get());
  EXPECT_NE(first.other.get(), mercator.other.get());
  const core::Geodetic zion = core::geodeticFromDegrees(37.3, -113.0, 0.0);
  EXPECT_EQ(first.fromGeodetic(zion).x, second.fromGeodetic(zion).x);
}

TEST(RasterGeoref, IntegerPixelCoordinatesAreCentres) {
  // Corner (10, 50), 0.5 x 0.25 deg pixels: pixel (0,0) is centred half a
  // pixel in from the corner, and the corner is pixel (-0.5, -0.5).
  RasterGeoref georef;
  georef.corner_x = 10.0;
  georef.corner_y = 50.0;
  georef.pixel_dx = 0.5;
  georef.pixel_dy = -0.25;
  const CrsPoint centre = georef.crsFromPixel({0, 0});
  EXPECT_DOUBLE_EQ(centre.x, 10.25);
  EXPECT_DOUBLE_EQ(centre.y, 49.875);
  const CrsPoint other = georef.crsFromPixel({3, 2});
  EXPECT_DOUBLE_EQ(other.x, 11.75);
  EXPECT_DOUBLE_EQ(other.y, 49.375);
  const PixelPoint corner = georef.pixelFromCrs({10.0, 50.0});
  EXPECT_DOUBLE_EQ(corner.col, -0.5);
  EXPECT_DOUBLE_EQ(corner.row, -0.5);
  const core::Geodetic g = georef.geodeticFromPixel({0, 0});
  EXPECT_NEAR(g.lat_rad * kDegPerRad, 49.875, 1e-12);
  EXPECT_NEAR(g.lon_rad * kDegPerRad, 10.25, 1e-12);
}

TEST(Crs, UtmOnTheCentralMeridianIsScaledMeridianArc) {
  // On the central meridian easting is 500 km and northing k0 = 0.9996 times
  // the meridian arc (plus 10,000 km in the south).
  const Crs north = Crs::utm(12, true);
  const CrsPoint p = north.fromGeodetic(core::geodeticFromDegrees(45.0, -111.0, 0.0));
  EXPECT_NEAR(p.x, 500000.0, 1e-3);
  EXPECT_NEAR(p.y, 0.9996 * kMeridianArc45_m, 1e-3);
  const Crs south = Crs::utm(33, false);
  const CrsPoint q = south.fromGeodetic(core::geodeticFromDegrees(-45.0, 15.0, 0.0));
  EXPECT_NEAR(q.x, 500000.0, 1e-3);
  EXPECT_NEAR(q.y, 10'000'000.0 - 0.9996 * kMeridianArc45_m, 1e-3);
}

TEST(Crs, UtmUsesTheRastersZoneOutsideIt) {
  // Points 6 deg east and west of zone 12's meridian (centres of zones 13 and
  // 11) stay in zone 12: eastings symmetric about 500 km, about
  // k0 * 6 deg * N cos(lat) = 512 km away.
  const Crs zone12 = Crs::utm(12, true);
  const CrsPoint east = zone12.fromGeodetic(core::geodeticFromDegrees(40.0, -105.0, 0.0));
  const CrsPoint west = zone12.fromGeodetic(core::geodeticFromDegrees(40.0, -117.0, 0.0));
  EXPECT_NEAR(east.x - 500000.0, 500000.0 - west.x, 1e-6);
  EXPECT_NEAR(east.y, west.y, 1e-6);
  EXPECT_NEAR(east.x - 500000.0, 512e3, 0.02 * 512e3);
  const core::Geodetic back = zone12.toGeodetic(east);
  EXPECT_NEAR(back.lat_rad * kDegPerRad, 40.0, 1e-9);
  EXPECT_NEAR(back.lon_rad * kDegPerRad, -105.0, 1e-9);
}

TEST(Crs, UtmUsesTheRastersHemisphere) {
  // 0.1 deg north of the equator in a southern zone: northing is 10,000 km
  // plus k0 * 11,057.43 m (the meridian arc of 0.1 deg at the equator).
  const Crs south = Crs::utm(33, false);
  const CrsPoint p = south.fromGeodetic(core::geodeticFromDegrees(0.1, 15.0, 0.0));
  EXPECT_NEAR(p.y, 10'000'000.0 + 0.9996 * 11057.43, 0.05);
  const core::Geodetic back = south.toGeodetic(p);
  EXPECT_NEAR(back.lat_rad * kDegPerRad, 0.1, 1e-10);
  const CrsPoint q = Crs::utm(33, true).fromGeodetic(core::geodeticFromDegrees(-0.1, 15.0, 0.0));
  EXPECT_NEAR(q.y, -0.9996 * 11057.43, 0.05);
}

TEST(RasterGeoref, PixelGeodeticPixelRoundTrip) {
  // pixel -> geodetic -> pixel returns within 1e-6 px for a 1" geographic
  // grid and a 30 m UTM grid, over and beyond the rasters.
  RasterGeoref geographic;
  geographic.corner_x = -72.0 - 0.5 / 3600;
  geographic.corner_y = 45.0 + 0.5 / 3600;
  geographic.pixel_dx = 1.0 / 3600;
  geographic.pixel_dy = -1.0 / 3600;
  RasterGeoref utm;
  utm.crs = Crs::utm(12, true);
  utm.corner_x = 301905.0;
  utm.corner_y = 4154085.0;
  utm.pixel_dx = 30.0;
  utm.pixel_dy = -30.0;
  for (const RasterGeoref* georef : {&geographic, &utm}) {
    for (double col = -100.5; col < 4000; col += 377.3) {
      for (double row = -50.25; row < 4000; row += 411.7) {
        const PixelPoint back = georef->pixelFromGeodetic(georef->geodeticFromPixel({col, row}));
        EXPECT_NEAR(back.col, col, 1e-6);
        EXPECT_NEAR(back.row, row, 1e-6);
      }
    }
  }
}

TEST(RasterGeoref, PixelNedPixelRoundTrip) {
  // pixel -> geodetic -> local NED -> geodetic -> pixel within 1e-6 px, with
  // the NED origin inside the raster.
  RasterGeoref utm;
  utm.crs = Crs::utm(12, true);
  utm.corner_x = 301905.0;
  utm.corner_y = 4154085.0;
  utm.pixel_dx = 30.0;
  utm.pixel_dy = -30.0;
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.32, -113.05, 1500.0));
  for (double col = 0; col < 1128; col += 101.7) {
    for (double row = 0; row < 1428; row += 133.3) {
      const core::Geodetic g = utm.geodeticFromPixel({col, row}, 1234.0);
      const Eigen::Vector3d ned = frame.nedFromGeodetic(g);
      const PixelPoint back = utm.pixelFromGeodetic(frame.geodeticFromNed(ned));
      EXPECT_NEAR(back.col, col, 1e-6);
      EXPECT_NEAR(back.row, row, 1e-6);
    }
  }
}

TEST(RasterGeoref, GroundPixelSize) {
  // 3" at 44.5 N: 3/3600 deg times the meridional radius M = 6,366,822 m
  // (row) and times N cos(lat), N = 6,388,651 m (column); UTM: 30 m / k,
  // k = 0.9996 on the central meridian.
  RasterGeoref geographic;
  geographic.corner_x = -72.0;
  geographic.corner_y = 45.0;
  geographic.pixel_dx = 3.0 / 3600;
  geographic.pixel_dy = -3.0 / 3600;
  // 1201 rows put the centre at 44.5 N.
  const PixelGroundSize size = geographic.groundPixelSize(1201, 1199);
  const double deg = std::numbers::pi / 180.0;
  EXPECT_NEAR(size.row_m, 3.0 / 3600 * deg * 6366822.04, 1e-3);
  EXPECT_NEAR(size.col_m, 3.0 / 3600 * deg * 6388651.06 * std::cos(44.5 * deg), 1e-3);
  RasterGeoref utm;
  utm.crs = Crs::utm(12, true);
  utm.corner_x = 500000.0 - 15.0 * 101;
  utm.corner_y = 4000000.0;
  utm.pixel_dx = 30.0;
  utm.pixel_dy = -30.0;
  const PixelGroundSize utm_size = utm.groundPixelSize(101, 101);
  EXPECT_NEAR(utm_size.col_m, 30.0 / 0.9996, 1e-6);
}

TEST(GeoTiff, PixelIsPointShiftsHalfAPixel) {
  // Same tiepoint (0,0) -> (7 E, 46 N): PixelIsArea puts it on the corner of
  // pixel (0,0), whose centre is then (7.005, 45.995); PixelIsPoint puts it on
  // the centre.
  const std::string area_path = tempPath("area.tif");
  const std::string point_path = tempPath("point.tif");
  writeSmallGeographicTiff(area_path, 1);
  writeSmallGeographicTiff(point_path, 2);
  const RasterInfo area = readRasterInfo(area_path);
  const RasterInfo point = readRasterInfo(point_path);
  EXPECT_EQ(area.georef.crs, Crs::geographic());
  const CrsPoint area_centre = area.georef.crsFromPixel({0, 0});
  EXPECT_NEAR(area_centre.x, 7.005, 1e-12);
  EXPECT_NEAR(area_centre.y, 45.995, 1e-12);
  const CrsPoint point_centre = point.georef.crsFromPixel({0, 0});
  EXPECT_NEAR(point_centre.x, 7.0, 1e-12);
  EXPECT_NEAR(point_centre.y, 46.0, 1e-12);
  EXPECT_EQ(area.width, 4);
  EXPECT_EQ(area.height, 3);
  EXPECT_EQ(area.depth, CV_16S);
  EXPECT_EQ(area.driver, "GTiff");
}

TEST(GeoTiff, ProjectedUtmAndModelTransformation) {
  // A UTM 33S GeoTIFF with a tiepoint at raster (2, 1); and one given by a
  // north-up ModelTransformation instead of scale + tiepoint.
  const cv::Mat pixels(3, 4, CV_16U, cv::Scalar(7));
  const std::string path = tempPath("utm33s.tif");
  writeGeoTiff(path, pixels, {10.0, 20.0, 0.0}, {2, 1, 0, 400020.0, 7000000.0, 0},
               geoKeys({{1024, 1}, {1025, 1}, {3072, 32733}, {3076, 9001}}));
  const RasterInfo info = readRasterInfo(path);
  EXPECT_EQ(info.georef.crs, Crs::utm(33, false));
  EXPECT_DOUBLE_EQ(info.georef.corner_x, 400000.0);
  EXPECT_DOUBLE_EQ(info.georef.corner_y, 7000020.0);
  EXPECT_DOUBLE_EQ(info.georef.pixel_dy, -20.0);

  const std::string transform_path = tempPath("transform.tif");
  writeGeoTiff(transform_path, pixels, {}, {},
               geoKeys({{1024, 1}, {1025, 1}, {3072, 32733}, {3076, 9001}}), "",
               {10, 0, 0, 400000, 0, -20, 0, 7000020, 0, 0, 0, 0, 0, 0, 0, 1});
  const RasterInfo from_transform = readRasterInfo(transform_path);
  EXPECT_TRUE(from_transform.georef.sameGrid(info.georef));
}

TEST(GeoTiff, BadFilesNameThePath) {
  // No georeferencing, a south-up raster, a text file and a missing file all
  // give a TerrainError naming the file and the problem.
  const auto expect_error = [](const std::string& path, const std::string& what) {
    try {
      readRasterInfo(path);
      ADD_FAILURE() << path << ": no exception";
    } catch (const TerrainError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  const cv::Mat pixels(3, 4, CV_16U, cv::Scalar(7));
  writeGeoTiff(tempPath("plain.tif"), pixels, {}, {}, {});
  expect_error(tempPath("plain.tif"), "no georeferencing");

  writeGeoTiff(tempPath("south_up.tif"), pixels, {}, {},
               geoKeys({{1024, 2}, {1025, 1}, {2048, 4326}}), "",
               {0.01, 0, 0, 7, 0, 0.01, 0, 46, 0, 0, 0, 0, 0, 0, 0, 1});
  expect_error(tempPath("south_up.tif"), "north-up");

  test::writeText(tempPath("text.tif"), "this is not an image\n");
  expect_error(tempPath("text.tif"), "text");
  expect_error(tempPath("missing.tif"), "cannot open");
}

}  // namespace
}  // namespace nadir::terrain
