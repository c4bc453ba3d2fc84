#include "nodes/node_main.h"

#include <unistd.h>

#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>

#include "core/clock.h"
#include "core/command_line.h"
#include "lcmtypes/bus_io.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"

namespace nadir::nodes {
namespace {

std::atomic<bool> g_stop{false};

void onSignal(int) { g_stop = true; }

// A --config file: the bus, then the node's own keys at the top level.
struct ProcessParams {
  explicit ProcessParams(core::AnyParams node_params) : node(std::move(node_params)) {}

  core::BusParams bus;
  core::AnyParams node;

  void visit(core::ParamVisitor& v) {
    core::visitGroup(v, "bus", "where messages come from and go", bus);
    node.visit(v);
  }
};

void listScenarios() {
  for (const std::string& name : builtinScenarioNames()) {
    std::string description;
    try {
      description = loadScenario(name).description;
    } catch (const std::exception& error) {
      description = std::string("(does not load: ") + error.what() + ")";
    }
    std::printf("%-20s %s\n", name.c_str(), description.c_str());
  }
}

// Sends the node's heartbeat now, then once a second of wall time, and a last
// one as it stops: what it has done and everything it has published.
class Heartbeat {
 public:
  Heartbeat(core::Bus& bus, std::string channel, std::string node)
      : bus_(bus), channel_(std::move(channel)), node_(std::move(node)) {}

  void beatIfDue(const Node& running) {
    const auto now = std::chrono::steady_clock::now();
    if (sequence_ > 0 && now - last_ < std::chrono::seconds(1)) return;
    beat(running, false);
  }

  void last(const Node& running) { beat(running, true); }

 private:
  void beat(const Node& running, bool done) {
    last_ = std::chrono::steady_clock::now();
    std::map<std::string, std::int64_t> sent = bus_.sent();
    sent.erase(channel_);  // its own heartbeats are not the node's output
    const auto stats = bus_.stats();
    std::string summary = running.summary() + "; " + core::describeLosses(stats, channel_);
    if (const std::string malformed = core::describeMalformed(stats); !malformed.empty()) {
      summary += "; " + malformed;
    }
    msg::publish(
        bus_, channel_,
        msg::Heartbeat{core::wallClockUtime(), node_, static_cast<std::int32_t>(::getpid()),
                       sequence_++, done, std::move(summary), std::move(sent)});
  }

  core::Bus& bus_;
  std::string channel_;
  std::string node_;
  std::int64_t sequence_ = 0;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace

int runNodeMain(int argc, char** argv, const char* node_name) {
  const Entry& node_entry = entry(node_name);
  const EntryInfo& info = node_entry.info();
  CLI::App app{info.program + ": " + info.description};
  std::string scenario_name = info.default_scenario;
  std::string config_path;
  std::vector<std::string> overrides;
  bool list = false;
  int resets_before = 0;
  auto* scenario_option =
      app.add_option("scenario,--scenario", scenario_name, "built-in scenario name or YAML file")
          ->capture_default_str();
  app.add_option("--config", config_path,
                 "the node's own parameters (YAML: its keys, and bus) instead of a scenario")
      ->check(CLI::ExistingFile)
      ->excludes(scenario_option);
  app.add_option("--set", overrides,
                 "override a parameter: key=value (repeatable; keys of the scenario, or of "
                 "the --config file)");
  app.add_flag("--list", list, "list the built-in scenarios and exit");
  app.add_option("--resets-before", resets_before,
                 "this process replaces one that died: a VO node's num_resets goes on from "
                 "here (nadir launch --restart sets it)")
      ->check(CLI::NonNegativeNumber);
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;
  if (list) {
    listScenarios();
    return 0;
  }

  try {
    ProcessParams params(node_entry.defaultParams());
    std::string source;
    std::map<std::string, double> expected_rates_hz;  // of the scenario's streams
    if (!config_path.empty()) {
      core::applyYamlFile(config_path, [&params](core::ParamVisitor& v) { params.visit(v); });
      core::applyAssignments(params, overrides);
      source = config_path;
    } else {
      const ScenarioParams scenario = loadScenario(scenario_name, overrides);
      params.bus = scenario.bus;
      params.node = node_entry.fromScenario(scenario);
      source = scenario_name;
      expected_rates_hz = expectedRates(scenario);
    }
    std::cout << info.program << " parameters (" << source << "):\n"
              << core::formatParamsOf(params.node) << std::flush;

    auto bus = core::openBus(params.bus);
    for (const auto& [channel, rate_hz] : expected_rates_hz) bus->expectRate(channel, rate_hz);
    const std::unique_ptr<Node> node = node_entry.start(*bus, params.node);
    if (resets_before > 0) node->continueResetCount(resets_before);
    if (const std::string about = node->describe(); !about.empty()) std::cout << about << "\n";
    std::cout << "bus: " << bus->url() << std::endl;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    std::signal(SIGHUP, onSignal);  // a remote node whose ssh went away
    // Not into a log file: its events are in message time, a heartbeat's is wall time.
    const bool live = bus->url().rfind("file://", 0) != 0;
    Heartbeat heartbeat(*bus, params.bus.heartbeat_channel, info.name);
    bool working = true;
    while (!g_stop && working) {
      if (live) heartbeat.beatIfDue(*node);
      working = node->turn(*bus);
    }
    if (live) heartbeat.last(*node);
    std::cout << info.program << ": " << (g_stop ? "stopped" : "done") << "; " << node->summary()
              << "\n"
              << info.program << ": received "
              << core::describeArrivals(bus->stats(), params.bus.heartbeat_channel) << std::endl;
  } catch (const std::exception& error) {
    std::cerr << info.program << ": error: " << error.what() << std::endl;
    return 1;
  }
  return 0;
}

}  // namespace nadir::nodes
