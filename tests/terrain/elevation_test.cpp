#include "terrain/elevation.h"

#include <clocale>
#include <cstdio>
#include <cstdlib>

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
#include "terrain/raster_file.h"

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
  const ElevationRaster dem = readElevation(dataPath("N44W072.hgt"));
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
  const ElevationRaster dem = readElevation(dataPath("N44W072.hgt"));
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
  const std::string path = test::tempFolderPath("S12E034.hgt");
  writeHgt(path, [](int col, int row) {
    const bool hole = (row == 600 && col >= 300 && col < 310) || (row == 5 && col == 7);
    return hole ? -32768 : 10 * row;
  });
  const ElevationRaster dem = readElevation(path);
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
  const ElevationRaster dem = readElevation(dataPath("zion_srtm.tif"));
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
  const ElevationRaster b = readElevation(centre);
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
  ElevationReadOptions in_utm;
  in_utm.crs_if_none = Crs::utm(12, true);
  const ElevationRaster dem = readElevation(utm, in_utm);
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
  // .tif, a GeoTIFF cut in half, a rotated raster, a .hgt with
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
  expectTerrainError([&] { readElevation(text); }, text, "text starting 'hello");

  const std::string cut_tiff = tempPath("cut_zion.tif");
  {
    std::ifstream in(dataPath("zion_srtm.tif"), std::ios::binary);
    std::string head(150000, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    std::ofstream(cut_tiff, std::ios::binary) << head;
  }
  expectTerrainError([&] { readElevation(cut_tiff); }, cut_tiff, "truncated");

  const std::string rotated = tempPath("dem_rotated.tif");
  writeGeoTiff(rotated, cv::Mat(2, 2, CV_16S, cv::Scalar(1)), {}, {}, geographicKeys(), "",
               {0.01, 0.002, 0, 7, 0.002, -0.01, 0, 46, 0, 0, 0, 0, 0, 0, 0, 1});
  expectTerrainError([&] { readElevation(rotated); }, rotated, "rotated");

  const std::string unnamed = tempPath("tile.hgt");
  writeHgt(unnamed, [](int, int) { return 1; });
  expectTerrainError([&] { readElevation(unnamed); }, unnamed, "file name starts with");

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
  expectTerrainError([&] { readElevation(bin); }, bin, "not a raster nadir can read");
}

// zion_srtm.tif's samples as they are in the file (uint16, row 0 north).
cv::Mat zionSamples() { return cv::imread(dataPath("zion_srtm.tif"), cv::IMREAD_UNCHANGED); }

