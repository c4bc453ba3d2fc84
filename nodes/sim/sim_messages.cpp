#include "nodes/sim/sim_messages.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "core/frames.h"
#include "core/lcm_log.h"

namespace nadir::sim {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

void copy3(const Eigen::Vector3d& v, double out[3]) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

Eigen::Vector3d vector3(const double in[3]) { return Eigen::Vector3d(in[0], in[1], in[2]); }

void requireFinite(const double* values, int count, const std::string& field,
                   const std::string& where) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) {
      throw std::invalid_argument(where + ": " + field + "[" + std::to_string(i) +
                                  "] is not finite (" + std::to_string(values[i]) + ")");
    }
  }
}

// The wire quaternion as R_world_body, normalised by core::quaternionFromWire
// (which refuses a norm off 1 by more than 1e-3). One that is already unit to
// rounding is kept as it is, so that encoding it again gives the same bits.
Eigen::Quaterniond orientationFromWire(const double wxyz[4], const std::string& field,
                                       const std::string& where) {
  requireFinite(wxyz, 4, field, where);
  Eigen::Quaterniond q;
  try {
    q = core::quaternionFromWire(wxyz);
  } catch (const std::invalid_argument& e) {
    const double norm = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).norm();
    throw std::invalid_argument(where + ": " + field + ": " + e.what() + " (norm " +
                                std::to_string(norm) + ", must be within 1e-3 of 1)");
  }
  const Eigen::Quaterniond raw(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  constexpr double kUnitToRounding = 4.0 * std::numeric_limits<double>::epsilon();
  if (std::abs(raw.squaredNorm() - 1.0) <= kUnitToRounding) return raw;
  return q;
}

std::string poseWhere(const nadir::pose_t& pose) {
  return "pose_t at utime " + std::to_string(pose.utime);
}

// ---------------------------------------------------------------- flight logs

template <typename Msg>
bool decodeEvent(const core::LogEvent& event, Msg& message) {
  if (event.data.empty()) return false;
  return message.decode(event.data.data(), 0, static_cast<int>(event.data.size())) >= 0;
}

struct TimedPosition {
  std::int64_t utime = 0;
  core::Geodetic point;
  bool operator==(const TimedPosition& o) const {
    return utime == o.utime && point.lat_rad == o.point.lat_rad &&
           point.lon_rad == o.point.lon_rad && point.alt_m == o.point.alt_m;
  }
};

struct TimedAttitude {
  std::int64_t utime = 0;
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  bool operator==(const TimedAttitude& o) const {
    return utime == o.utime && q_world_body.coeffs() == o.q_world_body.coeffs();
  }
};

bool samePose(const TrajectoryPose& a, const TrajectoryPose& b) {
  return a.utime == b.utime && a.p_ned_m == b.p_ned_m &&
         a.q_world_body.coeffs() == b.q_world_body.coeffs();
}

