#include "nodes/vo_feature/features.h"

#include <opencv2/core/hal/hal.hpp>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace nadir::vo {

namespace {

// Keypoints stay this far from every level's border (ORB-SLAM's EDGE_THRESHOLD):
// the rotated 31 px descriptor patch, its blur and the orientation disk fit inside.
constexpr int kBorderPx = 19;
constexpr int kPatchSize = 31;
constexpr int kHalfPatch = kPatchSize / 2;

void validate(const FeatureParams& params) {
  FeatureParams copy = params;
  core::validateParams([&copy](core::ParamVisitor& v) { copy.visit(v); }, "vo_feature features");
  if (params.min_fast_threshold > params.fast_threshold) {
    throw std::invalid_argument(
        "vo_feature features: min_fast_threshold must not exceed fast_threshold");
  }
}

// ORB-SLAM's split of the wanted features over the levels: level l gets a share
// proportional to 1 / scale_factor^l (its area shrinks by the square, but the
// features at coarse levels are the ones that survive scale changes).
std::vector<int> featuresPerLevel(const FeatureParams& params) {
  std::vector<int> per_level(static_cast<std::size_t>(params.num_levels), 0);
  const double factor = 1.0 / params.scale_factor;
  double wanted = params.num_features * (1.0 - factor) /
                  (1.0 - std::pow(factor, static_cast<double>(params.num_levels)));
  int sum = 0;
  for (int level = 0; level + 1 < params.num_levels; ++level) {
    per_level[static_cast<std::size_t>(level)] = static_cast<int>(std::lround(wanted));
    sum += per_level[static_cast<std::size_t>(level)];
    wanted *= factor;
  }
  per_level.back() = std::max(params.num_features - sum, 0);
  return per_level;
}

// ---- FAST-9 -----------------------------------------------------------------

using U8x16 = cv::v_uint8x16;
constexpr int kLanes = 16;

// The 16 pixels of the radius-3 Bresenham circle, in order around it.
constexpr std::array<int, 16> kRingX{0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1};
constexpr std::array<int, 16> kRingY{-3, -3, -2, -1, 0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3};

// max over the 16 arcs of 9 neighbouring circle pixels of the arc's minimum,
// lane by lane: min over k..k+8 is min(min k..k+3, min k+4..k+7, k+8).
U8x16 bestArcMin(const std::array<U8x16, 16>& x) {
  std::array<U8x16, 16> min2;
  std::array<U8x16, 16> min4;
  for (int k = 0; k < 16; ++k) min2[k] = cv::v_min(x[k], x[(k + 1) % 16]);
  for (int k = 0; k < 16; ++k) min4[k] = cv::v_min(min2[k], min2[(k + 2) % 16]);
  U8x16 best = cv::v_setzero_u8();
  for (int k = 0; k < 16; ++k) {
    best = cv::v_max(best, cv::v_min(cv::v_min(min4[k], min4[(k + 4) % 16]), x[(k + 8) % 16]));
  }
  return best;
}

struct Corner {
  int x;  // level pixels
  int y;
  int score;
};

// Strongest first; ties broken by position so the order never depends on the sort.
bool strongerThan(const Corner& a, const Corner& b) {
  if (a.score != b.score) return a.score > b.score;
  if (a.y != b.y) return a.y < b.y;
  return a.x < b.x;
}

// FAST-9 scores of one level, computed lazily: a pixel's score is the largest
// threshold t at which it is a corner (9 neighbouring circle pixels all brighter
// than centre + t, or all darker than centre - t), as cv::FAST scores it.
// Scores are computed 16 pixels of a row (a block) at a time, and only for the
// blocks whose cheap upper bound reaches the threshold asked for; a block
// whose bound is below t has no corner at t and cannot suppress one (its
// scores are below t too). So corners(t, cell) is exactly what cv::FAST(t)
// with non-maximum suppression finds in the cell on the whole level, however
// many thresholds were asked for before, and no score is computed twice.
class FastScores {
 public:
  // The maps live in the caller's buffers (reused from frame to frame).
  FastScores(const cv::Mat& image, std::vector<std::uint8_t>& bound_buffer,
             std::vector<std::uint8_t>& best_buffer, std::vector<std::uint8_t>& score_buffer)
      : image_(image),
        blocks_per_row_((image.cols - 2 * kOrigin + kLanes - 1) / kLanes),
        rows_(image.rows - 2 * kOrigin),
        stride_(kPad + blocks_per_row_ * kLanes + kPad),
        bound_(bound_buffer),
        best_(best_buffer),
        scores_(score_buffer) {
    // One vector past the end: the block maps are scanned 16 blocks at a time.
    const std::size_t blocks =
        static_cast<std::size_t>(blocks_per_row_) * static_cast<std::size_t>(rows_) + kLanes;
    bound_.resize(blocks);
    best_.assign(blocks, 0);
    scores_.assign(static_cast<std::size_t>(stride_) * static_cast<std::size_t>(rows_), 0);
    for (int k = 0; k < 16; ++k) {
      ring_[static_cast<std::size_t>(k)] =
          kRingY[static_cast<std::size_t>(k)] * static_cast<int>(image.step) +
          kRingX[static_cast<std::size_t>(k)];
    }
    // Of the four circle pixels at 0, 4, 8 and 12, two neighbouring ones are in
    // every arc of 9: the lesser of such a pair bounds the score from above.
    const std::array<int, 4> cardinal{ring_[0], ring_[4], ring_[8], ring_[12]};
    for (int r = 0; r < rows_; ++r) {
      const std::uint8_t* row = image_.ptr<std::uint8_t>(r + kOrigin) + kOrigin;
      std::uint8_t* bound = &bound_[static_cast<std::size_t>(r) * blocks_per_row_];
      for (int j = 0; j < blocks_per_row_; ++j) {
        const std::uint8_t* p = row + j * kLanes;
        const U8x16 c = cv::v_load(p);
        std::array<U8x16, 4> up;
        std::array<U8x16, 4> down;
        for (std::size_t k = 0; k < 4; ++k) {
          const U8x16 v = cv::v_load(p + cardinal[k]);
          up[k] = v - c;  // saturating: 0 where darker
          down[k] = c - v;
        }
        U8x16 q = cv::v_setzero_u8();
        for (std::size_t k = 0; k < 4; ++k) {
          q = cv::v_max(q, cv::v_min(up[k], up[(k + 1) % 4]));
          q = cv::v_max(q, cv::v_min(down[k], down[(k + 1) % 4]));
        }
        bound[j] = static_cast<std::uint8_t>(std::max(cv::v_reduce_max(q) - 1, 0));
      }
    }
  }

