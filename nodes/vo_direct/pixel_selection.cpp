#include "nodes/vo_direct/pixel_selection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace nadir::vo {

void PixelSelectionParams::visit(core::ParamVisitor& v) {
  v.field("target_points", &target_points,
          {.doc = "pixels a key-frame selects over the image", .min = 50, .max = 100000});
  v.field("block_px", &block_px,
          {.doc = "blocks the gradient threshold adapts over, px", .min = 8, .max = 512});
  v.field(
      "threshold_margin", &threshold_margin,
      {.doc = "a pixel's gradient must exceed its block's median by this", .min = 0, .max = 255});
  v.field("coarse_threshold_factor", &coarse_threshold_factor,
          {.doc = "threshold factor per coarser scale", .min = 0.1, .max = 1});
  v.field("border_px", &border_px,
          {.doc = "no pixel this close to the border, px", .min = 4, .max = 200});
}

namespace {

constexpr int kScales = 3;
constexpr int kHistogramBins = 64;
constexpr int kLastBinSquared = (kHistogramBins - 1) * (kHistogramBins - 1);

// Median gradient magnitude per block plus the margin, smoothed 3x3 over blocks.
cv::Mat blockThresholds(const cv::Mat& samples, int block, double margin) {
  const int bw = (samples.cols + block - 1) / block;
  const int bh = (samples.rows + block - 1) / block;
  // floor(sqrt(g2)) == floor(sqrt(floor(g2))): the bin of a squared magnitude
  // from a table, without a square root per pixel.
  static const std::array<std::uint8_t, kLastBinSquared> bin_of_squared = [] {
    std::array<std::uint8_t, kLastBinSquared> table{};
    for (int i = 0; i < kLastBinSquared; ++i)
      table[i] = static_cast<std::uint8_t>(std::sqrt(static_cast<double>(i)));
    return table;
  }();
  cv::Mat raw(bh, bw, CV_32F);
  std::array<int, kHistogramBins> histogram{};
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      histogram.fill(0);
      int count = 0;
      for (int y = by * block; y < std::min((by + 1) * block, samples.rows); ++y) {
        const float* row = samples.ptr<float>(y);
        for (int x = bx * block; x < std::min((bx + 1) * block, samples.cols); ++x) {
          const float g2 = row[3 * x + 1] * row[3 * x + 1] + row[3 * x + 2] * row[3 * x + 2];
          ++histogram[g2 < kLastBinSquared ? bin_of_squared[static_cast<int>(g2)]
                                           : kHistogramBins - 1];
          ++count;
        }
      }
      int seen = 0, median = 0;
      while (median < kHistogramBins - 1 && (seen += histogram[median]) < (count + 1) / 2) ++median;
      raw.at<float>(by, bx) = static_cast<float>(median + 0.5 + margin);
    }
  }
  cv::Mat smooth(bh, bw, CV_32F);
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      float sum = 0;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int y = by + dy, x = bx + dx;
          if (y < 0 || y >= bh || x < 0 || x >= bw) continue;
          sum += raw.at<float>(y, x);
          ++n;
        }
      smooth.at<float>(by, bx) = sum / static_cast<float>(n);
    }
  }
  return smooth;
}

// Sixteen directions; each cell projects gradients onto one so that the
// selected pixels do not all share one edge orientation.
struct Direction {
  float x, y;
};
const std::array<Direction, 16>& directions() {
  static const std::array<Direction, 16> table = [] {
    std::array<Direction, 16> d{};
    for (int i = 0; i < 16; ++i) {
      const double a = M_PI * i / 16.0;
      d[i] = {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a))};
    }
    return d;
  }();
  return table;
}

