// nadir-bench-ppa-gates: the SCAMP-5 emulator running Liu et al.'s (2021) gate
// pipeline on one core: frames rendered along a rover's approach to a gate
// among decoys (4 m to 0.6 m, as the gates scenario's camera sees it), each
// tracked many times. Prints, per stage, the emulated instructions, the chip's
// time at 10 MHz, and the host's time beside the paper's table 2; and the
// frames per second the emulator reaches on one core.
//
//   nadir-bench-ppa-gates [--frames 200] [--rounds 20]

#include <CLI/CLI.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <vector>

#include "core/command_line.h"
#include "nodes/ppa/gate_tracker.h"
#include "render/camera_renderer.h"
#include "render/egl_context.h"
#include "render/terrain_renderer.h"
#include "terrain/arena_world.h"
#include "terrain/course.h"
#include "terrain/tiles.h"

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The gates scenario's camera: 12 cm up, 10 deg above level, looking north.
Eigen::Isometry3d cameraAt(double north_m, double east_m) {
  const double t = 10.0 * kDeg;
  const Eigen::Vector3d forward(std::cos(t), 0.0, -std::sin(t));
  const Eigen::Vector3d right(0.0, 1.0, 0.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = right;
  T.linear().col(1) = forward.cross(right);
  T.linear().col(2) = forward;
  T.translation() = Eigen::Vector3d(north_m, east_m, -0.12);
  return T;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Liu et al.'s (2021) gate pipeline on the emulated SCAMP-5, one core"};
  int frames = 200;
  int rounds = 20;
  app.add_option("--frames", frames, "frames along the approach")->check(CLI::Range(2, 100000));
  app.add_option("--rounds", rounds, "times each frame is tracked")->check(CLI::Range(1, 100000));
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;
  using namespace nadir;

  // A gate 4.6 m ahead with a decoy either side, on the arena floor.
  terrain::CourseBoard gate;
  gate.north_m = 4.6;
  terrain::CourseBoard left = gate, right = gate;
  left.kind = right.kind = "decoy";
  left.east_m = -0.9;
  left.seed = 1;
  right.east_m = 1.0;
  right.decoy_pattern = "random";
  right.seed = 7;
  render::HeadlessGlContext context;
  auto world = std::make_shared<terrain::ArenaWorld>(terrain::ArenaParams{});
  auto tiles = std::make_shared<terrain::TileTree>(world, terrain::TileParams{});
  render::TerrainRenderer terrain(tiles, render::TerrainRendererParams{});
  terrain.setBoards({gate, left, right});
  render::CameraParams camera_params;
  camera_params.width = camera_params.height = 256;
  camera_params.hfov_deg = 50.0;
  camera_params.near_m = 0.02;
  render::CameraRenderer camera(terrain, camera_params);
  std::vector<cv::Mat> images;
  for (int i = 0; i < frames; ++i) {
    const double north = 0.6 + 4.0 * i / (frames - 1);
    images.push_back(camera.render(cameraAt(north, 0.03 * std::sin(0.1 * i)), 0).image.clone());
  }

  ppa::PpaParams array_params;
  array_params.pix_response = "linear";
  array_params.pix_gain = 0.5;
  ppa::GateTrackerParams tracker_params;
  tracker_params.threshold = 52.0;
  ppa::Ppa array(array_params);
  std::array<double, 4> host_ns{}, instructions{};
  int detected = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < rounds; ++r) {
    ppa::GateTracker tracker(tracker_params);
    for (const cv::Mat& image : images) {
      array.setLight(image.ptr<std::uint8_t>());
      const ppa::GateResult result = tracker.processFrame(array);
      for (int k = 0; k < 4; ++k) host_ns[k] += result.host_ns[k];
      instructions[0] += static_cast<double>(result.stages.threshold);
      instructions[1] += static_cast<double>(result.stages.flood);
      instructions[2] += static_cast<double>(result.stages.denoise);
      instructions[3] += static_cast<double>(result.stages.coordinates);
      detected += result.kind == ppa::PatternKind::kGate ? 1 : 0;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double n = static_cast<double>(frames) * rounds;
  const char* names[4] = {"capture and threshold", "flooding (intact and broken squares)",
                          "de-noising", "the disks' coordinates"};
  const double paper_us[4] = {52, 63, 4, 328};
  std::printf("%d frames x %d rounds, the gate found in %.1f %% of them\n", frames, rounds,
              100.0 * detected / n);
  std::printf("%-40s %12s %10s %10s %10s\n", "stage", "instructions", "chip us", "host us",
              "paper us");
  double total_host = 0.0, total_instr = 0.0;
  for (int k = 0; k < 4; ++k) {
    std::printf("%-40s %12.0f %10.1f %10.1f %10.0f\n", names[k], instructions[k] / n,
                instructions[k] / n / 10.0, host_ns[k] / n / 1e3, paper_us[k]);
    total_host += host_ns[k] / n / 1e3;
    total_instr += instructions[k] / n;
  }
  std::printf("%-40s %12.0f %10.1f %10.1f %10.0f\n", "total on the chip", total_instr,
              total_instr / 10.0, total_host, 447.0);
  std::printf("emulated on one core: %.0f frames/s (%.1f us a frame, setLight included)\n",
              n / seconds, 1e6 * seconds / n);
  return 0;
}
