#include "nodes/sim/sim_node.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "nodes/sim/sim_messages.h"

namespace nadir::sim {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

}  // namespace

std::optional<Trajectory> loadFlight(const FlightParams& params, const core::LocalNedFrame& frame,
                                     std::string* warning) {
  if (params.path.empty()) return std::nullopt;
  std::string format = params.format;
  if (format == "auto") {
    const std::string extension = lowerExtension(params.path);
    format = extension == ".tum" || extension == ".txt" ? "tum"
             : extension == ".csv"                      ? "csv"
                                                        : "lcm";
  }
  if (format == "tum") return readTumTrajectory(params.path);
  if (format == "csv") return readFlightCsv(params.path, frame);
  FlightLogStats stats;
  Trajectory flight = readFlightLog(
      params.path, {params.pose_channel, params.position_channel, params.attitude_channel}, frame,
      &stats);
  if (warning != nullptr) {
    warning->clear();
    if (!stats.damage.empty()) *warning += stats.damage;
    const std::int64_t skipped = stats.decode_failures + stats.invalid_messages;
    if (skipped > 0) {
      *warning += (warning->empty() ? "" : "; ") + std::to_string(skipped) +
                  " undecodable or invalid messages skipped";
    }
  }
  return flight;
}

SimPublisher::SimPublisher(core::Bus& bus, const SimParams& params, const Simulator& simulator)
    : bus_(bus), params_(params), simulator_(simulator) {}

template <class Msg>
void SimPublisher::send(const std::string& channel, const Msg& message) {
  core::publish(bus_, channel, message);
  ++counts_[channel];
}

void SimPublisher::publish(const SimOutput& output) {
  const SensorsParams& sensors = params_.sensors;
  send(params_.truth.channel, toPoseMessage(output.truth));
  if (output.imu) send(sensors.imu.channel, toImuMessage(*output.imu));
  if (output.range) {
    send(sensors.rangefinder.channel,
         toRangeMessage(*output.range, sensors.rangefinder.model.min_range_m,
                        sensors.rangefinder.model.max_range_m));
  }
  if (output.gps) send(sensors.gps.channel, toGpsMessage(*output.gps));
  if (output.baro) send(sensors.barometer.channel, toBaroMessage(*output.baro));
  if (output.nav_due) {
    const NavMessages nav =
        toNavMessages(output.truth, simulator_.frame(), simulator_.startAltitude_m());
    send(params_.truth.nav_position_channel, nav.position);
    send(params_.truth.nav_attitude_channel, nav.attitude);
    send(params_.truth.nav_velocity_channel, nav.velocity);
    send(params_.truth.nav_rates_channel, nav.rates);
  }
}

}  // namespace nadir::sim
