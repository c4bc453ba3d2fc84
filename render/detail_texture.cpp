#include "render/detail_texture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace nadir::render {
namespace {

constexpr int kSize = 512;

std::uint32_t hash(std::uint32_t x, std::uint32_t y, std::uint32_t octave) {
  std::uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ octave * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

// Value noise on a periodic lattice of `cells` cells across the texture.
double periodicNoise(double u, double v, int cells, std::uint32_t octave) {
  const double x = u * cells, y = v * cells;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  const auto corner = [&](int dx, int dy) {
    const auto cx = static_cast<std::uint32_t>(((x0 + dx) % cells + cells) % cells);
    const auto cy = static_cast<std::uint32_t>(((y0 + dy) % cells + cells) % cells);
    return (hash(cx, cy, octave) & 0xFFFFFF) / static_cast<double>(0xFFFFFF);
  };
  const double sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
  const double top = corner(0, 0) + (corner(1, 0) - corner(0, 0)) * sx;
  const double bottom = corner(0, 1) + (corner(1, 1) - corner(0, 1)) * sx;
  return top + (bottom - top) * sy;
}

}  // namespace

cv::Mat makeDetailTexture() {
  std::vector<double> values(static_cast<std::size_t>(kSize) * kSize);
  for (int row = 0; row < kSize; ++row) {
    for (int col = 0; col < kSize; ++col) {
      const double u = (col + 0.5) / kSize, v = (row + 0.5) / kSize;
      double sum = 0.0, amplitude = 1.0;
      // Octaves from clumps a thirty-second of the tile across (0.32 m in the
      // first layer) down to single texels: only structure finer than the imagery.
      for (int octave = 0; octave < 4; ++octave) {
        sum += amplitude *
               (periodicNoise(u, v, 32 << octave, static_cast<std::uint32_t>(octave)) - 0.5);
        amplitude *= 0.62;
      }
      values[static_cast<std::size_t>(row) * kSize + col] = sum;
    }
  }
  double mean = 0.0;
  for (double value : values) mean += value;
  mean /= static_cast<double>(values.size());
  double variance = 0.0;
  for (double value : values) variance += (value - mean) * (value - mean);
  const double stddev = std::sqrt(variance / static_cast<double>(values.size()));
  cv::Mat texture(kSize, kSize, CV_8UC1);
  for (int row = 0; row < kSize; ++row) {
    for (int col = 0; col < kSize; ++col) {
      const double z = (values[static_cast<std::size_t>(row) * kSize + col] - mean) / stddev;
      texture.at<std::uint8_t>(row, col) =
          static_cast<std::uint8_t>(std::clamp(std::lround(128.0 + 48.0 * z), 0L, 255L));
    }
  }
  return texture;
}

}  // namespace nadir::render
