#include "logs/run_log.h"

#include <algorithm>
#include <optional>

#include "core/lcm_log.h"
#include "lcmtypes/codec.h"

namespace nadir::logs {
namespace {

std::string channelList(const std::map<std::string, core::Trajectory>& poses) {
  std::string list;
  for (const auto& [channel, trajectory] : poses) {
    list += (list.empty() ? "" : ", ") + channel;
  }
  return list;
}

}  // namespace

void appendNote(std::string& notes, const std::string& note) {
  if (!notes.empty()) notes += "; ";
  notes += note;
}

TrajectoryCollector::TrajectoryCollector(std::string truth_channel)
    : truth_channel_(std::move(truth_channel)) {}

bool TrajectoryCollector::add(const std::string& channel, const void* data, std::size_t size) {
  const bool truth =
      truth_channel_.empty() ? msg::isType<msg::Pose>(data, size) : channel == truth_channel_;
  if (truth) {
    try {
      const msg::Pose pose = msg::decode<msg::Pose>(data, size);
      poses_[channel].push_back(
          {core::stampFromUtime(pose.utime), pose.p_ned_m, pose.q_world_body});
    } catch (const std::exception&) {
      ++undecodable_[channel];
    }
    return true;
  }
  if (msg::isType<msg::NavState>(data, size)) {
    try {
      const msg::NavState state = msg::decode<msg::NavState>(data, size);
      FilterState sample;
      sample.t_s = core::stampFromUtime(state.utime);
      sample.p_ned_m = state.p_ned_m;
      sample.q_world_body = state.q_world_body;
      sample.position_covariance_m2 = state.position_covariance_m2;
      sample.attitude_covariance_rad2 = state.attitude_covariance_rad2;
      if (state.last_gps_utime >= 0)
        sample.last_gps_t_s = core::stampFromUtime(state.last_gps_utime);
      filters_[state.source.empty() ? channel : state.source].push_back(sample);
    } catch (const std::exception&) {
      ++undecodable_[channel];
    }
    return true;
  }
  if (msg::isType<msg::WaypointReached>(data, size)) {
    try {
      const msg::WaypointReached w = msg::decode<msg::WaypointReached>(data, size);
      waypoints_.push_back({core::stampFromUtime(w.utime), w.index, w.count, w.waypoint_ned_m,
                            w.believed_ned_m, w.true_ned_m, w.source});
    } catch (const std::exception&) {
      ++undecodable_[channel];
    }
    return true;
  }
  if (!msg::isType<msg::VoEstimate>(data, size)) return false;
  try {
    const msg::VoEstimate estimate = msg::decode<msg::VoEstimate>(data, size);
    SourceEstimate sample;
    sample.t_s = core::stampFromUtime(estimate.utime);
    sample.status = static_cast<int>(estimate.status);
    sample.resets = estimate.num_resets;
    if (estimate.status == msg::VoStatus::TRACKING) {
      sample.p_ned_m = estimate.p_ned_m;
      sample.q_world_body = estimate.q_world_body;
    }
    sources_[estimate.source.empty() ? channel : estimate.source].push_back(sample);
  } catch (const std::exception&) {
    ++undecodable_[channel];
  }
  return true;
}

std::size_t TrajectoryCollector::truthPoses() const {
  std::size_t poses = 0;
  for (const auto& [channel, trajectory] : poses_) poses += trajectory.size();
  return poses;
}

LogTrajectories TrajectoryCollector::trajectories() const {
  if (truth_channel_.empty() && poses_.size() > 1) {
    throw RunLogError("pose_t comes on " + channelList(poses_) +
                      ": which is the truth is not known (name its channel)");
  }
  LogTrajectories out;
  if (!poses_.empty()) {
    out.truth_channel = poses_.begin()->first;
    out.truth = poses_.begin()->second;
  }
  out.sources = sources_;
  for (const auto& [channel, count] : undecodable_) {
    appendNote(out.damage, std::to_string(count) + " undecodable or invalid message" +
                               (count == 1 ? "" : "s") + " on " + channel);
  }
  std::stable_sort(out.truth.begin(), out.truth.end(),
                   [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  const auto duplicate = std::unique(out.truth.begin(), out.truth.end(),
                                     [](const auto& a, const auto& b) { return a.t_s == b.t_s; });
  out.truth.erase(duplicate, out.truth.end());
  for (auto& [name, estimates] : out.sources) {
    std::stable_sort(estimates.begin(), estimates.end(),
                     [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  }
  out.waypoints = waypoints_;
  std::stable_sort(out.waypoints.begin(), out.waypoints.end(),
                   [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  out.filters = filters_;
  for (auto& [name, states] : out.filters) {
    std::stable_sort(states.begin(), states.end(),
                     [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  }
  return out;
}

LogTrajectories readRunLog(const std::string& log_path, const std::string& truth_channel,
                           const core::ReadProgress& progress) {
  TrajectoryCollector collector(truth_channel);
  std::size_t events = 0;
  std::string reader_damage;
  try {
    core::LcmLogReader reader(log_path);
    if (progress) reader.onProgress(progress);
    while (const std::optional<core::LogEvent> event = reader.next()) {
      ++events;
      collector.add(event->channel, event->data.data(), event->data.size());
    }
    reader_damage = reader.damageReport();
  } catch (const core::LogError& error) {
    throw RunLogError(error.what());
  }
  if (events == 0) throw RunLogError(log_path + ": the log is empty (no events)");
  LogTrajectories out;
  try {
    out = collector.trajectories();
  } catch (const RunLogError& error) {
    throw RunLogError(log_path + ": " + error.what());
  }
  if (out.truth.empty()) {
    throw RunLogError(log_path + ": no truth: no valid pose_t" +
                      (truth_channel.empty() ? std::string() : " on " + truth_channel) + " among " +
                      std::to_string(events) + " events");
  }
  std::string damage = std::move(reader_damage);
  if (!out.damage.empty()) appendNote(damage, out.damage);
  out.damage = std::move(damage);
  return out;
}

core::Trajectory trackingTrajectory(const std::vector<SourceEstimate>& estimates) {
  core::Trajectory trajectory;
  for (const SourceEstimate& e : estimates) {
    if (e.status != SourceEstimate::kTracking) continue;
    // TUM needs strictly increasing stamps: keep the first of equal stamps.
    if (!trajectory.empty() && e.t_s <= trajectory.back().t_s) continue;
    trajectory.push_back({e.t_s, e.p_ned_m, e.q_world_body.normalized()});
  }
  return trajectory;
}

}  // namespace nadir::logs
