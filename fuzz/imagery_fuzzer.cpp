// The imagery readers on any bytes; the first byte picks the reader: an RGB
// raster (.tif, read by GDAL by content), three single-band rasters (the input as each band), or a
// plain image with given bounds. What reads is an 8-bit RGB raster whose colours can be asked
// anywhere. A read giving more than kMaxSamplesRead samples in its three bands is refused.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_input.h"
#include "terrain/imagery.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t kind = data[0] % 3;
  ++data;
  --size;
  using namespace nadir::terrain;
  try {
    ImageryRaster imagery;
    RasterRegion whole;
    whole.max_samples = nadir::fuzz::kMaxSamplesRead / 3;
    if (kind == 0) {
      imagery = readImageryRgb(nadir::fuzz::writeInput(data, size, "rgb.tif"), whole);
    } else if (kind == 1) {
      const std::string band = nadir::fuzz::writeInput(data, size, "band.tif");
      imagery = readImageryBands(band, band, band, whole);
    } else {
      imagery = readImageWithBounds(nadir::fuzz::writeInput(data, size, "image.png"),
                                    LatLonBounds{37.5, 37.1, -113.2, -112.8});
    }
    NADIR_FUZZ_REQUIRE(imagery.rgb.type() == CV_8UC3 && imagery.width() > 0 &&
                       imagery.height() > 0);
    for (const double fraction : {0.0, 0.37, 1.0}) {
      const PixelPoint pixel{fraction * imagery.width() - 0.5, fraction * imagery.height() - 0.5};
      (void)imagery.colourAtPixel(pixel);
      (void)imagery.colourAt(imagery.georef.geodeticFromPixel(pixel));
    }
  } catch (const TerrainError&) {
  }
  return 0;
}