  // The highest score a corner of the cell can have: no threshold above it
  // finds one.
  int ceiling(const cv::Rect& cell) const {
    const int j0 = (cell.x - kOrigin) / kLanes;
    const int j1 = (cell.x + cell.width - 1 - kOrigin) / kLanes;
    U8x16 most = cv::v_setzero_u8();
    for (int y = cell.y; y < cell.y + cell.height; ++y) {
      const std::size_t row = static_cast<std::size_t>(y - kOrigin) * blocks_per_row_;
      for (int j = j0; j <= j1; j += kLanes) {
        // Lanes past j1 are blocks of the next cell or row: the bound is looser.
        most =
            cv::v_max(most, cv::v_max(cv::v_load(&bound_[row + j]), cv::v_load(&best_[row + j])));
      }
    }
    return cv::v_reduce_max(most);
  }

  // Makes sure every block that may hold a corner at `threshold` in the cell or
  // next to it (non-maximum suppression looks one pixel further) has its scores.
  void computeFor(int threshold, const cv::Rect& cell) {
    const int j0 = (cell.x - 1 - kOrigin) / kLanes;
    const int j1 = (cell.x + cell.width - kOrigin) / kLanes;
    for (int y = cell.y - 1; y <= cell.y + cell.height; ++y) {
      const int r = y - kOrigin;
      std::uint8_t* bound = &bound_[static_cast<std::size_t>(r) * blocks_per_row_];
      forEachAtLeast(bound, j0, j1, threshold, [&](int j) {
        computeBlock(r, j);
        bound[j] = 0;
      });
    }
  }

  // Appends the corners of the cell at `threshold` after non-maximum
  // suppression (a corner must score above all 8 neighbours, as in cv::FAST).
  // computeFor(threshold, cell) must have run.
  void corners(int threshold, const cv::Rect& cell, std::vector<Corner>& out) const {
    const int x_end = cell.x + cell.width;
    const int j0 = (cell.x - kOrigin) / kLanes;
    const int j1 = (x_end - 1 - kOrigin) / kLanes;
    const U8x16 t = cv::v_setall_u8(static_cast<std::uint8_t>(threshold - 1));
    for (int y = cell.y; y < cell.y + cell.height; ++y) {
      const int r = y - kOrigin;
      const std::uint8_t* best = &best_[static_cast<std::size_t>(r) * blocks_per_row_];
      forEachAtLeast(best, j0, j1, threshold, [&](int j) {
        const std::uint8_t* s = &scores_[static_cast<std::size_t>(r) * stride_ + kPad + j * kLanes];
        const U8x16 centre = cv::v_load(s);
        U8x16 keep = centre > t;
        keep = keep & (centre > cv::v_load(s - 1)) & (centre > cv::v_load(s + 1));
        for (const int row : {-stride_, stride_}) {
          keep = keep & (centre > cv::v_load(s + row - 1)) & (centre > cv::v_load(s + row)) &
                 (centre > cv::v_load(s + row + 1));
        }
        unsigned mask = static_cast<unsigned>(cv::v_signmask(keep));
        const int x0 = kOrigin + j * kLanes;
        while (mask != 0) {
          const int lane = std::countr_zero(mask);
          mask &= mask - 1;
          const int x = x0 + lane;
          if (x >= cell.x && x < x_end) out.push_back({x, y, s[lane]});
        }
      });
    }
  }

 private:
  // First row and column scored: one pixel outside the keypoint area, for the
  // non-maximum suppression of its border. The circle stays inside the image,
  // the last block of a row included.
  static constexpr int kOrigin = kBorderPx - 1;
  // Score rows reach one block past both ends for the suppression's loads.
  static constexpr int kPad = kLanes;

  // Calls f(j) for every j in [j0, j1] with map[j] >= threshold, in order; a
  // vector compare per 16 blocks instead of a hard-to-predict branch per block.
  template <class F>
  static void forEachAtLeast(const std::uint8_t* map, int j0, int j1, int threshold, F&& f) {
    const U8x16 below = cv::v_setall_u8(static_cast<std::uint8_t>(threshold - 1));
    for (int j = j0; j <= j1; j += kLanes) {
      unsigned mask = static_cast<unsigned>(cv::v_signmask(cv::v_load(map + j) > below));
      if (j1 - j < kLanes - 1) mask &= (2u << (j1 - j)) - 1u;
      while (mask != 0) {
        f(j + std::countr_zero(mask));
        mask &= mask - 1;
      }
    }
  }

  void computeBlock(int r, int j) {
    const std::uint8_t* p = image_.ptr<std::uint8_t>(r + kOrigin) + kOrigin + j * kLanes;
    const U8x16 c = cv::v_load(p);
    std::array<U8x16, 16> brighter;
    std::array<U8x16, 16> darker;
    for (std::size_t k = 0; k < 16; ++k) {
      const U8x16 v = cv::v_load(p + ring_[k]);
      brighter[k] = v - c;
      darker[k] = c - v;
    }
    // A corner at t needs differences above t: the score is the best arc minimum - 1.
    const U8x16 score = cv::v_max(bestArcMin(brighter), bestArcMin(darker)) - cv::v_setall_u8(1);
    cv::v_store(&scores_[static_cast<std::size_t>(r) * stride_ + kPad + j * kLanes], score);
    best_[static_cast<std::size_t>(r) * blocks_per_row_ + j] =
        static_cast<std::uint8_t>(cv::v_reduce_max(score));
  }

