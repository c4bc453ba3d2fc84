#pragma once
// The ground, as everything above terrain/ sees it: height and imagery queried
// in the local NED world frame (docs/conventions.md). Real terrain (a DEM and
// imagery on the ellipsoid) and the procedural world both implement it, so the
// tiles, the renderer, the rangefinder and target placement never ask which.

#include <opencv2/core/mat.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace nadir::terrain {

// A square of ground in the world frame: north in [north_min_m, north_min_m +
// size_m], east in [east_min_m, east_min_m + size_m].
struct GroundSquare {
  double north_min_m = 0.0;
  double east_min_m = 0.0;
  double size_m = 0.0;
};

// Where the world has data, in the world frame.
struct WorldExtent {
  double north_min_m = 0.0;
  double north_max_m = 0.0;
  double east_min_m = 0.0;
  double east_max_m = 0.0;

  bool contains(double north_m, double east_m) const {
    return north_m >= north_min_m && north_m <= north_max_m && east_m >= east_min_m &&
           east_m <= east_max_m;
  }
};

// A thing standing on the ground with its real height, for drawing in 3D: a
// tree (a crown on a trunk) or a building (walls under a flat or gable roof).
// World frame (NED), metres.
struct GroundObject {
  enum class Kind : std::uint8_t { kBroadleaf, kConifer, kBuilding };
  Kind kind = Kind::kBroadleaf;
  double north_m = 0.0;
  double east_m = 0.0;
  double base_up_m = 0.0;  // the ground's height at its centre
  double height_m = 0.0;   // its top above base_up_m
  // Trees: the crown's radius (both); buildings: half the length and width.
  double half_length_m = 0.0;
  double half_width_m = 0.0;
  // Buildings: the long axis, rad clockwise from north.
  double heading_rad = 0.0;
  bool gable = false;
  std::array<std::uint8_t, 3> rgb{};  // unlit colour, sRGB
};

class World {
 public:
  virtual ~World() = default;

  // Height of the ground above the world frame's origin plane, metres (= -down)
  // at horizontal position (north, east); for real terrain this includes the
  // curvature of the ellipsoid. Outside extent() the nearest edge value.
  // Thread-safe.
  virtual double groundUp_m(double north_m, double east_m) const = 0;

  // The ground's colour over a square as an 8-bit RGB image (CV_8UC3, R first),
  // size_px x size_px, north up: row 0 is the north edge, column 0 the west edge,
  // pixel centres at the centres of size_px x size_px equal cells. Deterministic:
  // the same square and size give the same pixels. Thread-safe.
  virtual void imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const = 0;
  // The same with the tops of objects() (crowns, roofs) left out and their
  // shadows kept: the ground beneath them, for a renderer that draws them in
  // 3D. By default imagery().
  virtual void imageryBeneathObjects(const GroundSquare& square, int size_px, cv::Mat& rgb) const {
    imagery(square, size_px, rgb);
  }

  // Ground sample distance of the finest imagery the world holds, m/px.
  virtual double imageryResolution_m() const = 0;
  // Spacing of the finest elevation samples, m.
  virtual double elevationResolution_m() const = 0;

  virtual WorldExtent extent() const = 0;

  // The objects whose centre lies in the square (north in [north_min_m,
  // north_min_m + size_m), east likewise), in a fixed order: so the squares
  // of a partition hold each object once. Deterministic and thread-safe.
  // Their shadows and tops are already in imagery(); real terrain has none.
  virtual std::vector<GroundObject> objects(const GroundSquare& /*square*/) const { return {}; }

  // Unit vector towards the sun in the world frame (NED): the light objects()
  // are drawn under, the one imagery() was shaded with. By default the
  // procedural world's default sun (azimuth 150 deg, elevation 45 deg).
  virtual std::array<double, 3> sunDirectionNed() const { return sunDirectionNed(150.0, 45.0); }
  static std::array<double, 3> sunDirectionNed(double azimuth_deg, double elevation_deg) {
    const double az = azimuth_deg * 3.14159265358979323846 / 180.0;
    const double el = elevation_deg * 3.14159265358979323846 / 180.0;
    return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), -std::sin(el)};
  }
};

// Height of a point (world frame, NED) above the ground below it, m: what a
// rangefinder pointing straight down would read on level flight.
inline double heightAboveGround_m(const World& world, double north_m, double east_m,
                                  double down_m) {
  return -down_m - world.groundUp_m(north_m, east_m);
}

}  // namespace nadir::terrain
