#include "terrain/elevation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

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
using test::writeText;

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

// Geographic GeoTIFF keys (EPSG:4326, PixelIsArea).
std::vector<uint16_t> geographicKeys() { return geoKeys({{1024, 2}, {1025, 1}, {2048, 4326}}); }

// Writes an SRTM3 tile whose sample at (col, row) is value(col, row).
template <class F>
void writeHgt(const std::string& path, F value) {
  std::vector<unsigned char> bytes(1201 * 1201 * 2);
  for (int row = 0; row < 1201; ++row) {
    for (int col = 0; col < 1201; ++col) {
      const auto v = static_cast<uint16_t>(static_cast<int16_t>(value(col, row)));
      const std::size_t i = 2 * (static_cast<std::size_t>(row) * 1201 + col);
      bytes[i] = static_cast<unsigned char>(v >> 8);
      bytes[i + 1] = static_cast<unsigned char>(v & 0xFF);
    }
  }
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

// Expects a TerrainError whose message names path and contains what.
template <class F>
void expectTerrainError(F read, const std::string& path, const std::string& what) {
  try {
    read();
    ADD_FAILURE() << path << ": no exception";
  } catch (const TerrainError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(SrtmHgt, WhiteMountainsTileFacts) {
  // N44W072.hgt: 1201 x 1201, highest sample 1908 m at row 875, column 836
  // (Mount Washington), lowest 115 m, no voids.
  const ElevationRaster dem = readSrtmHgt(dataPath("N44W072.hgt"));
  ASSERT_EQ(dem.width, 1201);
  ASSERT_EQ(dem.height, 1201);
  EXPECT_EQ(dem.filled_voids, 0);
  EXPECT_EQ(dem.at(836, 875), 1908.0f);
  const auto [low, high] = std::minmax_element(dem.height_m.begin(), dem.height_m.end());
  EXPECT_EQ(*high, 1908.0f);
  EXPECT_EQ(*low, 115.0f);
  EXPECT_EQ(high - dem.height_m.begin(), 875 * 1201 + 836);
}

TEST(SrtmHgt, CornerPixelsAreCentredOnWholeDegrees) {
  // Pixel (0,0) is centred on (45 N, 72 W), pixel (1200, 1200) on (44 N, 71 W).
  const ElevationRaster dem = readSrtmHgt(dataPath("N44W072.hgt"));
  const core::Geodetic nw = dem.georef.geodeticFromPixel({0, 0});
  EXPECT_NEAR(nw.lat_rad * kDegPerRad, 45.0, 1e-12);
  EXPECT_NEAR(nw.lon_rad * kDegPerRad, -72.0, 1e-12);
  const core::Geodetic se = dem.georef.geodeticFromPixel({1200, 1200});
  EXPECT_NEAR(se.lat_rad * kDegPerRad, 44.0, 1e-12);
  EXPECT_NEAR(se.lon_rad * kDegPerRad, -71.0, 1e-12);
}

TEST(SrtmHgt, MountWashingtonHeightAt) {
  // heightAt(44.27083 N, 71.30333 W), 0.004 px from the 1908 m summit
  // sample, is 1908 m within interpolation tolerance; far outside -> nullopt.
  const ElevationRaster dem = readElevation(dataPath("N44W072.hgt"));
  const std::optional<double> summit =
      dem.heightAt(core::geodeticFromDegrees(44.27083, -71.30333, 0.0));
  ASSERT_TRUE(summit.has_value());
  EXPECT_NEAR(*summit, 1908.0, 0.5);
  EXPECT_FALSE(dem.heightAt(core::geodeticFromDegrees(46.0, -71.5, 0.0)).has_value());
  EXPECT_FALSE(dem.heightAt(core::geodeticFromDegrees(44.5, -70.99, 0.0)).has_value());
}

TEST(SrtmHgt, SouthEastNameAndVoidFilling) {
  // S12E034.hgt has its north-west sample on (11 S, 34 E); its voids (-32768)
  // in a field of height = 10 * row are filled with 10 * row.
  const std::string path = tempPath("S12E034.hgt");
  writeHgt(path, [](int col, int row) {
    const bool hole = (row == 600 && col >= 300 && col < 310) || (row == 5 && col == 7);
    return hole ? -32768 : 10 * row;
  });
  const ElevationRaster dem = readSrtmHgt(path);
  const core::Geodetic nw = dem.georef.geodeticFromPixel({0, 0});
  EXPECT_NEAR(nw.lat_rad * kDegPerRad, -11.0, 1e-12);
  EXPECT_NEAR(nw.lon_rad * kDegPerRad, 34.0, 1e-12);
  EXPECT_EQ(dem.filled_voids, 11);
  EXPECT_NEAR(dem.at(305, 600), 6000.0, 1e-3);
  EXPECT_NEAR(dem.at(7, 5), 50.0, 1e-3);
  EXPECT_TRUE(std::none_of(dem.height_m.begin(), dem.height_m.end(),
                           [](float h) { return std::isnan(h); }));
}

TEST(GeoTiffElevation, ZionFacts) {
  // zion_srtm.tif: uint16, EPSG:4326, 465 x 457, lon -113.2396..-112.8521,
  // lat 37.1321..37.5129, heights 1024..2892 m, no voids.
  const ElevationRaster dem = readGeoTiffElevation(dataPath("zion_srtm.tif"));
  ASSERT_EQ(dem.width, 465);
  ASSERT_EQ(dem.height, 457);
  EXPECT_EQ(dem.georef.crs, Crs::geographic());
  EXPECT_EQ(dem.filled_voids, 0);
  const auto [low, high] = std::minmax_element(dem.height_m.begin(), dem.height_m.end());
  EXPECT_EQ(*low, 1024.0f);
  EXPECT_EQ(*high, 2892.0f);
  const core::Geodetic nw = dem.georef.geodeticFromPixel({-0.5, -0.5});
  const core::Geodetic se = dem.georef.geodeticFromPixel({464.5, 456.5});
  EXPECT_NEAR(nw.lon_rad * kDegPerRad, -113.2396, 1e-4);
  EXPECT_NEAR(nw.lat_rad * kDegPerRad, 37.5129, 1e-4);
  EXPECT_NEAR(se.lon_rad * kDegPerRad, -112.8521, 1e-4);
  EXPECT_NEAR(se.lat_rad * kDegPerRad, 37.1321, 1e-4);
}

TEST(GeoTiffElevation, SampleTypes) {
  // int16 (negative heights), uint8, int32, float32 and float64 DEMs read
  // back their values: row 1, column 2 holds -3 + 10 + 2 = 9 and (0,0) -3
  // (uint8: 7 + 10 + 2 = 19).
  for (const int depth : {CV_16S, CV_8U, CV_32S, CV_32F, CV_64F}) {
    cv::Mat values(2, 3, CV_64F);
    const double base = depth == CV_8U ? 7.0 : -3.0;
    for (int row = 0; row < 2; ++row) {
      for (int col = 0; col < 3; ++col) values.at<double>(row, col) = base + 10 * row + col;
    }
    cv::Mat pixels;
    values.convertTo(pixels, depth);
    const std::string path = tempPath("type" + std::to_string(depth) + ".tif");
    writeGeoTiff(path, pixels, {0.5, 0.5, 0}, {0, 0, 0, 10, 20, 0}, geographicKeys());
    const ElevationRaster dem = readElevation(path);
    EXPECT_EQ(dem.at(0, 0), static_cast<float>(base)) << path;
    EXPECT_EQ(dem.at(2, 1), static_cast<float>(base + 12)) << path;
  }
}

TEST(GeoTiffElevation, NodataIsFilledFromNeighbours) {
  // A plane 100 + 10 col + 3 row with GDAL_NODATA -9999 at (2,2), (3,1) and
  // the corner (0,0): inner voids get the plane's value (inverse-distance
  // weighting along rows and columns is exact on a plane); the corner one a
  // value between its neighbours; 3 filled.
  cv::Mat plane(5, 6, CV_32F);
  for (int row = 0; row < 5; ++row) {
    for (int col = 0; col < 6; ++col) plane.at<float>(row, col) = 100.0f + 10 * col + 3 * row;
  }
  plane.at<float>(2, 2) = -9999;
  plane.at<float>(1, 3) = -9999;
  plane.at<float>(0, 0) = -9999;
  const std::string path = tempPath("nodata.tif");
  writeGeoTiff(path, plane, {0.1, 0.1, 0}, {0, 0, 0, 10, 20, 0}, geographicKeys(), "-9999");
  const ElevationRaster dem = readElevation(path);
  EXPECT_EQ(dem.filled_voids, 3);
  EXPECT_NEAR(dem.at(2, 2), 100 + 20 + 6, 1e-4);
  EXPECT_NEAR(dem.at(3, 1), 100 + 30 + 3, 1e-4);
  EXPECT_GE(dem.at(0, 0), 103.0f);
  EXPECT_LE(dem.at(0, 0), 110.0f);
}

TEST(GeoTiffElevation, LargeVoidsAndAllVoid) {
  // A raster void except one sample is filled with that sample everywhere; an
  // all-void raster is an error naming the file.
  cv::Mat values(6, 7, CV_16S, cv::Scalar(-32768));
  values.at<int16_t>(4, 5) = 321;
  const std::string path = tempPath("mostly_void.tif");
  writeGeoTiff(path, values, {0.1, 0.1, 0}, {0, 0, 0, 10, 20, 0}, geographicKeys(), "-32768");
  const ElevationRaster dem = readElevation(path);
  EXPECT_EQ(dem.filled_voids, 6 * 7 - 1);
  for (const float h : dem.height_m) EXPECT_EQ(h, 321.0f);

  values.at<int16_t>(4, 5) = -32768;
  const std::string void_path = tempPath("all_void.tif");
  writeGeoTiff(void_path, values, {0.1, 0.1, 0}, {0, 0, 0, 10, 20, 0}, geographicKeys(), "-32768");
  expectTerrainError([&] { readElevation(void_path); }, void_path, "void");
}

TEST(EsriAsciiGrid, CornerAndCentreOrigins) {
  // 3 x 2 cells of 0.5 deg: with xllcorner 10 / yllcorner 20 the lower-left
  // pixel (0, 1) is centred on (10.25, 20.25); with xllcenter/yllcenter on
  // (10, 20). NODATA_value samples are filled (row 0: 1 2 [3]).
  const std::string corner = tempPath("corner.asc");
  writeText(corner,
            "ncols 3\nnrows 2\nxllcorner 10\nyllcorner 20\ncellsize 0.5\nNODATA_value -9999\n"
            "1 2 -9999\n4 5 6\n");
  const std::string centre = tempPath("centre.asc");
  writeText(centre, "NCOLS 3\nNROWS 2\nXLLCENTER 10\nYLLCENTER 20\nCELLSIZE 0.5\n1 2 3\n4 5 6\n");
  const ElevationRaster a = readElevation(corner);
  const ElevationRaster b = readEsriAsciiGrid(centre);
  const CrsPoint a_ll = a.georef.crsFromPixel({0, 1});
  EXPECT_NEAR(a_ll.x, 10.25, 1e-12);
  EXPECT_NEAR(a_ll.y, 20.25, 1e-12);
  const CrsPoint b_ll = b.georef.crsFromPixel({0, 1});
  EXPECT_NEAR(b_ll.x, 10.0, 1e-12);
  EXPECT_NEAR(b_ll.y, 20.0, 1e-12);
  EXPECT_EQ(a.at(0, 0), 1.0f);
  EXPECT_EQ(a.at(2, 1), 6.0f);
  EXPECT_EQ(a.filled_voids, 1);
  // The void's neighbours: 2 to its left (distance 1), 6 below (distance 1).
  EXPECT_NEAR(a.at(2, 0), 4.0, 1e-5);
  EXPECT_EQ(b.filled_voids, 0);
}

TEST(EsriAsciiGrid, GivenCrsAndBadContent) {
  // A UTM CRS can be given; too few values, a non-number and a missing header
  // key are errors naming the file.
  const std::string utm = tempPath("utm.asc");
  writeText(utm, "ncols 2\nnrows 1\nxllcorner 300000\nyllcorner 4100000\ncellsize 30\n7 8\n");
  const ElevationRaster dem = readEsriAsciiGrid(utm, Crs::utm(12, true));
  EXPECT_EQ(dem.georef.crs, Crs::utm(12, true));
  EXPECT_DOUBLE_EQ(dem.georef.corner_y, 4100030.0);

  const std::string short_path = tempPath("short.asc");
  writeText(short_path, "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n");
  expectTerrainError([&] { readElevation(short_path); }, short_path, "found 3");
  const std::string word_path = tempPath("word.asc");
  writeText(word_path, "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 x\n");
  expectTerrainError([&] { readElevation(word_path); }, word_path, "'x' is not a number");
  const std::string header_path = tempPath("header.asc");
  writeText(header_path, "ncols 2\nnrows 1\nxllcorner 0\ncellsize 1\n1 2\n");
  expectTerrainError([&] { readElevation(header_path); }, header_path, "yllcorner");
}

TEST(ReadElevation, MalformedFilesNameThePath) {
  // Truncated and wrongly sized .hgt, a PNG renamed .hgt, a text file renamed
  // .tif, a GeoTIFF cut in half, an unsupported CRS (EPSG:3857), a .hgt with
  // no tile name, an RGB "DEM" and a missing file: each a TerrainError naming
  // the file and what is wrong.
  const std::string truncated = tempPath("N10E010.hgt");
  std::ofstream(truncated, std::ios::binary) << std::string(1000, '\x01');
  expectTerrainError([&] { readElevation(truncated); }, truncated, "1000 bytes");

  const std::string oversize = tempPath("N11E010.hgt");
  std::ofstream(oversize, std::ios::binary) << std::string(1201 * 1201 * 2 + 2, '\x01');
  expectTerrainError([&] { readElevation(oversize); }, oversize, "2884804 bytes");

  const std::string png = tempPath("N12E010.hgt");
  const std::string png_source = tempPath("image.png");
  cv::imwrite(png_source, cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
  std::filesystem::copy_file(png_source, png, std::filesystem::copy_options::overwrite_existing);
  expectTerrainError([&] { readElevation(png); }, png, "PNG");

  const std::string text = tempPath("dem_text.tif");
  writeText(text, "hello, I am not a GeoTIFF\n");
  expectTerrainError([&] { readElevation(text); }, text, "not a TIFF");

  const std::string cut_tiff = tempPath("cut_zion.tif");
  {
    std::ifstream in(dataPath("zion_srtm.tif"), std::ios::binary);
    std::string head(150000, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    std::ofstream(cut_tiff, std::ios::binary) << head;
  }
  expectTerrainError([&] { readElevation(cut_tiff); }, cut_tiff, "truncated");

  const std::string mercator = tempPath("dem_3857.tif");
  writeGeoTiff(mercator, cv::Mat(2, 2, CV_16S, cv::Scalar(1)), {30, 30, 0}, {0, 0, 0, 0, 0, 0},
               geoKeys({{1024, 1}, {1025, 1}, {3072, 3857}}));
  expectTerrainError([&] { readElevation(mercator); }, mercator, "3857");

  const std::string unnamed = tempPath("tile.hgt");
  writeHgt(unnamed, [](int, int) { return 1; });
  expectTerrainError([&] { readElevation(unnamed); }, unnamed, "file name");

  const std::string rgb = tempPath("rgb_dem.tif");
  writeGeoTiff(rgb, cv::Mat(2, 2, CV_8UC3, cv::Scalar(1, 2, 3)), {1, 1, 0}, {0, 0, 0, 0, 0, 0},
               geographicKeys());
  expectTerrainError([&] { readElevation(rgb); }, rgb, "3 bands");

  const std::string missing = tempPath("missing.hgt");
  expectTerrainError([&] { readElevation(missing); }, missing, "cannot open");
}

TEST(ReadElevation, DispatchesOnContentWithoutKnownExtension) {
  // A GeoTIFF named .dem and an ASCII grid named .txt are recognised by
  // content; random bytes named .bin are an error naming the file.
  const std::string tiff = tempPath("tiff_content.dem");
  writeGeoTiff(tiff, cv::Mat(2, 2, CV_16S, cv::Scalar(42)), {1, 1, 0}, {0, 0, 0, 0, 0, 0},
               geographicKeys());
  EXPECT_EQ(readElevation(tiff).at(1, 1), 42.0f);
  const std::string grid = tempPath("grid_content.txt");
  writeText(grid, "ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n17\n");
  EXPECT_EQ(readElevation(grid).at(0, 0), 17.0f);
  const std::string bin = tempPath("random.bin");
  std::ofstream(bin, std::ios::binary) << std::string("\x01\x02\x03\x80\x90", 5);
  expectTerrainError([&] { readElevation(bin); }, bin, "unknown elevation format");
}

}  // namespace
}  // namespace nadir::terrain