  const cv::Mat& image_;
  int blocks_per_row_;
  int rows_;
  int stride_;
  std::array<int, 16> ring_{};
  std::vector<std::uint8_t>& bound_;   // per block: bound of its scores; 0 once computed
  std::vector<std::uint8_t>& best_;    // per block: its best score, 0 until computed
  std::vector<std::uint8_t>& scores_;  // per pixel: its score, 0 until computed
};

// Scratch memory of one thread, kept from call to call: fresh buffers of
// megabytes cost a page fault per 4 KB, as much time as the work on them.
struct Scratch {
  std::vector<std::uint8_t> bound;
  std::vector<std::uint8_t> best;
  std::vector<std::uint8_t> scores;
  std::vector<std::uint8_t> needed;
  std::vector<std::uint8_t> blurred;
  std::vector<std::uint16_t> column_sums;
};

Scratch& threadScratch() {
  thread_local Scratch scratch;
  return scratch;
}

// Thresholds a cell's search goes down, strongest first: steps of 1.25 from
// about 4 x fast_threshold down to fast_threshold, then on down to
// min_fast_threshold. The steps only save work (a cell stops at the first
// threshold with enough corners); fast_threshold and min_fast_threshold are on it.
std::vector<int> thresholdLadder(const FeatureParams& params) {
  constexpr double kStep = 1.25;
  std::vector<int> ladder;
  const double top = std::min(255.0, 4.0 * params.fast_threshold);
  for (double t = params.fast_threshold * kStep; t <= top; t *= kStep) {
    ladder.insert(ladder.begin(), static_cast<int>(std::lround(t)));
  }
  ladder.push_back(params.fast_threshold);
  for (double t = params.fast_threshold / kStep; t > params.min_fast_threshold; t /= kStep) {
    ladder.push_back(static_cast<int>(std::lround(t)));
  }
  ladder.push_back(params.min_fast_threshold);
  ladder.erase(std::unique(ladder.begin(), ladder.end()), ladder.end());
  return ladder;
}

// The grid-spread corners of one level (level pixels), at most `wanted`,
// strongest first.
std::vector<Corner> detectOnLevel(const cv::Mat& level_image, int wanted,
                                  const FeatureParams& params, Scratch& scratch) {
  std::vector<Corner> kept;
  const int width = level_image.cols - 2 * kBorderPx;
  const int height = level_image.rows - 2 * kBorderPx;
  if (wanted <= 0 || width < 1 || height < 1) return kept;
  const int cols = std::min(params.grid_cols, width);
  const int rows = std::min(params.grid_rows, height);
  const int share = wanted / (cols * rows);
  const std::size_t enough = static_cast<std::size_t>(std::max(share, 1));
  const std::vector<int> ladder = thresholdLadder(params);
  const auto step_of = [&ladder](int threshold) {
    return static_cast<int>(std::find(ladder.begin(), ladder.end(), threshold) - ladder.begin());
  };
  const int last_step = static_cast<int>(ladder.size()) - 1;

  // Per cell: where on the ladder its search stands, and how far down its
  // left-overs count (fast_threshold, or min_fast_threshold for a poor cell).
  struct Cell {
    cv::Rect rect;
    int step;
    int floor_step;
  };
  std::vector<Cell> cells;
  FastScores scores(level_image, scratch.bound, scratch.best, scratch.scores);
  std::vector<Corner> spare;
  std::vector<Corner> found;
  for (int r = 0; r < rows; ++r) {
    const int y0 = kBorderPx + r * height / rows;
    const int y1 = kBorderPx + (r + 1) * height / rows;
    for (int c = 0; c < cols; ++c) {
      const int x0 = kBorderPx + c * width / cols;
      const int x1 = kBorderPx + (c + 1) * width / cols;
      Cell cell{cv::Rect(x0, y0, x1 - x0, y1 - y0), 0, 0};
      // Thresholds above the cell's ceiling find nothing: start below it.
      const int ceiling = scores.ceiling(cell.rect);
      while (cell.step < last_step && ladder[static_cast<std::size_t>(cell.step)] > ceiling) {
        ++cell.step;
      }
      found.clear();
      for (;; ++cell.step) {
        const int threshold = ladder[static_cast<std::size_t>(cell.step)];
        if (threshold <= ceiling) {
          scores.computeFor(threshold, cell.rect);
          found.clear();
          scores.corners(threshold, cell.rect, found);
        }
        if (found.size() >= enough || cell.step == last_step) break;
      }
      const bool rich = found.size() >= enough &&
                        ladder[static_cast<std::size_t>(cell.step)] >= params.fast_threshold;
      cell.floor_step = step_of(rich ? params.fast_threshold : params.min_fast_threshold);
      // The strongest corners at this threshold are the strongest at any lower one.
      const std::size_t take = std::min(found.size(), static_cast<std::size_t>(share));
      std::nth_element(found.begin(), found.begin() + static_cast<long>(take), found.end(),
                       strongerThan);
      kept.insert(kept.end(), found.begin(), found.begin() + static_cast<long>(take));
      spare.insert(spare.end(), found.begin() + static_cast<long>(take), found.end());
      cells.push_back(cell);
    }
  }

  // What the poor cells could not use goes to the strongest left-overs of the
  // level. The cells that stopped early go on down (to their floor) only until
  // the spare corners at or above the highest threshold still to search are
  // enough: those are the strongest.
  const std::size_t missing = static_cast<std::size_t>(wanted) - kept.size();
  while (missing > 0) {
    int open_step = std::numeric_limits<int>::max();
    for (const Cell& cell : cells) {
      if (cell.step < cell.floor_step) open_step = std::min(open_step, cell.step);
    }
    if (open_step == std::numeric_limits<int>::max()) break;
    const int open_threshold = ladder[static_cast<std::size_t>(open_step)];
    const auto complete = std::count_if(spare.begin(), spare.end(), [&](const Corner& corner) {
      return corner.score >= open_threshold;
    });
    if (static_cast<std::size_t>(complete) >= missing) break;
    for (Cell& cell : cells) {
      if (cell.step != open_step || cell.step >= cell.floor_step) continue;
      const int threshold = ladder[static_cast<std::size_t>(++cell.step)];
      scores.computeFor(threshold, cell.rect);
      found.clear();
      scores.corners(threshold, cell.rect, found);
      for (const Corner& corner : found) {
        if (corner.score < open_threshold) spare.push_back(corner);
      }
    }
  }
  if (missing > 0 && !spare.empty()) {
    const std::size_t take = std::min(missing, spare.size());
    std::nth_element(spare.begin(), spare.begin() + static_cast<long>(take), spare.end(),
                     strongerThan);
    kept.insert(kept.end(), spare.begin(), spare.begin() + static_cast<long>(take));
  }
  std::sort(kept.begin(), kept.end(), strongerThan);
  return kept;
}

// ---- orientation ------------------------------------------------------------

// Per row v of the disk of radius kHalfPatch, over columns u = -16 .. 15 (two
// 16-pixel loads): u inside the disk, else 0, and v inside the disk, else 0.
struct DiskWeights {
  std::array<std::array<std::int16_t, 32>, kHalfPatch + 1> u{};
  std::array<std::array<std::int16_t, 32>, kHalfPatch + 1> v{};
};

const DiskWeights& diskWeights() {
  static const DiskWeights weights = [] {
    DiskWeights w;
    for (int v = 0; v <= kHalfPatch; ++v) {
      const int umax =
          static_cast<int>(std::lround(std::sqrt(double(kHalfPatch * kHalfPatch - v * v))));
      for (int u = -umax; u <= umax; ++u) {
        w.u[static_cast<std::size_t>(v)][static_cast<std::size_t>(u + 16)] =
            static_cast<std::int16_t>(u);
        w.v[static_cast<std::size_t>(v)][static_cast<std::size_t>(u + 16)] =
            static_cast<std::int16_t>(v);
      }
    }
    return w;
  }();
  return weights;
}

// Sum over 32 pixels (two loads) of pixel * weight.
inline cv::v_int32x4 weightedSum(const cv::v_int16x8 (&pixels)[4], const std::int16_t* weights) {
  cv::v_int32x4 sum = cv::v_dotprod(pixels[0], cv::v_load(weights));
  for (int k = 1; k < 4; ++k) sum += cv::v_dotprod(pixels[k], cv::v_load(weights + 8 * k));
  return sum;
}

inline void loadRow(const std::uint8_t* p, cv::v_int16x8 (&out)[4]) {
  for (int k = 0; k < 2; ++k) {
    cv::v_uint16x8 lo;
    cv::v_uint16x8 hi;
    cv::v_expand(cv::v_load(p + 16 * k), lo, hi);
    out[2 * k] = cv::v_reinterpret_as_s16(lo);
    out[2 * k + 1] = cv::v_reinterpret_as_s16(hi);
  }
}

// Orientation by the intensity centroid of the disk around (x, y), degrees in
// [0, 360): rows v and -v together, (sum, difference) against (u, v) weights.
float centroidAngleDeg(const cv::Mat& level_image, int x, int y) {
  const DiskWeights& w = diskWeights();
  const std::size_t step = level_image.step;
  const std::uint8_t* centre = level_image.ptr<std::uint8_t>(y) + x - 16;
  cv::v_int16x8 above[4];
  cv::v_int16x8 below[4];
  loadRow(centre, above);
  cv::v_int32x4 m_10 = weightedSum(above, w.u[0].data());
  cv::v_int32x4 m_01 = cv::v_setzero_s32();
  for (int v = 1; v <= kHalfPatch; ++v) {
    loadRow(centre + static_cast<std::size_t>(v) * step, below);
    loadRow(centre - static_cast<std::size_t>(v) * step, above);
    cv::v_int16x8 sum[4];
    cv::v_int16x8 difference[4];
    for (int k = 0; k < 4; ++k) {
      sum[k] = below[k] + above[k];
      difference[k] = below[k] - above[k];
    }
    m_10 += weightedSum(sum, w.u[static_cast<std::size_t>(v)].data());
    m_01 += weightedSum(difference, w.v[static_cast<std::size_t>(v)].data());
  }
  return cv::fastAtan2(static_cast<float>(cv::v_reduce_sum(m_01)),
                       static_cast<float>(cv::v_reduce_sum(m_10)));
}

// ---- blur -------------------------------------------------------------------

// Gaussian, 7 taps, sigma 2 (ORB's descriptor smoothing), in 1/256.
constexpr std::array<int, 4> kBlurTaps{54, 49, 34, 18};  // centre, 1, 2, 3 px off
constexpr int kBlurRadius = 3;

// One row segment [x0, x1) of the blur; at least 8 px, inside the image by the
// blur radius. `column_sums` holds x1 - x0 + 6 values.
void blurSegment(const cv::Mat& image, int y, int x0, int x1, cv::Mat& out,
                 std::uint16_t* column_sums) {
  using U16x8 = cv::v_uint16x8;
  constexpr int kStep = 8;
  const std::size_t step = image.step;
  // Down the columns first: 256 x the column's blur, in 16 bits.
  const std::uint8_t* centre = image.ptr<std::uint8_t>(y) + x0 - kBlurRadius;
  const int n = x1 - x0 + 2 * kBlurRadius;
  const U16x8 w0 = cv::v_setall_u16(kBlurTaps[0]);
  const U16x8 w1 = cv::v_setall_u16(kBlurTaps[1]);
  const U16x8 w2 = cv::v_setall_u16(kBlurTaps[2]);
  const U16x8 w3 = cv::v_setall_u16(kBlurTaps[3]);
  for (int i = 0;; i += kStep) {
    i = std::min(i, n - kStep);  // the last step overlaps the one before
    const std::uint8_t* p = centre + i;
    const auto row = [&](int dy) {
      return cv::v_load_expand(p +
                               static_cast<std::ptrdiff_t>(dy) * static_cast<std::ptrdiff_t>(step));
    };
    const U16x8 sum = cv::v_mul_wrap(row(0), w0) + cv::v_mul_wrap(row(-1) + row(1), w1) +
                      cv::v_mul_wrap(row(-2) + row(2), w2) + cv::v_mul_wrap(row(-3) + row(3), w3);
    cv::v_store(column_sums + i, sum);
    if (i + kStep >= n) break;
  }
  // Then along the row: (sum * tap) >> 16 per tap keeps it in 16 bits.
  std::uint8_t* dst = out.ptr<std::uint8_t>(y) + x0;
  const int width = x1 - x0;
  const U16x8 half = cv::v_setall_u16(128);
  for (int i = 0;; i += kStep) {
    i = std::min(i, width - kStep);
    const std::uint16_t* q = column_sums + i + kBlurRadius;
    U16x8 sum = cv::v_mul_hi(cv::v_load(q), cv::v_setall_u16(kBlurTaps[0] << 8)) + half;
    for (int d = 1; d <= kBlurRadius; ++d) {
      const U16x8 tap =
          cv::v_setall_u16(static_cast<std::uint16_t>(kBlurTaps[static_cast<std::size_t>(d)] << 8));
      sum += cv::v_mul_hi(cv::v_load(q - d), tap) + cv::v_mul_hi(cv::v_load(q + d), tap);
    }
    cv::v_pack_store(dst + i, sum >> 8);
    if (i + kStep >= width) break;
  }
}

// The level blurred where the descriptor tests of `corners` read it: the
// squares of side kPatchSize around them, a third of the level or so; the
// rest of the result is not set.
cv::Mat blurAroundCorners(const cv::Mat& image, const std::vector<Corner>& corners,
                          Scratch& scratch) {
  constexpr int kColumns = 16;  // needed pixels are marked in runs of 16 columns
  const int groups = (image.cols + kColumns - 1) / kColumns;
  std::vector<std::uint8_t>& needed = scratch.needed;
  needed.assign(static_cast<std::size_t>(image.rows) * groups, 0);
  for (const Corner& corner : corners) {
    const int g0 = (corner.x - kHalfPatch) / kColumns;
    const int g1 = (corner.x + kHalfPatch) / kColumns;
    for (int y = corner.y - kHalfPatch; y <= corner.y + kHalfPatch; ++y) {
      std::uint8_t* row = &needed[static_cast<std::size_t>(y) * groups];
      std::fill(row + g0, row + g1 + 1, std::uint8_t{1});
    }
  }
  scratch.blurred.resize(image.total());
  cv::Mat out(image.size(), CV_8U, scratch.blurred.data());
  std::vector<std::uint16_t>& column_sums = scratch.column_sums;
  column_sums.resize(static_cast<std::size_t>(image.cols) + 2 * kBlurRadius);
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* row = &needed[static_cast<std::size_t>(y) * groups];
    for (int g = 0; g < groups;) {
      if (row[g] == 0) {
        ++g;
        continue;
      }
      const int g0 = g;
      while (g < groups && row[g] != 0) ++g;
      // Corners are kBorderPx inside, so the run holds a whole patch row and
      // the blur's reach stays in the image.
      const int x0 = std::max(g0 * kColumns, kBlurRadius);
      const int x1 = std::min(g * kColumns, image.cols - kBlurRadius);
      blurSegment(image, y, x0, x1, out, column_sums.data());
    }
  }
  return out;
}

