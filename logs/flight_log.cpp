#include "logs/flight_log.h"

#include <algorithm>
#include <functional>
#include <iterator>
#include <optional>
#include <vector>

#include "core/lcm_log.h"
#include "lcmtypes/codec.h"

namespace nadir::logs {
namespace {

struct TimedPose {
  std::int64_t utime = 0;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  bool operator==(const TimedPose& o) const {
    return utime == o.utime && p_ned_m == o.p_ned_m &&
           q_world_body.coeffs() == o.q_world_body.coeffs();
  }
};

struct TimedPosition {
  std::int64_t utime = 0;
  core::Geodetic point;
  bool operator==(const TimedPosition& o) const {
    return utime == o.utime && point.lat_rad == o.point.lat_rad &&
           point.lon_rad == o.point.lon_rad && point.alt_m == o.point.alt_m;
  }
};

// Sorts by utime (stable), drops exact repeats and requires strictly increasing
// times after that: two different messages at one time are an error.
template <typename T>
void sortAndDeduplicate(std::vector<T>& items, const std::string& path, const std::string& what,
                        FlightLogStats& stats) {
  std::stable_sort(items.begin(), items.end(),
                   [](const T& a, const T& b) { return a.utime < b.utime; });
  const auto end = std::unique(items.begin(), items.end());
  stats.duplicates += std::distance(end, items.end());
  items.erase(end, items.end());
  for (std::size_t i = 1; i < items.size(); ++i) {
    if (items[i].utime <= items[i - 1].utime) {
      throw core::TrajectoryError(path + ": times are not increasing: two different " + what +
                                  " at utime " + std::to_string(items[i].utime));
    }
  }
}

std::string skippedSummary(const FlightLogStats& stats) {
  std::string summary;
  const auto add = [&summary](const std::string& part) {
    summary += (summary.empty() ? " (" : "; ") + part;
  };
  if (stats.decode_failures > 0) {
    add(std::to_string(stats.decode_failures) + " messages did not decode");
  }
  if (stats.invalid_messages > 0) {
    add(std::to_string(stats.invalid_messages) + " messages had invalid values");
  }
  if (stats.positions_outside_attitude_span > 0) {
    add(std::to_string(stats.positions_outside_attitude_span) +
        " positions were outside the attitude span");
  }
  if (!stats.damage.empty()) add(stats.damage);
  return summary.empty() ? summary : summary + ")";
}

// Decodes one event as T, counting what fails; nothing when it does.
template <class T>
std::optional<T> decodeCounted(const core::LogEvent& event, FlightLogStats& stats) {
  try {
    return msg::decode<T>(event.data);
  } catch (const msg::DecodeError&) {
    ++stats.decode_failures;
  } catch (const msg::InvalidMessage&) {
    ++stats.invalid_messages;
  }
  return std::nullopt;
}

// Seconds from origin_utime to utime, in double: a log's times are any 64 bits
// (exact for the times of a real flight, below 2^53 us).
double secondsAfter(std::int64_t utime, std::int64_t origin_utime) {
  return (static_cast<double>(utime) - static_cast<double>(origin_utime)) / 1e6;
}

// Stamps are seconds after origin_utime: near the epoch, absolute seconds would
// keep only a quarter of a microsecond.
core::Trajectory toTrajectory(const std::vector<TimedPose>& poses, std::int64_t origin_utime = 0) {
  core::Trajectory trajectory;
  for (const TimedPose& pose : poses) {
    trajectory.push_back({secondsAfter(pose.utime, origin_utime), pose.p_ned_m, pose.q_world_body});
  }
  return trajectory;
}

// Each position paired with the attitude SLERPed at its time; positions outside
// the attitudes' span are counted and skipped.
std::vector<TimedPose> pairPositions(const std::vector<TimedPosition>& positions,
                                     const std::vector<TimedPose>& attitudes,
                                     const core::LocalNedFrame& frame, FlightLogStats& stats) {
  const std::int64_t origin_utime = attitudes.empty() ? 0 : attitudes.front().utime;
  const core::Trajectory attitude_track = toTrajectory(attitudes, origin_utime);
  std::vector<TimedPose> poses;
  for (const TimedPosition& position : positions) {
    const std::optional<core::StampedPose> attitude =
        core::interpolate(attitude_track, secondsAfter(position.utime, origin_utime));
    if (!attitude) {
      ++stats.positions_outside_attitude_span;
      continue;
    }
    // A height no flight has (found by fuzzing: 1e300 m) is no position in the frame.
    const Eigen::Vector3d p_ned_m = frame.nedFromGeodetic(position.point);
    if (!p_ned_m.allFinite()) {
      ++stats.invalid_messages;
      continue;
    }
    poses.push_back({position.utime, p_ned_m, attitude->q_world_body});
  }
  return poses;
}

}  // namespace

core::Trajectory readFlightLog(const std::string& path, const FlightLogChannels& channels,
                               const core::LocalNedFrame& frame, FlightLogStats* stats_out) {
  FlightLogStats stats;
  std::vector<TimedPose> poses;
  std::vector<TimedPosition> positions;
  std::vector<TimedPose> attitudes;
  try {
    core::LcmLogReader reader(path);
    while (const std::optional<core::LogEvent> event = reader.next()) {
      if (event->channel == channels.pose_channel) {
        if (const auto pose = decodeCounted<msg::Pose>(*event, stats)) {
          poses.push_back({pose->utime, pose->p_ned_m, pose->q_world_body});
        }
      } else if (event->channel == channels.position_channel) {
        if (const auto position = decodeCounted<msg::GeodeticPosition>(*event, stats)) {
          positions.push_back(
              {position->utime, {position->lat_rad, position->lon_rad, position->alt_m}});
        }
      } else if (event->channel == channels.attitude_channel) {
        if (const auto attitude = decodeCounted<msg::Attitude>(*event, stats)) {
          attitudes.push_back({attitude->utime, Eigen::Vector3d::Zero(), attitude->q_world_body});
        }
      }
    }
    stats.damage = reader.damageReport();
  } catch (const core::LogError& e) {
    throw core::TrajectoryError(e.what());
  }

  if (!poses.empty()) {
    sortAndDeduplicate(poses, path, "pose_t on " + channels.pose_channel, stats);
    stats.from_pose_channel = true;
  } else {
    sortAndDeduplicate(positions, path, "geodetic_position_t on " + channels.position_channel,
                       stats);
    sortAndDeduplicate(attitudes, path, "attitude_t on " + channels.attitude_channel, stats);
    poses = pairPositions(positions, attitudes, frame, stats);
  }

  if (poses.empty()) {
    throw core::TrajectoryError(path + " has no pose_t on " + channels.pose_channel + " and no " +
                                channels.position_channel + "/" + channels.attitude_channel +
                                " pairs" + skippedSummary(stats));
  }
  stats.poses = static_cast<std::int64_t>(poses.size());
  if (stats_out != nullptr) *stats_out = stats;
  core::Trajectory trajectory = toTrajectory(poses);
  core::requireIncreasing(trajectory, path, 2);
  return trajectory;
}

}  // namespace nadir::logs
