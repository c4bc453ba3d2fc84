#pragma once
// Helpers shared by the terrain reader tests: temporary and test-data paths,
// and writers of small GeoTIFF and text files with known tags.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace nadir::terrain {
namespace test {

std::string tempPath(const std::string& name);
// name itself in a folder of the test's own (for files whose name matters,
// like an SRTM tile's).
std::string tempFolderPath(const std::string& name);
std::string dataPath(const std::string& name);
std::vector<uint16_t> geoKeys(const std::vector<std::pair<uint16_t, uint16_t>>& keys);
// A strip GeoTIFF of pixels (channels in file order) with the given GeoTIFF
// tags; an empty argument leaves its tag out.
void writeGeoTiff(const std::string& path, const cv::Mat& pixels,
                  const std::vector<double>& pixel_scale, const std::vector<double>& tiepoint,
                  const std::vector<uint16_t>& geokeys, const std::string& nodata = "",
                  const std::vector<double>& transform = {});
// EGM96's geoid undulation at a point, m, as PROJ computes it (EPSG:9707,
// WGS 84 + EGM96 height, to EPSG:4979): an implementation independent of
// nadir's.
double egm96Undulation_m(double lat_deg, double lon_deg);
void writeText(const std::string& path, const std::string& text);

}  // namespace test
}  // namespace nadir::terrain
