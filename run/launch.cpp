#include "run/launch.h"

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/bus.h"
#include "core/clock.h"
#include "lcmtypes/codec.h"
#include "lcmtypes/messages.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"
#include "nodes/sim/simulator.h"
#include "run/process.h"
#include "run/run.h"
#include "terrain/world_factory.h"

namespace nadir::run {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

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

struct LaunchedNode {
  const nodes::Entry* entry = nullptr;
  std::unique_ptr<ChildProcess> process;
};

// Every channel's rate in the last window against what the scenario should
// produce, the VO nodes' status, and what each node's heartbeat says.
void printHealth(std::ostream& out, double elapsed_s, double window_s, double speed,
                 std::map<std::string, ChannelHealth>& channels,
                 const std::map<std::string, std::string>& heartbeats) {
  char line[256];
  std::snprintf(line, sizeof(line), "launch: %.0f s", elapsed_s);
  out << line << "\n";
  for (auto& [name, health] : channels) {
    std::snprintf(line, sizeof(line), "  %-18s %8.1f Hz", name.c_str(),
                  static_cast<double>(health.window) / window_s);
    out << line;
    if (health.expected_hz > 0.0) {
      std::snprintf(line, sizeof(line), " (expected %.1f), %lld missing",
                    health.expected_hz * speed, static_cast<long long>(health.missing()));
      out << line;
    }
    if (health.vo_status >= 0) {
      static const char* kStatus[] = {"INITIALIZING", "TRACKING", "LOST"};
      out << " " << (health.vo_status <= 2 ? kStatus[health.vo_status] : "?");
    }
    out << "\n";
    health.window = 0;
  }
  for (const auto& [node, summary] : heartbeats) out << "  " << node << ": " << summary << "\n";
  out.flush();
}

}  // namespace

int launchScenario(const LaunchOptions& options, std::ostream& out, const std::atomic<bool>& stop) {
  nodes::ScenarioParams scenario = nodes::loadScenario(options.scenario, options.overrides);
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
  const auto nodeLog = [&](const std::string& name) {
    return (out_path / (name + ".log")).string();
  };

  // One process per node the scenario runs, each given the scenario and overrides;
  // the simulator starts once the others are up, and the health report expects
  // what the nodes' streams say.
  ChildProcess logger("lcm-logger", {"lcm-logger", "--lcm-url=" + url, "-f", recording.string()},
                      nodeLog("lcm-logger"));
  std::vector<LaunchedNode> launched;
  std::map<std::string, ChannelHealth> channels;
  for (const auto& entry : nodes::registry()) {
    if (!entry->enabled(scenario)) continue;
    std::vector<std::string> argv = {programPath(bin_dir, entry->info().program), options.scenario};
    for (const std::string& assignment : options.overrides) {
      argv.push_back("--set");
      argv.push_back(assignment);
    }
    launched.push_back({entry.get(), std::make_unique<ChildProcess>(entry->info().program, argv,
                                                                    nodeLog(entry->info().name))});
    for (const nodes::Stream& stream : entry->streams(entry->fromScenario(scenario))) {
      if (stream.rate_hz > 0.0) channels[stream.channel].expected_hz = stream.rate_hz;
    }
  }
  const auto isSimulator = [](const LaunchedNode& node) {
    return node.entry->info().role == nodes::EntryInfo::Role::kSimulator;
  };
  std::vector<ChildProcess*> processes = {&logger};
  for (LaunchedNode& node : launched) processes.push_back(node.process.get());
  ChildProcess* simulator = nullptr;
  for (LaunchedNode& node : launched) {
    if (isSimulator(node)) simulator = node.process.get();
  }
  if (simulator == nullptr) throw std::logic_error("the registry has no simulator");

  // Health: what arrives on the bus, against what the scenario should produce;
  // the nodes' heartbeats say they are up and what they have done.
  auto bus = core::openBus(scenario.bus);
  std::map<std::string, std::string> heartbeats;  // node name -> its last summary
  auto subscription = bus->subscribe(".*", [&](const core::RawMessage& raw) {
    if (raw.channel == scenario.bus.heartbeat_channel) {
      try {
        const msg::Heartbeat beat = msg::decode<msg::Heartbeat>(raw.data, raw.size);
        heartbeats[beat.node] = beat.summary;
      } catch (const std::exception&) {
      }
      return;
    }
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
    for (auto it = processes.rbegin(); it != processes.rend(); ++it) (*it)->stop(5.0);
  };
  const auto failed = [&](const ChildProcess& node) {
    out << "launch: " << node.name() << " died (" << node.describeExit() << "); see "
        << node.logPath() << "\n";
    result = 1;
  };
  try {
    logger.start();
    for (LaunchedNode& node : launched) {
      if (!isSimulator(node)) node.process->start();
    }
    // Each node sets up (the camera its world and GL context) before its first
    // heartbeat; the simulator starts when all have sent one.
    const auto ready_deadline = Clock::now() + std::chrono::seconds(120);
    for (LaunchedNode& node : launched) {
      if (isSimulator(node)) continue;
      while (heartbeats.count(node.entry->info().name) == 0) {
        if (!node.process->running()) {
          failed(*node.process);
          stopAll();
          return result;
        }
        if (stop || Clock::now() > ready_deadline) {
          out << "launch: "
              << (stop ? "stopped" : node.process->name() + " not up after 120 s (no heartbeat)")
              << "\n";
          stopAll();
          return stop ? 130 : 1;
        }
        bus->handle(std::chrono::milliseconds(100));
      }
    }
    simulator->start();
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
      if (!simulator->running()) {
        if (simulator->exitStatus() != 0) {
          failed(*simulator);
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
      for (ChildProcess* node : processes) {
        if (node != simulator && !node->running()) {
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
        printHealth(out, std::chrono::duration<double>(now - started).count(), window_s,
                    scenario.time.speed, channels, heartbeats);
      }
    }
  } catch (...) {
    stopAll();
    throw;
  }
  out << "launch: nodes\n";
  for (const ChildProcess* node : processes) {
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
