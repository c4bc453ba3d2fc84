#pragma once
// The true state of a simulated vehicle: what sensors sample and POSE_TRUTH carries.

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lcmtypes/messages.h"

namespace nadir::sim {

// The state is what pose_t carries: utime (sim time), p_ned_m, v_ned_mps,
// a_ned_mps2, q_world_body (body FRD) and omega_body_rps (body frame).
using VehicleState = msg::Pose;

// Standard gravity, m/s^2; down in NED.
inline constexpr double kGravity_mps2 = 9.80665;

}  // namespace nadir::sim
