// nadir-sim as a program: a batch run written to a log file, its errors, and a
// live run over UDP multicast captured by lcm-logger and replayed by lcm-logplayer.

#include <gtest/gtest.h>

#include <algorithm>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "nadir/pose_t.hpp"
#include "tests/support/run_command.h"

extern char** environ;

namespace {

std::pair<int, std::string> run(const std::string& command) {
  return nadir::test::runCommand(command);
}

// Event counts per channel and the POSE_TRUTH messages of an LCM log.
struct LogContents {
  std::map<std::string, int> counts;
  std::vector<nadir::pose_t> poses;
};

LogContents readLog(const std::string& path) {
  LogContents contents;
  nadir::core::LcmLogReader reader(path);
  while (auto event = reader.next()) {
    ++contents.counts[event->channel];
    if (event->channel == "POSE_TRUTH") {
      nadir::pose_t pose;
      EXPECT_GT(pose.decode(event->data.data(), 0, static_cast<int>(event->data.size())), 0);
      contents.poses.push_back(pose);
    }
  }
  return contents;
}

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "nadir_sim_node_" + name;
}

// Starts a program with arguments; returns its pid.
pid_t spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  return pid;
}

// Messages on channel in the log at path so far (0 while it holds no whole event).
int recorded(const std::string& path, const std::string& channel) {
  try {
    int count = 0;
    nadir::core::LcmLogReader reader(path);
    while (auto event = reader.next()) count += event->channel == channel ? 1 : 0;
    return count;
  } catch (const nadir::core::LogError&) {
    return 0;
  }
}

