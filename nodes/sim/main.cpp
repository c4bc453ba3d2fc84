// nadir-sim: flies a scenario's vehicle (or replays a recorded flight) and
// publishes the truth and the sensor streams in sim time. Wiring only.
//
//   nadir-sim [SCENARIO] [--set key=value ...]
//   nadir-sim --list

#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <thread>

#include "core/bus.h"
#include "core/clock.h"
#include "nodes/sim/sim_node.h"
#include "nodes/sim/simulator.h"
#include "nodes/scenario.h"
#include "terrain/world_factory.h"

namespace {

std::atomic<bool> g_stop{false};

void onSignal(int) { g_stop = true; }

void listScenarios() {
  for (const std::string& name : nadir::scenario::builtinScenarioNames()) {
    std::string description;
    try {
      description = nadir::scenario::loadScenario(name).description;
    } catch (const std::exception& error) {
      description = std::string("(does not load: ") + error.what() + ")";
    }
    std::printf("%-20s %s\n", name.c_str(), description.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nadir-sim: the vehicle, its truth and its sensors over LCM"};
  std::string scenario_name = "default";
  std::vector<std::string> overrides;
  bool list = false;
  app.add_option("scenario", scenario_name, "built-in scenario name or YAML file")
      ->capture_default_str();
  app.add_option("--set", overrides, "override a parameter: key=value (repeatable)");
  app.add_flag("--list", list, "list the built-in scenarios and exit");
  CLI11_PARSE(app, argc, argv);
  if (list) {
    listScenarios();
    return 0;
  }

  try {
    nadir::scenario::ScenarioParams scenario =
        nadir::scenario::loadScenario(scenario_name, overrides);
    std::cout << "nadir-sim parameters (" << scenario_name << "):\n"
              << nadir::core::formatParamsOf(scenario) << std::flush;
    const nadir::terrain::BuiltWorld built = nadir::terrain::makeWorld(scenario.world);
    const nadir::core::LocalNedFrame frame(built.origin);
    std::string flight_warning;
    auto flight = nadir::sim::loadFlight(scenario.sim.flight, frame, &flight_warning);
    if (!flight_warning.empty()) std::cerr << "nadir-sim: flight log: " << flight_warning << "\n";
    nadir::sim::Simulator simulator(scenario.sim, built.world, frame, std::move(flight));
    std::cout << "world: " << built.description << "\n";

    auto bus = nadir::core::openBus(scenario.bus);
    const bool realtime = scenario.time.mode == "realtime";
    std::cout << "bus: " << bus->url() << "; time: "
              << (realtime ? std::to_string(scenario.time.speed) + " x real time" : "batch")
              << std::endl;
    nadir::sim::SimPublisher publisher(*bus, scenario.sim, simulator);

    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    const auto wall_start = std::chrono::steady_clock::now();
    double track_length_m = 0.0;
    Eigen::Vector3d previous_p = Eigen::Vector3d::Zero();
    std::int64_t last_report_utime = simulator.startUtime();
    std::int64_t utime = simulator.startUtime();
    bool first = true;
    while (!simulator.finished() && !g_stop) {
      const nadir::sim::SimOutput output = simulator.step();
      utime = output.truth.utime;
      if (!first) track_length_m += (output.truth.p_ned_m - previous_p).norm();
      first = false;
      previous_p = output.truth.p_ned_m;
      if (realtime) {
        const double elapsed_s =
            nadir::core::secondsFromUtime(utime - simulator.startUtime()) / scenario.time.speed;
        std::this_thread::sleep_until(wall_start + std::chrono::duration<double>(elapsed_s));
      }
      publisher.publish(output);
      if (utime - last_report_utime >= 10'000'000) {
        last_report_utime = utime;
        const Eigen::Vector3d& p = output.truth.p_ned_m;
        std::printf("t %7.1f s  north %8.1f m  east %8.1f m  height %7.1f m AGL  track %7.0f m\n",
                    nadir::core::secondsFromUtime(utime - simulator.startUtime()), p.x(), p.y(),
                    nadir::terrain::heightAboveGround_m(*built.world, p.x(), p.y(), p.z()),
                    track_length_m);
        std::fflush(stdout);
      }
    }
    std::cout << (g_stop ? "nadir-sim: stopped" : "nadir-sim: done") << " after "
              << nadir::core::secondsFromUtime(utime - simulator.startUtime())
              << " s of sim time; track " << static_cast<long>(track_length_m) << " m\n";
    for (const auto& [channel, count] : publisher.counts()) {
      std::cout << "  " << channel << ": " << count << " messages\n";
    }
  } catch (const std::exception& error) {
    std::cerr << "nadir-sim: error: " << error.what() << std::endl;
    return 1;
  }
  return 0;
}
