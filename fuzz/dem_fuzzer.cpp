// The DEM readers on any bytes; the first byte picks the file's name: an ESRI
// ASCII grid (.asc), a GeoTIFF (.tif), a name that says nothing (read by
// content: any format the readers open through GDAL, a VRT among them), or an
// SRTM tile (.hgt: the input repeated to the size of a 1201 x 1201 tile, so
// its voids and heights vary). What reads is a whole
// raster without NaN, and every height asked of it is finite or nothing. A
// read through GDAL giving more samples than an SRTM tile holds is refused.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "fuzz/fuzz_input.h"
#include "terrain/elevation.h"

namespace {

// The input repeated: copied once, then doubled until the tile is full.
std::string writeHgt(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> tile(1201u * 1201u * 2u, 0);
  std::size_t filled = std::min(size, tile.size());
  std::copy(data, data + filled, tile.begin());
  while (filled > 0 && filled < tile.size()) {
    const std::size_t more = std::min(filled, tile.size() - filled);
    std::copy(tile.begin(), tile.begin() + static_cast<std::ptrdiff_t>(more),
              tile.begin() + static_cast<std::ptrdiff_t>(filled));
    filled += more;
  }
  return nadir::fuzz::writeInput(tile.data(), tile.size(), "N44W072.hgt");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t kind = data[0] % 4;
  ++data;
  --size;
  using namespace nadir::terrain;
  try {
    const std::string path = kind == 0   ? nadir::fuzz::writeInput(data, size, "input.asc")
                             : kind == 1 ? nadir::fuzz::writeInput(data, size, "input.tif")
                             : kind == 2 ? nadir::fuzz::writeInput(data, size, "input.dem")
                                         : writeHgt(data, size);
    ElevationReadOptions options;
    options.region.max_samples = nadir::fuzz::kMaxSamplesRead;
    const ElevationRaster dem = readElevation(path, options);
    NADIR_FUZZ_REQUIRE(dem.width > 0 && dem.height > 0);
    NADIR_FUZZ_REQUIRE(dem.height_m.size() ==
                       static_cast<std::size_t>(dem.width) * static_cast<std::size_t>(dem.height));
    for (const float h : dem.height_m) NADIR_FUZZ_REQUIRE(std::isfinite(h));
    for (const double fraction : {0.0, 0.37, 1.0}) {
      const PixelPoint pixel{fraction * dem.width - 0.5, fraction * dem.height - 0.5};
      const auto at_pixel = dem.heightAtPixel(pixel);
      NADIR_FUZZ_REQUIRE(!at_pixel || std::isfinite(*at_pixel));
      const auto at_point = dem.heightAt(dem.georef.geodeticFromPixel(pixel));
      NADIR_FUZZ_REQUIRE(!at_point || std::isfinite(*at_point));
    }
  } catch (const TerrainError&) {
  }
  return 0;
}
