#include "run/launch.h"

#include <signal.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>

#include "core/bus.h"
#include "core/clock.h"
#include "core/lcm_log.h"
#include "lcmtypes/codec.h"
#include "lcmtypes/messages.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"
#include "nodes/sim/simulator.h"
#include "run/bus_check.h"
#include "run/launch_hosts.h"
#include "run/process.h"
#include "run/run.h"
#include "terrain/world_factory.h"

namespace nadir::run {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// How long the end of a launch waits for the nodes to finish their work and for
// the recording to hold it, at most.
constexpr auto kSettleLimit = std::chrono::seconds(120);
// Once every node is done, a recording that has not grown for this long holds
// all it will: the logger has written everything it received.
constexpr auto kRecordingIdle = std::chrono::seconds(5);
// Less free space than this where the recording is, when the logger dies: the
// disk is full (the logger stops at its first failed write).
constexpr std::uintmax_t kFullDisk_bytes = 1 << 20;

std::string programPath(const std::string& bin_dir, const std::string& name) {
  const fs::path path = fs::path(bin_dir) / name;
  if (!fs::exists(path)) throw std::runtime_error("cannot find " + path.string());
  return path.string();
}

// A rate as `nadir log record --rate` reads it back, to the last digit.
std::string formatRate(double rate_hz) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text), rate_hz);
  return std::string(text, result.ptr);
}

struct ChannelHealth {
  std::int64_t total = 0;
  std::int64_t window = 0;
  Clock::time_point last_arrival;
  // Rate the scenario should produce, Hz of sim time; 0 when not known.
  double expected_hz = 0.0;
  int vo_status = -1;
  bool quiet = false;  // reported quiet, nothing since
};

std::string formatSeconds(Clock::duration duration) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f s", std::chrono::duration<double>(duration).count());
  return text;
}

// Messages lost on the way to this process, from their times (the bus's count).
std::int64_t missingOn(const std::map<std::string, core::ChannelStats>& stats,
                       const std::string& channel) {
  const auto it = stats.find(channel);
  return it == stats.end() ? 0 : it->second.missing;
}

// The recording's messages by channel, read as the logger writes it: each
// update() reads only what was appended since the last.
class RecordingCounter {
 public:
  explicit RecordingCounter(std::string path) : path_(std::move(path)) {}

  void update() {
    std::error_code error;
    const auto size = fs::file_size(path_, error);
    if (error || size <= static_cast<std::uintmax_t>(resume_offset_)) return;
    try {
      core::LcmLogReader reader(path_);
      if (resume_offset_ > 0) reader.seek(resume_offset_);
      while (const auto event = reader.next()) {
        ++counts_[event->channel];
        resume_offset_ = reader.tell();
      }
    } catch (const core::LogError&) {
      // Not one whole event written yet: the next update reads it.
    }
  }
  std::int64_t count(const std::string& channel) const {
    const auto it = counts_.find(channel);
    return it == counts_.end() ? 0 : it->second;
  }
  // Events on every channel but one (the heartbeats, which go on to the end).
  std::int64_t totalExcept(const std::string& ignored) const {
    std::int64_t events = 0;
    for (const auto& [channel, count] : counts_) {
      if (channel != ignored) events += count;
    }
    return events;
  }

 private:
  std::string path_;
  std::int64_t resume_offset_ = 0;
  std::map<std::string, std::int64_t> counts_;
};

// What a node's heartbeats say: its summary, what it has sent, whether that
// changed since the heartbeat before (it is still at work) and whether it is
// done; when the last came, and what processes of it that died had sent.
struct NodeReport {
  std::string summary;
  std::map<std::string, std::int64_t> sent;
  bool working = true;
  bool done = false;
  std::int32_t pid = 0;
  std::map<std::string, std::int64_t> sent_before;  // by earlier processes
  Clock::time_point last_beat;
  bool silent = false;  // reported silent, not heard since

