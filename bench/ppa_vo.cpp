// nadir-bench-ppa: the SCAMP-5 emulator running the on-sensor programs of
// McConville et al. (2020) on one core: image-alignment visual odometry and target extraction
// on every frame of a moving textured scene (256x256 frames cut, with drift,
// yaw and a slow height change, from a large synthetic texture with a
// concentric target mat in it). Prints frames/s, ns per frame and instructions
// per frame of each program, and what single instructions cost the emulator.
//
//   nadir-bench-ppa [--frames 2000] [--seed 1]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <numbers>
#include <vector>

#include "nodes/ppa/ppa_array.h"
#include "nodes/ppa/target_extraction.h"
#include "nodes/ppa/visual_odometry.h"
// The synthetic scenes (shared with the ppa tests).
#include "bench/ppa_scenes.h"
#include "core/command_line.h"

namespace {

using Clock = std::chrono::steady_clock;
using nadir::ppa::Areg;
using nadir::ppa::Dir;
using nadir::ppa::Dreg;

double nsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::nano>(Clock::now() - start).count();
}

// Mean ns of one call of f, over enough calls.
double nsPerCall(const std::function<void()>& f) {
  f();
  const int n = 400;
  const auto start = Clock::now();
  for (int i = 0; i < n; ++i) f();
  return nsSince(start) / n;
}

struct Motion {
  double tx, ty, theta, scale;
};

// A frame-to-frame map p -> c + t + scale R(theta) (p - c), as the VO reports;
// a.then(b) is a after b: p -> a(b(p)).
struct Similarity {
  double tx = 0, ty = 0, theta = 0, scale = 1;
  Similarity then(const Similarity& b) const {
    const double c = std::cos(theta) * scale, s = std::sin(theta) * scale;
    return {tx + c * b.tx - s * b.ty, ty + s * b.tx + c * b.ty, theta + b.theta, scale * b.scale};
  }
};

