// Writes the fuzz targets' seed corpora (docs/reliability.md): one encoded
// message of each type, small LCM logs of a short flight, and small rasters cut
// from the real files in tests/data/terrain with their georeferencing. A seed
// for a target whose first byte picks the reader starts with that byte; logs
// have no .lcmlog ending (the repository ignores those).
//   nadir-fuzz-seeds tests/data/terrain fuzz/corpus
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/frames.h"
#include "core/lcm_log.h"
#include "lcmtypes/codec.h"
#include "terrain/georef.h"
#include "terrain/raster_file.h"
#include "tests/terrain/terrain_test_util.h"

namespace {

using namespace nadir;
namespace fs = std::filesystem;

void writeFile(const fs::path& path, const msg::Bytes& bytes, std::string_view prefix = {}) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(prefix.data(), static_cast<std::streamsize>(prefix.size()));
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

msg::Bytes readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return msg::Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

msg::Bytes textBytes(std::string_view text) { return msg::Bytes(text.begin(), text.end()); }

// A GeoTIFF of the window of a real one, with the same CRS and pixel size.
msg::Bytes cutGeoTiff(const fs::path& source, const cv::Rect& window, const fs::path& scratch) {
  const terrain::RasterInfo info = terrain::readRasterInfo(source.string());
  const cv::Mat pixels = cv::imread(source.string(), cv::IMREAD_UNCHANGED)(window).clone();
  const terrain::RasterGeoref& g = info.georef;
  const bool geographic = g.crs.kind == terrain::Crs::Kind::kGeographic;
  const std::vector<std::uint16_t> keys =
      geographic ? terrain::test::geoKeys({{1024, 2}, {1025, 1}, {2048, 4326}})
                 : terrain::test::geoKeys(
                       {{1024, 1}, {1025, 1}, {3072, static_cast<std::uint16_t>(g.crs.epsg())}});
  terrain::test::writeGeoTiff(
      scratch.string(), pixels, {g.pixel_dx, -g.pixel_dy, 0},
      {0, 0, 0, g.corner_x + window.x * g.pixel_dx, g.corner_y + window.y * g.pixel_dy, 0}, keys,
      info.has_nodata ? "-32768" : "");
  msg::Bytes bytes = readFile(scratch);
  fs::remove(scratch);
  return bytes;
}

void writeRasters(const fs::path& data, const fs::path& corpus) {
  const fs::path dem = corpus / "dem";
  const fs::path imagery = corpus / "imagery";
  fs::create_directories(dem);
  fs::create_directories(imagery);
  const fs::path scratch = fs::temp_directory_path() / "nadir-fuzz-seed.tif";
  writeFile(dem / "zion_srtm_cut.tif",
            cutGeoTiff(data / "zion_srtm.tif", {200, 200, 24, 20}, scratch),
            std::string_view("\x01", 1));
  const std::string grid =
      "ncols 4\nnrows 3\nxllcorner -113.0\nyllcorner 37.2\ncellsize 0.000833\n"
      "NODATA_value -9999\n1510 1512 1515 1519\n1508 -9999 1511 1516\n1505 1507 1509 1514\n";
  writeFile(dem / "grid.asc", textBytes(grid), std::string_view("\x00", 1));
  writeFile(dem / "grid_by_content", textBytes(grid), std::string_view("\x02", 1));
  // 2 KiB of a real tile (Mount Washington's rows), repeated by the target to a whole tile.
  const msg::Bytes tile = readFile(data / "N44W072.hgt");
  const std::size_t from = (875u * 1201u + 600u) * 2u;
  writeFile(dem / "N44W072_part.hgt", msg::Bytes(tile.begin() + from, tile.begin() + from + 2048),
            std::string_view("\x03", 1));

  const cv::Rect window(500, 600, 16, 12);
  std::vector<cv::Mat> bands;
  for (const char* band : {"zion_landsat_b4.tif", "zion_landsat_b3.tif", "zion_landsat_b2.tif"}) {
    bands.push_back(cv::imread((data / band).string(), cv::IMREAD_UNCHANGED)(window).clone());
  }
  writeFile(imagery / "landsat_b4_cut.tif",
            cutGeoTiff(data / "zion_landsat_b4.tif", window, scratch), std::string_view("\x01", 1));
  cv::Mat rgb16;
  cv::merge(bands, rgb16);
  const terrain::RasterInfo info = terrain::readRasterInfo((data / "zion_landsat_b4.tif").string());
  const terrain::RasterGeoref& g = info.georef;
  terrain::test::writeGeoTiff(
      scratch.string(), rgb16, {g.pixel_dx, -g.pixel_dy, 0},
      {0, 0, 0, g.corner_x + window.x * g.pixel_dx, g.corner_y + window.y * g.pixel_dy, 0},
      terrain::test::geoKeys(
          {{1024, 1}, {1025, 1}, {3072, static_cast<std::uint16_t>(g.crs.epsg())}}));
  writeFile(imagery / "landsat_rgb16_cut.tif", readFile(scratch), std::string_view("\x00", 1));
  fs::remove(scratch);
  cv::Mat rgb8;
  rgb16.convertTo(rgb8, CV_8UC3, 1.0 / 64.0);
  msg::Bytes png;
  cv::imencode(".png", rgb8, png);
  writeFile(imagery / "landsat_cut.png", png, std::string_view("\x02", 1));
}

void writeTrajectories(const fs::path& corpus) {
  const fs::path folder = corpus / "trajectory";
  fs::create_directories(folder);
  writeFile(folder / "flight.tum",
            textBytes("# t tx ty tz qx qy qz qw\n"
                      "1.0 0 0 -40 0 0 0 1\n"
                      "1.1 0.5 0.01 -40.02 0 0 0.0049999 0.9999875\n"
                      "1.2,1.0,0.02,-40.05,0,0,0.0099998,0.99995\n"),
            std::string_view("\x00", 1));
  writeFile(folder / "flight.csv",
            textBytes("time_s,lat_deg,lon_deg,alt_m,roll_deg,pitch_deg,yaw_deg,speed_mps\n"
                      "0.0,37.2,-113.0,1540.0,0.5,-1.0,90.0,5.0\n"
                      "0.1,37.2000045,-113.0,1540.1,0.6,-1.1,90.2,5.0\n"),
            std::string_view("\x01", 1));
}

template <class T>
void writeMessage(const fs::path& folder, const T& message) {
  writeFile(folder / msg::typeNameOf<T>(), msg::encode(message));
}

msg::Image smallImage(int jpeg_quality) {
  msg::Image image;
  image.utime = 1'000'000;
  image.pixels = cv::Mat(6, 8, CV_8UC1);
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 8; ++col)
      image.pixels.at<std::uint8_t>(row, col) = static_cast<std::uint8_t>(row * 30 + col * 7);
  }
  image.jpeg_quality = jpeg_quality;
  image.metadata = {{"exposure_s", {'0', '.', '0', '0', '2'}}};
  return image;
}

