#include "terrain/imagery.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <GeographicLib/UTMUPS.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/geodesy.h"

#include "terrain_test_util.h"

namespace nadir::terrain {

namespace {

using test::dataPath;
using test::geoKeys;
using test::tempPath;
using test::writeGeoTiff;

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

std::vector<uint16_t> geographicKeys() { return geoKeys({{1024, 2}, {1025, 1}, {2048, 4326}}); }

ImageryRaster readLandsat() {
  return readImageryBands(dataPath("zion_landsat_b4.tif"), dataPath("zion_landsat_b3.tif"),
                          dataPath("zion_landsat_b2.tif"));
}

TEST(Landsat, BandsAreUtm12NorthThirtyMetres) {
  // Every band: EPSG:32612, 1128 x 1428, 30 m pixels, corner of pixel (0,0)
  // at E 301905, N 4154085 (the file's tiepoint, PixelIsArea).
  for (const char* band : {"zion_landsat_b2.tif", "zion_landsat_b3.tif", "zion_landsat_b4.tif"}) {
    const RasterInfo info = readRasterInfo(dataPath(band));
    EXPECT_EQ(info.georef.crs, Crs::utm(12, true)) << band;
    EXPECT_EQ(info.width, 1128);
    EXPECT_EQ(info.height, 1428);
    EXPECT_EQ(info.depth, CV_16U);
    EXPECT_DOUBLE_EQ(info.georef.pixel_dx, 30.0);
    EXPECT_DOUBLE_EQ(info.georef.pixel_dy, -30.0);
    EXPECT_DOUBLE_EQ(info.georef.corner_x, 301905.0);
    EXPECT_DOUBLE_EQ(info.georef.corner_y, 4154085.0);
  }
}

TEST(Landsat, CornerGeodeticMatchesGeographicLib) {
  // The north-west corner of the combined imagery, as geodetic, is where
  // GeographicLib's own UTMUPS::Reverse puts E 301905, N 4154085 in zone 12N.
  const ImageryRaster imagery = readLandsat();
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  GeographicLib::UTMUPS::Reverse(12, true, 301905.0, 4154085.0, lat_deg, lon_deg);
  const core::Geodetic corner = imagery.georef.geodeticFromPixel({-0.5, -0.5});
  EXPECT_NEAR(corner.lat_rad * kDegPerRad, lat_deg, 1e-10);
  EXPECT_NEAR(corner.lon_rad * kDegPerRad, lon_deg, 1e-10);
  // About 37.51 N, 113.24 W: the north-west of Zion, as the data README says.
  EXPECT_NEAR(lat_deg, 37.51, 0.01);
  EXPECT_NEAR(lon_deg, -113.24, 0.01);
}

TEST(Landsat, PercentileStretchPutsRedFirst) {
  // Red is band 4 stretched: it rises with the raw band 4 value (read here
  // with OpenCV), about 2 % of pixels are 0 and about 2 % are 255.
  const ImageryRaster imagery = readLandsat();
  ASSERT_EQ(imagery.rgb.type(), CV_8UC3);
  ASSERT_EQ(imagery.width(), 1128);
  ASSERT_EQ(imagery.height(), 1428);
  const cv::Mat raw = cv::imread(dataPath("zion_landsat_b4.tif"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16UC1);
  // Highest red for each raw value, walking raw values upwards, never falls.
  std::vector<int> red_of_raw(65536, -1);
  int zeros = 0;
  int saturated = 0;
  for (int row = 0; row < raw.rows; ++row) {
    for (int col = 0; col < raw.cols; ++col) {
      const uint16_t value = raw.at<uint16_t>(row, col);
      const int red = imagery.rgb.at<cv::Vec3b>(row, col)[0];
      if (value == 65535) continue;  // the band's nodata
      if (red_of_raw[value] >= 0) {
        EXPECT_EQ(red_of_raw[value], red);
      }
      red_of_raw[value] = red;
      zeros += red == 0 ? 1 : 0;
      saturated += red == 255 ? 1 : 0;
    }
  }
  int last = 0;
  for (const int red : red_of_raw) {
    if (red < 0) continue;
    EXPECT_GE(red, last);
    last = red;
  }
  const double total = static_cast<double>(raw.total());
  EXPECT_NEAR(zeros / total, 0.02, 0.01);
  EXPECT_NEAR(saturated / total, 0.02, 0.01);
}

TEST(GeoTiffRgb, EightBitKeepsValuesRedFirst) {
  // An 8-bit RGB GeoTIFF written R, G, B reads back unchanged with R first.
  cv::Mat rgb(2, 3, CV_8UC3);
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 3; ++col) {
      rgb.at<cv::Vec3b>(row, col) = cv::Vec3b(static_cast<unsigned char>(10 + col),
                                              static_cast<unsigned char>(100 + row), 200);
    }
  }
  const std::string path = tempPath("rgb8.tif");
  writeGeoTiff(path, rgb, {0.1, 0.1, 0}, {0, 0, 0, 5, 50, 0}, geographicKeys());
  const ImageryRaster imagery = readImageryRgb(path);
  ASSERT_EQ(imagery.rgb.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(imagery.rgb, rgb, cv::NORM_INF), 0.0);
  EXPECT_DOUBLE_EQ(imagery.georef.corner_x, 5.0);
}

TEST(GeoTiffRgb, SixteenBitIsStretched) {
  // 16-bit RGB with the full 0..100 % stretch: each band's minimum maps to 0
  // and maximum to 255, a value 20 % of the way up to 51.
  cv::Mat rgb(1, 3, CV_16UC3);
  rgb.at<cv::Vec<uint16_t, 3>>(0, 0) = {0, 500, 40000};
  rgb.at<cv::Vec<uint16_t, 3>>(0, 1) = {400, 540, 40040};
  rgb.at<cv::Vec<uint16_t, 3>>(0, 2) = {2000, 700, 40200};
  const std::string path = tempPath("rgb16.tif");
  writeGeoTiff(path, rgb, {0.1, 0.1, 0}, {0, 0, 0, 5, 50, 0}, geographicKeys());
  const ImageryRaster imagery = readImageryRgb(path, {}, {.low_percent = 0, .high_percent = 100});
  EXPECT_EQ(imagery.rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(imagery.rgb.at<cv::Vec3b>(0, 1), cv::Vec3b(51, 51, 51));
  EXPECT_EQ(imagery.rgb.at<cv::Vec3b>(0, 2), cv::Vec3b(255, 255, 255));
}

TEST(GeoTiffBands, DifferentGridsAreAnErrorNamingTheFiles) {
  // Bands whose tiepoints differ by one pixel, or whose sizes differ, do not
  // combine; the error names both files.
  const cv::Mat band(4, 4, CV_16U, cv::Scalar(100));
  const std::string a = tempPath("band_a.tif");
  const std::string b = tempPath("band_b.tif");
  const std::string c = tempPath("band_c.tif");
  writeGeoTiff(a, band, {30, 30, 0}, {0, 0, 0, 300000, 4100000, 0},
               geoKeys({{1024, 1}, {1025, 1}, {3072, 32612}}));
  writeGeoTiff(b, band, {30, 30, 0}, {0, 0, 0, 300030, 4100000, 0},
               geoKeys({{1024, 1}, {1025, 1}, {3072, 32612}}));
  writeGeoTiff(c, cv::Mat(4, 5, CV_16U, cv::Scalar(1)), {30, 30, 0}, {0, 0, 0, 300000, 4100000, 0},
               geoKeys({{1024, 1}, {1025, 1}, {3072, 32612}}));
  for (const std::string& other : {b, c}) {
    try {
      readImageryBands(a, a, other);
      ADD_FAILURE() << "no exception";
    } catch (const TerrainError& e) {
      EXPECT_NE(std::string(e.what()).find(a), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(other), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(readImageryBands(a, a, a));
}

TEST(PlainImage, CornersGiveGeoreferenceAndNorthIsUp) {
  // A PNG with a red north half and a blue south half over 46..47 N,
  // 7..8 E: colourAt north of 46.5 is red, south blue, outside nullopt.
  cv::Mat bgr(10, 20, CV_8UC3, cv::Scalar(255, 0, 0));
  bgr(cv::Rect(0, 0, 20, 5)).setTo(cv::Scalar(0, 0, 255));
  const std::string path = tempPath("halves.png");
  ASSERT_TRUE(cv::imwrite(path, bgr));
  const ImageryRaster imagery = readImageWithBounds(
      path, {.north_deg = 47.0, .south_deg = 46.0, .west_deg = 7.0, .east_deg = 8.0});
  EXPECT_EQ(imagery.georef.crs, Crs::geographic());
  EXPECT_DOUBLE_EQ(imagery.georef.pixel_dx, 0.05);
  EXPECT_DOUBLE_EQ(imagery.georef.pixel_dy, -0.1);
  const auto north = imagery.colourAt(core::geodeticFromDegrees(46.8, 7.5, 0.0));
  const auto south = imagery.colourAt(core::geodeticFromDegrees(46.2, 7.5, 0.0));
  ASSERT_TRUE(north && south);
  EXPECT_EQ(*north, cv::Vec3b(255, 0, 0));
  EXPECT_EQ(*south, cv::Vec3b(0, 0, 255));
  EXPECT_FALSE(imagery.colourAt(core::geodeticFromDegrees(47.1, 7.5, 0.0)).has_value());
  EXPECT_THROW(
      readImageWithBounds(path, {.north_deg = 46, .south_deg = 47, .west_deg = 7, .east_deg = 8}),
      TerrainError);
}

// A JPEG whose EXIF says "rotate 90 deg to view" (orientation 6): imagery given
// by its corners is the pixels as stored, north up, never turned. The APP1
// segment: "Exif", a little-endian TIFF header and one IFD entry, tag 0x0112
// (orientation), SHORT, 1 value, 6.
TEST(PlainImage, AnExifOrientationDoesNotTurnTheImagery) {
  cv::Mat bgr(20, 40, CV_8UC3, cv::Scalar(255, 0, 0));
  bgr(cv::Rect(0, 0, 40, 10)).setTo(cv::Scalar(0, 0, 255));  // red north half
  std::vector<std::uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", bgr, jpeg));
  const std::vector<std::uint8_t> app1 = {0xFF, 0xE1, 0x00, 0x22, 'E',  'x',  'i',  'f',  0,
                                          0,    'I',  'I',  0x2A, 0x00, 0x08, 0x00, 0x00, 0x00,
                                          0x01, 0x00, 0x12, 0x01, 0x03, 0x00, 0x01, 0x00, 0x00,
                                          0x00, 0x06, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  jpeg.insert(jpeg.begin() + 2, app1.begin(), app1.end());
  const std::string path = tempPath("exif_rotated.jpg");
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(jpeg.data()),
              static_cast<std::streamsize>(jpeg.size()));
  }
  // OpenCV's default read turns it, which shows the EXIF is read.
  ASSERT_EQ(cv::imread(path, cv::IMREAD_COLOR).cols, 20);
  const ImageryRaster imagery = readImageWithBounds(
      path, {.north_deg = 47.0, .south_deg = 46.0, .west_deg = 7.0, .east_deg = 8.0});
  EXPECT_EQ(imagery.rgb.cols, 40);
  EXPECT_EQ(imagery.rgb.rows, 20);
  const auto north = imagery.colourAt(core::geodeticFromDegrees(46.8, 7.5, 0.0));
  ASSERT_TRUE(north);
  EXPECT_GT((*north)[0], 200);  // red, within JPEG's loss
  EXPECT_LT((*north)[2], 60);
}

TEST(ImageryRaster, NearestAndBilinearColour) {
  // Two pixels (0,0,0) and (100,200,40), 1 deg wide from 10 E, centred on
  // 10.5 and 11.5 E: at 11.0 E bilinear gives their mean; at 10.7 E nearest
  // gives the first and bilinear 20 % of the second; at 11.3 E nearest gives
  // the second.
  ImageryRaster imagery;
  imagery.rgb = cv::Mat(1, 2, CV_8UC3, cv::Scalar(0, 0, 0));
  imagery.rgb.at<cv::Vec3b>(0, 1) = cv::Vec3b(100, 200, 40);
  imagery.georef.corner_x = 10.0;
  imagery.georef.corner_y = 50.0;
  imagery.georef.pixel_dx = 1.0;
  imagery.georef.pixel_dy = -1.0;
  const core::Geodetic middle = core::geodeticFromDegrees(49.5, 11.0, 0.0);
  EXPECT_EQ(*imagery.colourAt(middle), cv::Vec3b(50, 100, 20));
  const core::Geodetic near_first = core::geodeticFromDegrees(49.5, 10.7, 0.0);
  EXPECT_EQ(*imagery.colourAt(near_first, Sampling::kNearest), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(*imagery.colourAt(near_first, Sampling::kBilinear), cv::Vec3b(20, 40, 8));
  const core::Geodetic near_second = core::geodeticFromDegrees(49.5, 11.3, 0.0);
  EXPECT_EQ(*imagery.colourAt(near_second, Sampling::kNearest), cv::Vec3b(100, 200, 40));
}

TEST(Stretch, BadPercentilesAreAnError) {
  // low >= high or outside 0..100 is refused, naming the file.
  const std::string path = tempPath("rgb8_again.tif");
  writeGeoTiff(path, cv::Mat(2, 2, CV_16UC3, cv::Scalar(1, 2, 3)), {0.1, 0.1, 0},
               {0, 0, 0, 5, 50, 0}, geographicKeys());
  EXPECT_THROW(readImageryRgb(path, {}, {.low_percent = 50, .high_percent = 50}), TerrainError);
  EXPECT_THROW(readImageryRgb(path, {}, {.low_percent = -1, .high_percent = 50}), TerrainError);
}

TEST(Stretch, PercentilesOfTheValidSamplesMapTo0And255) {
  // Ten valid samples 0..9 between a NaN and a masked 1000: the 10th and 90th
  // percentiles are the samples of rank round(0.1 x 9) = 1 and round(0.9 x 9) = 8,
  // so v becomes (v - 1) x 255 / 7 rounded and clamped to 0..255; the NaN and
  // the masked sample become 0 and take no part in the percentiles.
  cv::Mat band(1, 12, CV_32F);
  cv::Mat valid(1, 12, CV_8U, cv::Scalar(255));
  for (int col = 0; col < 10; ++col) band.at<float>(0, col) = static_cast<float>(col);
  band.at<float>(0, 10) = std::numeric_limits<float>::quiet_NaN();
  band.at<float>(0, 11) = 1000.0f;
  valid.at<unsigned char>(0, 11) = 0;
  const cv::Mat out =
      stretchBand(band, valid, {.low_percent = 10.0, .high_percent = 90.0}, "test band");
  const std::vector<int> expected{0, 0, 36, 73, 109, 146, 182, 219, 255, 255, 0, 0};
  ASSERT_EQ(out.type(), CV_8U);
  for (int col = 0; col < 12; ++col) EXPECT_EQ(out.at<unsigned char>(0, col), expected[col]) << col;
}

}  // namespace
}  // namespace nadir::terrain