  std::int64_t sentOn(const std::string& channel) const {
    const auto now = sent.find(channel);
    const auto before = sent_before.find(channel);
    return (now == sent.end() ? 0 : now->second) +
           (before == sent_before.end() ? 0 : before->second);
  }
  // A heartbeat from another process of this node: what the last sent stays counted.
  void newProcess(std::int32_t new_pid) {
    if (pid != 0 && new_pid != pid) {
      for (const auto& [channel, count] : sent) sent_before[channel] += count;
      sent.clear();
    }
    pid = new_pid;
  }
};

// Channels whose messages the recording holds fewer of than the nodes sent.
std::map<std::string, std::pair<std::int64_t, std::int64_t>> missingFromRecording(
    const std::map<std::string, NodeReport>& reports, const RecordingCounter& recording) {
  std::map<std::string, std::pair<std::int64_t, std::int64_t>> missing;  // sent, recorded
  for (const auto& [node, report] : reports) {
    std::set<std::string> channels;
    for (const auto& [channel, count] : report.sent) channels.insert(channel);
    for (const auto& [channel, count] : report.sent_before) channels.insert(channel);
    for (const std::string& channel : channels) {
      const std::int64_t sent = report.sentOn(channel);
      if (recording.count(channel) < sent) missing[channel] = {sent, recording.count(channel)};
    }
  }
  return missing;
}

struct LaunchedNode {
  const nodes::Entry* entry = nullptr;
  std::unique_ptr<ChildProcess> process;
  std::string host;
  std::vector<std::string> argv;                    // the program's, before the host's prefix
  std::vector<std::string> channels;                // what it publishes
  std::vector<std::unique_ptr<ChildProcess>> died;  // its processes that died, restarted
};

// A simulator on the bus that is not this launch's, seen before this one starts.
struct ForeignSimulator {
  std::optional<std::string> seen;  // what gave it away

  void refuseIfSeen(const std::string& url) const {
    if (!seen) return;
    throw std::runtime_error(
        "another simulator is flying on " + url + " (" + *seen +
        "): two flights on one bus mix their truths. Stop it, or give this launch a bus of its "
        "own (--set bus.url=udpm://239.255.76.67:7668?ttl=0, another port)");
  }
};

// Whether url sends nothing off this machine (udpm with ttl=0, or memq).
bool staysOnThisHost(const std::string& url) {
  return url.rfind("memq://", 0) == 0 || core::udpmTtl(url) == 0;
}

// The bus joins every host in use: a checker on each, and this launch, until
// each has heard every other (run/bus_check.h). Returns an empty string, or
// what failed.
std::string checkBusReachesHosts(core::Bus& bus, const LaunchHosts& hosts,
                                 const std::set<std::string>& used, const std::string& url,
                                 const std::string& bin_dir, const fs::path& out_path,
                                 double timeout_s, const std::atomic<bool>& stop,
                                 std::ostream& out) {
  std::random_device random;
  const std::int64_t launch_id =
      static_cast<std::int64_t>((static_cast<std::uint64_t>(random()) << 31) ^ random()) &
      0x7fffffffffffffff;
  std::set<std::string> everyone = used;
  everyone.insert("launch");
  std::string names;
  for (const std::string& name : everyone) names += (names.empty() ? "" : ",") + name;
  std::vector<std::unique_ptr<ChildProcess>> checkers;
  for (const std::string& host : used) {
    const std::vector<std::string> argv = {
        programPath(bin_dir, "nadir"), "bus",    "check", "--url",   url,   "--launch-id",
        std::to_string(launch_id),     "--host", host,    "--hosts", names, "--timeout",
        std::to_string(timeout_s)};
    checkers.push_back(std::make_unique<ChildProcess>(
        "bus check on " + host, hosts.command(hosts.host(host), argv, bin_dir),
        (out_path / ("bus-check-" + host + ".log")).string()));
    checkers.back()->start();
  }
  BusCheck check(bus, launch_id, "launch", everyone);
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  std::string problem;
  while (!check.complete() && problem.empty()) {
    if (stop) problem = "stopped";
    if (Clock::now() > deadline) problem = "timed out";
    for (const auto& checker : checkers) {
      if (!checker->running() && checker->exitStatus() != 0) {
        problem = checker->name() + " failed (" + checker->describeExit() + "); see " +
                  checker->logPath();
      }
    }
    check.beatIfDue();
    bus.handle(std::chrono::milliseconds(20));
  }
  // The checkers say they are done once everyone has heard them say so.
  const auto linger_deadline = Clock::now() + std::chrono::seconds(5);
  while (problem.empty() && Clock::now() < linger_deadline &&
         std::any_of(checkers.begin(), checkers.end(), [](auto& c) { return c->running(); })) {
    check.beatIfDue();
    bus.handle(std::chrono::milliseconds(20));
  }
  for (const auto& checker : checkers) checker->stop(1.0);
  if (!problem.empty()) {
    std::string missing;
    for (const std::string& link : check.missingLinks()) missing += "\n  " + link;
    return "the bus does not join every host (" + problem + " after " +
           std::to_string(static_cast<int>(timeout_s)) + " s):" + missing;
  }
  out << "launch: the bus joins every host (" << names << ")\n";
  return {};
}