// Writes columns [first_col, first_col + cols) of zion_srtm.tif as a
// geographic GeoTIFF on the same grid.
void writeZionColumns(const std::string& path, int first_col, int cols) {
  const RasterGeoref zion = readRasterInfo(dataPath("zion_srtm.tif")).georef;
  const cv::Mat samples = zionSamples();
  writeGeoTiff(path, samples.colRange(first_col, first_col + cols).clone(),
               {zion.pixel_dx, -zion.pixel_dy, 0},
               {0, 0, 0, zion.corner_x + first_col * zion.pixel_dx, zion.corner_y, 0},
               geographicKeys());
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

TEST(GdalTerrain, TwoTileVrtReadsAsTheWholeFile) {
  // zion_srtm.tif cut into a west tile (232 columns) and an east one (233),
  // joined again by a VRT written by hand: the mosaic is the whole file
  // sample for sample, and a flight line across the seam sees the same
  // ground in both.
  const std::string west = test::tempFolderPath("zion_west.tif");
  const std::string east = test::tempFolderPath("zion_east.tif");
  writeZionColumns(west, 0, 232);
  writeZionColumns(east, 232, 233);
  const RasterGeoref zion = readRasterInfo(dataPath("zion_srtm.tif")).georef;
  const auto source = [](const std::string& file, int x_off, int cols) {
    return "    <SimpleSource>\n      <SourceFilename relativeToVRT=\"1\">" + file +
           "</SourceFilename>\n      <SourceBand>1</SourceBand>\n      <SrcRect xOff=\"0\" "
           "yOff=\"0\" xSize=\"" +
           std::to_string(cols) + "\" ySize=\"457\"/>\n      <DstRect xOff=\"" +
           std::to_string(x_off) + "\" yOff=\"0\" xSize=\"" + std::to_string(cols) +
           "\" ySize=\"457\"/>\n    </SimpleSource>\n";
  };
  const std::string vrt = test::tempFolderPath("zion_mosaic.vrt");
  writeText(vrt,
            "<VRTDataset rasterXSize=\"465\" rasterYSize=\"457\">\n  <SRS>EPSG:4326</SRS>\n"
            "  <GeoTransform>" +
                number(zion.corner_x) + ", " + number(zion.pixel_dx) + ", 0, " +
                number(zion.corner_y) + ", 0, " + number(zion.pixel_dy) +
                "</GeoTransform>\n  <VRTRasterBand dataType=\"UInt16\" band=\"1\">\n" +
                source("zion_west.tif", 0, 232) + source("zion_east.tif", 232, 233) +
                "  </VRTRasterBand>\n</VRTDataset>\n");
  EXPECT_EQ(readRasterInfo(vrt).driver, "VRT");
  const ElevationRaster mosaic = readElevation(vrt);
  const ElevationRaster whole = readElevation(dataPath("zion_srtm.tif"));
  ASSERT_EQ(mosaic.width, 465);
  ASSERT_EQ(mosaic.height, 457);
  EXPECT_TRUE(mosaic.georef.sameGrid(whole.georef));
  EXPECT_EQ(mosaic.height_m, whole.height_m);
  const double seam_lon_deg = zion.corner_x + 232 * zion.pixel_dx;
  for (const double d_deg : {-0.003, -0.0001, 0.0001, 0.003}) {
    const core::Geodetic at = core::geodeticFromDegrees(37.3, seam_lon_deg + d_deg, 0.0);
    EXPECT_EQ(mosaic.heightAt(at), whole.heightAt(at)) << d_deg;
    EXPECT_TRUE(mosaic.heightAt(at).has_value());
  }
}

TEST(GdalTerrain, AWindowIsTheSameSamplesAsTheWholeFile) {
  // The 4 km square around (37.3 N, 113.0 W): 4000 m / 73.8 m = 54.2
  // columns and 4000 m / 92.5 m = 43.2 rows of the 3" grid (3" of longitude
  // is 92.8 m x cos 37.3 deg), plus two pixels of margin each side and up to
  // two more for rounding; each sample is the whole file's at the same place.
  const ElevationRaster whole = readElevation(dataPath("zion_srtm.tif"));
  ElevationReadOptions options;
  options.region.centre = core::geodeticFromDegrees(37.3, -113.0, 0.0);
  options.region.half_size_m = 2000.0;
  const ElevationRaster part = readElevation(dataPath("zion_srtm.tif"), options);
  EXPECT_GE(part.width, 54 + 4);
  EXPECT_LE(part.width, 55 + 4 + 2);
  EXPECT_GE(part.height, 43 + 4);
  EXPECT_LE(part.height, 44 + 4 + 2);
  const PixelPoint origin = whole.georef.pixelFromCrs(part.georef.crsFromPixel({0, 0}));
  EXPECT_NEAR(origin.col, std::round(origin.col), 1e-9);
  EXPECT_NEAR(origin.row, std::round(origin.row), 1e-9);
  for (int row = 0; row < part.height; ++row) {
    for (int col = 0; col < part.width; ++col) {
      ASSERT_EQ(part.at(col, row), whole.at(col + static_cast<int>(std::lround(origin.col)),
                                            row + static_cast<int>(std::lround(origin.row))));
    }
  }
  EXPECT_TRUE(part.heightAt(options.region.centre).has_value());

  // Read 3.5 x as coarse as the pixels are wide: every sample is the mean of
  // a 3 x 3 block of the file's pixels, rounded to the file's whole metres
  // (GDAL averages in the samples' type, as overviews of it are).
  options.region.resolution_m = 3.5 * whole.georef.groundPixelSize(465, 457).col_m;
  const ElevationRaster coarse = readElevation(dataPath("zion_srtm.tif"), options);
  EXPECT_NEAR(coarse.width, part.width / 3.0, 1.0);
  EXPECT_NEAR(coarse.height, part.height / 3.0, 1.0);
  EXPECT_NEAR(coarse.georef.pixel_dx, 3.0 * whole.georef.pixel_dx, 1e-15);
  EXPECT_NEAR(coarse.georef.pixel_dy, 3.0 * whole.georef.pixel_dy, 1e-15);
  const PixelPoint first = whole.georef.pixelFromCrs(coarse.georef.crsFromPixel({-0.5, -0.5}));
  const int c0 = static_cast<int>(std::lround(first.col + 0.5));
  const int r0 = static_cast<int>(std::lround(first.row + 0.5));
  for (const auto& [col, row] : std::vector<std::pair<int, int>>{{0, 0}, {5, 7}, {12, 3}}) {
    double block_sum = 0.0;
    for (int dr = 0; dr < 3; ++dr) {
      for (int dc = 0; dc < 3; ++dc) block_sum += whole.at(c0 + 3 * col + dc, r0 + 3 * row + dr);
    }
    EXPECT_NEAR(coarse.at(col, row), block_sum / 9.0, 0.5) << col << ", " << row;
  }

  options.region.centre = core::geodeticFromDegrees(10.0, 10.0, 0.0);
  expectTerrainError([&] { readElevation(dataPath("zion_srtm.tif"), options); },
                     dataPath("zion_srtm.tif"), "outside the raster");
}

TEST(GdalTerrain, AReadOverItsSampleLimitIsRefusedNamingTheLimit) {
  // A read may give at most region.max_samples samples: the whole file at
  // exactly its width x height reads, one fewer is refused with the limit and
  // the two settings that make a read smaller in the message.
  const ElevationRaster whole = readElevation(dataPath("zion_srtm.tif"));
  ElevationReadOptions options;
  options.region.max_samples = std::int64_t{whole.width} * whole.height;
  EXPECT_EQ(readElevation(dataPath("zion_srtm.tif"), options).height_m, whole.height_m);
  options.region.max_samples -= 1;
  const std::string limit = std::to_string(options.region.max_samples);
  expectTerrainError([&] { readElevation(dataPath("zion_srtm.tif"), options); },
                     dataPath("zion_srtm.tif"), "more than nadir reads at once (" + limit + ")");
  expectTerrainError([&] { readElevation(dataPath("zion_srtm.tif"), options); },
                     dataPath("zion_srtm.tif"), "world.resolution_m");
}

TEST(GdalTerrain, Nad83UtmDem) {
  // A 3 x 2 DEM in NAD83 / UTM 12N (EPSG:26912, as USGS 3DEP tiles come),
  // 10 m pixels, heights 100 + col + 10 row: read with its CRS; the height
  // under the geodetic position of pixel (2, 1)'s centre is that pixel's.
  cv::Mat heights(2, 3, CV_32F);
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 3; ++col) heights.at<float>(row, col) = 100.0f + col + 10.0f * row;
  }
  const std::string path = tempPath("nad83_utm12.tif");
  writeGeoTiff(path, heights, {10, 10, 0}, {0, 0, 0, 320000, 4130000, 0},
               geoKeys({{1024, 1}, {1025, 1}, {3072, 26912}}));
  const ElevationRaster dem = readElevation(path);
  EXPECT_EQ(dem.georef.crs.epsg(), 26912);
  EXPECT_EQ(dem.georef.crs.name(), "EPSG:26912 (NAD83 / UTM zone 12N)");
  const core::Geodetic centre = dem.georef.geodeticFromPixel({2, 1});
  EXPECT_NEAR(centre.lat_rad * kDegPerRad, 37.3, 0.05);
  EXPECT_NEAR(*dem.heightAt(centre), 112.0, 1e-6);
  // The same place in WGS-84 UTM 12N is within the datums' 1-2 m.
  const CrsPoint utm = Crs::utm(12, true).fromGeodetic(centre);
  EXPECT_LT(std::hypot(utm.x - 320025.0, utm.y - 4129985.0), 3.0);
}

