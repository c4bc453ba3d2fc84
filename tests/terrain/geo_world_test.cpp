#include "terrain/geo_world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/geodesy.h"

#include "terrain_test_util.h"

namespace nadir::terrain {

namespace {

using test::dataPath;

constexpr double kDeg = std::numbers::pi / 180.0;
// WGS-84, by hand: e^2 = f (2 - f).
constexpr double kA_m = 6378137.0;
constexpr double kF = 1.0 / 298.257223563;
constexpr double kE2 = kF * (2.0 - kF);

double meridionalRadius_m(double lat_deg) {
  const double s = std::sin(lat_deg * kDeg);
  return kA_m * (1.0 - kE2) / std::pow(1.0 - kE2 * s * s, 1.5);
}

double primeVerticalRadius_m(double lat_deg) {
  const double s = std::sin(lat_deg * kDeg);
  return kA_m / std::sqrt(1.0 - kE2 * s * s);
}

// A constant-height geographic DEM centred on (lat, lon), +-half_deg.
ElevationRaster flatDem(double lat_deg, double lon_deg, double half_deg, float height_m) {
  ElevationRaster dem;
  dem.width = 101;
  dem.height = 101;
  dem.height_m.assign(101 * 101, height_m);
  dem.georef.corner_x = lon_deg - half_deg;
  dem.georef.corner_y = lat_deg + half_deg;
  dem.georef.pixel_dx = 2.0 * half_deg / 101;
  dem.georef.pixel_dy = -2.0 * half_deg / 101;
  dem.source = "flat";
  return dem;
}

// 20 x 20 geographic imagery over +-half_deg around (lat, lon): north-west
// quarter red, north-east green, south-west blue, south-east white.
ImageryRaster quadrantImagery(double lat_deg, double lon_deg, double half_deg) {
  ImageryRaster imagery;
  imagery.rgb = cv::Mat(20, 20, CV_8UC3);
  imagery.rgb(cv::Rect(0, 0, 10, 10)).setTo(cv::Scalar(255, 0, 0));
  imagery.rgb(cv::Rect(10, 0, 10, 10)).setTo(cv::Scalar(0, 255, 0));
  imagery.rgb(cv::Rect(0, 10, 10, 10)).setTo(cv::Scalar(0, 0, 255));
  imagery.rgb(cv::Rect(10, 10, 10, 10)).setTo(cv::Scalar(255, 255, 255));
  imagery.georef.corner_x = lon_deg - half_deg;
  imagery.georef.corner_y = lat_deg + half_deg;
  imagery.georef.pixel_dx = 2.0 * half_deg / 20;
  imagery.georef.pixel_dy = -2.0 * half_deg / 20;
  imagery.source = "quadrants";
  return imagery;
}

const core::Geodetic kZionOrigin = core::geodeticFromDegrees(37.32, -113.05, 0.0);

GeoWorld zionWorld(const core::Geodetic& origin = kZionOrigin) {
  return GeoWorld(readElevation(dataPath("zion_srtm.tif")),
                  readImageryBands(dataPath("zion_landsat_b4.tif"), dataPath("zion_landsat_b3.tif"),
                                   dataPath("zion_landsat_b2.tif")),
                  core::LocalNedFrame(origin));
}

TEST(GeoWorld, GroundUpAtOriginIsHeightMinusOriginAltitude) {
  // At the origin the ground is the DEM height minus the origin's altitude:
  // 1234 - 1000 on a flat DEM; 1908 - 500 with the origin on the Mount
  // Washington summit sample (row 875, column 836: 44.2708333 N, 71.3033333 W).
  const core::LocalNedFrame flat_frame(core::geodeticFromDegrees(37.32, -113.05, 1000.0));
  const GeoWorld flat(flatDem(37.32, -113.05, 0.5, 1234.0f), std::nullopt, flat_frame);
  EXPECT_NEAR(flat.groundUp_m(0.0, 0.0), 234.0, 1e-6);

  const core::LocalNedFrame summit_frame(
      core::geodeticFromDegrees(45.0 - 875.0 / 1200, -72.0 + 836.0 / 1200, 500.0));
  const GeoWorld washington(readElevation(dataPath("N44W072.hgt")), std::nullopt, summit_frame);
  EXPECT_NEAR(washington.groundUp_m(0.0, 0.0), 1408.0, 1e-3);
}

TEST(GeoWorld, GroundFallsAwayWithTheEarthsCurvature) {
  // On a flat DEM at the origin's altitude the ground 10 km away lies
  // d^2 / 2R below the tangent plane: R = M = 6,358,895 m (7.863 m) northward,
  // R = N = 6,385,998 m (7.830 m) eastward, at 37.32 N.
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.32, -113.05, 0.0));
  const GeoWorld world(flatDem(37.32, -113.05, 0.5, 0.0f), std::nullopt, frame);
  const double d = 10000.0;
  EXPECT_NEAR(world.groundUp_m(d, 0.0), -d * d / (2.0 * meridionalRadius_m(37.32)), 2e-3);
  EXPECT_NEAR(world.groundUp_m(-d, 0.0), -d * d / (2.0 * meridionalRadius_m(37.32)), 2e-3);
  EXPECT_NEAR(world.groundUp_m(0.0, d), -d * d / (2.0 * primeVerticalRadius_m(37.32)), 2e-3);
  EXPECT_NEAR(world.groundUp_m(0.0, -d), -d * d / (2.0 * primeVerticalRadius_m(37.32)), 2e-3);
}