void writeMessages(const fs::path& folder) {
  fs::create_directories(folder);
  msg::Pose pose;
  pose.utime = 2'500'000;
  pose.p_ned_m = {1.0, -2.0, -40.0};
  pose.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  writeMessage(folder, pose);
  writeMessage(folder, msg::Imu{});
  writeMessage(folder, msg::Range{});
  writeMessage(folder, msg::Gps{});
  writeMessage(folder, msg::Baro{});
  writeMessage(folder, msg::Magnetometer{});
  writeMessage(folder, msg::GeodeticPosition{});
  writeMessage(folder, msg::Attitude{});
  writeMessage(folder, msg::Velocity{});
  writeMessage(folder, msg::BodyRates{});
  msg::CameraInfo camera;
  camera.camera_name = "down";
  camera.width = 640;
  camera.height = 480;
  camera.fx = camera.fy = 500.0;
  camera.cx = 320.0;
  camera.cy = 240.0;
  camera.distortion_model = msg::Distortion::RADTAN;
  camera.distortion = {-0.1, 0.01, 0.0, 0.0};
  camera.fps = 31.0;
  writeMessage(folder, camera);
  writeFile(folder / "image_t_raw", msg::encode(smallImage(0)));
  writeFile(folder / "image_t_jpeg", msg::encode(smallImage(90)));
  msg::VoEstimate estimate;
  estimate.source = "vo_feature";
  estimate.status = msg::VoStatus::TRACKING;
  writeMessage(folder, estimate);
  writeMessage(folder, msg::NavState{});
  writeMessage(folder, msg::PpaOdometry{});
  writeMessage(folder, msg::TargetDetection{});
  writeMessage(folder, msg::VoCommand{});
  writeMessage(folder, msg::GatePattern{});
  writeMessage(folder, msg::DriveCommand{});
  writeMessage(folder, msg::WaypointReached{});
  msg::Heartbeat heartbeat;
  writeMessage(folder, heartbeat);
  writeMessage(folder, msg::BusCheck{});
}