// Every channel's rate in the last window against what the scenario should
// produce, the VO nodes' status, and what each node's heartbeat says.
void printHealth(std::ostream& out, double elapsed_s, double window_s, double speed,
                 std::map<std::string, ChannelHealth>& channels,
                 const std::map<std::string, core::ChannelStats>& stats,
                 const std::map<std::string, NodeReport>& heartbeats,
                 const std::map<std::string, std::vector<std::string>>& nodes_by_host) {
  char line[256];
  std::snprintf(line, sizeof(line), "launch: %.0f s", elapsed_s);
  out << line << "\n";
  for (auto& [name, health] : channels) {
    std::snprintf(line, sizeof(line), "  %-18s %8.1f Hz", name.c_str(),
                  static_cast<double>(health.window) / window_s);
    out << line;
    if (health.expected_hz > 0.0) {
      std::snprintf(line, sizeof(line), " (expected %.1f), %lld missing",
                    health.expected_hz * speed, static_cast<long long>(missingOn(stats, name)));
      out << line;
    }
    if (health.vo_status >= 0) {
      static const char* kStatus[] = {"INITIALIZING", "TRACKING", "LOST"};
      out << " " << (health.vo_status <= 2 ? kStatus[health.vo_status] : "?");
    }
    out << "\n";
    health.window = 0;
  }
  for (const auto& [host, nodes_there] : nodes_by_host) {
    if (nodes_by_host.size() > 1) out << "  host " << host << ":\n";
    const std::string indent = nodes_by_host.size() > 1 ? "    " : "  ";
    for (const std::string& node : nodes_there) {
      const auto report = heartbeats.find(node);
      out << indent << node << ": "
          << (report == heartbeats.end() ? "no heartbeat yet" : report->second.summary) << "\n";
    }
  }
  out.flush();
}

}  // namespace