std::vector<SelectedPixel> selectWithCell(const ImagePyramid& pyramid, const cv::Mat& thresholds,
                                          const PixelSelectionParams& params, int cell) {
  std::vector<SelectedPixel> out;
  const int w0 = pyramid.width(0), h0 = pyramid.height(0);
  const int big = cell << (kScales - 1);  // the coarsest cell, level-0 px
  for (int by = 0; by * big < h0; ++by) {
    for (int bx = 0; bx * big < w0; ++bx) {
      // Each coarsest cell: its finest cells first; where a finer cell found
      // nothing, the coarser cell that holds it looks at its own scale.
      std::vector<SelectedPixel> found;
      bool covered[1 << (kScales - 1)][1 << (kScales - 1)] = {};
      for (int scale = 0; scale < kScales; ++scale) {
        const int sub = 1 << (kScales - 1 - scale);  // cells of this scale per coarsest cell side
        const cv::Mat& samples = pyramid.samples(scale);
        const float factor = static_cast<float>(std::pow(params.coarse_threshold_factor, scale));
        const int border = (params.border_px >> scale) + 1;
        for (int sy = 0; sy < sub; ++sy) {
          for (int sx = 0; sx < sub; ++sx) {
            // The finest cells this cell holds: skip it if one of them found a pixel.
            const int span = 1 << scale;
            bool any = false;
            for (int fy = 0; fy < span && !any; ++fy)
              for (int fx = 0; fx < span && !any; ++fx)
                any = covered[sy * span + fy][sx * span + fx];
            if (any) continue;
            const int x0_l0 = bx * big + sx * (cell << scale);
            const int y0_l0 = by * big + sy * (cell << scale);
            const int x0 = x0_l0 >> scale, y0 = y0_l0 >> scale;
            const int x1 = std::min(x0 + cell, samples.cols - border);
            const int y1 = std::min(y0 + cell, samples.rows - border);
            const int cell_index = (y0_l0 / cell) * 7919 + (x0_l0 / cell) * 104729 + scale;
            const Direction dir = directions()[static_cast<unsigned>(cell_index) % 16u];
            float best = 0;
            int best_x = -1, best_y = -1;
            for (int y = std::max(y0, border); y < y1; ++y) {
              const float* row = samples.ptr<float>(y);
              const float thr =
                  factor * thresholds.at<float>(
                               std::min((y << scale) / params.block_px, thresholds.rows - 1),
                               std::min((x0_l0) / params.block_px, thresholds.cols - 1));
              for (int x = std::max(x0, border); x < x1; ++x) {
                const float gx = row[3 * x + 1], gy = row[3 * x + 2];
                if (gx * gx + gy * gy <= thr * thr) continue;
                const float score = std::fabs(gx * dir.x + gy * dir.y);
                if (score > best) {
                  best = score;
                  best_x = x;
                  best_y = y;
                }
              }
            }
            if (best_x < 0) continue;
            const float* row = samples.ptr<float>(best_y);
            const float gx = row[3 * best_x + 1], gy = row[3 * best_x + 2];
            const float s = static_cast<float>(1 << scale);
            found.push_back({static_cast<float>(best_x) * s, static_cast<float>(best_y) * s, scale,
                             std::sqrt(gx * gx + gy * gy)});
            for (int fy = 0; fy < span; ++fy)
              for (int fx = 0; fx < span; ++fx) covered[sy * span + fy][sx * span + fx] = true;
          }
        }
      }
      out.insert(out.end(), found.begin(), found.end());
    }
  }
  return out;
}

}  // namespace

std::vector<SelectedPixel> selectPixels(const ImagePyramid& pyramid,
                                        const PixelSelectionParams& params, double* cell_px) {
  if (pyramid.levels() < kScales)
    throw std::invalid_argument("selectPixels: the pyramid needs at least 3 levels");
  for (int l = 0; l < kScales; ++l)
    if (!pyramid.hasGradients(l))
      throw std::invalid_argument("selectPixels: the pyramid needs gradients at levels 0-2");
  const cv::Mat thresholds =
      blockThresholds(pyramid.samples(0), params.block_px, params.threshold_margin);
  const double area = static_cast<double>(pyramid.width(0)) * pyramid.height(0);
  // A cell of c x c pixels gives at most one pixel: start where a full grid
  // would hit the target, then correct by the share found (textureless
  // regions give none), at most twice.
  double cell =
      cell_px != nullptr && *cell_px >= 1.0 ? *cell_px : std::sqrt(area / params.target_points);
  std::vector<SelectedPixel> best;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int c = std::max(1, static_cast<int>(std::lround(cell)));
    std::vector<SelectedPixel> pixels = selectWithCell(pyramid, thresholds, params, c);
    const double ratio = static_cast<double>(pixels.size()) / params.target_points;
    if (best.empty() || std::fabs(std::log(std::max(ratio, 1e-3))) <
                            std::fabs(std::log(std::max(
                                static_cast<double>(best.size()) / params.target_points, 1e-3)))) {
      best = std::move(pixels);
      if (cell_px != nullptr) *cell_px = c;
    }
    if (ratio > 0.8 && ratio < 1.25) break;
    if (ratio <= 0.0 || c == 1) break;
    cell = std::max(1.0, c * std::sqrt(ratio));
  }
  return best;
}

}  // namespace nadir::vo