TEST(GdalTerrain, AsciiGridCrsFromItsPrj) {
  // An ESRI grid with a .prj beside it (ESRI WKT of NAD83 / UTM 12N) is in
  // that CRS; without one, in the CRS given for grids naming none.
  const std::string grid = test::tempFolderPath("with_prj.asc");
  writeText(grid, "ncols 2\nnrows 1\nxllcorner 320000\nyllcorner 4130000\ncellsize 30\n7 8\n");
  writeText(test::tempFolderPath("with_prj.prj"),
            "PROJCS[\"NAD_1983_UTM_Zone_12N\",GEOGCS[\"GCS_North_American_1983\","
            "DATUM[\"D_North_American_1983\",SPHEROID[\"GRS_1980\",6378137.0,298.257222101]],"
            "PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]],"
            "PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"False_Easting\",500000.0],"
            "PARAMETER[\"False_Northing\",0.0],PARAMETER[\"Central_Meridian\",-111.0],"
            "PARAMETER[\"Scale_Factor\",0.9996],PARAMETER[\"Latitude_Of_Origin\",0.0],"
            "UNIT[\"Meter\",1.0]]");
  const ElevationRaster dem = readElevation(grid);
  EXPECT_EQ(dem.georef.crs, Crs::fromEpsg(26912, "test"));
  EXPECT_EQ(dem.at(1, 0), 8.0f);
}

