// Flight-log playback across three hosts (tests/support/hosts.h): `nadir log
// play` on A replays a recorded flight (truth, NAV_*, range, sensors, camera
// images), the feature and direct VO nodes run on B, `nadir log record` on C.
// The poses recorded on C give the same metrics, to within 1 %, as the same
// VO nodes run in one process (`nadir run`) on the same flight, with the
// images raw and as JPEG; every receiver says what it lost, and here that is
// nothing. Needs root and the receive buffers nadir doctor asks for;
// skipped with the reason elsewhere.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "logs/eval/run_metrics.h"
#include "tests/support/hosts.h"
#include "tests/support/playback.h"
#include "tests/support/run_command.h"

namespace nadir::test {
namespace {

namespace fs = std::filesystem;

constexpr char kBin[] = NADIR_BIN_DIR;
constexpr double kFlightS = 8.0;

// The flight flown in one process: its folder (log, scenario, VO metrics).
fs::path flyInOneProcess(const fs::path& dir, const std::string& extra_set) {
  const std::string command = (fs::path(kBin) / "nadir").string() + " run default --out " +
                              dir.string() +
                              " --force --set duration_s=" + std::to_string(kFlightS) +
                              " --set nav.enabled=false" + extra_set;
  const auto [status, output] = runCommand(command);
  EXPECT_EQ(status, 0) << output;
  return dir;
}

// A plays the flight, B runs both VO nodes (the feature VO's bundle
// adjustment on its tracking thread, as in the one-process run), C records.
PlaybackResult playAcross(const TestHosts& hosts, const fs::path& flight,
                          const std::string& encoding, const fs::path& out) {
  PlaybackSetup setup;
  setup.bin_dir = kBin;
  setup.flight = flight;
  setup.url = "udpm://239.255.76.67:7671?ttl=1";
  setup.image_encoding = encoding;
  setup.vo_programs = {"nadir-vo-feature", "nadir-vo-direct"};
  setup.vo_sets = {"vo_feature.vo.background_ba=false"};
  setup.out = out;
  PlaybackResult result = playAcrossHosts(hosts, setup);
  EXPECT_TRUE(result.ok) << result.problem;
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

class PlaybackAcrossHosts : public ::testing::Test {
 protected:
  void SetUp() override {
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
  const PlaybackResult played = playAcross(*hosts_, flight, "raw", dir_ / "raw_played");
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
  const PlaybackResult played = playAcross(*hosts_, flight, "jpeg:90", dir_ / "jpeg_played");
  EXPECT_NE(played.recorder_output.find("nothing lost on"), std::string::npos)
      << played.recorder_output;
  EXPECT_EQ(eventsOn(played.recording, "CAMERA_DOWN"),
            eventsOn(flight / "run.lcmlog", "CAMERA_DOWN"));
  const std::int64_t jpeg_bytes = reportedNumber(played.player_output, "CAMERA_DOWN");
  const std::int64_t raw_frame_bytes = 640 * 480;
  EXPECT_GT(jpeg_bytes, 0) << played.player_output;
  EXPECT_LT(jpeg_bytes, eventsOn(flight / "run.lcmlog", "CAMERA_DOWN") * raw_frame_bytes / 3)
      << played.player_output;
  expectSameMetrics(played.recording, jpeg_flight);
}

}  // namespace
}  // namespace nadir::test