TEST(GeoWorld, OutsideTheExtentTheNearestEdgeValue) {
  // 1000 km north of the data the ground is the value at the north edge.
  const GeoWorld world(readElevation(dataPath("N44W072.hgt")), std::nullopt,
                       core::LocalNedFrame(core::geodeticFromDegrees(44.5, -71.5, 0.0)));
  const WorldExtent extent = world.extent();
  EXPECT_EQ(world.groundUp_m(1e6, 1000.0), world.groundUp_m(extent.north_max_m, 1000.0));
  EXPECT_EQ(world.groundUp_m(-1e6, -1e6), world.groundUp_m(extent.north_min_m, extent.east_min_m));
}

TEST(GeoWorld, ImageryIsNorthUp) {
  // Quadrant imagery around the origin: the rendered square's north-west
  // pixel is red, north-east green, south-west blue, south-east white.
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.32, -113.05, 0.0));
  const GeoWorld world(flatDem(37.32, -113.05, 0.5, 0.0f), quadrantImagery(37.32, -113.05, 0.01),
                       frame);
  cv::Mat rgb;
  world.imagery({-500.0, -500.0, 1000.0}, 8, rgb);
  ASSERT_EQ(rgb.type(), CV_8UC3);
  ASSERT_EQ(rgb.rows, 8);
  ASSERT_EQ(rgb.cols, 8);
  EXPECT_EQ(rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 0, 0));
  EXPECT_EQ(rgb.at<cv::Vec3b>(0, 7), cv::Vec3b(0, 255, 0));
  EXPECT_EQ(rgb.at<cv::Vec3b>(7, 0), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(rgb.at<cv::Vec3b>(7, 7), cv::Vec3b(255, 255, 255));
}

TEST(GeoWorld, ExtentIsTheIntersectionOfBothRasters) {
  // Imagery +-0.01 deg inside a +-0.5 deg DEM: the extent is the imagery's,
  // +-0.01 deg * M = 1109.8 m north-south and +-0.01 deg * N cos(lat) =
  // 887.0 m east-west (to the imagery's narrower north edge within 0.5 m).
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.32, -113.05, 0.0));
  const GeoWorld world(flatDem(37.32, -113.05, 0.5, 0.0f), quadrantImagery(37.32, -113.05, 0.01),
                       frame);
  const WorldExtent extent = world.extent();
  const double north_m = 0.01 * kDeg * meridionalRadius_m(37.32);
  const double east_m = 0.01 * kDeg * primeVerticalRadius_m(37.32) * std::cos(37.32 * kDeg);
  EXPECT_NEAR(extent.north_max_m, north_m, 0.5);
  EXPECT_NEAR(extent.north_min_m, -north_m, 0.5);
  EXPECT_NEAR(extent.east_max_m, east_m, 0.5);
  EXPECT_NEAR(extent.east_min_m, -east_m, 0.5);

  const GeoWorld dem_only(flatDem(37.32, -113.05, 0.5, 0.0f), std::nullopt, frame);
  EXPECT_NEAR(dem_only.extent().north_max_m, 50.0 * north_m, 50.0);
}

