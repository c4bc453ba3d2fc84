#include "nodes/vo_feature/features.h"

#include <opencv2/core/hal/hal.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

namespace nadir::vo {

namespace {

// Keypoints stay this far from every level's border (ORB-SLAM's EDGE_THRESHOLD):
// the rotated 31 px descriptor patch and the orientation disk fit inside.
constexpr int kBorderPx = 19;
constexpr int kPatchSize = 31;
constexpr int kHalfPatch = kPatchSize / 2;
// FAST needs a 3 px ring around a candidate.
constexpr int kFastRing = 3;

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

// Column bounds of the disk of radius kHalfPatch: u in [-umax[v], umax[v]] on row v.
std::vector<int> diskBounds() {
  std::vector<int> umax(kHalfPatch + 1);
  for (int v = 0; v <= kHalfPatch; ++v) {
    umax[static_cast<std::size_t>(v)] =
        static_cast<int>(std::lround(std::sqrt(double(kHalfPatch * kHalfPatch - v * v))));
  }
  return umax;
}

// Orientation by the intensity centroid of the disk around (x, y), degrees in [0, 360).
float centroidAngleDeg(const cv::Mat& level_image, int x, int y, const std::vector<int>& umax) {
  long m_01 = 0;
  long m_10 = 0;
  for (int v = -kHalfPatch; v <= kHalfPatch; ++v) {
    const int d = umax[static_cast<std::size_t>(std::abs(v))];
    const std::uint8_t* row = level_image.ptr<std::uint8_t>(y + v);
    for (int u = -d; u <= d; ++u) {
      const int value = row[x + u];
      m_10 += static_cast<long>(u) * value;
      m_01 += static_cast<long>(v) * value;
    }
  }
  return cv::fastAtan2(static_cast<float>(m_01), static_cast<float>(m_10));
}

// Strongest first; ties broken by position so the order never depends on the sort.
bool strongerThan(const cv::KeyPoint& a, const cv::KeyPoint& b) {
  if (a.response != b.response) return a.response > b.response;
  if (a.pt.y != b.pt.y) return a.pt.y < b.pt.y;
  return a.pt.x < b.pt.x;
}

// FAST corners of one cell [x0, x1) x [y0, y1) of a level, in level pixels.
std::vector<cv::KeyPoint> fastInCell(const cv::Mat& level_image, int x0, int y0, int x1, int y1,
                                     int threshold) {
  const cv::Rect roi(x0 - kFastRing, y0 - kFastRing, x1 - x0 + 2 * kFastRing,
                     y1 - y0 + 2 * kFastRing);
  std::vector<cv::KeyPoint> corners;
  cv::FAST(level_image(roi), corners, threshold, true);
  for (cv::KeyPoint& corner : corners) {
    corner.pt.x += static_cast<float>(roi.x);
    corner.pt.y += static_cast<float>(roi.y);
  }
  return corners;
}

// The grid-spread corners of one level (level pixels), at most `wanted`.
std::vector<cv::KeyPoint> detectOnLevel(const cv::Mat& level_image, int wanted,
                                        const FeatureParams& params) {
  std::vector<cv::KeyPoint> kept;
  const int width = level_image.cols - 2 * kBorderPx;
  const int height = level_image.rows - 2 * kBorderPx;
  if (wanted <= 0 || width < 1 || height < 1) return kept;
  const int cols = std::min(params.grid_cols, width);
  const int rows = std::min(params.grid_rows, height);
  const int share = wanted / (cols * rows);

  std::vector<cv::KeyPoint> spare;
  for (int r = 0; r < rows; ++r) {
    const int y0 = kBorderPx + r * height / rows;
    const int y1 = kBorderPx + (r + 1) * height / rows;
    for (int c = 0; c < cols; ++c) {
      const int x0 = kBorderPx + c * width / cols;
      const int x1 = kBorderPx + (c + 1) * width / cols;
      std::vector<cv::KeyPoint> corners =
          fastInCell(level_image, x0, y0, x1, y1, params.fast_threshold);
      if (static_cast<int>(corners.size()) < std::max(share, 1) &&
          params.min_fast_threshold < params.fast_threshold) {
        corners = fastInCell(level_image, x0, y0, x1, y1, params.min_fast_threshold);
      }
      std::sort(corners.begin(), corners.end(), strongerThan);
      const std::size_t take = std::min(corners.size(), static_cast<std::size_t>(share));
      kept.insert(kept.end(), corners.begin(), corners.begin() + static_cast<long>(take));
      spare.insert(spare.end(), corners.begin() + static_cast<long>(take), corners.end());
    }
  }
  // What the poor cells could not use goes to the strongest corners left anywhere.
  const std::size_t missing = static_cast<std::size_t>(wanted) - kept.size();
  if (missing > 0 && !spare.empty()) {
    const std::size_t take = std::min(missing, spare.size());
    std::partial_sort(spare.begin(), spare.begin() + static_cast<long>(take), spare.end(),
                      strongerThan);
    kept.insert(kept.end(), spare.begin(), spare.begin() + static_cast<long>(take));
  }
  return kept;
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
  const std::vector<int> umax = diskBounds();

  // The pyramid, with the same level sizes and interpolation as cv::ORB, which
  // computes the descriptors.
  std::vector<cv::Mat> pyramid{gray};
  for (int level = 1; level < params.num_levels; ++level) {
    const double scale = std::pow(static_cast<double>(params.scale_factor), level);
    const cv::Size size(cvRound(gray.cols / scale), cvRound(gray.rows / scale));
    if (size.width <= 2 * kBorderPx || size.height <= 2 * kBorderPx) break;
    cv::Mat smaller;
    cv::resize(pyramid.back(), smaller, size, 0, 0, cv::INTER_LINEAR_EXACT);
    pyramid.push_back(smaller);
  }

  // Levels in parallel, each into its own list: the result does not depend on
  // the threads.
  std::vector<std::vector<cv::KeyPoint>> per_level_keypoints(pyramid.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(pyramid.size())), [&](const cv::Range& range) {
    for (int level = range.start; level < range.end; ++level) {
      const cv::Mat& level_image = pyramid[static_cast<std::size_t>(level)];
      const double scale = std::pow(static_cast<double>(params.scale_factor), level);
      std::vector<cv::KeyPoint> corners =
          detectOnLevel(level_image, per_level[static_cast<std::size_t>(level)], params);
      std::sort(corners.begin(), corners.end(), strongerThan);
      for (cv::KeyPoint& corner : corners) {
        const int x = cvRound(corner.pt.x);
        const int y = cvRound(corner.pt.y);
        corner.angle = centroidAngleDeg(level_image, x, y, umax);
        corner.octave = level;
        corner.size = static_cast<float>(kPatchSize * scale);
        corner.pt.x = static_cast<float>(x * scale);
        corner.pt.y = static_cast<float>(y * scale);
        corner.class_id = -1;
      }
      per_level_keypoints[static_cast<std::size_t>(level)] = std::move(corners);
    }
  });
  Features features;
  for (const std::vector<cv::KeyPoint>& level_keypoints : per_level_keypoints) {
    features.keypoints.insert(features.keypoints.end(), level_keypoints.begin(),
                              level_keypoints.end());
  }
  if (features.keypoints.empty()) return features;

  // cv::ORB with given keypoints keeps their positions, octaves and angles and
  // samples its own blurred pyramid; edgeThreshold = our border, so none is dropped.
  const cv::Ptr<cv::ORB> orb =
      cv::ORB::create(params.num_features, params.scale_factor, params.num_levels, kBorderPx, 0, 2,
                      cv::ORB::HARRIS_SCORE, kPatchSize, params.fast_threshold);
  orb->compute(gray, features.keypoints, features.descriptors);
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
