#include "core/sun.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace nadir::core {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

double wrap360(double deg) {
  const double wrapped = std::fmod(deg, 360.0);
  return wrapped < 0.0 ? wrapped + 360.0 : wrapped;
}

}  // namespace

SunPosition sunPosition(std::int64_t utime, double lat_deg, double lon_deg) {
  const double days_since_1970 = static_cast<double>(utime) / 86400e6;
  const double julian_day = days_since_1970 + 2440587.5;
  const double t = (julian_day - 2451545.0) / 36525.0;  // Julian centuries since J2000

  const double mean_longitude_deg = wrap360(280.46646 + t * (36000.76983 + t * 0.0003032));
  const double mean_anomaly_deg = 357.52911 + t * (35999.05029 - 0.0001537 * t);
  const double eccentricity = 0.016708634 - t * (0.000042037 + 0.0000001267 * t);
  const double m = mean_anomaly_deg * kRad;
  const double centre_deg = std::sin(m) * (1.914602 - t * (0.004817 + 0.000014 * t)) +
                            std::sin(2.0 * m) * (0.019993 - 0.000101 * t) +
                            std::sin(3.0 * m) * 0.000289;
  const double omega_deg = 125.04 - 1934.136 * t;
  const double apparent_longitude_deg =
      mean_longitude_deg + centre_deg - 0.00569 - 0.00478 * std::sin(omega_deg * kRad);
  const double mean_obliquity_deg =
      23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
  const double obliquity = (mean_obliquity_deg + 0.00256 * std::cos(omega_deg * kRad)) * kRad;
  const double declination =
      std::asin(std::sin(obliquity) * std::sin(apparent_longitude_deg * kRad));

  // The equation of time, minutes.
  const double y = std::pow(std::tan(obliquity / 2.0), 2);
  const double l0 = mean_longitude_deg * kRad;
  const double equation_of_time_min =
      4.0 / kRad *
      (y * std::sin(2.0 * l0) - 2.0 * eccentricity * std::sin(m) +
       4.0 * eccentricity * y * std::sin(m) * std::cos(2.0 * l0) -
       0.5 * y * y * std::sin(4.0 * l0) - 1.25 * eccentricity * eccentricity * std::sin(2.0 * m));
  const double minutes_of_day = (days_since_1970 - std::floor(days_since_1970)) * 1440.0;
  const double true_solar_min = minutes_of_day + equation_of_time_min + 4.0 * lon_deg;
  const double hour_angle = (true_solar_min / 4.0 - 180.0) * kRad;

  const double lat = lat_deg * kRad;
  const double cos_zenith = std::sin(lat) * std::sin(declination) +
                            std::cos(lat) * std::cos(declination) * std::cos(hour_angle);
  const double zenith = std::acos(std::clamp(cos_zenith, -1.0, 1.0));
  SunPosition sun;
  sun.elevation_deg = 90.0 - zenith / kRad;
  sun.azimuth_deg =
      wrap360(std::atan2(std::sin(hour_angle), std::cos(hour_angle) * std::sin(lat) -
                                                   std::tan(declination) * std::cos(lat)) /
                  kRad +
              180.0);
  return sun;
}

}  // namespace nadir::core
