#pragma once
// The main() of a node that takes its parameters from a scenario (nadir-ppa,
// nadir-vo-feature): `PROGRAM [SCENARIO] [--set key=value ...]`. It loads the
// scenario, prints the node's parameters, opens the scenario's bus, starts the
// node, handles messages until SIGINT or SIGTERM, and prints the node's summary.

#include <functional>
#include <memory>
#include <string>

#include "core/bus.h"
#include "nodes/scenario.h"

namespace nadir::scenario {

struct ScenarioNodeSpec {
  std::string program;      // e.g. "nadir-ppa"
  std::string description;  // one line for --help
  std::string default_scenario;
  // The node's parameter group as text, printed at start.
  std::function<std::string(ScenarioParams&)> format_params;
  // Builds the node on the bus (kept alive until the end) and returns what to
  // print when it stops; says "bus: ..." once it listens (nadir launch waits for that).
  std::function<std::function<std::string()>(core::Bus&, const ScenarioParams&)> start;
};

int runScenarioNode(int argc, char** argv, const ScenarioNodeSpec& spec);

}  // namespace nadir::scenario
