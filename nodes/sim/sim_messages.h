#pragma once
// Conversions between the simulator's plain structs and its LCM messages, in
// one place, and the reader of a real flight's LCM log as a Trajectory. Uses
// only the generated nadir/*.hpp types (no LCM C++ API).

#include <cstdint>
#include <string>

#include "core/geodesy.h"
#include "nadir/attitude_t.hpp"
#include "nadir/baro_t.hpp"
#include "nadir/body_rates_t.hpp"
#include "nadir/geodetic_position_t.hpp"
#include "nadir/gps_t.hpp"
#include "nadir/imu_t.hpp"
#include "nadir/pose_t.hpp"
#include "nadir/range_t.hpp"
#include "nadir/velocity_t.hpp"
#include "nodes/sim/sensors.h"
#include "nodes/sim/trajectory.h"
#include "nodes/sim/vehicle_state.h"

namespace nadir::sim {

// ---------------------------------------------------------------- truth pose

nadir::pose_t toPoseMessage(const VehicleState& state);

// The state a pose_t describes. Throws std::invalid_argument naming the field
// for a non-finite value, or for a quaternion whose norm is not within 1e-3 of
// 1. The quaternion is normalised; one already unit to rounding is kept bit for
// bit, so toPoseMessage -> stateFromPoseMessage is exact.
VehicleState stateFromPoseMessage(const nadir::pose_t& pose);

// ---------------------------------------------------------------- sensors

nadir::imu_t toImuMessage(const ImuSample& sample);
// The limits are the rangefinder's (RangefinderParams), which the sample does not carry.
nadir::range_t toRangeMessage(const RangeSample& sample, double min_range_m, double max_range_m);
nadir::gps_t toGpsMessage(const GpsSample& sample);
// pressure_pa is standardAtmospherePressure_pa(sample.altitude_m).
nadir::baro_t toBaroMessage(const BaroSample& sample);

// Static pressure of the ICAO standard atmosphere, Pa, at altitude_m:
// troposphere p = 101325 (1 - 2.25577e-5 h)^5.25588 up to 11 km, then the
// isothermal layer p = 22632.06 exp(-1.576883e-4 (h - 11000)) (valid to 20 km).
double standardAtmospherePressure_pa(double altitude_m);

// ---------------------------------------------------------------- NAV_* truth split

// The truth as LCM flight stacks publish it: NAV_POSITION, NAV_ATTITUDE,
// NAV_VELOCITY, NAV_RATES. All four carry state.utime.
struct NavMessages {
  nadir::geodetic_position_t position;
  nadir::attitude_t attitude;
  nadir::velocity_t velocity;
  nadir::body_rates_t rates;
};

// Geodetic position from state.p_ned_m through `frame`; altitude_rel_m is the
// ellipsoid height minus start_altitude_m (the height at the start of the run).
NavMessages toNavMessages(const VehicleState& state, const core::LocalNedFrame& frame,
                          double start_altitude_m);

// ---------------------------------------------------------------- flight logs

struct FlightLogChannels {
  std::string pose_channel = "POSE_TRUTH";
  std::string position_channel = "NAV_POSITION";
  std::string attitude_channel = "NAV_ATTITUDE";
};

// What readFlightLog skipped, for the caller to report.
struct FlightLogStats {
  // Messages on the three channels that did not decode as their type.
  std::int64_t decode_failures = 0;
  // Decoded messages with a non-finite value or a quaternion that is not a rotation.
  std::int64_t invalid_messages = 0;
  // Exact repeats (same utime, same values) dropped.
  std::int64_t duplicates = 0;
  // NAV_POSITION messages outside the span of the NAV_ATTITUDE messages.
  std::int64_t positions_outside_attitude_span = 0;
  // Poses in the returned trajectory and where they came from.
  std::int64_t poses = 0;
  bool from_pose_channel = false;
  // The log reader's account of damage and a truncated tail; empty if clean.
  std::string damage;
};

// A real (or recorded) flight from an LCM log, as truth. If the log has usable
// pose_t on channels.pose_channel, those poses (world frame NED, body FRD) are
// the trajectory. Otherwise each geodetic_position_t on position_channel is
// converted to NED with `frame` (its ellipsoid altitude_m; altitude_rel_m is not
// used) and paired with the attitude_t on attitude_channel SLERPed at its utime;
// positions outside the attitude span are skipped. Times are the messages'
// utime, sorted, with exact duplicates dropped. Messages that fail to decode
// or are invalid are skipped and counted; a damaged or truncated log is used up
// to what could be read. Throws TrajectoryError naming the file if it cannot
// be opened or is not an LCM log, if it has neither poses nor position/attitude
// pairs, or if two different messages share a time.
Trajectory readFlightLog(const std::string& path, const FlightLogChannels& channels,
                         const core::LocalNedFrame& frame, FlightLogStats* stats = nullptr);

}  // namespace nadir::sim
