#pragma once
// The ground, as everything above terrain/ sees it: height and imagery queried
// in the local NED world frame (docs/conventions.md). Real terrain (a DEM and
// imagery on the ellipsoid) and the procedural world both implement it, so the
// tiles, the renderer, the rangefinder and target placement never ask which.

#include <opencv2/core/mat.hpp>

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

  // Ground sample distance of the finest imagery the world holds, m/px.
  virtual double imageryResolution_m() const = 0;
  // Spacing of the finest elevation samples, m.
  virtual double elevationResolution_m() const = 0;

  virtual WorldExtent extent() const = 0;
};

// Height of a point (world frame, NED) above the ground below it, m: what a
// rangefinder pointing straight down would read on level flight.
inline double heightAboveGround_m(const World& world, double north_m, double east_m,
                                  double down_m) {
  return -down_m - world.groundUp_m(north_m, east_m);
}

}  // namespace nadir::terrain