// ---- descriptors ------------------------------------------------------------

// Steered BRIEF with learned tests (ORB's rBRIEF): 256 tests comparing two
// pixels of the blurred patch, turned by the keypoint angle. The turned
// pattern is tabled per degree (at most 0.13 px off at the disk's rim).
constexpr int kTests = 256;
constexpr int kAngleBins = 360;
constexpr std::size_t kDescriptorBytes = kTests / 8;

// The tests, (p.x, p.y, q.x, q.y) in pixels from the keypoint in its patch
// turned to angle 0: bit = blurred(p) < blurred(q). Chosen once as ORB chose
// its rBRIEF tests: 30000 random pairs of points of the disk were run over the
// 80000 keypoints of 40 frames of nadir's simulated flight over procedural
// terrain; of those whose bit is near even (|mean - 0.5| <= 0.2), most even
// first, a test was taken when it correlated with none taken before by more
// than 0.425 (the lowest bound that yields 256). Under rotation and scale
// changes, steered BRIEF's random Gaussian tests match 6-8 % fewer features,
// on the simulator's frames and on real Landsat imagery alike; these match as
// many as OpenCV's ORB pattern, with fewer wrong matches.
constexpr std::array<std::array<std::int8_t, 4>, kTests> kTestPattern{
    {{-9, 10, -7, -10},  {-1, 13, 0, 11},    {7, -9, 11, 10},     {3, 2, 6, -12},
     {-9, 1, -15, 0},    {5, 13, 3, -1},     {-9, -3, -6, -1},    {0, -2, 1, -6},
     {11, -9, 13, -6},   {-2, 5, -2, -7},    {-10, 7, -6, -5},    {-8, 11, -3, -3},
     {9, -10, 7, 0},     {9, 4, 11, -4},     {2, -11, 3, 12},     {-6, 13, -2, 4},
     {12, 7, 10, -1},    {-11, 9, -6, 7},    {12, 9, 10, 5},      {-14, 2, -12, 7},
     {-4, 6, -7, -13},   {-12, 2, -14, -4},  {-12, -1, -14, 3},   {-7, 1, -7, -5},
     {12, -7, 13, -3},   {-8, -3, -8, -6},   {-1, 6, -1, 9},      {-12, -9, -5, -5},
     {-4, 11, -2, -7},   {7, 0, 14, -5},     {4, 7, 5, -10},      {-3, 0, -5, -11},
     {-7, -1, -7, 4},    {6, -2, 9, 6},      {-11, 3, -7, 3},     {0, 8, 0, -13},
     {-4, 2, -4, 5},     {-13, 5, -9, 7},    {-9, 2, -6, 0},      {3, 9, 3, 5},
     {-10, 3, -11, 6},   {10, -6, 13, 2},    {-4, -11, -5, 14},   {6, 7, 9, 10},
     {8, 3, 12, 4},      {7, 11, 9, 11},     {-13, -5, -12, -8},  {4, -7, 6, 11},
     {-2, -6, -3, -12},  {3, -11, 3, -6},    {10, 6, 14, 1},      {3, 6, 3, 3},
     {-12, 6, -12, 8},   {6, -6, 8, -8},     {-14, 5, -10, -8},   {-13, -7, -6, 4},
     {6, 11, 6, 8},      {-4, 10, -5, 14},   {5, -14, 5, -11},    {8, -2, 15, 0},
     {-6, 0, -5, 1},     {6, -2, 7, 0},      {8, -12, 7, -8},     {-8, -6, -9, -9},
     {6, 13, 6, -12},    {2, 8, 3, 12},      {-14, -4, -7, -5},   {4, 5, 5, 6},
     {-9, 8, -8, 9},     {7, -12, 9, -12},   {6, -5, 7, -4},      {2, -4, 3, 9},
     {9, -10, 10, -8},   {0, -8, 0, 14},     {4, 3, 4, -1},       {1, 12, 2, 14},
     {-8, -6, -7, -7},   {2, -13, 3, -14},   {9, 8, 13, 6},       {5, -7, 5, -4},
     {-7, -10, -7, -12}, {-1, -11, 0, 3},    {-5, 4, -6, 7},      {-2, 3, -2, -1},
     {8, 9, 7, 4},       {-2, 12, -1, -11},  {3, 2, 4, 3},        {6, 4, 8, 5},
     {-8, 10, -8, 12},   {8, 1, 10, 0},      {-6, -9, -4, -7},    {6, -3, 8, -4},
     {4, 11, 6, 13},     {-1, -10, -1, -13}, {0, 15, 0, -2},      {5, 1, 7, -4},
     {2, -3, 2, 0},      {-8, 7, -9, 10},    {7, 13, 7, 11},      {-5, -13, -3, -11},
     {13, -6, 11, -3},   {1, -8, 1, -4},     {-12, -7, -11, -10}, {-4, -5, -5, 7},
     {-14, -1, -10, -5}, {10, 11, 11, 8},    {-1, -12, 0, -11},   {3, -5, 4, -6},
     {-7, 5, -6, 6},     {-5, 12, -4, 13},   {-11, -3, -13, -7},  {11, -9, 9, -6},
     {-9, -12, -6, -12}, {-4, -7, -3, -5},   {-7, 12, -5, 12},    {6, 6, 12, -9},
     {-13, -6, -10, 10}, {2, -7, 3, 5},      {-2, -13, -1, -14},  {5, 0, 7, 0},
     {-3, 6, -2, 5},     {7, -5, 10, -4},    {4, -11, 6, -12},    {-11, -9, -8, -11},
     {-4, -10, -4, 9},   {7, 7, 9, 5},       {9, -9, 11, -9},     {2, 10, 3, 9},
     {1, -11, 2, -10},   {7, -13, 8, 7},     {10, 11, 14, -4},    {7, 5, 10, 1},
     {-6, 7, -5, 8},     {-5, -12, -4, -14}, {-9, -7, -6, 8},     {-4, 12, -2, 11},
     {3, -2, 5, -4},     {13, 2, 14, -1},    {-1, -8, 0, -7},     {-2, 2, -1, 8},
     {-7, 8, -4, 7},     {14, -4, 12, -4},   {-11, 1, -10, -1},   {-10, 2, -11, -1},
     {-9, -9, -10, -10}, {3, -7, 4, -6},     {3, 13, 5, 12},      {-4, 13, -2, 14},
     {-2, -4, -1, 9},    {5, -14, 8, -12},   {0, -8, 1, -9},      {0, 14, 3, -14},
     {-1, -14, 1, -14},  {1, -14, 3, 4},     {5, -11, 7, -8},     {7, 2, 7, 6},
     {0, -15, 0, -13},   {-10, 3, -9, -12},  {-1, 9, 1, -9},      {-5, -4, -4, -7},
     {0, 12, 2, 11},     {-3, -7, -2, -8},   {-1, 14, 2, 3},      {-14, 2, -4, -6},
     {-6, -1, -4, -4},   {12, 5, 14, 5},     {-5, -13, -1, 12},   {7, 13, 9, -1},
     {6, -10, 14, 1},    {-3, 1, -13, 7},    {12, -6, 10, -6},    {-12, 0, -8, 11},
     {4, -14, 6, -1},    {1, 9, 3, 10},      {-13, 7, -5, -12},   {-3, 3, -8, -8},
     {-2, -14, 2, 12},   {10, 0, 8, -2},     {-5, 12, -9, -11},   {4, -6, 14, 5},
     {-6, -5, -3, -4},   {2, -14, 6, 10},    {2, -2, 3, -1},      {-3, 12, -3, 8},
     {-5, 5, -3, 5},     {-7, -3, -9, -1},   {3, 1, 6, 0},        {4, 9, 7, -4},
     {-13, 5, -11, 4},   {-4, -1, -3, 0},    {-7, 3, -3, 0},      {4, -9, 10, -8},
     {3, 3, 1, -1},      {-11, 9, -5, 14},   {5, -13, 2, 10},     {4, 11, 8, 8},
     {4, -9, 8, 3},      {-14, -3, -12, -2}, {-10, 10, -2, -8},   {-2, 9, 0, 9},
     {4, 12, 10, -9},    {2, -2, 11, -9},    {1, -8, 3, 0},       {2, 14, 5, -6},
     {11, 9, 9, 10},     {13, -1, 14, 0},    {-4, -4, -3, 14},    {-4, 7, -2, 9},
     {5, 12, 14, 3},     {-13, -2, -3, 6},   {2, 3, 12, 9},       {-2, -2, 1, -14},
     {1, -5, -2, 12},    {-2, -9, 1, 10},    {-9, -7, -4, -11},   {-5, 14, 1, -14},
     {-7, 2, -5, 12},    {-8, 5, -9, 3},     {-11, 10, -12, 8},   {-4, 5, -2, -13},
     {3, 4, 14, 1},      {-6, 1, -3, 4},     {4, -14, 14, -5},    {1, -7, 5, -10},
     {-13, -7, -3, 11},  {0, -10, 4, 8},     {-4, -8, -1, -7},    {3, -5, 7, -5},
     {-3, 12, 3, 14},    {3, 8, 12, 6},      {-2, 2, -1, 3},      {2, 7, 5, 6},
     {-8, 0, -5, -14},   {-8, 5, -3, -10},   {10, 11, 2, -4},     {-8, -11, -1, -13},
     {-6, 10, -1, -11},  {1, 6, 5, -5},      {6, 4, 4, 8},        {-2, 2, 3, 14},
     {1, -11, 6, -9},    {-3, 9, -14, 5},    {2, -2, 10, 3},      {3, 10, 14, -4},
     {-1, 6, 4, -14},    {13, 7, 4, -14},    {-7, -13, 1, -3},    {-3, 9, 1, 0},
     {1, 6, 9, -11},     {-10, -11, 0, 7},   {-11, -3, -2, -7},   {-2, -14, 4, -4},
     {5, 13, 0, -8},     {2, 4, 5, 2},       {-1, 0, 3, -3},      {-12, -7, -1, -2}}};

