#include "run/launch.h"

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/bus.h"
#include "core/clock.h"
#include "lcmtypes/codec.h"
#include "nodes/scenario.h"
#include "nodes/sim/simulator.h"
#include "run/process.h"
#include "run/run.h"
#include "terrain/world_factory.h"

namespace nadir::run {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

bool fileContains(const std::string& path, const std::string& text) {
  std::ifstream in(path);
  std::stringstream content;
  content << in.rdbuf();
  return content.str().find(text) != std::string::npos;
}

std::string programPath(const std::string& bin_dir, const std::string& name) {
  const fs::path path = fs::path(bin_dir) / name;
  if (!fs::exists(path)) throw std::runtime_error("cannot find " + path.string());
  return path.string();
}

struct ChannelHealth {
  std::int64_t total = 0;
  std::int64_t window = 0;
  // Rate the scenario should produce, Hz of sim time; 0 when not known.
  double expected_hz = 0.0;
  std::optional<std::int64_t> first_utime, last_utime;
  int vo_status = -1;

  // Messages missing so far: what the sim-time span at expected_hz holds
  // minus what arrived (the messages carry their sim time).
  std::int64_t missing() const {
    if (expected_hz <= 0.0 || !first_utime) return 0;
    const double span_s = core::secondsFromUtime(*last_utime - *first_utime);
    const auto expected = static_cast<std::int64_t>(std::floor(span_s * expected_hz + 1e-6)) + 1;
    return std::max<std::int64_t>(0, expected - total);
  }
};

}  // namespace

