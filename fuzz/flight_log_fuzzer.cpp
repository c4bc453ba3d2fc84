// The readers of whole flights and runs out of an LCM log on any bytes
// (logs::readFlightLog and logs::readRunLog): what they return is time-sorted
// with finite positions and unit quaternions.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "core/geodesy.h"
#include "core/trajectory.h"
#include "fuzz/fuzz_input.h"
#include "logs/flight_log.h"
#include "logs/run_log.h"

namespace {

void check(const nadir::core::Trajectory& trajectory) {
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    NADIR_FUZZ_REQUIRE(std::isfinite(trajectory[i].t_s) && trajectory[i].p_ned_m.allFinite());
    NADIR_FUZZ_REQUIRE(std::abs(trajectory[i].q_world_body.norm() - 1.0) < 1e-9);
    if (i > 0) NADIR_FUZZ_REQUIRE(trajectory[i].t_s >= trajectory[i - 1].t_s);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = nadir::fuzz::writeInput(data, size, "flight.lcmlog");
  static const nadir::core::LocalNedFrame frame(
      nadir::core::geodeticFromDegrees(37.2, -113.0, 1500.0));
  try {
    nadir::logs::FlightLogStats stats;
    check(nadir::logs::readFlightLog(path, {}, frame, &stats));
    NADIR_FUZZ_REQUIRE(stats.poses > 0);
  } catch (const nadir::core::TrajectoryError&) {
  }
  try {
    const nadir::logs::LogTrajectories run = nadir::logs::readRunLog(path);
    check(run.truth);
    for (const auto& [name, estimates] : run.sources)
      (void)nadir::logs::trackingTrajectory(estimates);
  } catch (const nadir::logs::RunLogError&) {
  }
  return 0;
}
