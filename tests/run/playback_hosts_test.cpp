// Flight-log playback across three hosts (tests/support/hosts.h): `nadir log
// play` on A replays a recorded flight (truth, NAV_*, range, sensors, camera
// images), the feature and direct VO nodes run on B, `nadir log record` on C.
// The poses recorded on C give the same metrics, to within 1 %, as the same
// VO nodes run in one process (`nadir run`) on the same flight, with the
// images raw and as JPEG; every receiver says what it lost, and here that is
// nothing. Needs root and the receive buffers nadir doctor asks for;
// skipped with the reason elsewhere.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/lcm_log.h"
#include "logs/eval/run_metrics.h"
#include "run/process.h"
#include "tests/support/hosts.h"
#include "tests/support/run_command.h"

namespace nadir::test {
namespace {

namespace fs = std::filesystem;

constexpr char kBin[] = NADIR_BIN_DIR;
constexpr char kUrl[] = "udpm://239.255.76.67:7671?ttl=1";
// What the VO nodes read and the recorder keeps: the flight, not its estimates.
constexpr char kPlayedChannels[] =
    "POSE_TRUTH|NAV_.*|RANGE|CAMERA_DOWN|CAMERA_DOWN_INFO|IMU|BARO|GPS|MAG";
constexpr double kFlightS = 8.0;

std::string bin(const std::string& program) { return (fs::path(kBin) / program).string(); }

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Waits until the program's log holds text (it has set up), or it died.
::testing::AssertionResult waitForLine(run::ChildProcess& process, const std::string& text) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    if (readText(process.logPath()).find(text) != std::string::npos) {
      return ::testing::AssertionSuccess();
    }
    if (!process.running()) {
      return ::testing::AssertionFailure() << process.name() << " ended (" << process.describeExit()
                                           << "): " << readText(process.logPath());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return ::testing::AssertionFailure() << process.name() << " never printed '" << text << "'";
}

std::int64_t eventsOn(const fs::path& log, const std::string& channel) {
  core::LcmLogReader reader(log.string());
  std::int64_t count = 0;
  while (const auto event = reader.next()) count += event->channel == channel ? 1 : 0;
  return count;
}

// The flight flown in one process: its log, and the VO metrics it gave.
fs::path flyInOneProcess(const fs::path& dir, const std::string& extra_set) {
  const std::string command = bin("nadir") + " run default --out " + dir.string() +
                              " --force --set duration_s=" + std::to_string(kFlightS) +
                              " --set nav.enabled=false" + extra_set;
  const auto [status, output] = runCommand(command);
  EXPECT_EQ(status, 0) << output;
  return dir;
}

struct Playback {
  std::string player_output;
  std::string recorder_output;
  std::vector<std::string> vo_outputs;
  fs::path recording;
};

// A plays the flight, B runs the VO nodes, C records.
Playback playAcross(const TestHosts& hosts, const fs::path& flight, const std::string& encoding,
                    const fs::path& out) {
  fs::create_directories(out);
  Playback result;
  result.recording = out / "recorded.lcmlog";
  const auto onHost = [&](int host, std::vector<std::string> argv) {
    std::vector<std::string> command = {"ip", "netns", "exec", hosts.name(host)};
    command.insert(command.end(), argv.begin(), argv.end());
    return command;
  };
  run::ChildProcess recorder(
      "recorder",
      onHost(2, {bin("nadir"), "log", "record", result.recording.string(), "--url", kUrl,
                 "--scenario", "default", "--idle-stop", "5", "--force"}),
      (out / "recorder.out").string());
  std::vector<std::unique_ptr<run::ChildProcess>> vo_nodes;
  for (const char* program : {"nadir-vo-feature", "nadir-vo-direct"}) {
    vo_nodes.push_back(std::make_unique<run::ChildProcess>(
        program,
        onHost(1, {bin(program), "default", "--set", std::string("bus.url=") + kUrl, "--set",
                   "vo_feature.vo.background_ba=false"}),
        (out / (std::string(program) + ".out")).string()));
  }
  recorder.start();
  EXPECT_TRUE(waitForLine(recorder, "Ctrl-C stops"));
  for (auto& node : vo_nodes) {
    node->start();
    EXPECT_TRUE(waitForLine(*node, "bus: "));
  }
  const auto [status, output] = runCommand(
      hosts.prefix(0) + bin("nadir") + " log play " + (flight / "run.lcmlog").string() +
      " --url '" + kUrl + "' --channels '" + kPlayedChannels + "' --image-encoding " + encoding);
  EXPECT_EQ(status, 0) << output;
  result.player_output = output;
  // The recorder stops once the VO nodes have sent their last pose.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(300);
  while (recorder.running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_FALSE(recorder.running()) << "the recorder did not stop";
  recorder.stop(5.0);
  EXPECT_EQ(recorder.exitStatus(), 0) << readText(recorder.logPath());
  result.recorder_output = readText(recorder.logPath());
  for (auto& node : vo_nodes) {
    node->stop(10.0);
    EXPECT_EQ(node->exitStatus(), 0) << readText(node->logPath());
    result.vo_outputs.push_back(readText(node->logPath()));
  }
  return result;
}

// Each VO source's metrics from the recording on C against the one-process run's.
void expectSameMetrics(const fs::path& recording, const fs::path& reference_run) {
  const eval::RunEvaluation played =
      eval::evaluateRunLog(recording.string(), recording.parent_path().string(), {}, "POSE_TRUTH");
  const eval::RunMetrics reference =
      eval::readMetricsJson((reference_run / "metrics.json").string());
  for (const char* source : {"vo_feature", "vo_direct"}) {
    SCOPED_TRACE(source);
    ASSERT_EQ(played.metrics.sources.count(source), 1u);
    const eval::SourceMetrics& got = played.metrics.sources.at(source);
    const eval::SourceMetrics& want = reference.sources.at(source);
    EXPECT_NEAR(got.position_rmse_m, want.position_rmse_m, 0.01 * want.position_rmse_m);
    EXPECT_NEAR(got.rotation_rmse_deg, want.rotation_rmse_deg, 0.01 * want.rotation_rmse_deg);
    EXPECT_NEAR(got.tracked_pct, want.tracked_pct, 0.01 * want.tracked_pct);
    EXPECT_EQ(got.estimates, want.estimates);
  }
}

// What the line "  CHANNEL: N messages, B bytes..." of a program's output says.
std::int64_t bytesOn(const std::string& output, const std::string& channel) {
  const std::string key = "  " + channel + ": ";
  const std::size_t at = output.find(key);
  if (at == std::string::npos) return -1;
  std::istringstream line(output.substr(at + key.size()));
  std::int64_t bytes = -1;
  line >> bytes;
  return bytes;
}

class PlaybackAcrossHosts : public ::testing::Test {
 protected:
  void SetUp() override {
    long rmem_max = 0;
    std::ifstream("/proc/sys/net/core/rmem_max") >> rmem_max;
    long rmem_default = 0;
    std::ifstream("/proc/sys/net/core/rmem_default") >> rmem_default;
    if (rmem_default < 64L << 20) {
      GTEST_SKIP() << "net.core.rmem_default is " << rmem_default
                   << " bytes: camera frames would be dropped on the way; `nadir doctor` says "
                      "how to raise it";
    }
    hosts_ = std::make_unique<TestHosts>(3);
    if (!hosts_->available()) GTEST_SKIP() << hosts_->whyNot();
    dir_ = fs::path(::testing::TempDir()) / ("nadir_playback_" + std::to_string(getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  std::unique_ptr<TestHosts> hosts_;
  fs::path dir_;
};

// Raw frames: the recording holds every frame the flight had, each receiver
// lost nothing, and the poses give the one-process run's metrics.
TEST_F(PlaybackAcrossHosts, RawFramesGiveTheOneProcessMetrics) {
  const fs::path flight = flyInOneProcess(dir_ / "raw_flight", "");
  const Playback played = playAcross(*hosts_, flight, "raw", dir_ / "raw_played");
  EXPECT_NE(played.recorder_output.find("nothing lost on"), std::string::npos)
      << played.recorder_output;
  for (const std::string& vo : played.vo_outputs) {
    EXPECT_NE(
        vo.find("CAMERA_DOWN " + std::to_string(eventsOn(flight / "run.lcmlog", "CAMERA_DOWN")) +
                " at 20.0 Hz, 0 lost"),
        std::string::npos)
        << vo;
  }
  EXPECT_EQ(eventsOn(played.recording, "CAMERA_DOWN"),
            eventsOn(flight / "run.lcmlog", "CAMERA_DOWN"));
  expectSameMetrics(played.recording, flight);
}

// JPEG on the wire (quality 90): the player re-encodes what the flight
// recorded raw, as the camera does when asked for JPEG, so the VO nodes on B
// see what they saw in a one-process run with camera.jpeg_quality=90; the
// frames take a fraction of the bytes.
TEST_F(PlaybackAcrossHosts, JpegFramesGiveTheOneProcessJpegMetrics) {
  const fs::path flight = flyInOneProcess(dir_ / "raw_flight", "");
  const fs::path jpeg_flight =
      flyInOneProcess(dir_ / "jpeg_flight", " --set camera.jpeg_quality=90");
  const Playback played = playAcross(*hosts_, flight, "jpeg:90", dir_ / "jpeg_played");
  EXPECT_NE(played.recorder_output.find("nothing lost on"), std::string::npos)
      << played.recorder_output;
  EXPECT_EQ(eventsOn(played.recording, "CAMERA_DOWN"),
            eventsOn(flight / "run.lcmlog", "CAMERA_DOWN"));
  const std::int64_t jpeg_bytes = bytesOn(played.player_output, "CAMERA_DOWN");
  const std::int64_t raw_frame_bytes = 640 * 480;
  EXPECT_GT(jpeg_bytes, 0) << played.player_output;
  EXPECT_LT(jpeg_bytes, eventsOn(flight / "run.lcmlog", "CAMERA_DOWN") * raw_frame_bytes / 3)
      << played.player_output;
  expectSameMetrics(played.recording, jpeg_flight);
}

}  // namespace
}  // namespace nadir::test
