#pragma once
// A recorded flight read from an LCM log as truth, for the simulator to replay:
// pose_t when the log has it, else NAV_POSITION paired with NAV_ATTITUDE as
// flight stacks publish them.

#include <cstdint>
#include <string>

#include "core/geodesy.h"
#include "core/trajectory.h"

namespace nadir::logs {

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

// The flight, time-sorted with exact repeats dropped. With usable pose_t on
// pose_channel those poses are the trajectory; otherwise each position
// (converted into `frame` from its ellipsoid altitude) is paired with the
// attitude SLERPed at its time, and positions outside the attitude span are
// skipped. Bad messages are skipped and counted; a damaged log is read up to
// the damage. Throws core::TrajectoryError naming the file when it cannot be
// read as an LCM log, holds neither poses nor pairs, or has two different
// messages at one time.
core::Trajectory readFlightLog(const std::string& path, const FlightLogChannels& channels,
                               const core::LocalNedFrame& frame, FlightLogStats* stats = nullptr);

}  // namespace nadir::logs
