// nadir-bench-render: flies a straight line over the procedural world at a
// fixed height above ground and renders every camera frame, timing each
// frame from the pose to an encoded image_t (render, readback, encoding).
// Prints frames/s, ms/frame (median, p95) per camera and the peak RSS, then
// the same camera re-rendering the flight's first pose (no new ground) and
// the flight's speed as a share of that.
//
//   nadir-bench-render [--seconds 60] [--speed 25] [--agl 300] [--seed 1] [--timing]

#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/clock.h"
#include "core/command_line.h"
#include "core/frames.h"
#include "core/stage_times.h"
#include "lcmtypes/codec.h"
#include "render/camera_renderer.h"
#include "render/egl_context.h"
#include "terrain/procedural_world.h"
#include "terrain/tiles.h"

namespace {

long peakRssKib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

struct Case {
  const char* name;
  int width;
  int height;
  double hfov_deg;
  double fps;
  const char* format;
  bool motion_blur = false;
  bool rolling_shutter = false;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Render benchmark over the procedural world"};
  double seconds = 60.0, speed_mps = 25.0, agl_m = 300.0;
  std::int64_t seed = 1;
  app.add_option("--seconds", seconds, "flight time, s")->check(CLI::PositiveNumber);
  app.add_option("--speed", speed_mps, "ground speed, m/s")->check(CLI::PositiveNumber);
  app.add_option("--agl", agl_m, "height above ground, m")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "procedural world seed");
  nadir::terrain::TileParams tile_params;
  app.add_option("--texture-px", tile_params.texture_px, "tile texture size, px")
      ->capture_default_str();
  app.add_option("--mesh-quads", tile_params.mesh_quads, "mesh quads along a tile edge")
      ->capture_default_str();
  app.add_option("--max-texel-px", tile_params.max_texel_px,
                 "refine while a texel covers more pixels")
      ->capture_default_str();
  std::string only;
  app.add_option("--only", only, "run only the cameras whose name contains this");
  nadir::render::TerrainRendererParams renderer_params;
  app.add_flag("--objects", renderer_params.objects_3d,
               "trees and buildings as 3D objects (renderer.objects_3d)");
  app.add_flag("--no-prefetch{false}", renderer_params.prefetch_tiles,
               "make each tile's imagery when it is first drawn (renderer.prefetch_tiles=false)");
  std::string frame_png;
  app.add_option("--frame-png", frame_png,
                 "write each camera's first frame here (the camera's name is appended)");
  bool timing = false;
  app.add_flag("--timing", timing, "print where each camera's flight spent its time, by stage");
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;

  nadir::render::HeadlessGlContext context;
  nadir::terrain::ProceduralWorldParams world_params;
  world_params.seed = seed;
  auto world = std::make_shared<nadir::terrain::ProceduralWorld>(world_params);
  std::printf("nadir-bench-render: %s, %s\n", context.info().gl_renderer.c_str(),
              context.info().gl_version.c_str());
  std::printf(
      "flight: %.0f s at %.1f m/s, %.0f m above ground, procedural world seed %lld (%.0f km "
      "square)\n",
      seconds, speed_mps, agl_m, static_cast<long long>(seed), world_params.size_m / 1000.0);
  std::printf("tiles: %d px textures, %d mesh quads, refine above %.2f px per texel\n",
              tile_params.texture_px, tile_params.mesh_quads, tile_params.max_texel_px);
  std::printf("3D trees and buildings: %s; tile imagery made ahead: %s\n",
              renderer_params.objects_3d ? "on" : "off",
              renderer_params.prefetch_tiles ? "yes" : "no");
  std::printf("%-26s %8s %9s %9s %9s %8s %9s %8s %8s %9s\n", "camera", "frames", "frames/s",
              "median ms", "p95 ms", "tiles", "triangles", "objects", "made", "RSS MiB");

