#include "core/geodesy.h"

#include <gtest/gtest.h>
#include <GeographicLib/Geodesic.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace nadir::core {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// WGS-84 defining constants.
constexpr double kA = 6378137.0;
constexpr double kF = 1.0 / 298.257223563;
constexpr double kE2 = kF * (2.0 - kF);

// Test origin: 44.27 N, 71.30 W, 300 m above the ellipsoid.
constexpr double kLat0Deg = 44.27;
constexpr double kLon0Deg = -71.30;
constexpr double kAlt0 = 300.0;

Geodetic origin() { return geodeticFromDegrees(kLat0Deg, kLon0Deg, kAlt0); }

// Prime-vertical radius of curvature N(lat).
double primeVerticalRadius(double lat_rad) {
  return kA / std::sqrt(1.0 - kE2 * std::sin(lat_rad) * std::sin(lat_rad));
}

// Meridian radius of curvature M(lat).
double meridianRadius(double lat_rad) {
  const double w2 = 1.0 - kE2 * std::sin(lat_rad) * std::sin(lat_rad);
  return kA * (1.0 - kE2) / (w2 * std::sqrt(w2));
}

// Textbook geodetic -> ECEF, independent of GeographicLib.
Eigen::Vector3d handEcef(double lat_rad, double lon_rad, double h) {
  const double n = primeVerticalRadius(lat_rad);
  return {(n + h) * std::cos(lat_rad) * std::cos(lon_rad),
          (n + h) * std::cos(lat_rad) * std::sin(lon_rad),
          (n * (1.0 - kE2) + h) * std::sin(lat_rad)};
}

// Textbook NED coordinates of a point relative to an origin: ECEF difference rotated into the
// origin's north/east/down axes (the tangent plane to the ellipsoid at the origin).
Eigen::Vector3d handNed(const Geodetic& o, const Geodetic& p) {
  const Eigen::Vector3d d =
      handEcef(p.lat_rad, p.lon_rad, p.alt_m) - handEcef(o.lat_rad, o.lon_rad, o.alt_m);
  const double sl = std::sin(o.lat_rad);
  const double cl = std::cos(o.lat_rad);
  const double so = std::sin(o.lon_rad);
  const double co = std::cos(o.lon_rad);
  return {-sl * co * d.x() - sl * so * d.y() + cl * d.z(),  //
          -so * d.x() + co * d.y(),                         //
          -cl * co * d.x() - cl * so * d.y() - sl * d.z()};
}

// Horizontal separation in metres (geodesic on the ellipsoid) between two geodetic points.
double horizontalDistance(const Geodetic& a, const Geodetic& b) {
  double s12 = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(a.lat_rad / kDeg, a.lon_rad / kDeg, b.lat_rad / kDeg,
                                           b.lon_rad / kDeg, s12);
  return s12;
}

std::string describe(const Geodetic& g) {
  return "lat " + std::to_string(g.lat_rad / kDeg) + " deg, lon " +
         std::to_string(g.lon_rad / kDeg) + " deg, alt " + std::to_string(g.alt_m) + " m";
}

// geodeticFromDegrees converts degrees to radians and keeps the height.
TEST(GeodesyTest, GeodeticFromDegrees) {
  const Geodetic g = geodeticFromDegrees(90.0, -180.0, 123.5);
  EXPECT_NEAR(g.lat_rad, kPi / 2, 1e-15);
  EXPECT_NEAR(g.lon_rad, -kPi, 1e-15);
  EXPECT_EQ(g.alt_m, 123.5);
  EXPECT_EQ(LocalNedFrame(g).origin().alt_m, 123.5);
}

// The origin itself maps to (0, 0, 0).
TEST(GeodesyTest, OriginMapsToZero) {
  const LocalNedFrame frame(origin());
  const Eigen::Vector3d ned = frame.nedFromGeodetic(origin());
  EXPECT_NEAR(ned.x(), 0.0, 1e-9);
  EXPECT_NEAR(ned.y(), 0.0, 1e-9);
  EXPECT_NEAR(ned.z(), 0.0, 1e-9);
}

// A point 100 m straight above the origin maps to down = -100 (NED: down positive).
TEST(GeodesyTest, PointAboveOriginHasNegativeDown) {
  const LocalNedFrame frame(origin());
  const Eigen::Vector3d ned =
      frame.nedFromGeodetic(geodeticFromDegrees(kLat0Deg, kLon0Deg, kAlt0 + 100.0));
  EXPECT_NEAR(ned.x(), 0.0, 1e-9);
  EXPECT_NEAR(ned.y(), 0.0, 1e-9);
  EXPECT_NEAR(ned.z(), -100.0, 1e-9);
}

