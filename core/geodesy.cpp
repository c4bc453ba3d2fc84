#include "core/geodesy.h"

#include <GeographicLib/LocalCartesian.hpp>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace nadir::core {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

void checkGeodetic(const Geodetic& point, const char* what) {
  if (!std::isfinite(point.lat_rad) || !std::isfinite(point.lon_rad) ||
      !std::isfinite(point.alt_m)) {
    throw std::invalid_argument(std::string(what) + " has a non-finite coordinate");
  }
  if (std::abs(point.lat_rad) > std::numbers::pi / 2) {
    throw std::invalid_argument(std::string(what) + " latitude " +
                                std::to_string(point.lat_rad * kDegPerRad) +
                                " deg is outside [-90, 90]");
  }
}

}  // namespace

struct LocalNedFrame::Impl {
  GeographicLib::LocalCartesian enu;
};

Eigen::Vector3d magneticField_ned(double declination_deg, double inclination_deg, double strength) {
  constexpr double kRad = std::numbers::pi / 180.0;
  const double d = declination_deg * kRad, i = inclination_deg * kRad;
  return strength *
         Eigen::Vector3d(std::cos(i) * std::cos(d), std::cos(i) * std::sin(d), std::sin(i));
}

Geodetic geodeticFromDegrees(double lat_deg, double lon_deg, double alt_m) {
  return Geodetic{lat_deg / kDegPerRad, lon_deg / kDegPerRad, alt_m};
}

LocalNedFrame::LocalNedFrame(const Geodetic& origin) : origin_(origin) {
  checkGeodetic(origin, "NED origin");
  impl_ = std::make_shared<const Impl>(Impl{GeographicLib::LocalCartesian(
      origin.lat_rad * kDegPerRad, origin.lon_rad * kDegPerRad, origin.alt_m)});
}

Eigen::Vector3d LocalNedFrame::nedFromGeodetic(const Geodetic& point) const {
  checkGeodetic(point, "point");
  double east = 0, north = 0, up = 0;
  impl_->enu.Forward(point.lat_rad * kDegPerRad, point.lon_rad * kDegPerRad, point.alt_m, east,
                     north, up);
  return {north, east, -up};
}

Geodetic LocalNedFrame::geodeticFromNed(const Eigen::Vector3d& p_ned_m) const {
  double lat_deg = 0, lon_deg = 0, alt_m = 0;
  impl_->enu.Reverse(p_ned_m.y(), p_ned_m.x(), -p_ned_m.z(), lat_deg, lon_deg, alt_m);
  return Geodetic{lat_deg / kDegPerRad, lon_deg / kDegPerRad, alt_m};
}

}  // namespace nadir::core