// Per degree, per test: p.x, p.y, q.x, q.y turned by that angle.
using RotatedPattern = std::vector<std::array<std::int8_t, 4 * kTests>>;

const RotatedPattern& rotatedPattern() {
  static const RotatedPattern pattern = [] {
    RotatedPattern rotated(kAngleBins);
    for (int bin = 0; bin < kAngleBins; ++bin) {
      const double angle = 2.0 * std::numbers::pi * bin / kAngleBins;
      const double c = std::cos(angle);
      const double s = std::sin(angle);
      auto& table = rotated[static_cast<std::size_t>(bin)];
      std::size_t k = 0;
      for (const auto& test : kTestPattern) {
        for (std::size_t end = 0; end < 4; end += 2) {
          // Inside the disk before, inside it after: |coordinates| <= kHalfPatch.
          const double x = test[end];
          const double y = test[end + 1];
          table[k++] = static_cast<std::int8_t>(std::lround(c * x - s * y));
          table[k++] = static_cast<std::int8_t>(std::lround(s * x + c * y));
        }
      }
    }
    return rotated;
  }();
  return pattern;
}

// The 32 descriptor bytes of the keypoint at (x, y) of the blurred level; bit
// b of byte i is test 8 i + b.
void describe(const cv::Mat& blurred, int x, int y, float angle_deg, std::uint8_t* out) {
  const RotatedPattern& pattern = rotatedPattern();
  const int bin = static_cast<int>(std::lround(angle_deg * (kAngleBins / 360.0f))) % kAngleBins;
  const std::int8_t* test = pattern[static_cast<std::size_t>(bin)].data();
  const int step = static_cast<int>(blurred.step);
  const std::uint8_t* centre = blurred.ptr<std::uint8_t>(y) + x;
  for (std::size_t byte = 0; byte < kDescriptorBytes; ++byte) {
    unsigned bits = 0;
    for (unsigned bit = 0; bit < 8; ++bit, test += 4) {
      const std::uint8_t p = centre[test[1] * step + test[0]];
      const std::uint8_t q = centre[test[3] * step + test[2]];
      bits |= static_cast<unsigned>(p < q) << bit;
    }
    out[byte] = static_cast<std::uint8_t>(bits);
  }
}

