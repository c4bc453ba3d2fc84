#include "terrain/targets.h"

#include <algorithm>
#include <cmath>

namespace nadir::terrain {
namespace {

constexpr double kWhite = 235.0;
constexpr double kBlack = 20.0;

// Reflectance at mat coordinates (x right, y down) in [0, 1]^2.
double concentric(double x, double y, int rings) {
  // Distance from the edge in the square (Chebyshev) metric, in bands of
  // width 1 / (2 (2 rings + 1)): white margin, then black and white bands.
  const double from_edge = std::min({x, y, 1.0 - x, 1.0 - y});
  const int band = static_cast<int>(std::floor(from_edge * 2.0 * (2 * rings + 1)));
  return band % 2 == 1 && band < 2 * rings ? kBlack : kWhite;
}

double gate(double x, double y) {
  const double from_edge = std::min({x, y, 1.0 - x, 1.0 - y});
  // Outer square outline, white gap, inner square outline.
  if ((from_edge >= 0.04 && from_edge < 0.09) || (from_edge >= 0.14 && from_edge < 0.19))
    return kBlack;
  for (const double cx : {0.36, 0.64}) {
    for (const double cy : {0.36, 0.64}) {
      if (std::hypot(x - cx, y - cy) < 0.09) return kBlack;
    }
  }
  return kWhite;
}

}  // namespace

void GroundTarget::visit(core::ParamVisitor& v) {
  v.field("kind", &kind, {.doc = "concentric or gate", .choices = {"concentric", "gate"}});
  v.field("north_m", &north_m, {.doc = "centre north of the origin, m", .min = -1e6, .max = 1e6});
  v.field("east_m", &east_m, {.doc = "centre east of the origin, m", .min = -1e6, .max = 1e6});
  v.field("geodetic", &geodetic, {.doc = "place by lat_deg/lon_deg instead of north_m/east_m"});
  v.field("lat_deg", &lat_deg,
          {.doc = "centre latitude (WGS-84), deg, with geodetic", .min = -90, .max = 90});
  v.field("lon_deg", &lon_deg,
          {.doc = "centre longitude, deg, with geodetic", .min = -180, .max = 180});
  v.field("size_m", &size_m, {.doc = "edge length of the mat, m", .min = 0.05, .max = 100});
  v.field("yaw_deg", &yaw_deg,
          {.doc = "rotation from north towards east, deg", .min = -360, .max = 360});
  v.field("rings", &rings,
          {.doc = "concentric: black rings (two boundaries each)", .min = 1, .max = 50});
}

void resolveGeodeticTargets(std::vector<GroundTarget>& targets, const core::LocalNedFrame& frame) {
  for (GroundTarget& target : targets) {
    if (!target.geodetic) continue;
    const Eigen::Vector3d p_ned = frame.nedFromGeodetic(
        core::geodeticFromDegrees(target.lat_deg, target.lon_deg, frame.origin().alt_m));
    target.north_m = p_ned.x();
    target.east_m = p_ned.y();
  }
}

cv::Mat targetTexture(const GroundTarget& target, int size_px) {
  cv::Mat rgb(size_px, size_px, CV_8UC3);
  constexpr int kSamples = 4;
  const bool is_gate = target.kind == "gate";
  for (int row = 0; row < size_px; ++row) {
    for (int col = 0; col < size_px; ++col) {
      double sum = 0.0;
      for (int i = 0; i < kSamples; ++i) {
        for (int j = 0; j < kSamples; ++j) {
          const double x = (col + (j + 0.5) / kSamples) / size_px;
          const double y = (row + (i + 0.5) / kSamples) / size_px;
          sum += is_gate ? gate(x, y) : concentric(x, y, target.rings);
        }
      }
      const auto value = static_cast<unsigned char>(std::lround(sum / (kSamples * kSamples)));
      rgb.at<cv::Vec3b>(row, col) = cv::Vec3b(value, value, value);
    }
  }
  return rgb;
}

}  // namespace nadir::terrain