// Makes a de_DE.UTF-8 locale (decimal comma) in a folder of the test's own
// with glibc's localedef and switches to it, as Qt does for a German user.
class GermanLocale {
 public:
  GermanLocale() {
    const std::string folder = test::tempFolderPath("locales");
    std::filesystem::create_directories(folder);
    const std::string command = "localedef -i de_DE -f UTF-8 '" + folder + "/de_DE.UTF-8' 2>&1";
    made_ = std::system(command.c_str()) == 0;
    setenv("LOCPATH", folder.c_str(), 1);
    made_ = made_ && std::setlocale(LC_ALL, "de_DE.UTF-8") != nullptr;
  }
  ~GermanLocale() {
    std::setlocale(LC_ALL, "C");
    unsetenv("LOCPATH");
  }
  bool made() const { return made_; }

 private:
  bool made_ = false;
};

TEST(GdalTerrain, NodataIsReadTheSameUnderADecimalCommaLocale) {
  // A float DEM whose nodata is -3.4028234663852886e+38 (GDAL's usual float
  // nodata) read under de_DE, where strtod stops at the '.' and reads -3: the
  // two voids are still voids and are filled from their neighbours (all 50).
  cv::Mat heights(3, 4, CV_32F, cv::Scalar(50.0f));
  heights.at<float>(1, 1) = -3.4028234663852886e+38f;
  heights.at<float>(2, 3) = -3.4028234663852886e+38f;
  const std::string path = tempPath("float_nodata.tif");
  writeGeoTiff(path, heights, {0.1, 0.1, 0}, {0, 0, 0, 10, 20, 0}, geographicKeys(),
               "-3.4028234663852886e+38");
  const GermanLocale german;
  ASSERT_TRUE(german.made()) << "localedef could not make de_DE.UTF-8 (package locales)";
  char text[16];
  std::snprintf(text, sizeof(text), "%.1f", 2.5);
  ASSERT_EQ(std::string(text), "2,5");  // the locale is really in force
  const ElevationRaster dem = readElevation(path);
  EXPECT_EQ(dem.filled_voids, 2);
  for (const float h : dem.height_m) EXPECT_EQ(h, 50.0f);
}

TEST(GdalTerrain, GeoidHeightsBecomeEllipsoidHeights) {
  // With Debian's EGM96 grid (proj-data), h = H + N. N at (0 N, 0 E) is the
  // often-quoted 17.16 m; over Zion N is about -22 m, and at each sample
  // nadir's N matches PROJ's own EGM96 conversion (EPSG:9707 -> 4979, its
  // own interpolation of the grid) to a centimetre.
  const std::string egm96 = "/usr/share/proj/egm96_15.gtx";
  ASSERT_TRUE(std::filesystem::exists(egm96)) << "package proj-data";
  cv::Mat flat(3, 3, CV_32F, cv::Scalar(0.0f));
  const std::string null_island = tempPath("null_island.tif");
  writeGeoTiff(null_island, flat, {0.01, 0.01, 0}, {0, 0, 0, -0.015, 0.015, 0}, geographicKeys());
  ElevationReadOptions options;
  options.geoid_path = egm96;
  const ElevationRaster island = readElevation(null_island, options);
  EXPECT_NEAR(island.at(1, 1), 17.16, 0.01);
  EXPECT_EQ(island.geoid_source, egm96);

  const ElevationRaster plain = readElevation(dataPath("zion_srtm.tif"));
  const ElevationRaster lifted = readElevation(dataPath("zion_srtm.tif"), options);
  EXPECT_GT(lifted.geoid_min_m, -25.0);
  EXPECT_LT(lifted.geoid_max_m, -19.0);
  for (const auto& [col, row] :
       std::vector<std::pair<int, int>>{{0, 0}, {464, 456}, {200, 300}, {17, 33}}) {
    const core::Geodetic at = plain.georef.geodeticFromPixel({double(col), double(row)});
    const double proj_n_m =
        test::egm96Undulation_m(at.lat_rad * kDegPerRad, at.lon_rad * kDegPerRad);
    EXPECT_NEAR(lifted.at(col, row) - plain.at(col, row), proj_n_m, 0.01) << col << ", " << row;
  }

  const std::string far_away = tempPath("not_a_geoid.tif");
  writeGeoTiff(far_away, flat, {0.01, 0.01, 0}, {0, 0, 0, 50, 50, 0}, geographicKeys());
  options.geoid_path = far_away;
  expectTerrainError([&] { readElevation(null_island, options); }, far_away, "outside the raster");
}

}  // namespace
}  // namespace nadir::terrain
