#pragma once
// A recorded flight played across three hosts (tests/support/hosts.h), for the
// playback test and its benchmark: `nadir log play` on host 0 replays the
// flight's log, VO node programs run on host 1 and `nadir log record` on host
// 2 records what comes back; each program's output is kept.

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/lcm_log.h"
#include "run/process.h"
#include "tests/support/hosts.h"
#include "tests/support/run_command.h"

namespace nadir::test {

struct PlaybackSetup {
  std::string bin_dir;
  std::filesystem::path flight;  // a `nadir run` folder: run.lcmlog and scenario.yaml
  std::string url;               // udpm://...?ttl=1
  // What the VO nodes read: the flight, not the estimates made of it.
  std::string channels = "POSE_TRUTH|NAV_.*|RANGE|CAMERA_DOWN|CAMERA_DOWN_INFO|IMU|BARO|GPS|MAG";
  std::string image_encoding = "raw";
  std::vector<std::string> vo_programs;  // nadir-vo-feature, ...
  std::vector<std::string> vo_sets;      // --set for each of them
  double speed = 1.0;
  double idle_stop_s = 5.0;  // the recorder stops when the VO nodes have been quiet this long
  std::filesystem::path out;
};

struct PlaybackResult {
  bool ok = false;
  std::string problem;  // what went wrong when not ok
  std::string player_output;
  std::string recorder_output;
  std::vector<std::string> vo_outputs;
  std::filesystem::path recording;
  double play_wall_s = 0.0;  // how long the player took
};

inline std::string readTextFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Messages on a channel in a log.
inline std::int64_t eventsOn(const std::filesystem::path& log, const std::string& channel) {
  core::LcmLogReader reader(log.string());
  std::int64_t count = 0;
  while (const auto event = reader.next()) count += event->channel == channel ? 1 : 0;
  return count;
}

// The number after "  CHANNEL: " in a program's report ("  CAMERA_DOWN: 123 bytes").
inline std::int64_t reportedNumber(const std::string& output, const std::string& channel) {
  const std::string key = "  " + channel + ": ";
  const std::size_t at = output.find(key);
  if (at == std::string::npos) return -1;
  std::istringstream line(output.substr(at + key.size()));
  std::int64_t number = -1;
  line >> number;
  return number;
}

inline PlaybackResult playAcrossHosts(const TestHosts& hosts, const PlaybackSetup& setup) {
  namespace fs = std::filesystem;
  using Clock = std::chrono::steady_clock;
  fs::create_directories(setup.out);
  PlaybackResult result;
  result.recording = setup.out / "recorded.lcmlog";
  const std::string nadir = (fs::path(setup.bin_dir) / "nadir").string();
  const std::string scenario = (setup.flight / "scenario.yaml").string();
  const auto onHost = [&](int host, std::vector<std::string> argv) {
    std::vector<std::string> command = {"ip", "netns", "exec", hosts.name(host)};
    command.insert(command.end(), argv.begin(), argv.end());
    return command;
  };
  // Waits until a program's output holds text (it has set up), or it ended.
  const auto waitFor = [&](run::ChildProcess& process, const std::string& text) {
    const auto deadline = Clock::now() + std::chrono::seconds(120);
    while (Clock::now() < deadline) {
      if (readTextFile(process.logPath()).find(text) != std::string::npos) return true;
      if (!process.running()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    result.problem = process.name() + " did not set up (" +
                     (process.running() ? "no '" + text + "'" : process.describeExit()) +
                     "): " + readTextFile(process.logPath());
    return false;
  };

  run::ChildProcess recorder("recorder",
                             onHost(2, {nadir, "log", "record", result.recording.string(), "--url",
                                        setup.url, "--scenario", scenario, "--idle-stop",
                                        std::to_string(setup.idle_stop_s), "--force"}),
                             (setup.out / "recorder.out").string());
  std::vector<std::unique_ptr<run::ChildProcess>> vo_nodes;
  for (const std::string& program : setup.vo_programs) {
    std::vector<std::string> argv = {(fs::path(setup.bin_dir) / program).string(), scenario,
                                     "--set", "bus.url=" + setup.url};
    for (const std::string& assignment : setup.vo_sets) {
      argv.push_back("--set");
      argv.push_back(assignment);
    }
    vo_nodes.push_back(std::make_unique<run::ChildProcess>(
        program, onHost(1, argv), (setup.out / (program + ".out")).string()));
  }
  const auto stopAll = [&] {
    recorder.stop(5.0);
    for (auto& node : vo_nodes) node->stop(10.0);
  };
  recorder.start();
  bool ready = waitFor(recorder, "Ctrl-C stops");
  for (auto& node : vo_nodes) {
    if (!ready) break;
    node->start();
    ready = waitFor(*node, "bus: ");
  }
  if (!ready) {
    stopAll();
    return result;
  }
  const auto play_started = Clock::now();
  const auto [status, output] = runCommand(
      hosts.prefix(0) + nadir + " log play " + (setup.flight / "run.lcmlog").string() + " --url '" +
      setup.url + "' --channels '" + setup.channels + "' --image-encoding " + setup.image_encoding +
      " --speed " + std::to_string(setup.speed));
  result.play_wall_s = std::chrono::duration<double>(Clock::now() - play_started).count();
  result.player_output = output;
  // The recorder stops once the VO nodes have sent their last pose.
  const auto deadline = Clock::now() + std::chrono::seconds(600);
  while (recorder.running() && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const bool recorder_stopped = !recorder.running();
  stopAll();
  result.recorder_output = readTextFile(recorder.logPath());
  for (auto& node : vo_nodes) result.vo_outputs.push_back(readTextFile(node->logPath()));
  if (status != 0) {
    result.problem = "nadir log play failed: " + output;
  } else if (!recorder_stopped) {
    result.problem = "the recorder did not stop: " + result.recorder_output;
  } else if (recorder.exitStatus() != 0) {
    result.problem = "the recorder failed: " + result.recorder_output;
  } else {
    for (std::size_t i = 0; i < vo_nodes.size(); ++i) {
      if (vo_nodes[i]->exitStatus() != 0) {
        result.problem = vo_nodes[i]->name() + " failed: " + result.vo_outputs[i];
      }
    }
  }
  result.ok = result.problem.empty();
  return result;
}

}  // namespace nadir::test
