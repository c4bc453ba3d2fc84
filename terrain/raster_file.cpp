#include "terrain/raster_file.h"

#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>

#include <opencv2/core.hpp>

#include "terrain/gdal_support.h"

namespace nadir::terrain {
namespace {

// The formats nadir opens (docs/terrain.md); GDAL knows many more, but a
// terrain file in any of those is better converted with gdal_translate.
constexpr std::array<const char*, 12> kDrivers{"GTiff",       "VRT", "SRTMHGT", "AAIGrid",
                                               "GTX",         "HFA", "EHdr",    "ISIS3",
                                               "JP2OpenJPEG", "PNG", "JPEG",    nullptr};

struct DatasetCloser {
  void operator()(GDALDataset* dataset) const { GDALClose(dataset); }
};
using DatasetPtr = std::unique_ptr<GDALDataset, DatasetCloser>;

DatasetPtr openRaster(const std::string& path, GdalErrors& errors) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw TerrainError(path + ": cannot open file" +
                       (std::filesystem::exists(path, ec) ? " (not a regular file)" : ""));
  }
  DatasetPtr dataset(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY,
                                       kDrivers.data(), nullptr, nullptr));
  if (!dataset) {
    const std::string content = describeFileContent(path);
    throw TerrainError(path + ": not a raster nadir can read" +
                       (content.empty() ? std::string() : " (it is " + content + ")") +
                       errors.said());
  }
  return dataset;
}

int cvDepthOf(GDALDataType type, const std::string& path) {
  switch (type) {
    case GDT_Byte:
      return CV_8U;
    case GDT_UInt16:
      return CV_16U;
    case GDT_Int16:
      return CV_16S;
    case GDT_Int32:
    case GDT_UInt32:
      return CV_32S;
    case GDT_Float32:
      return CV_32F;
    case GDT_Float64:
      return CV_64F;
    default:
      throw TerrainError(path + ": unsupported sample type " + GDALGetDataTypeName(type));
  }
}

bool isSignedByte(GDALRasterBand& band) {
  const char* type = band.GetMetadataItem("PIXELTYPE", "IMAGE_STRUCTURE");
  return band.GetRasterDataType() == GDT_Byte && type != nullptr &&
         std::string_view(type) == "SIGNEDBYTE";
}

}  // namespace

RasterInfo readRasterInfo(const std::string& path, const Crs& crs_if_none) {
  GdalErrors errors;
  const DatasetPtr dataset = openRaster(path, errors);
  RasterInfo info;
  info.path = path;
  info.driver = dataset->GetDriverName();
  info.width = dataset->GetRasterXSize();
  info.height = dataset->GetRasterYSize();
  info.bands = dataset->GetRasterCount();
  if (info.width <= 0 || info.height <= 0 || info.bands <= 0) {
    throw TerrainError(path + ": no pixels (" + std::to_string(info.width) + " x " +
                       std::to_string(info.height) + ", " + std::to_string(info.bands) + " bands)");
  }
  GDALRasterBand* band = dataset->GetRasterBand(1);
  info.depth = cvDepthOf(band->GetRasterDataType(), path);
  if (isSignedByte(*band)) info.depth = CV_8S;
  int has_nodata = 0;
  info.nodata = band->GetNoDataValue(&has_nodata);
  info.has_nodata = has_nodata != 0;
  info.overviews = band->GetOverviewCount();

  std::array<double, 6> transform{};
  if (dataset->GetGeoTransform(transform.data()) != CE_None) {
    throw TerrainError(path + ": no georeferencing (GDAL finds no geotransform" +
                       (info.driver == "GTiff" ? ": no GeoTIFF tags or world file)" : ")"));
  }
  if (transform[2] != 0.0 || transform[4] != 0.0) {
    throw TerrainError(path + ": rotated raster (its geotransform has shear terms " +
                       std::to_string(transform[2]) + ", " + std::to_string(transform[4]) +
                       "); warp it north-up with gdalwarp");
  }
  if (!(transform[1] > 0.0) || !(transform[5] < 0.0) || !std::isfinite(transform[0]) ||
      !std::isfinite(transform[3])) {
    throw TerrainError(path + ": not a north-up raster (pixel size " +
                       std::to_string(transform[1]) + ", " + std::to_string(transform[5]) + ")");
  }
  info.georef.corner_x = transform[0];
  info.georef.pixel_dx = transform[1];
  info.georef.corner_y = transform[3];
  info.georef.pixel_dy = transform[5];

  const OGRSpatialReference* srs = dataset->GetSpatialRef();
  if (srs == nullptr || srs->IsEmpty()) {
    info.crs_given = false;
    info.georef.crs = crs_if_none;
  } else {
    char* wkt = nullptr;
    const char* options[] = {"FORMAT=WKT2_2019", nullptr};
    srs->exportToWkt(&wkt, options);
    const std::string definition = wkt == nullptr ? "" : wkt;
    CPLFree(wkt);
    info.georef.crs = Crs::fromDefinition(definition, path);
  }
  return info;
}

