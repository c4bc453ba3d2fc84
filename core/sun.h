#pragma once
// Where the sun stands in the sky at a time and place: NOAA's solar position
// equations (after Meeus, Astronomical Algorithms), good to about 0.01 deg
// between 1950 and 2050, without atmospheric refraction.

#include <cstdint>

namespace nadir::core {

struct SunPosition {
  double azimuth_deg = 0.0;    // clockwise from true north, [0, 360)
  double elevation_deg = 0.0;  // above the horizon (negative below)
};

// utime: microseconds since 1970-01-01T00:00:00Z (UTC).
SunPosition sunPosition(std::int64_t utime, double lat_deg, double lon_deg);

}  // namespace nadir::core