TEST(GeoWorld, ZionExtentAndResolutions) {
  // Zion: every extent corner lies inside both footprints; imagery resolution
  // is the Landsat 30 m (over a scale factor of ~1.0000); elevation
  // resolution the DEM's 3" east-west spacing at its centre (37.3225 N),
  // 3/3600 deg * N cos(lat).
  const GeoWorld world = zionWorld();
  const WorldExtent extent = world.extent();
  const ElevationRaster& dem = world.elevation();
  const RasterInfo landsat = readRasterInfo(dataPath("zion_landsat_b2.tif"));
  for (const double north_m : {extent.north_min_m, extent.north_max_m}) {
    for (const double east_m : {extent.east_min_m, extent.east_max_m}) {
      const core::Geodetic g = world.frame().geodeticFromNed({north_m, east_m, 0.0});
      const PixelPoint in_dem = dem.georef.pixelFromGeodetic(g);
      const PixelPoint in_landsat = landsat.georef.pixelFromGeodetic(g);
      EXPECT_GE(in_dem.col, -0.5);
      EXPECT_LE(in_dem.col, dem.width - 0.5);
      EXPECT_GE(in_dem.row, -0.5);
      EXPECT_LE(in_dem.row, dem.height - 0.5);
      EXPECT_GE(in_landsat.col, -0.5);
      EXPECT_LE(in_landsat.col, 1128 - 0.5);
      EXPECT_GE(in_landsat.row, -0.5);
      EXPECT_LE(in_landsat.row, 1428 - 0.5);
    }
  }
  // The two footprints overlap over at least 30 x 40 km.
  EXPECT_GT(extent.east_max_m - extent.east_min_m, 30e3);
  EXPECT_GT(extent.north_max_m - extent.north_min_m, 40e3);
  EXPECT_NEAR(world.imageryResolution_m(), 30.0, 0.01);
  const double centre_lat_deg = (37.1321 + 37.5129) / 2.0;
  EXPECT_NEAR(
      world.elevationResolution_m(),
      3.0 / 3600 * kDeg * primeVerticalRadius_m(centre_lat_deg) * std::cos(centre_lat_deg * kDeg),
      0.05);
}