// The camera's path over the texture: drift, a slow yaw, a slow height change.
Motion motionAt(int frame) {
  return {0.35 * frame, 0.2 * frame, 0.0003 * frame,
          1.0 + 0.03 * std::sin(2.0 * std::numbers::pi * frame / 800.0)};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"SCAMP-5 emulator: visual odometry + target extraction per frame"};
  int frames = 2000;
  std::uint32_t seed = 1;
  app.add_option("--frames", frames, "frames to process")->check(CLI::Range(2, 100000));
  app.add_option("--seed", seed, "texture seed");
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;

  namespace ppa = nadir::ppa;
  namespace scenes = nadir::ppa::test;
  // The texture, with a 66 px concentric mat (5 rings) where the path passes
  // at a third of the run.
  const Motion last = motionAt(frames - 1);
  const int margin = 200;
  const int size = static_cast<int>(2 * margin + 256 + std::max(last.tx, last.ty) + 64);
  cv::Mat texture = scenes::patchTexture(size, seed);
  nadir::terrain::GroundTarget target;
  target.rings = 5;
  const cv::Mat mat = scenes::matImage(target, 66);
  const Motion at_target = motionAt(frames / 3);
  const int mat_x0 = static_cast<int>(margin + scenes::kCentrePx + at_target.tx) - 33;
  const int mat_y0 = static_cast<int>(margin + scenes::kCentrePx + at_target.ty) - 33;
  scenes::paste(texture, mat, mat_x0, mat_y0);
  // Where a frame shows the mat's centre: p = c + R(-theta) (P - origin - c - t) / scale.
  const auto matCentreIn = [&](const Motion& m) {
    const double dx = mat_x0 + 32.5 - margin - scenes::kCentrePx - m.tx;
    const double dy = mat_y0 + 32.5 - margin - scenes::kCentrePx - m.ty;
    const double c = std::cos(m.theta) / m.scale, s = std::sin(m.theta) / m.scale;
    return std::array<double, 2>{scenes::kCentrePx + c * dx + s * dy,
                                 scenes::kCentrePx - s * dx + c * dy};
  };

  std::printf("nadir-bench-ppa: %d frames of 256x256, texture %dx%d (seed %u), one core\n", frames,
              size, size, seed);
  std::printf("making the frames...\n");
  std::vector<cv::Mat> images;
  images.reserve(frames);
  for (int i = 0; i < frames; ++i) {
    const Motion m = motionAt(i);
    images.push_back(scenes::viewOf(texture, margin, margin, m.tx, m.ty, m.theta, m.scale));
  }

  ppa::Ppa array;
  ppa::VisualOdometry vo(ppa::VisualOdometryParams{});
  ppa::TargetExtractor extractor(ppa::TargetExtractionParams{});
  double vo_ns = 0, te_ns = 0, total_ns = 0;
  std::uint64_t vo_instructions = 0, te_instructions = 0;
  int keyframes = 0, iterations = 0, in_view = 0, found_in_view = 0, found_elsewhere = 0;
  int false_detections = 0;
  double max_frame_ns = 0;
  // The key-frame's map into frame 0, chained over the key-frames, and the
  // worst error of the image centre's position in frame 0.
  Similarity keyframe_to_first;
  double max_error_px = 0, last_error_px = 0;
  for (int i = 0; i < frames; ++i) {
    const auto start = Clock::now();
    scenes::expose(array, images[i]);
    const auto vo_start = Clock::now();
    const ppa::VisualOdometryResult odometry = vo.processFrame(array);
    const auto te_start = Clock::now();
    const ppa::TargetExtractionResult found = extractor.processFrame(array);
    const double te = nsSince(te_start);
    const double vo_time = std::chrono::duration<double, std::nano>(te_start - vo_start).count();
    const double frame_ns = nsSince(start);
    vo_ns += vo_time;
    te_ns += te;
    total_ns += frame_ns;
    max_frame_ns = std::max(max_frame_ns, vo_time + te);
    vo_instructions += odometry.instructions;
    te_instructions += found.instructions;
    keyframes += odometry.new_keyframe ? 1 : 0;
    // The mat (66 px, rotated) is whole in the frame with a margin of 40 px.
    const auto centre = matCentreIn(motionAt(i));
    const bool visible =
        std::min(centre[0], centre[1]) > 40 && std::max(centre[0], centre[1]) < 215;
    in_view += visible ? 1 : 0;
    if (found.detected) {
      const double error = std::hypot(found.center_x_px - centre[0], found.center_y_px - centre[1]);
      if (error >= 3.0) {
        ++false_detections;
      } else if (visible) {
        ++found_in_view;
      } else {
        ++found_elsewhere;
      }
    }
    iterations += odometry.iterations;
    // Frame i's pixel p shows frame 0's c + t_i + s_i R_i (p - c): at p = c, c + t_i.
    const Similarity now =
        keyframe_to_first.then({odometry.translation_x_px, odometry.translation_y_px,
                                odometry.rotation_rad, odometry.scale});
    const Motion truth = motionAt(i);
    last_error_px = std::hypot(now.tx - truth.tx, now.ty - truth.ty);
    max_error_px = std::max(max_error_px, last_error_px);
    if (odometry.new_keyframe) keyframe_to_first = now;
  }
  const double n = frames;
  std::printf("\n%-32s %12s %16s\n", "", "ns/frame", "instructions/frame");
  std::printf("%-32s %12.0f %16.0f\n", "visual odometry", vo_ns / n, vo_instructions / n);
  std::printf("%-32s %12.0f %16.0f\n", "target extraction", te_ns / n, te_instructions / n);
  std::printf("%-32s %12.0f %16.0f\n", "both", (vo_ns + te_ns) / n,
              (vo_instructions + te_instructions) / n);
  std::printf(
      "\nframes/s, both programs: %.0f (with setting the light: %.0f); slowest frame %.0f us\n",
      1e9 * n / (vo_ns + te_ns), 1e9 * n / total_ns, max_frame_ns / 1e3);
  std::printf("key-frames: %d, alignment iterations/frame: %.2f\n", keyframes, iterations / n);
  const Motion end = motionAt(frames - 1);
  std::printf(
      "odometry: flew %.0f px, %.1f deg, scale %.3f; image centre off by %.1f px at the "
      "end, %.1f px at worst\n",
      std::hypot(end.tx, end.ty), end.theta * 180.0 / std::numbers::pi, end.scale, last_error_px,
      max_error_px);
  std::printf(
      "target: whole in view in %d frames, found (centre within 3 px) in %d of them "
      "and in %d frames near the edge; wrong detections %d\n",
      in_view, found_in_view, found_elsewhere, false_detections);

  // What single instructions cost the emulator, ns.
  ppa::Ppa probe;
  scenes::expose(probe, images[0]);
  probe.getImage(Areg::A);
  probe.where(Areg::A);
  probe.storeFlag(Dreg::R1);
  probe.all();
  std::printf("\nemulator, ns per instruction:\n");
  std::printf("  analog  getImage %.0f, bus(2 sources) %.0f, busFrom %.0f, where %.0f\n",
              nsPerCall([&] { probe.getImage(Areg::A); }),
              nsPerCall([&] { probe.bus(Areg::B, Areg::A, Areg::C); }),
              nsPerCall([&] { probe.busFrom(Areg::C, Dir::East); }),
              nsPerCall([&] { probe.where(Areg::B); }));
  probe.all();
  std::printf(
      "  digital and %.0f, move east %.0f, move south %.0f, globalCount %.0f, "
      "floodFromBorder %.0f\n",
      nsPerCall([&] { probe.andOp(Dreg::R2, Dreg::R1, Dreg::R1); }),
      nsPerCall([&] { probe.movFrom(Dreg::R2, Dreg::R1, Dir::East); }),
      nsPerCall([&] { probe.movFrom(Dreg::R2, Dreg::R1, Dir::South); }),
      nsPerCall([&] { probe.globalCount(Dreg::R1); }),
      nsPerCall([&] { probe.floodFromBorder(Dreg::R2, Dreg::R1); }));
  return 0;
}
