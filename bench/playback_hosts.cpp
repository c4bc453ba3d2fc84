// nadir-bench-playback: a recorded flight played across three hosts, as the
// playback test does (tests/support/playback.h): `nadir log play` on host A,
// the VO node programs on host B, `nadir log record` on host C, over real UDP
// multicast between network namespaces joined by a bridge. For each image
// encoding it prints the frames the flight had, those each receiver got and
// the ones it counted lost, the bytes on the wire, how long the playback and
// the VO took against the flight, and each VO source's accuracy from the
// recording on C beside the one-process run's (RUN_DIR/metrics.json).
//
//   nadir run thesis-oscillating --out out/thesis        (with images)
//   sudo nadir-bench-playback out/thesis [--encoding raw --encoding jpeg:90]
//
// Needs root (namespaces) and the receive buffers nadir doctor asks for.

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <string>
#include <vector>

#include "core/command_line.h"
#include "core/lcm_log.h"
#include "logs/eval/run_metrics.h"
#include "run/process.h"
#include "tests/support/hosts.h"
#include "tests/support/playback.h"

namespace {

namespace fs = std::filesystem;

struct Received {
  long long messages = -1;
  long long lost = -1;
};

// "CHANNEL N at R Hz, L lost" in a VO node's last line.
Received receivedByNode(const std::string& output, const std::string& channel) {
  std::smatch m;
  const std::regex line(channel + R"( (\d+) at [\d.]+ Hz, (\d+) lost)");
  if (!std::regex_search(output, m, line)) return {};
  return {std::stoll(m[1]), std::stoll(m[2])};
}

// "  CHANNEL: N messages, B bytes, R Hz, L lost in G gaps" in the recorder's report.
Received receivedByRecorder(const std::string& output, const std::string& channel) {
  std::smatch m;
  const std::regex line("  " + channel + R"(: (\d+) messages, \d+ bytes, [\d.]+ Hz, (\d+) lost)");
  if (!std::regex_search(output, m, line)) return {};
  return {std::stoll(m[1]), std::stoll(m[2])};
}

// Wall seconds from the last image to the last message of channel, in the recording.
double lagAfterLastImage(const fs::path& recording, const std::string& image_channel,
                         const std::string& channel) {
  nadir::core::LcmLogReader reader(recording.string());
  std::int64_t last_image = 0, last = 0;
  while (const auto event = reader.next()) {
    if (event->channel == image_channel) last_image = event->timestamp_utime;
    if (event->channel == channel) last = event->timestamp_utime;
  }
  return 1e-6 * static_cast<double>(last - last_image);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "A recorded flight played across three hosts: frames delivered and lost, bytes "
      "on the wire, VO accuracy"};
  std::string run_dir;
  std::vector<std::string> encodings = {"raw", "jpeg:90"};
  std::vector<std::string> programs = {"nadir-vo-feature"};
  std::vector<std::string> sets = {"vo_feature.vo.background_ba=false"};
  double speed = 1.0;
  std::string out_dir;
  app.add_option("run_dir", run_dir, "a nadir run folder recorded with images")->required();
  app.add_option("--encoding", encodings, "image encodings on the wire (raw, jpeg:Q)")
      ->capture_default_str();
  app.add_option("--vo", programs, "VO node programs to run on host B")->capture_default_str();
  app.add_option("--set", sets, "--set for the VO nodes (default: the BA on the tracking thread)")
      ->capture_default_str();
  app.add_option("--speed", speed, "play speed, x real time")->capture_default_str();
  app.add_option("--out", out_dir, "where the recordings go (default RUN_DIR/playback)");
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (out_dir.empty()) out_dir = (fs::path(run_dir) / "playback").string();

  nadir::test::TestHosts hosts(3);
  if (!hosts.available()) {
    std::cerr << "nadir-bench-playback: " << hosts.whyNot() << "\n";
    return 1;
  }
  const fs::path flight(run_dir);
  const std::int64_t frames = nadir::test::eventsOn(flight / "run.lcmlog", "CAMERA_DOWN");
  const nadir::eval::RunMetrics one_process =
      nadir::eval::readMetricsJson((flight / "metrics.json").string());
  std::printf("flight %s: %lld frames on CAMERA_DOWN, %.1f s; played x%.2f\n\n", run_dir.c_str(),
              static_cast<long long>(frames), one_process.truth_duration_s, speed);

  for (const std::string& encoding : encodings) {
    nadir::test::PlaybackSetup setup;
    setup.bin_dir = nadir::run::selfDirectory();
    setup.flight = flight;
    setup.url = "udpm://239.255.76.67:7672?ttl=1";
    setup.image_encoding = encoding;
    setup.vo_programs = programs;
    setup.vo_sets = sets;
    setup.speed = speed;
    std::string folder = encoding;
    for (char& c : folder) c = c == ':' ? '_' : c;
    setup.out = fs::path(out_dir) / folder;
    const nadir::test::PlaybackResult played = nadir::test::playAcrossHosts(hosts, setup);
    if (!played.ok) {
      std::cerr << "nadir-bench-playback: " << encoding << ": " << played.problem << "\n";
      return 1;
    }
    const long long image_bytes = nadir::test::reportedNumber(played.player_output, "CAMERA_DOWN");
    const Received on_c = receivedByRecorder(played.recorder_output, "CAMERA_DOWN");
    std::printf("%s: played in %.1f s; %lld image bytes on the wire (%.1f MB/s, %.0f kB a frame)\n",
                encoding.c_str(), played.play_wall_s, image_bytes,
                1e-6 * static_cast<double>(image_bytes) / played.play_wall_s,
                1e-3 * static_cast<double>(image_bytes) / static_cast<double>(frames));
    std::printf("  host C (recorder): %lld of %lld frames, %lld counted lost\n", on_c.messages,
                static_cast<long long>(frames), on_c.lost);
    for (std::size_t i = 0; i < programs.size(); ++i) {
      const Received on_b = receivedByNode(played.vo_outputs[i], "CAMERA_DOWN");
      std::printf("  host B (%s): %lld of %lld frames, %lld counted lost\n", programs[i].c_str(),
                  on_b.messages, static_cast<long long>(frames), on_b.lost);
    }
    nadir::eval::RunEvaluation evaluated;
    try {
      evaluated = nadir::eval::evaluateRunLog(played.recording.string(), setup.out.string(), {},
                                              "POSE_TRUTH");
    } catch (const std::exception& error) {
      std::printf("  the recording does not evaluate: %s\n", error.what());
      continue;
    }
    for (const auto& [source, metrics] : evaluated.metrics.sources) {
      const auto reference = one_process.sources.find(source);
      std::printf(
          "  %-11s position RMSE %.3f m, rotation RMSE %.3f deg, tracked %.1f %%, %zu "
          "estimates",
          source.c_str(), metrics.position_rmse_m, metrics.rotation_rmse_deg, metrics.tracked_pct,
          metrics.estimates);
      if (reference != one_process.sources.end()) {
        std::printf("; one process: %.3f m, %.3f deg, %.1f %%, %zu",
                    reference->second.position_rmse_m, reference->second.rotation_rmse_deg,
                    reference->second.tracked_pct, reference->second.estimates);
      }
      std::printf("; last pose %.1f s after the last frame\n",
                  lagAfterLastImage(
                      played.recording, "CAMERA_DOWN", "POSE_" + [&] {
                        std::string upper = source;
                        for (char& c : upper) c = static_cast<char>(std::toupper(c));
                        return upper;
                      }()));
    }
  }
  return 0;
}
