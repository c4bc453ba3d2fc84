#include "nodes/sim/trajectory.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "core/clock.h"
#include "core/frames.h"
#include "logs/eval/trajectory.h"

namespace nadir::sim {
namespace {

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) {
    field.erase(0, field.find_first_not_of(" \t\r"));
    field.erase(field.find_last_not_of(" \t\r") + 1);
    fields.push_back(field);
  }
  return fields;
}

double parseNumber(const std::string& text, const std::string& where) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || !std::isfinite(value)) {
    throw TrajectoryError(where + ": '" + text + "' is not a number");
  }
  return value;
}

}  // namespace

Trajectory::Trajectory(std::vector<TrajectoryPose> poses, std::string source)
    : poses_(std::move(poses)), source_(std::move(source)) {
  if (poses_.size() < 2) {
    throw TrajectoryError(source_ + ": a trajectory needs at least two poses, got " +
                          std::to_string(poses_.size()));
  }
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    if (poses_[i].utime <= poses_[i - 1].utime) {
      throw TrajectoryError(source_ + ": pose " + std::to_string(i + 1) +
                            " is not later than the one before");
    }
  }
  for (TrajectoryPose& pose : poses_) pose.q_world_body.normalize();
}

std::size_t Trajectory::intervalOf(std::int64_t utime) const {
  const auto after =
      std::upper_bound(poses_.begin(), poses_.end(), utime,
                       [](std::int64_t t, const TrajectoryPose& p) { return t < p.utime; });
  const auto index = static_cast<std::size_t>(after - poses_.begin());
  return std::clamp<std::size_t>(index, 1, poses_.size() - 1) - 1;
}

VehicleState Trajectory::at(std::int64_t utime) const {
  const std::int64_t t = std::clamp(utime, startUtime(), endUtime());
  const std::size_t i = intervalOf(t);
  const TrajectoryPose& a = poses_[i];
  const TrajectoryPose& b = poses_[i + 1];
  const double span_s = core::secondsFromUtime(b.utime - a.utime);
  const double s = static_cast<double>(t - a.utime) / static_cast<double>(b.utime - a.utime);
  VehicleState state;
  state.utime = utime;
  state.p_ned_m = a.p_ned_m + s * (b.p_ned_m - a.p_ned_m);
  state.q_world_body = a.q_world_body.slerp(s, b.q_world_body);
  state.v_ned_mps = (b.p_ned_m - a.p_ned_m) / span_s;
  // Body rate over the interval: the rotation from a to b, in a's body frame.
  const Eigen::AngleAxisd delta(a.q_world_body.conjugate() * b.q_world_body);
  state.omega_body_rps = delta.axis() * delta.angle() / span_s;
  const auto velocityOf = [this](std::size_t k) {
    return (poses_[k + 1].p_ned_m - poses_[k].p_ned_m) /
           core::secondsFromUtime(poses_[k + 1].utime - poses_[k].utime);
  };
  if (i + 2 < poses_.size()) {
    const double mid_span_s = 0.5 * core::secondsFromUtime(poses_[i + 2].utime - poses_[i].utime);
    state.a_ned_mps2 = (velocityOf(i + 1) - velocityOf(i)) / mid_span_s;
  } else if (i > 0) {
    const double mid_span_s =
        0.5 * core::secondsFromUtime(poses_[i + 1].utime - poses_[i - 1].utime);
    state.a_ned_mps2 = (velocityOf(i) - velocityOf(i - 1)) / mid_span_s;
  }
  return state;
}

Trajectory readTumTrajectory(const std::string& path) {
  eval::PoseTrajectory tum;
  try {
    tum = eval::readTum(path);
  } catch (const eval::EvalError& error) {
    throw TrajectoryError(error.what());
  }
  std::vector<TrajectoryPose> poses;
  for (const eval::StampedPose& pose : tum) {
    poses.push_back({core::utimeFromSeconds(pose.t_s), pose.p_m, pose.q});
  }
  return Trajectory(std::move(poses), path);
}

Trajectory readFlightCsv(const std::string& path, const core::LocalNedFrame& frame) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError("cannot open flight CSV " + path);
  std::string line;
  if (!std::getline(in, line)) throw TrajectoryError(path + ": empty file, expected a header");
  const std::vector<std::string> header = splitCsv(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t i = 0; i < header.size(); ++i) column[header[i]] = i;
  const char* required[] = {"time_s",   "lat_deg",   "lon_deg", "alt_m",
                            "roll_deg", "pitch_deg", "yaw_deg"};
  for (const char* name : required) {
    if (column.count(name) == 0) {
      throw TrajectoryError(
          path + ": the header has no column '" + name +
          "' (needs time_s, lat_deg, lon_deg, alt_m, roll_deg, pitch_deg, yaw_deg)");
    }
  }
  constexpr double kDeg = std::numbers::pi / 180.0;
  std::vector<TrajectoryPose> poses;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> fields = splitCsv(line);
    const std::string where = path + ":" + std::to_string(line_number);
    if (fields.size() < header.size()) {
      throw TrajectoryError(where + ": " + std::to_string(fields.size()) +
                            " fields, the header has " + std::to_string(header.size()));
    }
    const auto value = [&](const char* name) {
      return parseNumber(fields[column.at(name)], where);
    };
    const core::Geodetic point =
        core::geodeticFromDegrees(value("lat_deg"), value("lon_deg"), value("alt_m"));
    poses.push_back({core::utimeFromSeconds(value("time_s")), frame.nedFromGeodetic(point),
                     core::quaternionFromRpy({value("roll_deg") * kDeg, value("pitch_deg") * kDeg,
                                              value("yaw_deg") * kDeg})});
  }
  return Trajectory(std::move(poses), path);
}

}  // namespace nadir::sim
