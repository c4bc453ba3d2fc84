// nadir-ppa: the emulated SCAMP-5 vision sensor as a live node: the PPA
// camera's frames in, POSE_PPA, PPA_ODOMETRY and PPA_TARGET out. Wiring only.
//
//   nadir-ppa SCENARIO [--set key=value ...]   (the scenario's ppa group, bus and targets)

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <iostream>

#include "core/bus.h"
#include "nodes/ppa/ppa_node.h"
#include "scenario/scenario.h"

namespace {

std::atomic<bool> g_stop{false};

void onSignal(int) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nadir-ppa: the emulated SCAMP-5 pixel processor array over LCM"};
  std::string scenario_name = "scamp-rectangle";
  std::vector<std::string> overrides;
  app.add_option("scenario", scenario_name, "built-in scenario name or YAML file")
      ->capture_default_str();
  app.add_option("--set", overrides, "override a parameter: key=value (repeatable)");
  CLI11_PARSE(app, argc, argv);

  try {
    nadir::scenario::ScenarioParams scenario =
        nadir::scenario::loadScenario(scenario_name, overrides);
    std::cout << "nadir-ppa parameters (" << scenario_name << ", ppa):\n"
              << nadir::core::formatParamsOf(scenario.ppa) << std::flush;
    auto bus = nadir::core::openBus(scenario.bus);
    const nadir::core::LocalNedFrame frame(nadir::scenario::scenarioOrigin(scenario));
    nadir::ppa::PpaNode node(*bus, scenario.ppa, nadir::scenario::knownTargets(scenario, frame));
    std::cout << "bus: " << bus->url() << ", frames from " << scenario.ppa.image_channel
              << std::endl;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    while (!g_stop) bus->handle(std::chrono::milliseconds(100));
    if (node.droppedImages() > 0) {
      std::cerr << "nadir-ppa: dropped " << node.droppedImages()
                << " images; the first: " << node.firstDropReason() << "\n";
    }
    std::cout << "nadir-ppa: " << node.frames() << " frames, "
              << static_cast<long long>(node.meanInstructionsPerFrame())
              << " instructions per frame on average" << std::endl;
  } catch (const std::exception& error) {
    std::cerr << "nadir-ppa: error: " << error.what() << std::endl;
    return 1;
  }
  return 0;
}