// Waits until the log at path holds `sent` messages on channel, or has taken none
// for 5 s (a logger drops what overflows its queue), within 120 s: on what was
// recorded, not on how long a loaded machine takes to record it.
void waitUntilRecorded(const std::string& path, const std::string& channel, int sent) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  int last = -1;
  auto last_change = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < deadline) {
    const int now = recorded(path, channel);
    if (now >= sent) return;
    if (now != last) {
      last = now;
      last_change = std::chrono::steady_clock::now();
    } else if (std::chrono::steady_clock::now() - last_change > std::chrono::seconds(5)) {
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

// Publishes probe messages until the lcm-logger writing path has recorded one (it is
// subscribed), or 60 s have passed. The probes are on their own channel.
bool waitForLogger(const std::string& url, const std::string& path) {
  auto bus = nadir::core::openBus(url);
  const std::uint8_t probe[16] = {};
  for (int i = 0; i < 600; ++i) {
    bus->publish("NADIR_TEST_PROBE", probe, sizeof(probe), 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::error_code error;
    if (std::filesystem::file_size(path, error) > 0 && !error) return true;
  }
  return false;
}

bool onPath(const std::string& program) { return run("command -v " + program).first == 0; }

// A batch run to a log file: the truth at 400 Hz from utime 0, the sensors at their rates.
TEST(SimNode, BatchRunWritesTheStreamsToALog) {
  const std::string log = tempPath("batch.lcmlog");
  std::filesystem::remove(log);
  const auto [status, output] =
      run(std::string(NADIR_SIM_BIN) +
          " scamp-rectangle --set duration_s=2 --set time.mode=batch --set bus.url=file://" + log +
          "?mode=w");
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("nadir-sim: done; 2 s of sim time"), std::string::npos) << output;
  const LogContents contents = readLog(log);
  EXPECT_EQ(contents.counts.at("POSE_TRUTH"), 801);
  EXPECT_EQ(contents.counts.at("IMU"), 801);           // 400 Hz in this scenario
  EXPECT_EQ(contents.counts.at("RANGE"), 401);         // 200 Hz
  EXPECT_EQ(contents.counts.at("GPS"), 11);            // 5 Hz
  EXPECT_EQ(contents.counts.at("BARO"), 101);          // 50 Hz
  EXPECT_EQ(contents.counts.at("NAV_POSITION"), 401);  // 200 Hz
  ASSERT_EQ(contents.poses.size(), 801u);
  for (std::size_t i = 0; i < contents.poses.size(); ++i) {
    ASSERT_EQ(contents.poses[i].utime, static_cast<std::int64_t>(i) * 2500);
  }
  // 5 m above the start's ground, which is the world origin's plane plus its relief.
  EXPECT_LT(contents.poses.front().pos[2], 0.0);
}

// The node's own parameter file instead of a scenario (--config): the simulator's
// keys at the top level, world, time and bus; --set overrides its keys.
TEST(SimNode, ConfigFileInsteadOfAScenario) {
  const std::string log = tempPath("config.lcmlog");
  const std::string config = tempPath("sim.yaml");
  std::filesystem::remove(log);
  std::ofstream(config) << "duration_s: 1\n"
                           "route:\n  waypoints: [[300, 0], [300, 300]]\n"
                           "time:\n  mode: batch\n"
                           "bus:\n  url: \"file://" +
                               log + "?mode=w\"\n";
  const auto [status, output] =
      run(std::string(NADIR_SIM_BIN) + " --config " + config + " --set truth.rate_hz=200");
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("nadir-sim parameters (" + config + ")"), std::string::npos) << output;
  EXPECT_EQ(readLog(log).counts.at("POSE_TRUTH"), 201);  // 1 s at 200 Hz, ends included
  // A key the simulator does not have is refused, naming the file.
  std::ofstream(config, std::ios::app) << "nonsense: 3\n";
  const auto [bad_status, bad_output] = run(std::string(NADIR_SIM_BIN) + " --config " + config);
  EXPECT_EQ(bad_status, 1);
  EXPECT_NE(bad_output.find("nonsense: unknown key"), std::string::npos) << bad_output;
}

// A bad override stops the program before it publishes anything, naming the key.
TEST(SimNode, BadOverrideIsRefused) {
  const auto [status, output] =
      run(std::string(NADIR_SIM_BIN) + " box --set vehicle.airspeed_mps=-5 --set bus.url=memq://");
  EXPECT_EQ(status, 1);
  EXPECT_NE(output.find("nadir-sim: error: --set vehicle.airspeed_mps=-5: vehicle.airspeed_mps: "
                        "-5 is out of range"),
            std::string::npos)
      << output;
}

// Live: lcm-logger records the truth stream from UDP multicast, and lcm-logplayer replays
// the recording to a second lcm-logger, which receives the messages again unchanged.
TEST(SimNode, LcmLoggerRecordsAndLcmLogplayerReplays) {
  if (!onPath("lcm-logger") || !onPath("lcm-logplayer")) GTEST_SKIP() << "no lcm-logger";
  const std::string url = "udpm://239.255.76.67:7841?ttl=0";
  const std::string first = tempPath("live.lcmlog"), second = tempPath("replayed.lcmlog");
  std::filesystem::remove(first);
  std::filesystem::remove(second);

  const pid_t logger = spawn({"lcm-logger", "--lcm-url=" + url, "-f", first});
  ASSERT_GT(logger, 0);
  if (!waitForLogger(url, first)) {
    kill(logger, SIGINT);
    waitpid(logger, nullptr, 0);
    GTEST_SKIP() << "UDP multicast does not reach this process here (see nadir doctor)";
  }
  // At real time: lcm-logger keeps LCM's default queue of 30 messages, about
  // 50 ms of these streams at 1x (13 ms at 4x), which a loaded machine can
  // starve it of.
  const auto [status, output] =
      run(std::string(NADIR_SIM_BIN) +
          " default --set duration_s=4 --set time.speed=1 --set sensors.imu.enabled=false" +
          " --set sensors.ahrs.estimator=ideal" + " --set 'bus.url=" + url + "'");
  waitUntilRecorded(first, "POSE_TRUTH", 4 * 400 + 1);
  kill(logger, SIGINT);
  waitpid(logger, nullptr, 0);
  ASSERT_EQ(status, 0) << output;
  LogContents live = readLog(first);
  // lcm-logger subscribes with LCM's default queue of 30 messages: starved of CPU (a
  // loaded machine), it drops a few. Nearly all must arrive, on the 400 Hz sim-time grid.
  EXPECT_GE(live.counts.at("POSE_TRUTH"), 0.99 * (4 * 400 + 1));
  EXPECT_LE(live.counts.at("POSE_TRUTH"), 4 * 400 + 1);
  EXPECT_GE(live.counts.at("NAV_ATTITUDE"), 0.99 * (4 * 50 + 1));
  for (std::size_t i = 1; i < live.poses.size(); ++i) {
    ASSERT_GT(live.poses[i].utime, live.poses[i - 1].utime);
    ASSERT_EQ(live.poses[i].utime % 2500, 0);
  }

  const pid_t relogger = spawn({"lcm-logger", "--lcm-url=" + url, "-f", second});
  ASSERT_GT(relogger, 0);
  ASSERT_TRUE(waitForLogger(url, second));
  const auto [play_status, play_output] =
      // At the recorded pace: the live run's rate, which the loggers kept up with.
      run("lcm-logplayer --speed=1 --lcm-url='" + url + "' " + first);
  waitUntilRecorded(second, "POSE_TRUTH", readLog(first).counts.at("POSE_TRUTH"));
  kill(relogger, SIGINT);
  waitpid(relogger, nullptr, 0);
  ASSERT_EQ(play_status, 0) << play_output;
  LogContents replayed = readLog(second);
  // The probes that found the loggers listening are not part of the comparison, nor
  // LCM's own LCM_SELF_TEST, which every UDP LCM instance may send when it starts
  // (nadir-sim's is in the recording, lcm-logplayer's own can reach the second logger).
  for (const char* channel : {"NADIR_TEST_PROBE", "LCM_SELF_TEST"}) {
    live.counts.erase(channel);
    replayed.counts.erase(channel);
  }
  // The second logger may drop as the first did: 1 % of a channel, and at
  // least one message of a channel too small for 1 % to be one.
  for (const auto& [channel, count] : live.counts) {
    EXPECT_GE(replayed.counts[channel], count - std::max(1.0, 0.01 * count)) << channel;
    EXPECT_LE(replayed.counts[channel], count) << channel;
  }
  // Every replayed pose is the recorded one, unchanged.
  std::map<std::int64_t, double> live_north;
  for (const nadir::pose_t& pose : live.poses) live_north[pose.utime] = pose.pos[0];
  for (const nadir::pose_t& pose : replayed.poses) {
    ASSERT_EQ(live_north.count(pose.utime), 1u) << pose.utime;
    ASSERT_EQ(live_north[pose.utime], pose.pos[0]);
  }
}

}  // namespace