TEST(GeoWorld, LandsatLinesUpWithTheDem) {
  // The Landsat scene (18 Aug 2015, ~10:25 local solar time: sun by hand at
  // azimuth 132 deg, elevation 57 deg) is brighter where the DEM's slopes
  // face the sun. Correlating brightness with the DEM's illumination over an
  // 18 km square while shifting the imagery by up to 180 m gives a clear
  // peak (well above every 180 m shift) less than a DEM pixel from no shift.
  // The peak sits about 50 m west, 10 m south (the same for sun azimuths
  // 100..160 deg, so a registration difference between these SRTM and
  // Landsat files, not the shading model); it is pinned to within 30 m so
  // that either reader moving the data by one or two Landsat pixels fails.
  const GeoWorld world = zionWorld();
  constexpr int kN = 200;
  constexpr double kPixel_m = 90.0;
  constexpr double kSize_m = kN * kPixel_m;
  const GroundSquare square{-kSize_m / 2, -kSize_m / 2, kSize_m};
  cv::Mat up(kN, kN, CV_64F);
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      up.at<double>(i, j) = world.groundUp_m(square.north_min_m + kSize_m * (1 - (i + 0.5) / kN),
                                             square.east_min_m + kSize_m * (j + 0.5) / kN);
    }
  }
  const double azimuth = 132.0 * kDeg;
  const double elevation = 57.0 * kDeg;
  const cv::Vec3d sun(std::sin(azimuth) * std::cos(elevation),
                      std::cos(azimuth) * std::cos(elevation), std::sin(elevation));
  cv::Mat illumination(kN - 2, kN - 2, CV_64F);
  for (int i = 1; i < kN - 1; ++i) {
    for (int j = 1; j < kN - 1; ++j) {
      const double de = (up.at<double>(i, j + 1) - up.at<double>(i, j - 1)) / (2 * kPixel_m);
      const double dn = (up.at<double>(i - 1, j) - up.at<double>(i + 1, j)) / (2 * kPixel_m);
      illumination.at<double>(i - 1, j - 1) =
          (-de * sun[0] - dn * sun[1] + sun[2]) / std::sqrt(de * de + dn * dn + 1);
    }
  }
  cv::Scalar illumination_mean, illumination_sd;
  cv::meanStdDev(illumination, illumination_mean, illumination_sd);

  const auto correlation = [&](double shift_north_m, double shift_east_m) {
    cv::Mat rgb, small, grey, brightness;
    world.imagery({square.north_min_m + shift_north_m, square.east_min_m + shift_east_m, kSize_m},
                  3 * kN, rgb);
    cv::resize(rgb, small, cv::Size(kN, kN), 0, 0, cv::INTER_AREA);
    cv::cvtColor(small, grey, cv::COLOR_RGB2GRAY);
    grey(cv::Rect(1, 1, kN - 2, kN - 2)).convertTo(brightness, CV_64F);
    cv::Scalar mean, sd;
    cv::meanStdDev(brightness, mean, sd);
    return cv::mean((illumination - illumination_mean[0]).mul(brightness - mean[0]))[0] /
           (illumination_sd[0] * sd[0]);
  };
  constexpr double kStep_m = 60.0;
  constexpr int kSteps = 3;  // shifts -180 .. 180 m
  cv::Mat c(2 * kSteps + 1, 2 * kSteps + 1, CV_64F);
  for (int i = -kSteps; i <= kSteps; ++i) {
    for (int j = -kSteps; j <= kSteps; ++j) {
      c.at<double>(i + kSteps, j + kSteps) = correlation(i * kStep_m, j * kStep_m);
    }
  }
  double best = 0.0;
  cv::Point at;
  cv::minMaxLoc(c, nullptr, &best, nullptr, &at);
  ASSERT_GT(at.x, 0);
  ASSERT_LT(at.x, 2 * kSteps);
  ASSERT_GT(at.y, 0);
  ASSERT_LT(at.y, 2 * kSteps);
  // Sub-step peak: the vertex of a parabola through the best and its
  // neighbours along each axis.
  const auto vertex = [](double before, double peak, double after) {
    return 0.5 * (before - after) / (before - 2.0 * peak + after);
  };
  const double peak_north_m =
      kStep_m *
      (at.y - kSteps + vertex(c.at<double>(at.y - 1, at.x), best, c.at<double>(at.y + 1, at.x)));
  const double peak_east_m =
      kStep_m *
      (at.x - kSteps + vertex(c.at<double>(at.y, at.x - 1), best, c.at<double>(at.y, at.x + 1)));
  double best_at_180_m = -1.0;
  for (int i = 0; i <= 2 * kSteps; ++i) {
    for (int j = 0; j <= 2 * kSteps; ++j) {
      if (i == 0 || j == 0 || i == 2 * kSteps || j == 2 * kSteps) {
        best_at_180_m = std::max(best_at_180_m, c.at<double>(i, j));
      }
    }
  }
  EXPECT_GT(best, 0.15);
  EXPECT_GT(best - best_at_180_m, 0.04);
  EXPECT_LT(std::hypot(peak_north_m, peak_east_m), 75.0);
  EXPECT_NEAR(peak_north_m, -10.0, 30.0);
  EXPECT_NEAR(peak_east_m, -50.0, 30.0);
  RecordProperty("peak_north_m", std::to_string(peak_north_m));
  RecordProperty("peak_east_m", std::to_string(peak_east_m));
}