int launchScenario(const LaunchOptions& options, std::ostream& out, const std::atomic<bool>& stop) {
  scenario::ScenarioParams scenario = scenario::loadScenario(options.scenario, options.overrides);
  {
    // Refuse what nadir-sim would refuse before any process starts.
    const terrain::BuiltWorld built = terrain::makeWorld(scenario.world);
    sim::Simulator check(scenario.sim, built.world, core::LocalNedFrame(built.origin));
  }
  if (scenario.time.mode != "realtime") {
    throw std::runtime_error(
        "nadir launch runs in real time (time.mode=realtime); for batch "
        "runs use nadir run");
  }
  const std::string out_dir =
      options.out_dir.empty()
          ? (fs::path("out") / (fs::path(options.scenario).stem().string() + "-live")).string()
          : options.out_dir;
  const fs::path out_path(out_dir);
  const fs::path recording = out_path / "launch.lcmlog";
  if (!options.force && fs::exists(recording)) {
    throw std::runtime_error(out_dir +
                             " already holds a launch (launch.lcmlog); choose another "
                             "--out or pass --force to replace it");
  }
  fs::create_directories(out_path);
  writeEffectiveScenario(out_dir, "nadir launch " + options.scenario, scenario);
  const std::string bin_dir = options.bin_dir.empty() ? selfDirectory() : options.bin_dir;
  const std::string url = scenario.bus.resolvedUrl();

  std::vector<std::string> scenario_args = {options.scenario};
  for (const std::string& assignment : options.overrides) {
    scenario_args.push_back("--set");
    scenario_args.push_back(assignment);
  }
  const auto nodeLog = [&](const std::string& name) {
    return (out_path / (name + ".log")).string();
  };
  const auto withScenario = [&scenario_args](std::vector<std::string> argv) {
    argv.insert(argv.end(), scenario_args.begin(), scenario_args.end());
    return argv;
  };
  ChildProcess logger("lcm-logger", {"lcm-logger", "--lcm-url=" + url, "-f", recording.string()},
                      nodeLog("lcm-logger"));
  ChildProcess camera("nadir-camera",
                      withScenario({programPath(bin_dir, "nadir-camera"), "--scenario"}),
                      nodeLog("camera"));
  ChildProcess simulator("nadir-sim", withScenario({programPath(bin_dir, "nadir-sim")}),
                         nodeLog("sim"));
  // The VO nodes the scenario names.
  ChildProcess ppa("nadir-ppa",
                   withScenario({scenario.ppa.enabled ? programPath(bin_dir, "nadir-ppa")
                                                      : std::string("nadir-ppa")}),
                   nodeLog("ppa"));
  ChildProcess vo_feature(
      "nadir-vo-feature",
      withScenario({scenario.vo_feature.enabled ? programPath(bin_dir, "nadir-vo-feature")
                                                : std::string("nadir-vo-feature")}),
      nodeLog("vo_feature"));
  std::vector<ChildProcess*> listeners = {&camera};
  if (scenario.ppa.enabled) listeners.push_back(&ppa);
  if (scenario.vo_feature.enabled) listeners.push_back(&vo_feature);
  std::vector<ChildProcess*> nodes = {&logger};
  nodes.insert(nodes.end(), listeners.begin(), listeners.end());
  nodes.push_back(&simulator);

  // Health: what arrives on the bus, against what the scenario should produce.
  auto bus = core::openBus(scenario.bus);
  std::map<std::string, ChannelHealth> channels;
  channels[scenario.sim.truth.channel].expected_hz = scenario.sim.truth.rate_hz;
  for (const auto& [name, spec] : scenario.allCameras())
    channels[spec.channel].expected_hz = spec.fps;
  auto subscription = bus->subscribe(".*", [&](const core::RawMessage& raw) {
    ChannelHealth& health = channels[std::string(raw.channel)];
    ++health.total;
    ++health.window;
    if (const auto utime = core::peekUtime(raw)) {
      if (!health.first_utime) health.first_utime = *utime;
      health.last_utime = std::max(*utime, health.last_utime.value_or(*utime));
    }
    if (msg::isType<msg::VoEstimate>(raw.data, raw.size)) {
      try {
        health.vo_status =
            static_cast<int>(msg::decode<msg::VoEstimate>(raw.data, raw.size).status);
      } catch (const std::exception&) {
      }
    }
  });

  out << "launch: " << options.scenario << " on " << url << "; node logs and the recording in "
      << out_dir << "\n";
  int result = 0;
  const auto stopAll = [&] {
    for (auto it = nodes.rbegin(); it != nodes.rend(); ++it) (*it)->stop(5.0);
  };
  const auto failed = [&](const ChildProcess& node) {
    out << "launch: " << node.name() << " died (" << node.describeExit() << "); see "
        << node.logPath() << "\n";
    result = 1;
  };
  try {
    logger.start();
    for (ChildProcess* node : listeners) node->start();
    // Each node sets up (the camera its world and GL context) before it listens
    // and says "bus: ..."; the simulator starts when all have.
    const auto ready_deadline = Clock::now() + std::chrono::seconds(120);
    for (ChildProcess* node : listeners) {
      while (!fileContains(node->logPath(), "bus: ")) {
        if (!node->running()) {
          failed(*node);
          stopAll();
          return result;
        }
        if (stop || Clock::now() > ready_deadline) {
          out << "launch: " << (stop ? "stopped" : node->name() + " not ready after 120 s") << "\n";
          stopAll();
          return stop ? 130 : 1;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    simulator.start();
    out << "launch: nadir-sim started; Ctrl-C stops every node\n";

    const auto started = Clock::now();
    auto last_report = started;
    while (true) {
      bus->handle(std::chrono::milliseconds(50));
      if (stop) {
        out << "launch: stopping\n";
        stopAll();
        result = 130;
        break;
      }
      if (!simulator.running()) {
        if (simulator.exitStatus() != 0) {
          failed(simulator);
          stopAll();
          break;
        }
        out << "launch: the scenario has ended\n";
        // Let the last frames and estimates arrive and be recorded.
        const auto tail_end = Clock::now() + std::chrono::seconds(2);
        while (Clock::now() < tail_end) bus->handle(std::chrono::milliseconds(50));
        stopAll();
        break;
      }
      bool node_died = false;
      for (ChildProcess* node : nodes) {
        if (node != &simulator && !node->running()) {
          failed(*node);
          node_died = true;
        }
      }
      if (node_died) {
        stopAll();
        break;
      }
      const auto now = Clock::now();
      const double window_s = std::chrono::duration<double>(now - last_report).count();
      if (window_s >= options.report_period_s) {
        last_report = now;
        char line[256];
        std::snprintf(line, sizeof(line), "launch: %.0f s",
                      std::chrono::duration<double>(now - started).count());
        out << line << "\n";
        for (auto& [name, health] : channels) {
          std::snprintf(line, sizeof(line), "  %-18s %8.1f Hz", name.c_str(),
                        static_cast<double>(health.window) / window_s);
          out << line;
          if (health.expected_hz > 0.0) {
            std::snprintf(line, sizeof(line), " (expected %.1f), %lld missing",
                          health.expected_hz * scenario.time.speed,
                          static_cast<long long>(health.missing()));
            out << line;
          }
          if (health.vo_status >= 0) {
            static const char* kStatus[] = {"INITIALIZING", "TRACKING", "LOST"};
            out << " " << (health.vo_status <= 2 ? kStatus[health.vo_status] : "?");
          }
          out << "\n";
          health.window = 0;
        }
        out.flush();
      }
    }
  } catch (...) {
    stopAll();
    throw;
  }
  out << "launch: nodes\n";
  for (const ChildProcess* node : nodes) {
    const bool clean =
        node->exitStatus() == 0 || (node->stoppedByUs() && node->exitStatus() != 128 + SIGKILL);
    out << "  " << node->name() << ": " << node->describeExit()
        << (node->stoppedByUs() ? " (stopped by launch)" : "") << (clean ? "" : "  <- problem")
        << "\n";
    if (!clean && result == 0) result = 1;
  }
  out << "launch: messages received\n";
  for (const auto& [name, health] : channels) {
    out << "  " << name << ": " << health.total;
    if (health.expected_hz > 0.0) out << " (" << health.missing() << " missing)";
    out << "\n";
  }
  out << "launch: recording " << recording.string() << "\n";
  // Every run has its charts, a launch's too (a stopped one's as far as it went).
  const RunPlots plots = renderRunPlots(recording.string(), (out_path / "plots").string(), bin_dir);
  if (plots.problem.empty()) {
    out << "launch: charts in " << (out_path / "plots").string() << "\n";
  } else {
    out << "launch: " << plots.problem << "\n";
  }
  return result;
}

}  // namespace nadir::run