// Per feature of a its best and second best distance to b, and per feature of b
// the feature of a closest to it among those that had it as a candidate.
struct MatchState {
  std::vector<int> best_b;     // per feature of a: best j, -1 if none
  std::vector<int> best_dist;  // its distance
  std::vector<int> second;     // distance of the second best
  std::vector<int> best_a;     // per feature of b: best i among the a that saw it
  std::vector<int> best_a_dist;
};

// for_each_candidate(i, visit) calls visit(j) for every feature j of b that
// feature i of a may match.
template <class ForEachCandidate>
std::vector<cv::DMatch> matchCandidates(const Features& a, const Features& b, int max_hamming,
                                        float ratio, ForEachCandidate&& for_each_candidate) {
  const int na = static_cast<int>(a.keypoints.size());
  const int nb = static_cast<int>(b.keypoints.size());
  std::vector<cv::DMatch> matches;
  if (na == 0 || nb == 0) return matches;
  if (a.descriptors.rows != na || b.descriptors.rows != nb || a.descriptors.type() != CV_8U ||
      b.descriptors.type() != CV_8U || a.descriptors.cols != b.descriptors.cols) {
    throw std::invalid_argument("vo_feature matching: descriptors do not fit the keypoints");
  }
  constexpr int kNone = std::numeric_limits<int>::max();
  MatchState s{std::vector<int>(na, -1), std::vector<int>(na, kNone), std::vector<int>(na, kNone),
               std::vector<int>(nb, -1), std::vector<int>(nb, kNone)};
  for (int i = 0; i < na; ++i) {
    for_each_candidate(i, [&](int j) {
      const int d = hammingDistance(a.descriptors, i, b.descriptors, j);
      if (d < s.best_dist[i]) {
        s.second[i] = s.best_dist[i];
        s.best_dist[i] = d;
        s.best_b[i] = j;
      } else if (d < s.second[i]) {
        s.second[i] = d;
      }
      if (d < s.best_a_dist[j]) {
        s.best_a_dist[j] = d;
        s.best_a[j] = i;
      }
    });
  }
  for (int i = 0; i < na; ++i) {
    const int j = s.best_b[i];
    if (j < 0 || s.best_dist[i] > max_hamming || s.best_a[j] != i) continue;
    if (ratio < 1.0f && s.second[i] != kNone &&
        !(static_cast<float>(s.best_dist[i]) < ratio * static_cast<float>(s.second[i]))) {
      continue;
    }
    matches.emplace_back(i, j, static_cast<float>(s.best_dist[i]));
  }
  return matches;
}

