// The TUM and flight-CSV trajectory readers on any bytes (the first byte picks
// the reader): what they return keeps their promises (times strictly
// increasing, finite positions, unit quaternions).
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "core/geodesy.h"
#include "core/trajectory.h"
#include "fuzz/fuzz_input.h"

namespace {

void check(const nadir::core::Trajectory& trajectory, bool increasing) {
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const nadir::core::StampedPose& pose = trajectory[i];
    NADIR_FUZZ_REQUIRE(std::isfinite(pose.t_s) && pose.p_ned_m.allFinite());
    NADIR_FUZZ_REQUIRE(std::abs(pose.q_world_body.norm() - 1.0) < 1e-9);
    if (increasing && i > 0) NADIR_FUZZ_REQUIRE(pose.t_s > trajectory[i - 1].t_s);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool tum = data[0] % 2 == 0;
  try {
    if (tum) {
      check(nadir::core::readTum(nadir::fuzz::writeInput(data + 1, size - 1, "input.tum")), true);
    } else {
      static const nadir::core::LocalNedFrame frame(
          nadir::core::geodeticFromDegrees(37.2, -113.0, 1500.0));
      check(nadir::core::readFlightCsv(nadir::fuzz::writeInput(data + 1, size - 1, "input.csv"),
                                       frame),
            false);
    }
  } catch (const nadir::core::TrajectoryError&) {
  }
  return 0;
}
