#include "nodes/sim/sim_node.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "lcmtypes/bus_io.h"
#include "logs/flight_log.h"
#include "nodes/sim/nav_truth.h"

namespace nadir::sim {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

}  // namespace

std::optional<FlightReplay> loadFlight(const FlightParams& params, const core::LocalNedFrame& frame,
                                       std::string* warning) {
  if (params.path.empty()) return std::nullopt;
  std::string format = params.format;
  if (format == "auto") {
    const std::string extension = lowerExtension(params.path);
    format = extension == ".tum" || extension == ".txt" ? "tum"
             : extension == ".csv"                      ? "csv"
                                                        : "lcm";
  }
  if (format == "tum") return FlightReplay(core::readTum(params.path), params.path);
  if (format == "csv") return FlightReplay(core::readFlightCsv(params.path, frame), params.path);
  logs::FlightLogStats stats;
  core::Trajectory flight = logs::readFlightLog(
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
  return FlightReplay(std::move(flight), params.path);
}

SimPublisher::SimPublisher(core::Bus& bus, const SimParams& params, const Simulator& simulator)
    : bus_(bus), params_(params), simulator_(simulator) {}

template <class T>
void SimPublisher::send(const std::string& channel, const T& message) {
  msg::publish(bus_, channel, message);
  ++counts_[channel];
}

void SimPublisher::publish(const SimOutput& output) {
  const SensorsParams& sensors = params_.sensors;
  send(params_.truth.channel, output.truth);
  if (output.imu) send(sensors.imu.channel, *output.imu);
  if (output.range) send(sensors.rangefinder.channel, *output.range);
  if (output.gps) send(sensors.gps.channel, *output.gps);
  if (output.baro) send(sensors.barometer.channel, *output.baro);
  if (output.mag) send(sensors.magnetometer.channel, *output.mag);
  if (output.waypoint) send(params_.guidance.waypoint_channel, *output.waypoint);
  if (output.nav) {
    send(params_.truth.nav_position_channel, output.nav->position);
    send(params_.truth.nav_attitude_channel, output.nav->attitude);
    send(params_.truth.nav_velocity_channel, output.nav->velocity);
    send(params_.truth.nav_rates_channel, output.nav->rates);
  }
}

GuidanceInput::GuidanceInput(core::Bus& bus, const SimParams& params, Simulator& simulator)
    : simulator_(simulator) {
  const GuidanceParams& guidance = params.guidance;
  if (guidance.source == "truth") return;
  const std::string channel = guidance.estimateChannel();
  if (guidance.source == "gps") {
    subscription_ = msg::subscribe<msg::Gps>(bus, channel, [this](const msg::Gps& fix) {
      if (fix.fix == msg::GpsFix::NONE) return;
      ++fixes_;
      simulator_.positionFix(
          fix.utime, simulator_.frame().nedFromGeodetic({fix.lat_rad, fix.lon_rad, fix.alt_m}));
    });
    return;
  }
  subscription_ =
      msg::subscribe<msg::VoEstimate>(bus, channel, [this](const msg::VoEstimate& estimate) {
        if (estimate.status != msg::VoStatus::TRACKING) return;
        ++fixes_;
        simulator_.positionFix(estimate.utime, estimate.p_ned_m);
      });
}

DriveCommandInput::DriveCommandInput(core::Bus& bus, const SimParams& params, Simulator& simulator)
    : simulator_(simulator) {
  if (!simulator.externalControl()) return;
  subscription_ = msg::subscribe<msg::DriveCommand>(
      bus, params.vehicle.command_channel,
      [this](const msg::DriveCommand& command) {
        ++received_;
        simulator_.drive({command.utime, command.steer_rad, command.speed_mps});
      },
      [this](const std::string&) { ++dropped_; });
}

}  // namespace nadir::sim