RasterWindow rasterWindow(const RasterInfo& info, const RasterRegion& region) {
  RasterWindow window;
  window.width = info.width;
  window.height = info.height;
  if (region.half_size_m > 0.0) {
    constexpr int kSamplesPerSide = 16;
    const core::LocalNedFrame frame(region.centre);
    double col_min = std::numeric_limits<double>::infinity();
    double col_max = -col_min, row_min = col_min, row_max = -col_min;
    for (int side = 0; side < 4; ++side) {
      for (int i = 0; i <= kSamplesPerSide; ++i) {
        const double t = region.half_size_m * (2.0 * i / kSamplesPerSide - 1.0);
        const double h = region.half_size_m;
        const Eigen::Vector3d ned = side == 0   ? Eigen::Vector3d(h, t, 0)
                                    : side == 1 ? Eigen::Vector3d(-h, t, 0)
                                    : side == 2 ? Eigen::Vector3d(t, h, 0)
                                                : Eigen::Vector3d(t, -h, 0);
        const PixelPoint pixel = info.georef.pixelFromGeodetic(frame.geodeticFromNed(ned));
        if (!std::isfinite(pixel.col) || !std::isfinite(pixel.row)) continue;
        col_min = std::min(col_min, pixel.col);
        col_max = std::max(col_max, pixel.col);
        row_min = std::min(row_min, pixel.row);
        row_max = std::max(row_max, pixel.row);
      }
    }
    constexpr double kMargin_px = 2.0;
    const double first_col = std::max(std::floor(col_min - kMargin_px), 0.0);
    const double last_col = std::min(std::ceil(col_max + kMargin_px), info.width - 1.0);
    const double first_row = std::max(std::floor(row_min - kMargin_px), 0.0);
    const double last_row = std::min(std::ceil(row_max + kMargin_px), info.height - 1.0);
    if (!(first_col <= last_col) || !(first_row <= last_row)) {
      const double kDeg = 180.0 / std::numbers::pi;
      throw TerrainError(info.path + ": the " + std::to_string(2.0 * region.half_size_m) +
                         " m square around " + std::to_string(region.centre.lat_rad * kDeg) + ", " +
                         std::to_string(region.centre.lon_rad * kDeg) +
                         " deg is outside the raster");
    }
    window.col = static_cast<int>(first_col);
    window.row = static_cast<int>(first_row);
    window.width = static_cast<int>(last_col - first_col) + 1;
    window.height = static_cast<int>(last_row - first_row) + 1;
  }
  // A whole number of file pixels per sample, so that each sample is the
  // mean of a k x k block; the window grows (or, at the raster's edge,
  // shrinks) to whole blocks.
  int k = 1;
  if (region.resolution_m > 0.0) {
    const PixelGroundSize ground = info.georef.groundPixelSize(info.width, info.height);
    const double native_m = std::min(ground.col_m, ground.row_m);
    if (native_m > 0.0) {
      k = static_cast<int>(std::clamp(std::floor(region.resolution_m / native_m + 1e-9), 1.0,
                                      static_cast<double>(std::max(info.width, info.height))));
    }
  }
  const auto whole_blocks = [k](int& first, int& size, int limit) {
    size = (size + k - 1) / k * k;
    if (first + size > limit) first = std::max(limit - size, 0);
    if (first + size > limit) size = (limit - first) / k * k;
  };
  whole_blocks(window.col, window.width, info.width);
  whole_blocks(window.row, window.height, info.height);
  if (window.width < k || window.height < k) {
    throw TerrainError(info.path + ": " + std::to_string(region.resolution_m) +
                       " m samples are coarser than the raster's window");
  }
  window.out_width = window.width / k;
  window.out_height = window.height / k;
  const std::int64_t samples = std::int64_t{window.out_width} * window.out_height;
  if (samples > region.max_samples) {
    throw TerrainError(info.path + ": reading " + std::to_string(window.out_width) + " x " +
                       std::to_string(window.out_height) +
                       " samples is more than nadir reads at once (" +
                       std::to_string(region.max_samples) +
                       "); read a smaller square (world.extent_m) or coarser (world.resolution_m)");
  }
  window.georef = info.georef;
  window.georef.corner_x = info.georef.corner_x + window.col * info.georef.pixel_dx;
  window.georef.corner_y = info.georef.corner_y + window.row * info.georef.pixel_dy;
  window.georef.pixel_dx = info.georef.pixel_dx * window.width / window.out_width;
  window.georef.pixel_dy = info.georef.pixel_dy * window.height / window.out_height;
  return window;
}