// Sorts by utime (stable), drops exact repeats and requires strictly increasing
// times after that: two different messages at one time are an error.
template <typename T, typename Same>
void sortAndDeduplicate(std::vector<T>& items, Same same, const std::string& path,
                        const std::string& what, FlightLogStats& stats) {
  std::stable_sort(items.begin(), items.end(),
                   [](const T& a, const T& b) { return a.utime < b.utime; });
  const auto end = std::unique(items.begin(), items.end(), same);
  stats.duplicates += std::distance(end, items.end());
  items.erase(end, items.end());
  for (std::size_t i = 1; i < items.size(); ++i) {
    if (items[i].utime <= items[i - 1].utime) {
      throw TrajectoryError(path + ": times are not increasing: two different " + what +
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

}  // namespace

// ---------------------------------------------------------------- truth pose

nadir::pose_t toPoseMessage(const VehicleState& state) {
  nadir::pose_t pose{};
  pose.utime = state.utime;
  copy3(state.p_ned_m, pose.pos);
  copy3(state.v_ned_mps, pose.vel);
  core::quaternionToWire(state.q_world_body, pose.orientation);
  copy3(state.omega_body_rps, pose.rotation_rate);
  copy3(state.a_ned_mps2, pose.accel);
  return pose;
}

VehicleState stateFromPoseMessage(const nadir::pose_t& pose) {
  const std::string where = poseWhere(pose);
  requireFinite(pose.pos, 3, "pos", where);
  requireFinite(pose.vel, 3, "vel", where);
  requireFinite(pose.rotation_rate, 3, "rotation_rate", where);
  requireFinite(pose.accel, 3, "accel", where);
  VehicleState state;
  state.utime = pose.utime;
  state.p_ned_m = vector3(pose.pos);
  state.v_ned_mps = vector3(pose.vel);
  state.q_world_body = orientationFromWire(pose.orientation, "orientation", where);
  state.omega_body_rps = vector3(pose.rotation_rate);
  state.a_ned_mps2 = vector3(pose.accel);
  return state;
}

// ---------------------------------------------------------------- sensors

nadir::imu_t toImuMessage(const ImuSample& sample) {
  nadir::imu_t imu{};
  imu.utime = sample.utime;
  copy3(sample.angular_velocity_rps, imu.angular_velocity_rps);
  copy3(sample.linear_acceleration_mps2, imu.linear_acceleration_mps2);
  return imu;
}

nadir::range_t toRangeMessage(const RangeSample& sample, double min_range_m, double max_range_m) {
  nadir::range_t range{};
  range.utime = sample.utime;
  range.range_m = sample.range_m;
  range.min_range_m = min_range_m;
  range.max_range_m = max_range_m;
  copy3(sample.direction_body, range.direction_body);
  switch (sample.status) {
    case RangeStatus::VALID:
      range.status = nadir::range_t::STATUS_VALID;
      break;
    case RangeStatus::TOO_CLOSE:
      range.status = nadir::range_t::STATUS_TOO_CLOSE;
      break;
    case RangeStatus::OUT_OF_RANGE:
      range.status = nadir::range_t::STATUS_OUT_OF_RANGE;
      break;
  }
  return range;
}

nadir::gps_t toGpsMessage(const GpsSample& sample) {
  nadir::gps_t gps{};
  gps.utime = sample.utime;
  gps.latitude_rad = sample.lat_rad;
  gps.longitude_rad = sample.lon_rad;
  gps.altitude_m = sample.alt_m;
  copy3(sample.velocity_ned_mps, gps.velocity_ned_mps);
  gps.horizontal_accuracy_m = sample.horizontal_accuracy_m;
  gps.vertical_accuracy_m = sample.vertical_accuracy_m;
  gps.num_satellites = static_cast<std::int16_t>(
      std::clamp<int>(sample.num_satellites, 0, std::numeric_limits<std::int16_t>::max()));
  switch (sample.fix) {
    case GpsFix::NONE:
      gps.fix_type = nadir::gps_t::FIX_NONE;
      break;
    case GpsFix::FIX_3D:
      gps.fix_type = nadir::gps_t::FIX_3D;
      break;
  }
  return gps;
}

nadir::baro_t toBaroMessage(const BaroSample& sample) {
  nadir::baro_t baro{};
  baro.utime = sample.utime;
  baro.altitude_m = sample.altitude_m;
  baro.pressure_pa = standardAtmospherePressure_pa(sample.altitude_m);
  return baro;
}

double standardAtmospherePressure_pa(double altitude_m) {
  constexpr double kTropopause_m = 11000.0;
  if (altitude_m <= kTropopause_m) {
    return 101325.0 * std::pow(1.0 - 2.25577e-5 * altitude_m, 5.25588);
  }
  return 22632.06 * std::exp(-1.576883e-4 * (altitude_m - kTropopause_m));
}

// ---------------------------------------------------------------- NAV_* truth split

NavMessages toNavMessages(const VehicleState& state, const core::LocalNedFrame& frame,
                          double start_altitude_m) {
  NavMessages nav{};
  const core::Geodetic point = frame.geodeticFromNed(state.p_ned_m);
  nav.position.utime = state.utime;
  nav.position.latitude_rad = point.lat_rad;
  nav.position.longitude_rad = point.lon_rad;
  nav.position.altitude_m = point.alt_m;
  nav.position.altitude_rel_m = point.alt_m - start_altitude_m;

  nav.attitude.utime = state.utime;
  core::quaternionToWire(state.q_world_body, nav.attitude.orientation);
  const core::RollPitchYaw rpy = core::rpyFromQuaternion(state.q_world_body);
  nav.attitude.roll_rad = rpy.roll_rad;
  nav.attitude.pitch_rad = rpy.pitch_rad;
  nav.attitude.yaw_rad = rpy.yaw_rad;

  nav.velocity.utime = state.utime;
  copy3(state.v_ned_mps, nav.velocity.velocity_ned_mps);

  nav.rates.utime = state.utime;
  copy3(state.omega_body_rps * kDegPerRad, nav.rates.angular_velocity_dps);
  return nav;
}

// ---------------------------------------------------------------- flight logs

Trajectory readFlightLog(const std::string& path, const FlightLogChannels& channels,
                         const core::LocalNedFrame& frame, FlightLogStats* stats_out) {
  FlightLogStats stats;
  std::vector<TrajectoryPose> poses;
  std::vector<TimedPosition> positions;
  std::vector<TimedAttitude> attitudes;
  try {
    core::LcmLogReader reader(path);
    while (const std::optional<core::LogEvent> event = reader.next()) {
      if (event->channel == channels.pose_channel) {
        nadir::pose_t pose{};
        if (!decodeEvent(*event, pose)) {
          ++stats.decode_failures;
          continue;
        }
        // Only position and orientation make the trajectory; the other fields may be unset.
        try {
          const std::string where = poseWhere(pose);
          requireFinite(pose.pos, 3, "pos", where);
          poses.push_back({pose.utime, vector3(pose.pos),
                           orientationFromWire(pose.orientation, "orientation", where)});
        } catch (const std::invalid_argument&) {
          ++stats.invalid_messages;
        }
      } else if (event->channel == channels.position_channel) {
        nadir::geodetic_position_t position{};
        if (!decodeEvent(*event, position)) {
          ++stats.decode_failures;
          continue;
        }
        const core::Geodetic point{position.latitude_rad, position.longitude_rad,
                                   position.altitude_m};
        if (!std::isfinite(point.lat_rad) || !std::isfinite(point.lon_rad) ||
            !std::isfinite(point.alt_m) || std::abs(point.lat_rad) > std::numbers::pi / 2) {
          ++stats.invalid_messages;
          continue;
        }
        positions.push_back({position.utime, point});
      } else if (event->channel == channels.attitude_channel) {
        nadir::attitude_t attitude{};
        if (!decodeEvent(*event, attitude)) {
          ++stats.decode_failures;
          continue;
        }
        try {
          attitudes.push_back(
              {attitude.utime,
               orientationFromWire(attitude.orientation, "orientation",
                                   "attitude_t at utime " + std::to_string(attitude.utime))});
        } catch (const std::invalid_argument&) {
          ++stats.invalid_messages;
        }
      }
    }
    stats.damage = reader.damageReport();
  } catch (const core::LogError& e) {
    throw TrajectoryError(e.what());
  }

  if (!poses.empty()) {
    sortAndDeduplicate(poses, samePose, path, "pose_t on " + channels.pose_channel, stats);
    stats.from_pose_channel = true;
  } else {
    sortAndDeduplicate(positions, std::equal_to<>(), path,
                       "geodetic_position_t on " + channels.position_channel, stats);
    sortAndDeduplicate(attitudes, std::equal_to<>(), path,
                       "attitude_t on " + channels.attitude_channel, stats);
    for (const TimedPosition& position : positions) {
      if (attitudes.empty() || position.utime < attitudes.front().utime ||
          position.utime > attitudes.back().utime) {
        ++stats.positions_outside_attitude_span;
        continue;
      }
      // The last attitude at or before the position, and the one after it.
      const auto after =
          std::upper_bound(attitudes.begin(), attitudes.end(), position.utime,
                           [](std::int64_t t, const TimedAttitude& a) { return t < a.utime; });
      const TimedAttitude& a = *std::prev(after);
      Eigen::Quaterniond q_world_body = a.q_world_body;
      if (after != attitudes.end() && position.utime != a.utime) {
        const double s = static_cast<double>(position.utime - a.utime) /
                         static_cast<double>(after->utime - a.utime);
        q_world_body = a.q_world_body.slerp(s, after->q_world_body);
      }
      poses.push_back({position.utime, frame.nedFromGeodetic(position.point), q_world_body});
    }
  }

  if (poses.empty()) {
    throw TrajectoryError(path + " has no pose_t on " + channels.pose_channel + " and no " +
                          channels.position_channel + "/" + channels.attitude_channel + " pairs" +
                          skippedSummary(stats));
  }
  stats.poses = static_cast<std::int64_t>(poses.size());
  if (stats_out != nullptr) *stats_out = stats;
  return Trajectory(std::move(poses), path);
}

}  // namespace nadir::sim