double shortestDouble(float value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::strtod(std::string(buffer, end).c_str(), nullptr);
}

}  // namespace

void FeatureParams::visit(core::ParamVisitor& v) {
  v.field("num_features", &num_features,
          {.doc = "features wanted over all pyramid levels", .min = 1, .max = 100000});
  v.field("grid_cols", &grid_cols,
          {.doc = "columns of the grid each level is cut into (spreads the features)",
           .min = 1,
           .max = 100});
  v.field("grid_rows", &grid_rows,
          {.doc = "rows of the grid each level is cut into", .min = 1, .max = 100});
  // The params files hold doubles; the float goes through its shortest decimal
  // form so 1.2f prints as 1.2.
  double scale = shortestDouble(scale_factor);
  v.field("scale_factor", &scale, {.doc = "scale between pyramid levels", .min = 1.01, .max = 4.0});
  scale_factor = static_cast<float>(scale);
  v.field("num_levels", &num_levels, {.doc = "pyramid levels", .min = 1, .max = 16});
  v.field("fast_threshold", &fast_threshold,
          {.doc = "FAST threshold, grey levels", .min = 1, .max = 255});
  v.field("min_fast_threshold", &min_fast_threshold,
          {.doc = "FAST threshold in cells with too few corners, grey levels (<= fast_threshold)",
           .min = 1,
           .max = 255});
}

Features extractOrb(const cv::Mat& gray, const FeatureParams& params) {
  if (gray.empty() || gray.type() != CV_8UC1) {
    throw std::invalid_argument("extractOrb: expected an 8-bit single-channel image");
  }
  validate(params);
  const std::vector<int> per_level = featuresPerLevel(params);

  // The pyramid, each level resized from the one before (as ORB-SLAM), into
  // this thread's level buffers of the last call (same sizes: no allocation).
  thread_local std::vector<cv::Mat> level_buffers;
  std::vector<cv::Mat> pyramid{gray};
  for (int level = 1; level < params.num_levels; ++level) {
    const double scale = std::pow(static_cast<double>(params.scale_factor), level);
    const cv::Size size(cvRound(gray.cols / scale), cvRound(gray.rows / scale));
    if (size.width <= 2 * kBorderPx || size.height <= 2 * kBorderPx) break;
    if (level_buffers.size() < static_cast<std::size_t>(level)) level_buffers.resize(level);
    cv::Mat& smaller = level_buffers[static_cast<std::size_t>(level - 1)];
    cv::resize(pyramid.back(), smaller, size, 0, 0, cv::INTER_LINEAR);
    pyramid.push_back(smaller);
  }

  // Levels in parallel, each into its own lists: the result does not depend on
  // the threads.
  const std::size_t levels = pyramid.size();
  std::vector<std::vector<cv::KeyPoint>> per_level_keypoints(levels);
  std::vector<cv::Mat> per_level_descriptors(levels);
  cv::parallel_for_(cv::Range(0, static_cast<int>(levels)), [&](const cv::Range& range) {
    for (int level = range.start; level < range.end; ++level) {
      const cv::Mat& level_image = pyramid[static_cast<std::size_t>(level)];
      Scratch& scratch = threadScratch();
      const std::vector<Corner> corners =
          detectOnLevel(level_image, per_level[static_cast<std::size_t>(level)], params, scratch);
      if (corners.empty()) continue;
      // The descriptor tests compare pixels of the blurred level (as ORB).
      const cv::Mat blurred = blurAroundCorners(level_image, corners, scratch);
      const double scale = std::pow(static_cast<double>(params.scale_factor), level);
      std::vector<cv::KeyPoint>& keypoints = per_level_keypoints[static_cast<std::size_t>(level)];
      cv::Mat& descriptors = per_level_descriptors[static_cast<std::size_t>(level)];
      keypoints.reserve(corners.size());
      descriptors.create(static_cast<int>(corners.size()), static_cast<int>(kDescriptorBytes),
                         CV_8U);
      for (const Corner& corner : corners) {
        const float angle = centroidAngleDeg(level_image, corner.x, corner.y);
        describe(blurred, corner.x, corner.y, angle,
                 descriptors.ptr<std::uint8_t>(static_cast<int>(keypoints.size())));
        keypoints.emplace_back(static_cast<float>(corner.x * scale),
                               static_cast<float>(corner.y * scale),
                               static_cast<float>(kPatchSize * scale), angle,
                               static_cast<float>(corner.score), level, -1);
      }
    }
  });
  Features features;
  for (std::size_t level = 0; level < levels; ++level) {
    features.keypoints.insert(features.keypoints.end(), per_level_keypoints[level].begin(),
                              per_level_keypoints[level].end());
  }
  if (features.keypoints.empty()) return features;
  std::erase_if(per_level_descriptors, [](const cv::Mat& m) { return m.empty(); });
  cv::vconcat(per_level_descriptors, features.descriptors);
  return features;
}

