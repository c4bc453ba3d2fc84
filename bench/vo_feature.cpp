// nadir-bench-vo-feature: the feature VO over the images of a recorded run, on
// one core, as fast as it goes. Reads RUN_DIR/run.lcmlog (recorded by `nadir
// run` with images) and RUN_DIR/scenario.yaml (the feature VO's parameters,
// changed with --set), feeds every message through the same VoFeatureNode as
// nadir run and the live node, and prints frames/s with the time of each stage
// and the accuracy against the recorded truth. The local BA runs as the run's
// scenario.yaml says: on the tracking thread, as nadir run ran it (the metrics
// then equal the run's to the last digit); --set vo_feature.vo.background_ba=true
// runs it in its own thread, as live. The estimates and the truth go
// to OUT/run.lcmlog with metrics.json, as `nadir run` writes them.
//
//   nadir run thesis-oscillating --set vehicle.altitude_agl_m=300
//       --set vo_feature.enabled=false --out out/rec300   (one line)
//   nadir-bench-vo-feature out/rec300 [--out DIR] [--set vo_feature.attitude_prior=true]

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "lcmtypes/bus_io.h"
#include "logs/eval/run_metrics.h"
#include "nodes/scenario.h"
#include "nodes/vo_feature/vo_feature_node.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double msPerFrame(double seconds, std::int64_t frames) {
  return frames > 0 ? 1e3 * seconds / static_cast<double>(frames) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The feature VO over a recorded run's images: frames/s and accuracy"};
  std::string run_dir;
  std::string out_dir;
  std::vector<std::string> overrides;
  std::int64_t max_frames = 0;
  int threads = 1;
  std::string debug_png;
  double debug_at_s = 60.0;
  app.add_option("run_dir", run_dir, "a nadir run folder recorded with images")->required();
  app.add_option("--out", out_dir, "where the estimates and metrics go (default RUN_DIR/bench)");
  app.add_option("--set", overrides, "override a scenario parameter: key=value (repeatable)");
  app.add_option("--frames", max_frames, "stop after this many frames (0: all)");
  app.add_option("--threads", threads, "OpenCV threads (ORB pyramid levels; 1: one core)")
      ->check(CLI::Range(1, 64));
  app.add_option("--debug-png", debug_png,
                 "write the debug image (tracked features) nearest after --debug-at-s here");
  app.add_option("--debug-at-s", debug_at_s, "seconds from the first image, for --debug-png");
  CLI11_PARSE(app, argc, argv);
  cv::setNumThreads(threads);

  try {
    const fs::path run(run_dir);
    const fs::path log_path = run / "run.lcmlog";
    const fs::path scenario_path = run / "scenario.yaml";
    if (!fs::exists(log_path) || !fs::exists(scenario_path)) {
      std::cerr << "nadir-bench-vo-feature: " << run_dir
                << " is not a nadir run folder (run.lcmlog and scenario.yaml)\n";
      return 2;
    }
    if (out_dir.empty()) out_dir = (run / "bench").string();
    fs::create_directories(out_dir);

    nadir::nodes::ScenarioParams scenario =
        nadir::nodes::loadScenario(scenario_path.string(), overrides);
    nadir::vo::VoFeatureNodeParams params =
        scenario.node<nadir::vo::VoFeatureNodeParams>(nadir::vo::kFeatureSourceName);
    params.wall_clock_timing = true;
    nadir::core::BusParams bus_params;
    bus_params.url = "memq://";
    auto bus = nadir::core::openBus(bus_params);

    const std::string out_log = (fs::path(out_dir) / "run.lcmlog").string();
    nadir::core::LcmLogWriter writer(out_log);
    nadir::core::Subscription recorder =
        bus->subscribe(params.truth_channel + "|" + params.pose_channel,
                       [&writer](const nadir::core::RawMessage& raw) {
                         writer.write(nadir::core::peekUtime(raw).value_or(0),
                                      std::string(raw.channel), raw.data, raw.size);
                       });
    nadir::vo::VoFeatureNode node(*bus, params);
    std::optional<std::int64_t> first_image_utime;
    bool debug_written = false;
    nadir::core::Subscription debug_subscription = nadir::msg::subscribe<nadir::msg::Image>(
        *bus, params.debug_channel, [&](const nadir::msg::Image& image) {
          if (debug_png.empty() || debug_written || !first_image_utime) return;
          if (image.utime < *first_image_utime + static_cast<std::int64_t>(debug_at_s * 1e6))
            return;
          cv::Mat bgr;
          cv::cvtColor(image.pixels, bgr, cv::COLOR_RGB2BGR);
          cv::imwrite(debug_png, bgr);
          debug_written = true;
        });

    nadir::core::LcmLogReader reader(log_path.string());
    bool saw_images = false;
    const auto wall_start = Clock::now();
    while (auto event = reader.next()) {
      if (event->channel == params.image_channel) {
        saw_images = true;
        if (!first_image_utime) first_image_utime = event->timestamp_utime;
      }
      bus->publish(event->channel, event->data.data(), event->data.size(), event->timestamp_utime);
      bus->handleAvailable();
      if (max_frames > 0 && static_cast<std::int64_t>(node.frames()) >= max_frames) break;
    }
    const double wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
    writer.flush();
    if (!saw_images) {
      std::cerr << "nadir-bench-vo-feature: " << log_path.string() << " holds no "
                << params.image_channel << " images (recorded with --no-images?)\n";
      return 2;
    }

    const nadir::vo::FeatureVoTiming& t = node.timing();
    std::printf("frames            %lld (%lld key-frames), %llu images dropped\n",
                static_cast<long long>(t.frames), static_cast<long long>(t.keyframes),
                static_cast<unsigned long long>(node.droppedImages()));
    std::printf("process           %.2f ms/frame = %.1f frames/s (%d OpenCV thread%s)\n",
                msPerFrame(node.processingSeconds(), t.frames),
                t.frames / std::max(node.processingSeconds(), 1e-9), threads,
                threads == 1 ? "" : "s");
    std::printf("  extract         %.2f ms/frame\n", msPerFrame(t.extract_s, t.frames));
    std::printf("  track           %.2f ms/frame\n", msPerFrame(t.track_s, t.frames));
    std::printf("  mapping         %.2f ms/frame (%.1f ms per key-frame; local BA %s)\n",
                msPerFrame(t.mapping_s, t.frames), msPerFrame(t.mapping_s, t.keyframes),
                params.vo.background_ba ? "in a background thread, not counted"
                                        : "at its key-frame, counted");
    std::printf("map at the end    %d points alive, %zu stored, %d key-frames in the window\n",
                node.vo().numMapPoints(), node.vo().storedMapPoints(), node.vo().numKeyframes());
    std::printf("wall (with log)   %.1f s\n", wall_s);
    if (!debug_png.empty())
      std::printf("debug image       %s\n", debug_written ? debug_png.c_str() : "none written");
    if (!node.firstDropReason().empty())
      std::printf("first drop        %s\n", node.firstDropReason().c_str());

    nadir::eval::EvalOptions options;
    const nadir::eval::RunEvaluation evaluation =
        nadir::eval::evaluateRunLog(out_log, out_dir, options);
    std::cout << nadir::eval::formatResultsTable(evaluation.metrics);
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "nadir-bench-vo-feature: " << error.what() << '\n';
    return 1;
  }
}