TEST(GeoWorld, WithoutImageryShadedRelief) {
  // Without imagery the DEM is drawn: a varied image, green-tinted (G > R,
  // G > B) around the lowest sample, near-grey around the highest.
  const ElevationRaster dem = readElevation(dataPath("N44W072.hgt"));
  const auto [low, high] = std::minmax_element(dem.height_m.begin(), dem.height_m.end());
  const auto pixel_of = [&dem](std::vector<float>::const_iterator it) {
    const auto index = static_cast<int>(it - dem.height_m.begin());
    return PixelPoint{static_cast<double>(index % dem.width),
                      static_cast<double>(index / dem.width)};
  };
  const core::Geodetic lowest = dem.georef.geodeticFromPixel(pixel_of(low));
  const core::Geodetic highest = dem.georef.geodeticFromPixel(pixel_of(high));
  const core::LocalNedFrame frame(core::geodeticFromDegrees(44.5, -71.5, 0.0));
  const GeoWorld world(dem, std::nullopt, frame);
  EXPECT_FALSE(world.hasImagery());
  EXPECT_EQ(world.imageryResolution_m(), world.elevationResolution_m());

  cv::Mat rgb;
  world.imagery({-20e3, -20e3, 40e3}, 256, rgb);
  cv::Scalar mean, sd;
  cv::meanStdDev(rgb, mean, sd);
  EXPECT_GT(sd[0] + sd[1] + sd[2], 30.0);

  const Eigen::Vector3d low_ned = frame.nedFromGeodetic(lowest);
  world.imagery({low_ned.x() - 20.0, low_ned.y() - 20.0, 40.0}, 4, rgb);
  const cv::Scalar low_colour = cv::mean(rgb);
  EXPECT_GT(low_colour[1], low_colour[0]);
  EXPECT_GT(low_colour[1], low_colour[2]);
  const Eigen::Vector3d high_ned = frame.nedFromGeodetic(highest);
  world.imagery({high_ned.x() - 20.0, high_ned.y() - 20.0, 40.0}, 4, rgb);
  const cv::Scalar high_colour = cv::mean(rgb);
  EXPECT_NEAR(high_colour[0], high_colour[1], 15.0);
  EXPECT_NEAR(high_colour[1], high_colour[2], 15.0);
}

TEST(GeoWorld, DeterministicAndThreadSafe) {
  // The same squares give the same pixels and heights, called again or from
  // four threads at once.
  const GeoWorld world = zionWorld();
  const std::vector<GroundSquare> squares{
      {-500.0, -500.0, 1000.0}, {3000.0, -7000.0, 256.0}, {-12000.0, 4000.0, 5000.0}};
  const auto render = [&world, &squares]() {
    std::vector<cv::Mat> images;
    for (const GroundSquare& square : squares) {
      cv::Mat rgb;
      world.imagery(square, 128, rgb);
      images.push_back(rgb);
    }
    std::vector<double> heights;
    for (int k = 0; k < 500; ++k) heights.push_back(world.groundUp_m(37.0 * k - 9000, 23.0 * k));
    return std::make_pair(images, heights);
  };
  const auto reference = render();
  std::vector<decltype(render())> results(4);
  std::vector<std::thread> threads;
  for (auto& result : results) threads.emplace_back([&result, &render] { result = render(); });
  for (std::thread& thread : threads) thread.join();
  for (const auto& [images, heights] : results) {
    for (std::size_t k = 0; k < squares.size(); ++k) {
      EXPECT_EQ(cv::norm(images[k], reference.first[k], cv::NORM_INF), 0.0);
    }
    EXPECT_EQ(heights, reference.second);
  }
}

