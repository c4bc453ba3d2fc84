#include "nodes/node_main.h"

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <iostream>

namespace nadir::scenario {
namespace {

std::atomic<bool> g_stop{false};

void onSignal(int) { g_stop = true; }

}  // namespace

int runScenarioNode(int argc, char** argv, const ScenarioNodeSpec& spec) {
  CLI::App app{spec.program + ": " + spec.description};
  std::string scenario_name = spec.default_scenario;
  std::vector<std::string> overrides;
  app.add_option("scenario", scenario_name, "built-in scenario name or YAML file")
      ->capture_default_str();
  app.add_option("--set", overrides, "override a parameter: key=value (repeatable)");
  CLI11_PARSE(app, argc, argv);

  try {
    ScenarioParams scenario = loadScenario(scenario_name, overrides);
    std::cout << spec.program << " parameters (" << scenario_name << "):\n"
              << spec.format_params(scenario) << std::flush;
    auto bus = core::openBus(scenario.bus);
    const std::function<std::string()> summary = spec.start(*bus, scenario);
    std::cout << "bus: " << bus->url() << std::endl;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    while (!g_stop) bus->handle(std::chrono::milliseconds(100));
    std::cout << spec.program << ": " << summary() << std::endl;
  } catch (const std::exception& error) {
    std::cerr << spec.program << ": error: " << error.what() << std::endl;
    return 1;
  }
  return 0;
}

}  // namespace nadir::scenario