int launchScenario(const LaunchOptions& options, std::ostream& out, const std::atomic<bool>& stop) {
  nodes::ScenarioParams scenario = nodes::loadScenario(options.scenario, options.overrides);
  {
    // Refuse what nadir-sim would refuse before any process starts.
    terrain::requireFlightWorld(scenario.world);
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
  const fs::path recording_path = out_path / "launch.lcmlog";
  if (!options.force && fs::exists(recording_path)) {
    throw std::runtime_error(out_dir +
                             " already holds a launch (launch.lcmlog); choose another "
                             "--out or pass --force to replace it");
  }
  fs::create_directories(out_path);
  writeEffectiveScenario(out_dir, "nadir launch " + options.scenario, scenario);
  const std::string bin_dir = options.bin_dir.empty() ? selfDirectory() : options.bin_dir;
  const std::string url = scenario.bus.resolvedUrl();
  std::vector<std::string> node_names;
  for (const auto& entry : nodes::registry()) node_names.push_back(entry->info().name);
  const LaunchHosts hosts =
      options.hosts_file.empty() ? localHosts() : loadLaunchHosts(options.hosts_file, node_names);
  std::set<std::string> used_hosts = {hosts.hostOf(kLoggerNode).name};
  for (const auto& entry : nodes::registry()) {
    if (entry->enabled(scenario)) used_hosts.insert(hosts.hostOf(entry->info().name).name);
  }
  const bool several_hosts = !options.hosts_file.empty();
  if (several_hosts && used_hosts.size() > 1 && staysOnThisHost(url)) {
    throw std::runtime_error("the nodes are on " + std::to_string(used_hosts.size()) +
                             " hosts but the bus " + url +
                             " stays on each (ttl=0); give it ttl=1: --set "
                             "bus.url=udpm://239.255.76.67:7667?ttl=1");
  }
  const auto nodeLog = [&](const std::string& name) {
    return (out_path / (name + ".log")).string();
  };

  // One process per node the scenario runs, each given the scenario and overrides;
  // the simulator starts once the others are up, and the health report expects
  // what the nodes' streams say.
  // The logger is nadir's own recorder, not lcm-logger: lcm-logger subscribes
  // with LCM's default queue of 30 messages and drops, uncounted, what a burst
  // brings beyond it while it waits for the CPU.
  const LaunchHost& logger_host = hosts.hostOf(kLoggerNode);
  std::vector<std::string> logger_argv = {programPath(bin_dir, "nadir"),
                                          "log",
                                          "record",
                                          recording_path.string(),
                                          "--force",
                                          "--url",
                                          url};
  for (const auto& [channel, rate_hz] : nodes::expectedRates(scenario)) {
    logger_argv.push_back("--rate");
    logger_argv.push_back(channel + "=" + formatRate(rate_hz));
  }
  ChildProcess logger(kLoggerNode, hosts.command(logger_host, logger_argv, bin_dir),
                      nodeLog(kLoggerNode));
  RecordingCounter recording(recording_path.string());
  std::vector<LaunchedNode> launched;
  std::map<std::string, ChannelHealth> channels;
  for (const auto& entry : nodes::registry()) {
    if (!entry->enabled(scenario)) continue;
    std::vector<std::string> argv = {programPath(bin_dir, entry->info().program), options.scenario};
    for (const std::string& assignment : options.overrides) {
      argv.push_back("--set");
      argv.push_back(assignment);
    }
    const LaunchHost& host = hosts.hostOf(entry->info().name);
    std::vector<std::string> published;
    for (const nodes::Stream& stream : entry->streams(entry->fromScenario(scenario))) {
      published.push_back(stream.channel);
    }
    launched.push_back(
        {entry.get(),
         std::make_unique<ChildProcess>(entry->info().program, hosts.command(host, argv, bin_dir),
                                        nodeLog(entry->info().name)),
         host.name,
         argv,
         std::move(published),
         {}});
  }
  for (const auto& [channel, rate_hz] : nodes::expectedRates(scenario)) {
    channels[channel].expected_hz = rate_hz;
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
  for (const auto& [channel, health] : channels) {
    if (health.expected_hz > 0.0) bus->expectRate(channel, health.expected_hz);
  }
  const auto bus_opened = Clock::now();
  std::map<std::string, NodeReport> heartbeats;  // by node name
  std::map<std::string, int> resets_by_source;   // the last num_resets of each VO source
  ForeignSimulator foreign;
  bool simulator_started = false;
  const auto programOf = [&](const std::string& node_name) {
    for (const LaunchedNode& node : launched) {
      if (node.entry->info().name == node_name) return node.entry->info().program;
    }
    return node_name;
  };
  const std::string simulator_name = [&] {
    for (const LaunchedNode& node : launched) {
      if (isSimulator(node)) return node.entry->info().name;
    }
    return std::string();
  }();
  auto subscription = bus->subscribe(".*", [&](const core::RawMessage& raw) {
    if (raw.channel == kBusCheckChannel) return;
    if (!simulator_started && !foreign.seen && raw.channel == scenario.sim.truth.channel) {
      foreign.seen = "its truth arrives on " + scenario.sim.truth.channel;
    }
    if (raw.channel == scenario.bus.heartbeat_channel) {
      try {
        const msg::Heartbeat beat = msg::decode<msg::Heartbeat>(raw.data, raw.size);
        if (!simulator_started && beat.node == simulator_name && !foreign.seen) {
          foreign.seen = "a heartbeat of " + simulator_name + " pid " + std::to_string(beat.pid);
          return;
        }
        NodeReport& report = heartbeats[beat.node];
        report.newProcess(beat.pid);
        report.working = beat.sent != report.sent;
        report.sent = beat.sent;
        report.summary = beat.summary;
        report.done = report.done || beat.done;
        const auto now = Clock::now();
        if (report.silent) {
          out << "launch: " << programOf(beat.node) << " heard again after "
              << formatSeconds(now - report.last_beat) << " of silence\n";
          report.silent = false;
        }
        report.last_beat = now;
      } catch (const std::exception&) {
        bus->countDecodeError(raw.channel);
      }
      return;
    }
    ChannelHealth& health = channels[std::string(raw.channel)];
    ++health.total;
    ++health.window;
    const auto now = Clock::now();
    if (health.quiet) {
      out << "launch: " << raw.channel << " flowing again after "
          << formatSeconds(now - health.last_arrival) << "\n";
      health.quiet = false;
    }
    health.last_arrival = now;
    if (msg::isType<msg::VoEstimate>(raw.data, raw.size)) {
      try {
        const msg::VoEstimate estimate = msg::decode<msg::VoEstimate>(raw.data, raw.size);
        health.vo_status = static_cast<int>(estimate.status);
        resets_by_source[estimate.source] = estimate.num_resets;
      } catch (const std::exception&) {
        bus->countDecodeError(raw.channel);
      }
    }
  });

  out << "launch: " << options.scenario << " on " << url << "; node logs and the recording in "
      << out_dir << "\n";
  std::map<std::string, std::vector<std::string>> nodes_by_host;
  for (const LaunchedNode& node : launched) {
    nodes_by_host[node.host].push_back(node.entry->info().name);
  }
  if (several_hosts) {
    for (const std::string& host : used_hosts) {
      out << "launch: host " << hosts.host(host).describe() << ":";
      if (host == logger_host.name) out << " " << kLoggerNode;
      for (const std::string& node : nodes_by_host[host]) out << " " << node;
      out << "\n";
    }
    const std::string problem = checkBusReachesHosts(
        *bus, hosts, used_hosts, url, bin_dir, out_path, options.bus_check_timeout_s, stop, out);
    if (!problem.empty()) {
      out << "launch: " << problem << "\n";
      return stop ? 130 : 1;
    }
  }
  // A second simulator is refused before anything starts (and checked again
  // before this one does, once its heartbeat has had time to come).
  while (Clock::now() - bus_opened < std::chrono::milliseconds(200)) {
    bus->handle(std::chrono::milliseconds(20));
  }
  foreign.refuseIfSeen(url);
  int result = 0;
  // Over ssh the logger writes on another machine; seen here only through a shared folder.
  const auto recordingHere = [&] { return !logger_host.viaSsh() || fs::exists(recording_path); };
  const auto stopAll = [&] {
    for (auto it = processes.rbegin(); it != processes.rend(); ++it) (*it)->stop(5.0);
  };
  const auto reportDeath = [&](const ChildProcess& node) {
    out << "launch: " << node.name() << " died (" << node.describeExit() << ")";
    if (const std::string words = node.lastWords(); !words.empty()) {
      out << ", its last words: \"" << words << "\"";
    }
    out << "; see " << node.logPath() << "\n";
  };
  const auto failed = [&](const ChildProcess& node) {
    reportDeath(node);
    result = 1;
  };
  // A node started again in place of one that died; a VO node's num_resets
  // goes on from the last its estimates carried, plus its fresh start.
  const auto restart = [&](LaunchedNode& node) {
    const std::string& name = node.entry->info().name;
    const int number = static_cast<int>(node.died.size()) + 1;
    std::vector<std::string> argv = node.argv;
    const auto resets = resets_by_source.find(name);
    if (resets != resets_by_source.end()) {
      argv.push_back("--resets-before");
      argv.push_back(std::to_string(resets->second + 1));
    }
    auto process = std::make_unique<ChildProcess>(
        node.process->name(), hosts.command(hosts.hostOf(name), argv, bin_dir),
        nodeLog(name + "-restart" + std::to_string(number)));
    process->start();
    out << "launch: restarted " << process->name() << " (restart " << number << " of at most "
        << options.max_restarts << ")";
    if (resets != resets_by_source.end()) {
      out << "; its num_resets goes on from " << resets->second + 1;
    }
    out << "; see " << process->logPath() << "\n";
    std::replace(processes.begin(), processes.end(), node.process.get(), process.get());
    node.died.push_back(std::move(node.process));
    node.process = std::move(process);
    // Not silent while it starts: watched again from its first heartbeat.
    NodeReport& report = heartbeats[name];
    report.last_beat = {};
    report.silent = false;
  };
  // A node whose heartbeat is late, a channel with a rate (the scenario's, or
  // as learnt) that has stopped: said at once, and again when heard.
  const auto reportSilence = [&] {
    const auto now = Clock::now();
    const auto stats = bus->stats();
    const auto late = std::chrono::duration<double>(kSilentAfter_s);
    for (const LaunchedNode& node : launched) {
      const auto report = heartbeats.find(node.entry->info().name);
      if (report == heartbeats.end() || report->second.silent ||
          report->second.last_beat == Clock::time_point{} ||
          now - report->second.last_beat < late) {
        continue;
      }
      report->second.silent = true;
      out << "launch: " << node.entry->info().program << " silent: no heartbeat for "
          << formatSeconds(now - report->second.last_beat) << "\n";
    }
    for (auto& [name, health] : channels) {
      if (health.quiet || health.total == 0) continue;
      const auto learnt = stats.find(name);
      const double rate_hz = health.expected_hz > 0.0 ? health.expected_hz
                             : learnt != stats.end()  ? learnt->second.rate_hz
                                                      : 0.0;
      if (rate_hz <= 0.0) continue;
      const auto expected_gap = std::chrono::duration<double>(
          std::max(kSilentAfter_s, 3.0 / (rate_hz * scenario.time.speed)));
      if (now - health.last_arrival < expected_gap) continue;
      health.quiet = true;
      std::string from;
      for (const LaunchedNode& node : launched) {
        for (const std::string& channel : node.channels) {
          if (channel == name) from = " (" + node.entry->info().program + ")";
        }
      }
      out << "launch: " << name << from << " quiet for " << formatSeconds(now - health.last_arrival)
          << "\n";
    }
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
    // Heartbeats come once a second: listen that long before the check.
    while (Clock::now() - bus_opened < std::chrono::milliseconds(1500) && !foreign.seen) {
      bus->handle(std::chrono::milliseconds(50));
    }
    if (foreign.seen) {
      stopAll();
      foreign.refuseIfSeen(url);
    }
    simulator_started = true;
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
        // The nodes finish what they have (a VO behind by some frames), then the
        // recording must hold all they sent: waited for, not timed, while the
        // logger still writes (what it dropped never comes, and is reported).
        const auto settle_deadline = Clock::now() + kSettleLimit;
        std::int64_t recorded_events = -1;
        auto recording_grew = Clock::now();
        const auto settled = [&] {
          recording.update();
          for (const LaunchedNode& node : launched) {
            const auto report = heartbeats.find(node.entry->info().name);
            if (report == heartbeats.end()) return false;
            if (isSimulator(node) ? !report->second.done : report->second.working) return false;
          }
          const std::int64_t events = recording.totalExcept(scenario.bus.heartbeat_channel);
          if (events != recorded_events) {
            recorded_events = events;
            recording_grew = Clock::now();
          }
          return !recordingHere() || missingFromRecording(heartbeats, recording).empty() ||
                 Clock::now() - recording_grew > kRecordingIdle;
        };
        while (!stop && !settled() && Clock::now() < settle_deadline) {
          bus->handle(std::chrono::milliseconds(100));
        }
        stopAll();
        break;
      }
      bool must_stop = false;
      if (!logger.running()) {
        failed(logger);
        std::error_code error;
        const fs::space_info space = fs::space(out_path, error);
        if (!error && space.available < kFullDisk_bytes) {
          out << "launch: the disk holding " << out_dir << " is full (" << space.available
              << " bytes free)\n";
        }
        out << "launch: the recording ends there; stopping every node\n";
        must_stop = true;
      }
      for (LaunchedNode& node : launched) {
        if (isSimulator(node) || node.process->running()) continue;
        if (static_cast<int>(node.died.size()) < options.max_restarts && !must_stop) {
          reportDeath(*node.process);
          restart(node);
        } else {
          failed(*node.process);
          must_stop = true;
        }
      }
      if (must_stop) {
        stopAll();
        break;
      }
      reportSilence();
      const auto now = Clock::now();
      const double window_s = std::chrono::duration<double>(now - last_report).count();
      if (window_s >= options.report_period_s) {
        last_report = now;
        printHealth(out, std::chrono::duration<double>(now - started).count(), window_s,
                    scenario.time.speed, channels, bus->stats(), heartbeats, nodes_by_host);
        recording.update();
      }
    }
  } catch (...) {
    stopAll();
    throw;
  }
  out << "launch: nodes\n";
  std::map<const ChildProcess*, std::string> host_of = {{&logger, logger_host.name}};
  for (const LaunchedNode& node : launched) {
    host_of[node.process.get()] = node.host;
    for (const auto& dead : node.died) {
      out << "  " << dead->name() << (several_hosts ? " on " + node.host : "") << ": "
          << dead->describeExit() << ", restarted; see " << dead->logPath() << "\n";
    }
  }
  for (const ChildProcess* node : processes) {
    const bool clean =
        node->exitStatus() == 0 || (node->stoppedByUs() && node->exitStatus() != 128 + SIGKILL);
    out << "  " << node->name() << (several_hosts ? " on " + host_of[node] : "") << ": "
        << node->describeExit() << (node->stoppedByUs() ? " (stopped by launch)" : "")
        << (clean ? "" : "  <- problem") << "\n";
    if (!clean && result == 0) result = 1;
  }
  out << "launch: what each node said last\n";
  for (const LaunchedNode& node : launched) {
    const auto report = heartbeats.find(node.entry->info().name);
    out << "  " << node.entry->info().program << ": "
        << (report == heartbeats.end() ? "no heartbeat" : report->second.summary) << "\n";
  }
  out << "launch: messages received\n";
  const auto final_stats = bus->stats();
  for (const auto& [name, health] : channels) {
    out << "  " << name << ": " << health.total;
    if (health.expected_hz > 0.0) out << " (" << missingOn(final_stats, name) << " missing)";
    out << "\n";
  }
  if (const std::string malformed = core::describeMalformed(final_stats); !malformed.empty()) {
    out << "launch: " << malformed << "\n";
  }
  if (!recordingHere()) {
    out << "launch: the recording is on " << logger_host.describe() << " at "
        << recording_path.string() << " (not seen from here: not checked, no charts)\n";
    return result;
  }
  recording.update();
  const auto missing = missingFromRecording(heartbeats, recording);
  for (const auto& [channel, counts] : missing) {
    out << "launch: the recording holds " << counts.second << " of the " << counts.first << " "
        << channel << " messages sent\n";
  }
  if (missing.empty() && !heartbeats.empty()) {
    out << "launch: the recording holds every message the nodes said they sent\n";
  }
  out << "launch: recording " << recording_path.string() << "\n";
  // Every run has its charts, a launch's too (a stopped one's as far as it went).
  const RunPlots plots =
      renderRunPlots(recording_path.string(), (out_path / "plots").string(), bin_dir);
  if (plots.problem.empty()) {
    out << "launch: charts in " << (out_path / "plots").string() << "\n";
  } else {
    out << "launch: " << plots.problem << "\n";
  }
  return result;
}

}  // namespace nadir::run