int hammingDistance(const cv::Mat& descriptors_a, int row_a, const cv::Mat& descriptors_b,
                    int row_b) {
  return cv::hal::normHamming(descriptors_a.ptr<std::uint8_t>(row_a),
                              descriptors_b.ptr<std::uint8_t>(row_b), descriptors_a.cols);
}

std::vector<cv::DMatch> matchByWindow(const Features& a, const Features& b,
                                      const std::vector<cv::Point2f>& predicted_in_b,
                                      float radius_px, int max_hamming, float ratio) {
  if (predicted_in_b.size() != a.keypoints.size()) {
    throw std::invalid_argument("matchByWindow: " + std::to_string(predicted_in_b.size()) +
                                " predictions for " + std::to_string(a.keypoints.size()) +
                                " features");
  }
  if (!(radius_px > 0.0f)) throw std::invalid_argument("matchByWindow: radius_px must be > 0");
  if (b.keypoints.empty()) return {};

  // Features of b bucketed in square cells of the window's radius.
  float min_x = b.keypoints[0].pt.x;
  float min_y = b.keypoints[0].pt.y;
  float max_x = min_x;
  float max_y = min_y;
  for (const cv::KeyPoint& kp : b.keypoints) {
    min_x = std::min(min_x, kp.pt.x);
    min_y = std::min(min_y, kp.pt.y);
    max_x = std::max(max_x, kp.pt.x);
    max_y = std::max(max_y, kp.pt.y);
  }
  const float cell = std::max(radius_px, 1.0f);
  const int cols = static_cast<int>((max_x - min_x) / cell) + 1;
  const int rows = static_cast<int>((max_y - min_y) / cell) + 1;
  std::vector<std::vector<int>> buckets(static_cast<std::size_t>(cols) * rows);
  for (int j = 0; j < static_cast<int>(b.keypoints.size()); ++j) {
    const int cx = static_cast<int>((b.keypoints[j].pt.x - min_x) / cell);
    const int cy = static_cast<int>((b.keypoints[j].pt.y - min_y) / cell);
    buckets[static_cast<std::size_t>(cy) * cols + cx].push_back(j);
  }
  const float radius2 = radius_px * radius_px;

  return matchCandidates(a, b, max_hamming, ratio, [&](int i, auto&& visit) {
    const cv::Point2f p = predicted_in_b[static_cast<std::size_t>(i)];
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    const int cx0 = std::max(0, static_cast<int>(std::floor((p.x - radius_px - min_x) / cell)));
    const int cx1 =
        std::min(cols - 1, static_cast<int>(std::floor((p.x + radius_px - min_x) / cell)));
    const int cy0 = std::max(0, static_cast<int>(std::floor((p.y - radius_px - min_y) / cell)));
    const int cy1 =
        std::min(rows - 1, static_cast<int>(std::floor((p.y + radius_px - min_y) / cell)));
    for (int cy = cy0; cy <= cy1; ++cy) {
      for (int cx = cx0; cx <= cx1; ++cx) {
        for (int j : buckets[static_cast<std::size_t>(cy) * cols + cx]) {
          const cv::Point2f d = b.keypoints[static_cast<std::size_t>(j)].pt - p;
          if (d.x * d.x + d.y * d.y <= radius2) visit(j);
        }
      }
    }
  });
}

std::vector<cv::DMatch> matchBruteForce(const Features& a, const Features& b, int max_hamming,
                                        float ratio) {
  const int nb = static_cast<int>(b.keypoints.size());
  return matchCandidates(a, b, max_hamming, ratio, [nb](int, auto&& visit) {
    for (int j = 0; j < nb; ++j) visit(j);
  });
}

std::vector<cv::DMatch> filterByOrientation(const Features& a, const Features& b,
                                            const std::vector<cv::DMatch>& matches, int bins) {
  if (bins < 1) throw std::invalid_argument("filterByOrientation: bins must be >= 1");
  std::vector<int> bin_of(matches.size());
  std::vector<int> count(static_cast<std::size_t>(bins), 0);
  for (std::size_t k = 0; k < matches.size(); ++k) {
    float rotation_deg = b.keypoints[static_cast<std::size_t>(matches[k].trainIdx)].angle -
                         a.keypoints[static_cast<std::size_t>(matches[k].queryIdx)].angle;
    rotation_deg = std::fmod(rotation_deg, 360.0f);
    if (rotation_deg < 0.0f) rotation_deg += 360.0f;
    const int bin =
        std::min(bins - 1, static_cast<int>(rotation_deg / 360.0f * static_cast<float>(bins)));
    bin_of[k] = bin;
    ++count[static_cast<std::size_t>(bin)];
  }
  // The three fullest bins (lowest index first on ties).
  std::vector<int> order(static_cast<std::size_t>(bins));
  for (int i = 0; i < bins; ++i) order[static_cast<std::size_t>(i)] = i;
  std::stable_sort(order.begin(), order.end(), [&count](int x, int y) {
    return count[static_cast<std::size_t>(x)] > count[static_cast<std::size_t>(y)];
  });
  std::vector<bool> keep_bin(static_cast<std::size_t>(bins), false);
  const int fullest = bins > 0 ? count[static_cast<std::size_t>(order[0])] : 0;
  for (int rank = 0; rank < std::min(3, bins); ++rank) {
    const int n = count[static_cast<std::size_t>(order[static_cast<std::size_t>(rank)])];
    if (n == 0 || (rank > 0 && n < 0.1 * fullest)) break;
    keep_bin[static_cast<std::size_t>(order[static_cast<std::size_t>(rank)])] = true;
  }
  std::vector<cv::DMatch> kept;
  for (std::size_t k = 0; k < matches.size(); ++k) {
    if (keep_bin[static_cast<std::size_t>(bin_of[k])]) kept.push_back(matches[k]);
  }
  return kept;
}

}  // namespace nadir::vo
