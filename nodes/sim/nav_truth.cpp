#include "nodes/sim/nav_truth.h"

#include <numbers>

#include "core/frames.h"

namespace nadir::sim {

NavMessages toNavMessages(const VehicleState& state, const core::LocalNedFrame& frame,
                          double start_altitude_m) {
  constexpr double kDegPerRad = 180.0 / std::numbers::pi;
  NavMessages nav;
  const core::Geodetic point = frame.geodeticFromNed(state.p_ned_m);
  nav.position = {state.utime, point.lat_rad, point.lon_rad, point.alt_m,
                  point.alt_m - start_altitude_m};
  const core::RollPitchYaw rpy = core::rpyFromQuaternion(state.q_world_body);
  nav.attitude = {state.utime, state.q_world_body, rpy.roll_rad, rpy.pitch_rad, rpy.yaw_rad};
  nav.velocity = {state.utime, state.v_ned_mps};
  nav.rates = {state.utime, state.omega_body_rps * kDegPerRad};
  return nav;
}

}  // namespace nadir::sim
