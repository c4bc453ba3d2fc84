// Shading: one sun lights the relief (Lambertian hillshade on the smooth
// grid) and casts the shadows of trees and buildings; the haze of distance
// mutes the colours.

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {

void Generator::setSun() {
  const double az = p.sun_azimuth_deg * kPi / 180.0;
  const double el = p.sun_elevation_deg * kPi / 180.0;
  sun_x = std::sin(az) * std::cos(el);
  sun_y = std::cos(az) * std::cos(el);
  sun_z = std::sin(el);
  inv_tan_sun = std::cos(el) / std::sin(el);
  shadow_x = -std::sin(az) * inv_tan_sun;
  shadow_y = -std::cos(az) * inv_tan_sun;
}

// The hillshade on the grid (channel 0), from the heights' gradient.
void Generator::hillshade(SmoothGrid& grid) const {
  constexpr int kCh = SmoothGrid::kCh;
  const int nx = grid.nx, ny = grid.ny;
  const double s = grid.s;
  const std::vector<double>& up = grid.up;
  std::vector<double>& nodes = grid.nodes;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * nx + i;
      const int ia = std::max(i - 1, 0), ib = std::min(i + 1, nx - 1);
      const int ja = std::max(j - 1, 0), jb = std::min(j + 1, ny - 1);
      const auto idx = [&](int a, int b) { return static_cast<std::size_t>(b) * nx + a; };
      const double gx = (up[idx(ib, j)] - up[idx(ia, j)]) / ((ib - ia) * s);
      const double gy = (up[idx(i, jb)] - up[idx(i, ja)]) / ((jb - ja) * s);
      const double lam = (-gx * sun_x - gy * sun_y + sun_z) / std::sqrt(gx * gx + gy * gy + 1.0);
      nodes[k * kCh] = std::clamp(1.0 + 0.9 * (lam / sun_z - 1.0), 0.35, 1.6);
    }
  }
}

void Generator::applyShadows(Scratch& scratch) {
  std::vector<Rgb>& col = scratch.col;
  const std::vector<float>& shadow = scratch.shadow;
  const std::size_t n = col.size();
  for (std::size_t i = 0; i < n; ++i) col[i] = col[i] * (1.0 - shadow[i]);
}

// The block's colours, shaded and hazed, into its place in out.
void Generator::writePixels(const PixelFrame& pf, const Scratch& scratch, cv::Mat& out) {
  const int rows = pf.rows, cols = pf.cols, r0 = pf.r0, c0 = pf.c0;
  const std::vector<Rgb>& col = scratch.col;
  const std::vector<float>& shade_px = scratch.shade;
  for (int r = 0; r < rows; ++r) {
    auto* row = out.ptr<cv::Vec3b>(r0 + r);
    for (int c = 0; c < cols; ++c) {
      const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
      Rgb v = col[idx] * shade_px[idx];
      const double lum = 0.3 * v.r + 0.59 * v.g + 0.11 * v.b;
      v = Rgb{lum, lum, lum} + (v - Rgb{lum, lum, lum}) * 0.88;  // the haze of distance
      row[c0 + c] = cv::Vec3b(cv::saturate_cast<uchar>(v.r), cv::saturate_cast<uchar>(v.g),
                              cv::saturate_cast<uchar>(v.b));
    }
  }
}

}  // namespace nadir::terrain::procedural