// A 2 s flight at 10 Hz north at 5 m/s: truth on POSE_TRUTH, an estimate on
// POSE_VO_FEATURE, a navigator's NAV_POSITION and NAV_ATTITUDE, an image.
void writeFlightLog(const fs::path& path, bool with_truth) {
  core::LcmLogWriter log(path.string());
  const double lat0_rad = 37.2 * M_PI / 180.0;
  const double lon0_rad = -113.0 * M_PI / 180.0;
  for (int i = 0; i < 20; ++i) {
    const std::int64_t utime = 1'000'000 + i * 100'000;
    const double north_m = 0.5 * i;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitZ()));
    if (with_truth) {
      msg::Pose pose;
      pose.utime = utime;
      pose.p_ned_m = {north_m, 0.0, -40.0};
      pose.q_world_body = q;
      const msg::Bytes bytes = msg::encode(pose);
      log.write(utime, "POSE_TRUTH", bytes.data(), bytes.size());
      msg::VoEstimate estimate;
      estimate.utime = utime;
      estimate.source = "vo_feature";
      estimate.status = i < 3 ? msg::VoStatus::INITIALIZING : msg::VoStatus::TRACKING;
      estimate.p_ned_m = {north_m * 1.01, 0.02 * i, -40.0};
      estimate.q_world_body = q;
      const msg::Bytes vo = msg::encode(estimate);
      log.write(utime + 5000, "POSE_VO_FEATURE", vo.data(), vo.size());
    }
    msg::GeodeticPosition position;
    position.utime = utime;
    position.lat_rad = lat0_rad + north_m / 6'371'000.0;
    position.lon_rad = lon0_rad;
    position.alt_m = 1540.0;
    const msg::Bytes p = msg::encode(position);
    log.write(utime, "NAV_POSITION", p.data(), p.size());
    msg::Attitude attitude;
    attitude.utime = utime;
    attitude.q_world_body = q;
    attitude.yaw_rad = 0.01 * i;
    const msg::Bytes a = msg::encode(attitude);
    log.write(utime, "NAV_ATTITUDE", a.data(), a.size());
  }
  const msg::Bytes image = msg::encode(smallImage(0));
  log.write(1'050'000, "CAMERA_DOWN", image.data(), image.size());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: nadir-fuzz-seeds TERRAIN_DATA_DIR CORPUS_DIR\n");
    return 2;
  }
  const fs::path corpus = argv[2];
  writeRasters(argv[1], corpus);
  writeTrajectories(corpus);
  writeMessages(corpus / "messages");
  fs::create_directories(corpus / "lcm_log");
  fs::create_directories(corpus / "flight_log");
  writeFlightLog(corpus / "lcm_log" / "flight", true);
  writeFlightLog(corpus / "flight_log" / "run", true);
  writeFlightLog(corpus / "flight_log" / "navigator", false);
  return 0;
}