  // The motion cases roll at 45 deg/s while flying: 5 ms exposure at 8
  // instants, 30 ms readout.
  const Case cases[] = {
      {"1280x960 gray8 84.9 deg", 1280, 960, 84.872, 31.0, "gray8"},
      {"256x256 gray8 50 deg", 256, 256, 50.0, 200.0, "gray8"},
      {"1280x960 rgb8 84.9 deg", 1280, 960, 84.872, 31.0, "rgb8"},
      {"1280x960 gray8 blur", 1280, 960, 84.872, 31.0, "gray8", true, false},
      {"1280x960 gray8 rolling", 1280, 960, 84.872, 31.0, "gray8", false, true},
      {"1280x960 gray8 blur+rolling", 1280, 960, 84.872, 31.0, "gray8", true, true}};
  for (const Case& c : cases) {
    if (!only.empty() && std::string(c.name).find(only) == std::string::npos) continue;
    auto tiles = std::make_shared<nadir::terrain::TileTree>(world, tile_params);
    nadir::render::TerrainRenderer terrain(tiles, renderer_params);
    nadir::render::CameraParams params;
    params.width = c.width;
    params.height = c.height;
    params.hfov_deg = c.hfov_deg;
    params.pixel_format = c.format;
    params.motion_blur = c.motion_blur;
    params.rolling_shutter = c.rolling_shutter;
    nadir::render::CameraRenderer camera(terrain, params);
    nadir::render::CameraMotion motion;
    motion.omega_cam_rps = nadir::core::rotationBodyFromDownCamera().transpose() *
                           Eigen::Vector3d(45.0 * M_PI / 180.0, 0.0, 0.0);
    motion.v_cam_mps = Eigen::Vector3d(0.0, -speed_mps, 0.0);
    const int frames = static_cast<int>(seconds * c.fps);
    // Heading 30 deg east of north from the origin.
    const auto poseAt = [&](double t_s) {
      const double north = std::cos(0.5236) * speed_mps * t_s,
                   east = std::sin(0.5236) * speed_mps * t_s;
      Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
      T_world_cam.linear() = nadir::core::rotationFromRpy({0.0, 0.0, 0.5236}) *
                             nadir::core::rotationBodyFromDownCamera();
      T_world_cam.translation() =
          Eigen::Vector3d(north, east, -(world->groundUp_m(north, east) + agl_m));
      return T_world_cam;
    };
    // One frame from the pose to an encoded image_t, ms.
    const auto frameMs = [&](const Eigen::Isometry3d& T_world_cam, double t_s,
                             nadir::render::RenderedImage& image) {
      const auto frame_start = std::chrono::steady_clock::now();
      image = camera.render(T_world_cam, nadir::core::utimeFromSeconds(t_s), false, motion);
      const nadir::core::ScopedStage stage("encode image_t");
      const std::vector<std::uint8_t> bytes =
          nadir::msg::encode(nadir::msg::Image{image.utime, image.image, 0, {}});
      if (bytes.empty()) throw std::runtime_error("an image encoded to no bytes");
      return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                       frame_start)
          .count();
    };
    struct Row {
      double frames_per_s = 0.0, median_ms = 0.0, p95_ms = 0.0;
    };
    const auto rowOf = [](std::vector<double> frame_ms, double total_s) {
      std::sort(frame_ms.begin(), frame_ms.end());
      return Row{static_cast<double>(frame_ms.size()) / total_s, frame_ms[frame_ms.size() / 2],
                 frame_ms[frame_ms.size() * 95 / 100]};
    };

    nadir::core::enableStageTimes(timing);
    nadir::core::clearStageTimes();
    std::vector<double> frame_ms;
    frame_ms.reserve(static_cast<std::size_t>(frames));
    long tiles_drawn = 0, triangles = 0, uploads = 0, objects = 0;
    nadir::render::RenderedImage image;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < frames; ++i) {
      const double t_s = i / c.fps;
      frame_ms.push_back(frameMs(poseAt(t_s), t_s, image));
      if (i == 0 && !frame_png.empty()) {
        std::string name = c.name;
        std::replace(name.begin(), name.end(), ' ', '_');
        cv::Mat out = image.image;
        if (out.channels() == 3) cv::cvtColor(out, out, cv::COLOR_RGB2BGR);
        cv::imwrite(frame_png + "_" + name + ".png", out);
      }
      tiles_drawn += image.stats.tiles;
      objects += image.stats.objects;
      triangles += image.stats.triangles;
      uploads += image.stats.tiles_uploaded;
    }
    const double total_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nadir::core::enableStageTimes(false);
    const Row flight = rowOf(frame_ms, total_s);
    std::printf("%-26s %8d %9.1f %9.2f %9.2f %8.1f %9.0f %8.0f %8ld %9.0f\n", c.name, frames,
                flight.frames_per_s, flight.median_ms, flight.p95_ms,
                static_cast<double>(tiles_drawn) / frames, static_cast<double>(triangles) / frames,
                static_cast<double>(objects) / frames, uploads, peakRssKib() / 1024.0);

    if (const nadir::terrain::TilePrefetcher* prefetcher = terrain.prefetcher()) {
      const nadir::terrain::TilePrefetchStats made = prefetcher->stats();
      std::printf("  new tiles' imagery: %lld made ahead and taken, %lld made when drawn\n",
                  static_cast<long long>(made.taken_ready), static_cast<long long>(made.made_here));
    }

    // The reference: the flight's first pose again and again (its tiles made
    // once, before timing), as many frames as 20 s of the camera at most.
    const int reference_frames = std::min(frames, static_cast<int>(20.0 * c.fps));
    const Eigen::Isometry3d T_first = poseAt(0.0);
    frameMs(T_first, 0.0, image);
    std::vector<double> reference_ms;
    const auto reference_start = std::chrono::steady_clock::now();
    for (int i = 0; i < reference_frames; ++i)
      reference_ms.push_back(frameMs(T_first, i / c.fps, image));
    const Row reference = rowOf(
        reference_ms,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - reference_start).count());
    std::printf("%-26s %8d %9.1f %9.2f %9.2f   flight / one pose: %.2f\n", "  one pose again",
                reference_frames, reference.frames_per_s, reference.median_ms, reference.p95_ms,
                flight.frames_per_s / reference.frames_per_s);
    if (timing) {
      std::printf(
          "\n%s\n",
          nadir::core::formatStageTimes(nadir::core::stageTimes(), total_s, frames).c_str());
    }
  }
  return 0;
}