TEST(GeoWorld, ImageryNotOverlappingTheDemIsAnError) {
  // Imagery 2 deg away from the DEM: TerrainError naming both sources.
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.32, -113.05, 0.0));
  try {
    GeoWorld world(flatDem(37.32, -113.05, 0.5, 0.0f), quadrantImagery(39.5, -113.05, 0.01), frame);
    FAIL() << "no exception";
  } catch (const TerrainError& e) {
    EXPECT_NE(std::string(e.what()).find("flat"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("quadrants"), std::string::npos) << e.what();
  }
}

TEST(RasterPixelsOfSquare, InterpolationErrorIsBelowAMillimetre) {
  // The knot-interpolated raster pixels of every output pixel agree with the
  // exact tangent plane -> geodetic -> raster mapping to < 1 mm on the ground,
  // for a 3" geographic grid at 37 and 60 N and a 1 m UTM grid, over squares
  // of 256 m to 50 km, 20 km away from the origin.
  for (const double lat_deg : {37.32, 60.0}) {
    const core::LocalNedFrame frame(core::geodeticFromDegrees(lat_deg, -113.05, 500.0));
    RasterGeoref geographic;
    geographic.corner_x = -114.0;
    geographic.corner_y = lat_deg + 1.0;
    geographic.pixel_dx = 3.0 / 3600;
    geographic.pixel_dy = -3.0 / 3600;
    RasterGeoref utm;
    utm.crs = Crs::utm(12, true);
    utm.corner_x = 300000.0;
    utm.corner_y = 7000000.0;
    utm.pixel_dx = 1.0;
    utm.pixel_dy = -1.0;
    for (const RasterGeoref* georef : {&geographic, &utm}) {
      const PixelGroundSize pixel = georef->groundPixelSize(1, 1);
      for (const double size_m : {256.0, 5000.0, 50000.0}) {
        const int n = 256;
        const GroundSquare square{20000.0 - size_m / 2, -20000.0 - size_m / 2, size_m};
        std::vector<PixelPoint> pixels;
        rasterPixelsOfSquare(frame, *georef, square, n, pixels);
        ASSERT_EQ(pixels.size(), static_cast<std::size_t>(n * n));
        double worst_m = 0.0;
        for (int i = 0; i < n; ++i) {
          for (int j = 0; j < n; ++j) {
            const double north_m = square.north_min_m + size_m * (1.0 - (i + 0.5) / n);
            const double east_m = square.east_min_m + size_m * (j + 0.5) / n;
            const PixelPoint exact =
                georef->pixelFromGeodetic(frame.geodeticFromNed({north_m, east_m, 0.0}));
            const PixelPoint& got = pixels[static_cast<std::size_t>(i * n + j)];
            worst_m = std::max(worst_m, std::hypot((got.col - exact.col) * pixel.col_m,
                                                   (got.row - exact.row) * pixel.row_m));
          }
        }
        EXPECT_LT(worst_m, 1e-3) << "lat " << lat_deg << ", " << georef->crs.name() << ", "
                                 << size_m << " m";
      }
    }
  }
}

TEST(GeoWorld, ImageryAtTwoTileSizes) {
  // imagery() gives 256 x 256 and 1024 x 1024 RGB tiles of Zion; the time each
  // takes is printed, not asserted (a sanitized build is ten times slower).
  const GeoWorld world = zionWorld();
  cv::Mat rgb;
  for (const int size_px : {256, 1024}) {
    const GroundSquare square{-1000.0, -1000.0, 2000.0};
    world.imagery(square, size_px, rgb);
    const int repeats = size_px == 256 ? 20 : 5;
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < repeats; ++k) world.imagery(square, size_px, rgb);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count() /
        repeats;
    std::cout << "GeoWorld::imagery " << size_px << " x " << size_px << ": " << ms << " ms\n";
    RecordProperty("imagery_ms_" + std::to_string(size_px), std::to_string(ms));
    EXPECT_EQ(rgb.cols, size_px);
    EXPECT_EQ(rgb.rows, size_px);
    EXPECT_EQ(rgb.type(), CV_8UC3);
  }
}

}  // namespace
}  // namespace nadir::terrain