std::vector<BandSamples> readBands(const RasterInfo& info, const std::vector<int>& bands,
                                   const RasterWindow& window, bool eight_bit) {
  GdalErrors errors;
  const DatasetPtr dataset = openRaster(info.path, errors);
  if (dataset->GetRasterXSize() != info.width || dataset->GetRasterYSize() != info.height) {
    throw TerrainError(info.path + ": changed since it was first read");
  }
  GDALRasterIOExtraArg resample;
  INIT_RASTERIO_EXTRA_ARG(resample);
  const bool coarser = window.out_width < window.width || window.out_height < window.height;
  resample.eResampleAlg = coarser ? GRIORA_Average : GRIORA_NearestNeighbour;
  GDALRasterIOExtraArg nearest;
  INIT_RASTERIO_EXTRA_ARG(nearest);

  std::vector<BandSamples> out;
  for (const int index : bands) {
    if (index < 1 || index > dataset->GetRasterCount()) {
      throw TerrainError(info.path + ": has no band " + std::to_string(index));
    }
    GDALRasterBand* band = dataset->GetRasterBand(index);
    const bool as_bytes =
        eight_bit && band->GetRasterDataType() == GDT_Byte && !isSignedByte(*band);
    BandSamples samples;
    samples.values.create(window.out_height, window.out_width, as_bytes ? CV_8U : CV_32F);
    if (band->RasterIO(GF_Read, window.col, window.row, window.width, window.height,
                       samples.values.data, window.out_width, window.out_height,
                       as_bytes ? GDT_Byte : GDT_Float32, 0,
                       static_cast<GSpacing>(samples.values.step[0]), &resample) != CE_None) {
      throw TerrainError(info.path + ": cannot read band " + std::to_string(index) +
                         " (truncated or corrupt?)" + errors.said());
    }
    if (isSignedByte(*band)) {
      cv::subtract(samples.values, cv::Scalar(256.0), samples.values, samples.values > 127.0f);
    }
    samples.valid.create(window.out_height, window.out_width, CV_8U);
    if ((band->GetMaskFlags() & GMF_ALL_VALID) != 0) {
      samples.valid.setTo(255);
    } else if (band->GetMaskBand()->RasterIO(
                   GF_Read, window.col, window.row, window.width, window.height, samples.valid.data,
                   window.out_width, window.out_height, GDT_Byte, 0,
                   static_cast<GSpacing>(samples.valid.step[0]), &nearest) != CE_None) {
      throw TerrainError(info.path + ": cannot read the valid samples of band " +
                         std::to_string(index) + errors.said());
    }
    if (!as_bytes) {
      // NaN is the one value unequal to itself. Whole-raster OpenCV operations here, not
      // a loop per sample: a raster can hold 2^28 samples.
      cv::Mat not_nan;
      cv::compare(samples.values, samples.values, not_nan, cv::CMP_EQ);
      samples.valid &= not_nan;
    }
    out.push_back(std::move(samples));
  }
  return out;
}

}  // namespace nadir::terrain
