#include "terrain/arena_world.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "terrain/procedural/noise.h"

namespace nadir::terrain {

void ArenaParams::visit(core::ParamVisitor& v) {
  v.field("half_size_m", &half_size_m,
          {.doc = "half the floor's side, m", .min = 1.0, .max = 10000.0});
  v.field("floor_grey", &floor_grey,
          {.doc = "mean grey of the floor, 8-bit counts", .min = 0.0, .max = 255.0});
  v.field("mottle_counts", &mottle_counts,
          {.doc = "amplitude of the floor's mottling, counts", .min = 0.0, .max = 128.0});
  v.field("mottle_m", &mottle_m,
          {.doc = "wavelength of the coarsest mottling, m", .min = 0.005, .max = 100.0});
  v.field("seed", &seed, {.doc = "seed of the floor's mottling", .min = 0});
}

ArenaWorld::ArenaWorld(const ArenaParams& params) : params_(params) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "arena");
}

double ArenaWorld::groundUp_m(double, double) const { return 0.0; }

WorldExtent ArenaWorld::extent() const {
  return {-params_.half_size_m, params_.half_size_m, -params_.half_size_m, params_.half_size_m};
}

namespace {

// The mottling's octaves: wavelengths mottle_m, mottle_m / 2, mottle_m / 4.
constexpr int kOctaves = 3;
// Samples per finest wavelength the mottling is computed at; finer imagery
// interpolates between them (the mottling is smooth at that scale).
constexpr double kSamplesPerWavelength = 8.0;

}  // namespace

double ArenaWorld::floorGrey(double north_m, double east_m, double footprint_m) const {
  const auto seed = static_cast<procedural::u64>(params_.seed);
  const double mottle =
      procedural::fbm(east_m, north_m, seed, params_.mottle_m, kOctaves, 0.6, footprint_m);
  return std::clamp(params_.floor_grey + params_.mottle_counts * mottle, 0.0, 255.0);
}

void ArenaWorld::imagery(const GroundSquare& sq, int size_px, cv::Mat& rgb) const {
  const double cell_m = sq.size_m / size_px;
  const double finest_m = params_.mottle_m / double(1 << (kOctaves - 1));
  const int samples =
      std::min(size_px, static_cast<int>(std::ceil(sq.size_m * kSamplesPerWavelength / finest_m)));
  // The grey at a grid of samples x samples cell centres, then (when coarser
  // than the imagery) interpolated to size_px.
  const double sample_m = sq.size_m / samples;
  cv::Mat grey(samples, samples, CV_32FC1);
  for (int row = 0; row < samples; ++row) {
    auto* out = grey.ptr<float>(row);
    const double north = sq.north_min_m + sq.size_m - (row + 0.5) * sample_m;
    for (int col = 0; col < samples; ++col) {
      const double east = sq.east_min_m + (col + 0.5) * sample_m;
      out[col] = static_cast<float>(floorGrey(north, east, std::max(cell_m, sample_m)));
    }
  }
  if (samples != size_px)
    cv::resize(grey, grey, cv::Size(size_px, size_px), 0, 0, cv::INTER_LINEAR);
  cv::Mat gray8;
  grey.convertTo(gray8, CV_8UC1);
  cv::cvtColor(gray8, rgb, cv::COLOR_GRAY2RGB);
}

}  // namespace nadir::terrain
