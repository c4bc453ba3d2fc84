#include "terrain_test_util.h"
#include <gtest/gtest.h>
#include <ogr_spatialref.h>
#include <tiffio.h>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <opencv2/core.hpp>
#include <string>
#include <vector>
#include "core/geodesy.h"
#include "terrain/georef.h"

namespace nadir::terrain {
namespace test {

std::string tempPath(const std::string& name) {
  return (std::filesystem::path(::testing::TempDir()) / ("nadir_terrain_" + name)).string();
}

std::string tempFolderPath(const std::string& name) {
  const std::filesystem::path folder =
      std::filesystem::path(::testing::TempDir()) / "nadir_terrain";
  std::filesystem::create_directories(folder);
  return (folder / name).string();
}

double egm96Undulation_m(double lat_deg, double lon_deg) {
  OGRSpatialReference geoid_heights;
  OGRSpatialReference ellipsoid_heights;
  geoid_heights.importFromEPSG(9707);
  ellipsoid_heights.importFromEPSG(4979);
  geoid_heights.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  ellipsoid_heights.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  const std::unique_ptr<OGRCoordinateTransformation> to_ellipsoid(
      OGRCreateCoordinateTransformation(&geoid_heights, &ellipsoid_heights));
  double x = lon_deg, y = lat_deg, z = 0.0;
  if (!to_ellipsoid || !to_ellipsoid->Transform(1, &x, &y, &z)) {
    ADD_FAILURE() << "PROJ cannot convert EGM96 heights at " << lat_deg << ", " << lon_deg;
  }
  return z;
}

std::string dataPath(const std::string& name) {
  return (std::filesystem::path(NADIR_TEST_DATA_DIR) / "terrain" / name).string();
}

std::vector<uint16_t> geoKeys(const std::vector<std::pair<uint16_t, uint16_t>>& keys) {
  std::vector<uint16_t> directory{1, 1, 0, static_cast<uint16_t>(keys.size())};
  for (const auto& [id, value] : keys) {
    directory.insert(directory.end(), {id, 0, 1, value});
  }
  return directory;
}

void writeGeoTiff(const std::string& path, const cv::Mat& pixels,
                  const std::vector<double>& pixel_scale, const std::vector<double>& tiepoint,
                  const std::vector<uint16_t>& geokeys, const std::string& nodata,
                  const std::vector<double>& transform) {
  static const TIFFFieldInfo kGeoTiffFields[] = {
      {33550, -1, -1, TIFF_DOUBLE, FIELD_CUSTOM, 1, 1, const_cast<char*>("ModelPixelScale")},
      {33922, -1, -1, TIFF_DOUBLE, FIELD_CUSTOM, 1, 1, const_cast<char*>("ModelTiepoint")},
      {34264, -1, -1, TIFF_DOUBLE, FIELD_CUSTOM, 1, 1, const_cast<char*>("ModelTransformation")},
      {34735, -1, -1, TIFF_SHORT, FIELD_CUSTOM, 1, 1, const_cast<char*>("GeoKeyDirectory")},
      {42113, -1, -1, TIFF_ASCII, FIELD_CUSTOM, 1, 0, const_cast<char*>("GDALNoDataValue")},
  };
  int format = SAMPLEFORMAT_UINT;
  if (pixels.depth() == CV_8S || pixels.depth() == CV_16S || pixels.depth() == CV_32S) {
    format = SAMPLEFORMAT_INT;
  }
  if (pixels.depth() == CV_32F || pixels.depth() == CV_64F) format = SAMPLEFORMAT_IEEEFP;
  TIFF* tif = TIFFOpen(path.c_str(), "w");
  ASSERT_NE(tif, nullptr) << path;
  ASSERT_EQ(TIFFMergeFieldInfo(tif, kGeoTiffFields, 5), 0);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, pixels.cols);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, pixels.rows);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, pixels.channels());
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, static_cast<int>(8 * pixels.elemSize1()));
  TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, format);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC,
               pixels.channels() >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, pixels.rows);
  if (!pixel_scale.empty()) {
    TIFFSetField(tif, 33550, static_cast<int>(pixel_scale.size()), pixel_scale.data());
  }
  if (!tiepoint.empty()) {
    TIFFSetField(tif, 33922, static_cast<int>(tiepoint.size()), tiepoint.data());
  }
  if (!transform.empty()) {
    TIFFSetField(tif, 34264, static_cast<int>(transform.size()), transform.data());
  }
  if (!geokeys.empty()) {
    TIFFSetField(tif, 34735, static_cast<int>(geokeys.size()), geokeys.data());
  }
  if (!nodata.empty()) TIFFSetField(tif, 42113, nodata.c_str());
  for (int r = 0; r < pixels.rows; ++r) {
    ASSERT_EQ(TIFFWriteScanline(tif, const_cast<unsigned char*>(pixels.ptr<unsigned char>(r)),
                                static_cast<uint32_t>(r), 0),
              1);
  }
  TIFFClose(tif);
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace test
}  // namespace nadir::terrain