// 0.1 deg of latitude north (same lon, same height) lies ~11.1 km north and ~9.7 m down.
TEST(GeodesyTest, KnownOffsetNorth) {
  const LocalNedFrame frame(origin());
  const Geodetic point = geodeticFromDegrees(kLat0Deg + 0.1, kLon0Deg, kAlt0);
  const Eigen::Vector3d ned = frame.nedFromGeodetic(point);

  double s12 = 0.0;  // geodesic (meridian arc) length on the ellipsoid, about 11111.85 m
  GeographicLib::Geodesic::WGS84().Inverse(kLat0Deg, kLon0Deg, kLat0Deg + 0.1, kLon0Deg, s12);
  ASSERT_NEAR(s12, 11112.0, 1.0);

  // Along the meridian with radius of curvature M (~6.3636e6 m here) the point at height h
  // sweeps dphi = 0.1 deg = 1.745e-3 rad, so north = (M + h) sin(dphi) and
  // s12 = M dphi (the variation of M along the arc cancels to first order). Hence
  // north - s12 = h dphi - M dphi^3 / 6 = 0.524 - 0.006 = 0.518 m: below 1 m, and within a
  // centimetre of that hand value.
  const double dphi = 0.1 * kDeg;
  const double m = meridianRadius(origin().lat_rad);
  EXPECT_NEAR(ned.x(), s12, 1.0);
  EXPECT_NEAR(ned.x() - s12, kAlt0 * dphi - m * dphi * dphi * dphi / 6.0, 0.01);

  // Same meridian: the point stays in the origin's meridian plane, so east is zero.
  EXPECT_NEAR(ned.y(), 0.0, 1e-6);

  // The point is below the tangent plane by (M + h)(1 - cos dphi) ~ s12^2 / (2 M) = 9.70 m
  // (the h and dM/dphi corrections are below 1 mm); R = 6.37e6 would give the same to 1 cm.
  EXPECT_GT(ned.z(), 9.0);
  EXPECT_NEAR(ned.z(), s12 * s12 / (2.0 * m), 0.005);

  // Exact textbook ECEF -> NED value (independent of GeographicLib) to a micrometre.
  const Eigen::Vector3d expected = handNed(origin(), point);
  EXPECT_NEAR(ned.x(), expected.x(), 1e-6);
  EXPECT_NEAR(ned.y(), expected.y(), 1e-6);
  EXPECT_NEAR(ned.z(), expected.z(), 1e-6);
}

// 0.1 deg of longitude east (same lat, same height) lies ~7.98 km east, ~5 m down, ~4.9 m north.
TEST(GeodesyTest, KnownOffsetEast) {
  const LocalNedFrame frame(origin());
  const Geodetic point = geodeticFromDegrees(kLat0Deg, kLon0Deg + 0.1, kAlt0);
  const Eigen::Vector3d ned = frame.nedFromGeodetic(point);

  double s12 = 0.0;  // geodesic length on the ellipsoid, about 7984.16 m
  GeographicLib::Geodesic::WGS84().Inverse(kLat0Deg, kLon0Deg, kLat0Deg, kLon0Deg + 0.1, s12);
  ASSERT_NEAR(s12, 7984.0, 1.0);

  // Both points lie on the parallel circle of radius p = (N + h) cos(lat) (N ~ 6.3885e6 m is
  // the prime-vertical radius), centred on the polar axis. The chord subtending dlon is
  // p sin(dlon) east and p (1 - cos(dlon)) towards the axis; the inward direction is
  // -cos(lat) up + sin(lat) north. So, exactly:
  //   east = p sin(dlon), north = p (1 - cos dlon) sin(lat), down = p (1 - cos dlon) cos(lat).
  const double lat = origin().lat_rad;
  const double dlon = 0.1 * kDeg;
  const double n = primeVerticalRadius(lat);
  const double p = (n + kAlt0) * std::cos(lat);
  EXPECT_NEAR(ned.y(), p * std::sin(dlon), 1e-6);
  EXPECT_NEAR(ned.x(), p * (1.0 - std::cos(dlon)) * std::sin(lat), 1e-6);
  EXPECT_NEAR(ned.z(), p * (1.0 - std::cos(dlon)) * std::cos(lat), 1e-6);

  // Against the geodesic: east - s12 ~ h cos(lat) dlon - N cos(lat) dlon^3 / 6 = 0.37 m.
  EXPECT_NEAR(ned.y(), s12, 1.0);
  // Drop below the tangent plane ~ s12^2 / (2 N) = 4.99 m, and the parallel curves
  // poleward by s12^2 tan(lat) / (2 N) = 4.86 m north (h and geodesic-vs-parallel < 1 mm).
  EXPECT_NEAR(ned.z(), s12 * s12 / (2.0 * n), 0.005);
  EXPECT_NEAR(ned.x(), s12 * s12 * std::tan(lat) / (2.0 * n), 0.005);

  const Eigen::Vector3d expected = handNed(origin(), point);
  EXPECT_NEAR(ned.x(), expected.x(), 1e-6);
  EXPECT_NEAR(ned.y(), expected.y(), 1e-6);
  EXPECT_NEAR(ned.z(), expected.z(), 1e-6);
}

