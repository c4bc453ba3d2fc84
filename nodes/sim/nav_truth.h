#pragma once
// The truth as LCM flight stacks publish it, split into NAV_POSITION,
// NAV_ATTITUDE, NAV_VELOCITY and NAV_RATES.

#include "core/geodesy.h"
#include "lcmtypes/messages.h"
#include "nodes/sim/vehicle_state.h"

namespace nadir::sim {

struct NavMessages {
  msg::GeodeticPosition position;
  msg::Attitude attitude;
  msg::Velocity velocity;
  msg::BodyRates rates;
};

// All four stamped state.utime. The geodetic position comes from state.p_ned_m
// through `frame`; altitude_rel_m is the ellipsoid height minus start_altitude_m.
NavMessages toNavMessages(const VehicleState& state, const core::LocalNedFrame& frame,
                          double start_altitude_m);

}  // namespace nadir::sim
