#pragma once
// WGS-84 geodetic coordinates and the local NED world frame.

#include <memory>

#include <Eigen/Core>

namespace nadir::core {

// WGS-84 geodetic position; alt_m is the height above the ellipsoid.
struct Geodetic {
  double lat_rad = 0.0;
  double lon_rad = 0.0;
  double alt_m = 0.0;
};

Geodetic geodeticFromDegrees(double lat_deg, double lon_deg, double alt_m);

// The Earth's magnetic field in NED from its declination (east of true north)
// and inclination (below the horizon), deg, and its strength:
// F (cos I cos D, cos I sin D, sin I), in the strength's unit.
Eigen::Vector3d magneticField_ned(double declination_deg, double inclination_deg, double strength);

// Local north-east-down frame tangent to the ellipsoid at an origin
// (GeographicLib::LocalCartesian, which is east-north-up, converted here once).
// Exact: no flat-earth approximation, so it round-trips at any distance.
class LocalNedFrame {
 public:
  // Throws std::invalid_argument for a latitude outside [-90, 90] deg or a
  // non-finite value.
  explicit LocalNedFrame(const Geodetic& origin);

  const Geodetic& origin() const { return origin_; }
  Eigen::Vector3d nedFromGeodetic(const Geodetic& point) const;
  Geodetic geodeticFromNed(const Eigen::Vector3d& p_ned_m) const;

 private:
  struct Impl;
  Geodetic origin_;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace nadir::core