// geodetic -> NED -> geodetic returns within 1 mm for points 50 km away in 8 directions at
// heights 0, 1000 and 5000 m; the NED values also match the textbook ECEF -> NED computation.
TEST(GeodesyTest, GeodeticNedGeodeticRoundTrip50km) {
  const LocalNedFrame frame(origin());
  const GeographicLib::Geodesic& geod = GeographicLib::Geodesic::WGS84();
  for (double azimuth_deg = 0.0; azimuth_deg < 360.0; azimuth_deg += 45.0) {
    // Point 50 km along the geodesic from the origin at this azimuth (from north to east).
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    geod.Direct(kLat0Deg, kLon0Deg, azimuth_deg, 50000.0, lat_deg, lon_deg);
    for (double alt : {0.0, 1000.0, 5000.0}) {
      const Geodetic point = geodeticFromDegrees(lat_deg, lon_deg, alt);
      SCOPED_TRACE("azimuth " + std::to_string(azimuth_deg) + " deg, " + describe(point));

      const Eigen::Vector3d ned = frame.nedFromGeodetic(point);
      const Eigen::Vector3d expected = handNed(origin(), point);
      EXPECT_LT((ned - expected).norm(), 1e-5);
      // Sanity on direction: the horizontal NED bearing is close to the geodesic azimuth.
      const double bearing_deg = std::atan2(ned.y(), ned.x()) / kDeg;
      EXPECT_NEAR(std::remainder(bearing_deg - azimuth_deg, 360.0), 0.0, 0.5);

      const Geodetic back = frame.geodeticFromNed(ned);
      EXPECT_LT(horizontalDistance(back, point), 1e-3);
      EXPECT_NEAR(back.alt_m, alt, 1e-3);
    }
  }
}

// NED -> geodetic -> NED returns within 1 mm over a fixed grid of offsets up to 50 km.
TEST(GeodesyTest, NedGeodeticNedRoundTrip) {
  const LocalNedFrame frame(origin());
  for (double north : {-50000.0, -1234.5, 0.0, 777.0, 50000.0}) {
    for (double east : {-50000.0, 0.0, 3333.3, 50000.0}) {
      for (double down : {-5000.0, -1000.0, 0.0, 250.0}) {
        const Eigen::Vector3d ned(north, east, down);
        const Eigen::Vector3d back = frame.nedFromGeodetic(frame.geodeticFromNed(ned));
        EXPECT_LT((back - ned).norm(), 1e-3) << ned.transpose();
      }
    }
  }
}

// An invalid origin (|lat| > 90 deg or any non-finite value) throws std::invalid_argument.
TEST(GeodesyTest, InvalidOriginThrows) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(LocalNedFrame(geodeticFromDegrees(91.0, kLon0Deg, kAlt0)), std::invalid_argument);
  EXPECT_THROW(LocalNedFrame(geodeticFromDegrees(-91.0, kLon0Deg, kAlt0)), std::invalid_argument);
  EXPECT_THROW(LocalNedFrame(geodeticFromDegrees(nan, kLon0Deg, kAlt0)), std::invalid_argument);
  EXPECT_THROW(LocalNedFrame(geodeticFromDegrees(kLat0Deg, nan, kAlt0)), std::invalid_argument);
  EXPECT_THROW(LocalNedFrame(geodeticFromDegrees(kLat0Deg, kLon0Deg, nan)), std::invalid_argument);
  EXPECT_THROW(LocalNedFrame(geodeticFromDegrees(kLat0Deg, inf, kAlt0)), std::invalid_argument);
  EXPECT_THROW(LocalNedFrame(geodeticFromDegrees(kLat0Deg, kLon0Deg, -inf)), std::invalid_argument);
}

// The poles themselves (latitude exactly +-90 deg) are valid origins.
TEST(GeodesyTest, PoleOriginAccepted) {
  EXPECT_NO_THROW(LocalNedFrame(geodeticFromDegrees(90.0, 0.0, 0.0)));
  EXPECT_NO_THROW(LocalNedFrame(geodeticFromDegrees(-90.0, 0.0, 0.0)));
  EXPECT_NO_THROW(LocalNedFrame(Geodetic{kPi / 2, 0.0, 0.0}));
}

}  // namespace
}  // namespace nadir::core
