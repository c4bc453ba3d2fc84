// The sun's position against facts of spherical astronomy worked out by hand:
// at local noon the sun stands 90 deg - latitude + declination high, due south
// (north of the tropic) or due north (south of it), and rises due east at an
// equinox on the equator.
#include "core/sun.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "core/utc_time.h"

namespace nadir::core {
namespace {

struct Noon {
  std::int64_t utime = 0;
  SunPosition sun;
};

// The highest the sun gets on the day starting at day_utc, minute by minute.
Noon highestOfTheDay(const char* day_utc, double lat_deg, double lon_deg) {
  const std::int64_t start = utimeFromUtc(day_utc);
  Noon best;
  best.sun.elevation_deg = -100.0;
  for (int minute = 0; minute < 1440; ++minute) {
    const std::int64_t utime = start + std::int64_t{minute} * 60'000'000;
    const SunPosition sun = sunPosition(utime, lat_deg, lon_deg);
    if (sun.elevation_deg > best.sun.elevation_deg) best = {utime, sun};
  }
  return best;
}

TEST(Sun, SolsticeNoonInTheAlps) {
  // 2024-06-21 (declination 23.44 deg) at 47 N, 8 E: noon elevation
  // 90 - 47 + 23.44 = 66.44 deg, due south, at 12:00 - 8 x 4 min + 1.6 min
  // (the equation of time is -1.6 min) = 11:29.6 UTC.
  const Noon noon = highestOfTheDay("2024-06-21T00:00:00Z", 47.0, 8.0);
  EXPECT_NEAR(noon.sun.elevation_deg, 66.44, 0.05);
  EXPECT_NEAR(noon.sun.azimuth_deg, 180.0, 1.0);
  EXPECT_NEAR(static_cast<double>(noon.utime - utimeFromUtc("2024-06-21T11:29:36Z")) / 60e6, 0.0,
              2.0);
  // And at 23:00 UTC it is night there.
  EXPECT_LT(sunPosition(utimeFromUtc("2024-06-21T23:00:00Z"), 47.0, 8.0).elevation_deg, -10.0);
}

TEST(Sun, SouthernWinterNoonIsDueNorth) {
  // The same day at Sydney (33.87 S, 151.21 E): 90 - 33.87 - 23.44 = 32.69
  // deg, due north.
  const Noon noon = highestOfTheDay("2024-06-20T12:00:00Z", -33.87, 151.21);
  EXPECT_NEAR(noon.sun.elevation_deg, 32.69, 0.05);
  EXPECT_LT(std::min(noon.sun.azimuth_deg, 360.0 - noon.sun.azimuth_deg), 1.0);
}

TEST(Sun, EquinoxOnTheEquatorRisesDueEast) {
  // The March equinox of 2024 was at 03:06 UTC on the 20th, and the
  // declination grows 0.395 deg a day then: +0.05 deg at sunrise on the
  // equator at 0 E (about 06:07.5 UTC, 06:00 minus the equation of time's
  // -7.5 min), +0.15 deg at noon. So the noon sun stands 90 - 0.15 = 89.85 deg
  // high, and it rises 0.05 deg north of due east, at azimuth 89.95 deg.
  const Noon noon = highestOfTheDay("2024-03-20T00:00:00Z", 0.0, 0.0);
  EXPECT_NEAR(noon.sun.elevation_deg, 89.85, 0.03);
  std::int64_t utime = utimeFromUtc("2024-03-20T05:00:00Z");
  while (sunPosition(utime, 0.0, 0.0).elevation_deg < 0.0) utime += 1'000'000;
  EXPECT_NEAR(sunPosition(utime, 0.0, 0.0).azimuth_deg, 89.95, 0.03);
  EXPECT_NEAR(static_cast<double>(utime - utimeFromUtc("2024-03-20T06:07:30Z")) / 60e6, 0.0, 2.0);
}

}  // namespace
}  // namespace nadir::core
