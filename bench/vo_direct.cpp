// nadir-bench-vo-direct: the direct VO over the images of a recorded run, on
// one core, as fast as it goes. Reads RUN_DIR/run.lcmlog (recorded by `nadir
// run` with images) and RUN_DIR/scenario.yaml (the direct VO's parameters,
// changed with --set), feeds every message through the same VoDirectNode as
// nadir run and the live node, and prints frames/s with the time of each
// stage, the points aligned per frame, the peak memory and the accuracy
// against the recorded truth. The estimates and the truth go to OUT/run.lcmlog
// with metrics.json, as `nadir run` writes them; --debug-png writes the debug
// image (the thesis's figure 20) at --debug-at-s.
//
//   nadir run thesis-oscillating --set vehicle.altitude_agl_m=300
//       --set vo_feature.enabled=false --out out/rec300   (one line)
//   nadir-bench-vo-direct out/rec300 [--out DIR] [--set vo_direct.vo.window_keyframes=5]

#include <sys/resource.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>

#include "bench/vo_replay.h"
#include "core/command_line.h"
#include "logs/eval/run_metrics.h"
#include "nodes/scenario.h"
#include "nodes/vo_direct/vo_direct_node.h"

int main(int argc, char** argv) {
  CLI::App app{"The direct VO over a recorded run's images: frames/s and accuracy"};
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
  app.add_option("--threads", threads, "OpenCV threads (1: one core)")->check(CLI::Range(1, 64));
  app.add_option("--debug-png", debug_png,
                 "write the debug image (points by inverse depth) nearest after --debug-at-s here");
  app.add_option("--debug-at-s", debug_at_s, "seconds from the first image, for --debug-png");
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;
  cv::setNumThreads(threads);

  try {
    const nadir::bench::RunFolder folder = nadir::bench::openRunFolder(run_dir, out_dir);
    nadir::nodes::ScenarioParams scenario =
        nadir::nodes::loadScenario(folder.scenario.string(), overrides);
    nadir::vo::VoDirectNodeParams params =
        scenario.node<nadir::vo::VoDirectNodeParams>(nadir::vo::kDirectSourceName);
    params.wall_clock_timing = true;
    nadir::bench::VoReplay replay(folder, params.truth_channel, params.pose_channel,
                                  params.image_channel, params.debug_channel, debug_png,
                                  debug_at_s);
    std::int64_t estimates = 0, tracking = 0, points = 0;
    nadir::core::Subscription counter = nadir::msg::subscribe<nadir::msg::VoEstimate>(
        replay.bus(), params.pose_channel, [&](const nadir::msg::VoEstimate& e) {
          ++estimates;
          if (e.status == nadir::msg::VoStatus::TRACKING) ++tracking;
          points += e.num_features;
        });
    nadir::vo::VoDirectNode node(replay.bus(), params);
    const double wall_s = replay.replay(
        [&] { return max_frames > 0 && static_cast<std::int64_t>(node.frames()) >= max_frames; });
    using nadir::bench::msPerFrame;

    const nadir::vo::DirectVoTiming& t = node.vo().timing();
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf("frames            %lld (%lld key-frames), %llu images dropped\n",
                static_cast<long long>(t.frames), static_cast<long long>(t.keyframes),
                static_cast<unsigned long long>(node.droppedImages()));
    std::printf("process           %.2f ms/frame = %.1f frames/s (%d OpenCV thread%s)\n",
                msPerFrame(node.processingSeconds(), t.frames),
                t.frames / std::max(node.processingSeconds(), 1e-9), threads,
                threads == 1 ? "" : "s");
    std::printf("  pyramid         %.2f ms/frame\n", msPerFrame(t.pyramid_s, t.frames));
    std::printf("  track           %.2f ms/frame (pyramid levels %d to %d, %.1f steps a frame)\n",
                msPerFrame(t.track_s, t.frames), params.vo.pyramid_levels - 1,
                params.vo.tracker.finest_level,
                t.frames ? static_cast<double>(t.track_iterations) / t.frames : 0.0);
    std::printf("  key-frames      %.2f ms/frame (selection, new points, reference)\n",
                msPerFrame(t.keyframe_s, t.frames));
    std::printf("  window          %.2f ms/frame (%.1f ms per key-frame)\n",
                msPerFrame(t.window_s, t.frames), msPerFrame(t.window_s, t.keyframes));
    std::printf("points aligned    %.0f per frame; tracked %lld of %lld estimates\n",
                estimates ? static_cast<double>(points) / estimates : 0.0,
                static_cast<long long>(tracking), static_cast<long long>(estimates));
    std::printf("window at the end %d key-frames, %d points\n", node.vo().numKeyframes(),
                node.vo().numPoints());
    std::printf("peak memory       %.0f MB (the whole process, the log reader included)\n",
                usage.ru_maxrss / 1024.0);
    std::printf("wall (with log)   %.1f s\n", wall_s);
    if (!debug_png.empty())
      std::printf("debug image       %s\n",
                  replay.debugWritten() ? debug_png.c_str() : "none written");
    if (!node.firstDropReason().empty())
      std::printf("first drop        %s\n", node.firstDropReason().c_str());

    nadir::eval::EvalOptions options;
    const nadir::eval::RunEvaluation evaluation =
        nadir::eval::evaluateRunLog(replay.estimatesLog(), folder.out.string(), options);
    std::cout << nadir::eval::formatResultsTable(evaluation.metrics);
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "nadir-bench-vo-direct: " << error.what() << '\n';
    return 1;
  }
}
