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
//
// --drift-every-s S adds the map's tilt, heading and height error against the
// truth every S seconds, and it prints how many key-frames saw the points the
// map dropped (docs/vo_feature.md, "Where the tilt comes from").

#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core/utility.hpp>

#include "bench/vo_replay.h"
#include "core/command_line.h"
#include "core/trajectory.h"
#include "logs/eval/run_metrics.h"
#include "nodes/scenario.h"
#include "nodes/vo_feature/vo_feature_node.h"

namespace {

// Of the points the map dropped, how many key-frames saw them.
void printMapStats(const nadir::vo::FeatureVoMapStats& stats) {
  std::printf(
      "map upkeep        %lld observations fused, %lld points merged, %lld new points culled\n",
      static_cast<long long>(stats.observations_fused), static_cast<long long>(stats.points_merged),
      static_cast<long long>(stats.points_culled));
  if (stats.points_dropped == 0) return;
  std::printf("points dropped    %lld; key-frames that saw them:",
              static_cast<long long>(stats.points_dropped));
  std::int64_t cumulative = 0;
  std::int64_t median_bin = -1;
  for (std::size_t k = 0; k < stats.points_by_keyframes.size(); ++k) {
    cumulative += stats.points_by_keyframes[k];
    if (median_bin < 0 && 2 * cumulative >= stats.points_dropped)
      median_bin = static_cast<std::int64_t>(k);
  }
  std::printf(" median %lld\n", static_cast<long long>(median_bin));
  for (std::size_t k = 0; k < stats.points_by_keyframes.size(); ++k)
    if (stats.points_by_keyframes[k] > 0)
      std::printf("  %2zu%s key-frames  %5.1f %%\n", k,
                  k + 1 == stats.points_by_keyframes.size() ? "+" : " ",
                  100.0 * static_cast<double>(stats.points_by_keyframes[k]) /
                      static_cast<double>(stats.points_dropped));
}

// The estimate's error against the truth at every step_s of its tracked poses:
// the world-frame rotation error R_est R_true^T as a rotation vector (about
// north and east: the map's tilt; about down: its heading), and the height
// and horizontal position errors.
void printDrift(const nadir::core::Trajectory& truth, const nadir::core::Trajectory& estimate,
                double step_s) {
  if (estimate.empty()) return;
  std::printf("\n    t s  tilt N deg  tilt E deg  heading deg  height m  horizontal m\n");
  const double t0 = estimate.front().t_s;
  double next = t0;
  for (const nadir::core::StampedPose& e : estimate) {
    if (e.t_s < next && &e != &estimate.back()) continue;
    next = e.t_s + step_s;
    const std::optional<nadir::core::StampedPose> t = nadir::core::interpolate(truth, e.t_s, 0.1);
    if (!t) continue;
    const Eigen::AngleAxisd error(e.q_world_body * t->q_world_body.conjugate());
    const Eigen::Vector3d rv_deg = error.angle() * error.axis() * 180.0 / std::numbers::pi;
    const Eigen::Vector3d dp = e.p_ned_m - t->p_ned_m;
    std::printf("  %5.1f  %10.3f  %10.3f  %11.3f  %8.2f  %12.2f\n", e.t_s - t0, rv_deg.x(),
                rv_deg.y(), rv_deg.z(), -dp.z(), dp.head<2>().norm());
  }
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
  double drift_every_s = 0.0;
  app.add_option("run_dir", run_dir, "a nadir run folder recorded with images")->required();
  app.add_option("--out", out_dir, "where the estimates and metrics go (default RUN_DIR/bench)");
  app.add_option("--set", overrides, "override a scenario parameter: key=value (repeatable)");
  app.add_option("--frames", max_frames, "stop after this many frames (0: all)");
  app.add_option("--threads", threads, "OpenCV threads (ORB pyramid levels; 1: one core)")
      ->check(CLI::Range(1, 64));
  app.add_option("--debug-png", debug_png,
                 "write the debug image (tracked features) nearest after --debug-at-s here");
  app.add_option("--debug-at-s", debug_at_s, "seconds from the first image, for --debug-png");
  app.add_option("--drift-every-s", drift_every_s,
                 "print the map's tilt, heading and height error against the truth every this "
                 "many seconds (0: not)");
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;
  cv::setNumThreads(threads);

  try {
    const nadir::bench::RunFolder folder = nadir::bench::openRunFolder(run_dir, out_dir);
    nadir::nodes::ScenarioParams scenario =
        nadir::nodes::loadScenario(folder.scenario.string(), overrides);
    nadir::vo::VoFeatureNodeParams params =
        scenario.node<nadir::vo::VoFeatureNodeParams>(nadir::vo::kFeatureSourceName);
    params.wall_clock_timing = true;
    nadir::bench::VoReplay replay(folder, params.truth_channel, params.pose_channel,
                                  params.image_channel, params.debug_channel, debug_png,
                                  debug_at_s);
    nadir::vo::VoFeatureNode node(replay.bus(), params);
    const double wall_s = replay.replay(
        [&] { return max_frames > 0 && static_cast<std::int64_t>(node.frames()) >= max_frames; });
    using nadir::bench::msPerFrame;

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
    std::printf("map at the end    %d points alive, %zu stored, %d key-frames in the map\n",
                node.vo().numMapPoints(), node.vo().storedMapPoints(), node.vo().numKeyframes());
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
    printMapStats(node.vo().mapStats());
    const auto tracked = evaluation.tracked.find(nadir::vo::kFeatureSourceName);
    if (drift_every_s > 0.0 && tracked != evaluation.tracked.end())
      printDrift(evaluation.recorded.truth, tracked->second, drift_every_s);
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "nadir-bench-vo-feature: " << error.what() << '\n';
    return 1;
  }
}
