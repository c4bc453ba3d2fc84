#pragma once
// The simulator's wiring to a bus, shared by nadir-sim and the batch runner:
// loading a recorded flight, and publishing each step's truth and sensor
// samples as messages on the scenario's channels, and a rover's drive commands
// taken from the bus.

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "core/bus.h"
#include "core/geodesy.h"
#include "nodes/sim/flight_replay.h"
#include "nodes/sim/sim_params.h"
#include "nodes/sim/simulator.h"

namespace nadir::sim {

// The recorded flight of params.path, or nothing if the path is empty. The
// format is taken from the extension with "auto" (.tum or .txt: TUM, .csv:
// flight CSV, anything else: LCM log). Throws core::TrajectoryError naming the
// file. A damaged LCM log is used up to the damage and *warning says so.
std::optional<FlightReplay> loadFlight(const FlightParams& params, const core::LocalNedFrame& frame,
                                       std::string* warning = nullptr);

class SimPublisher {
 public:
  SimPublisher(core::Bus& bus, const SimParams& params, const Simulator& simulator);
  // Publishes the truth pose and whatever else fell due in this step.
  void publish(const SimOutput& output);
  // Messages published per channel.
  const std::map<std::string, std::int64_t>& counts() const { return counts_; }

 private:
  template <class T>
  void send(const std::string& channel, const T& message);

  core::Bus& bus_;
  SimParams params_;
  const Simulator& simulator_;
  std::map<std::string, std::int64_t> counts_;
};

// A navigation source's positions for the guidance (guidance.source other
// than truth): vo_estimate_t while TRACKING, or gps_t fixes, to
// Simulator::positionFix.
class GuidanceInput {
 public:
  GuidanceInput(core::Bus& bus, const SimParams& params, Simulator& simulator);
  std::int64_t fixes() const { return fixes_; }

 private:
  Simulator& simulator_;
  std::int64_t fixes_ = 0;
  std::optional<core::Subscription> subscription_;
};

// Under external control, the drive commands on vehicle.command_channel go to
// the simulator; commands that are not valid are dropped and counted.
class DriveCommandInput {
 public:
  DriveCommandInput(core::Bus& bus, const SimParams& params, Simulator& simulator);
  std::int64_t received() const { return received_; }
  std::int64_t dropped() const { return dropped_; }

 private:
  Simulator& simulator_;
  std::int64_t received_ = 0;
  std::int64_t dropped_ = 0;
  std::optional<core::Subscription> subscription_;
};

}  // namespace nadir::sim
