// ORB extraction and matching on a synthetic texture: the shift put into
// cv::warpAffine is what the matches must recover.

#include "nodes/vo_feature/features.h"

#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>
#include <set>
#include <tuple>
#include <vector>

namespace nadir::vo {
namespace {

constexpr int kWidth = 1280;
constexpr int kHeight = 960;
// Keypoints keep this far from the image border (the descriptor patch fits).
constexpr int kBorder = 19;

// Smooth noise at three scales under random rectangles and disks: corners and
// blobs at every pyramid level, nothing repeats.
cv::Mat texture(unsigned seed) {
  cv::RNG rng(seed);
  cv::Mat image(kHeight, kWidth, CV_32F, cv::Scalar(0));
  for (const int cell : {64, 16, 4}) {
    cv::Mat coarse(kHeight / cell + 2, kWidth / cell + 2, CV_32F);
    rng.fill(coarse, cv::RNG::UNIFORM, 0.0, 60.0);
    cv::Mat fine;
    cv::resize(coarse, fine, cv::Size((kWidth / cell + 2) * cell, (kHeight / cell + 2) * cell), 0,
               0, cv::INTER_CUBIC);
    image += fine(cv::Rect(0, 0, kWidth, kHeight));
  }
  for (int k = 0; k < 2500; ++k) {
    const cv::Point centre(rng.uniform(0, kWidth), rng.uniform(0, kHeight));
    const double grey = rng.uniform(0.0, 255.0);
    if (k % 2 == 0) {
      const cv::Point half(rng.uniform(3, 25), rng.uniform(3, 25));
      cv::rectangle(image, centre - half, centre + half, cv::Scalar(grey), cv::FILLED);
    } else {
      cv::circle(image, centre, rng.uniform(3, 20), cv::Scalar(grey), cv::FILLED, cv::LINE_AA);
    }
  }
  cv::Mat gray;
  image.convertTo(gray, CV_8U);
  cv::GaussianBlur(gray, gray, cv::Size(0, 0), 0.8);
  return gray;
}

cv::Mat shifted(const cv::Mat& image, double dx, double dy) {
  const cv::Matx23d shift(1, 0, dx, 0, 1, dy);
  cv::Mat out;
  cv::warpAffine(image, out, shift, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  return out;
}

// Share of matches whose displacement is (dx, dy) within a level pixel.
double shareWithShift(const Features& a, const Features& b, const std::vector<cv::DMatch>& matches,
                      double dx, double dy, float scale_factor) {
  int right = 0;
  for (const cv::DMatch& m : matches) {
    const cv::KeyPoint& ka = a.keypoints[static_cast<std::size_t>(m.queryIdx)];
    const cv::KeyPoint& kb = b.keypoints[static_cast<std::size_t>(m.trainIdx)];
    const double tolerance = std::pow(scale_factor, ka.octave);
    if (std::hypot(kb.pt.x - ka.pt.x - dx, kb.pt.y - ka.pt.y - dy) <= tolerance) ++right;
  }
  return matches.empty() ? 0.0 : static_cast<double>(right) / static_cast<double>(matches.size());
}

class FeaturesTest : public ::testing::Test {
 protected:
  FeatureParams params_;
  cv::Mat image_ = texture(11);
};

// About num_features features with descriptors, and every cell of the grid gets some.
TEST_F(FeaturesTest, SpreadOverTheGrid) {
  const Features f = extractOrb(image_, params_);
  EXPECT_LE(static_cast<int>(f.keypoints.size()), params_.num_features);
  EXPECT_GE(static_cast<int>(f.keypoints.size()), params_.num_features * 9 / 10);
  ASSERT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
  EXPECT_EQ(f.descriptors.cols, 32);
  EXPECT_EQ(f.descriptors.type(), CV_8U);

  const int cols = params_.grid_cols;
  const int rows = params_.grid_rows;
  std::vector<int> per_cell(static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows), 0);
  std::set<int> octaves;
  for (const cv::KeyPoint& kp : f.keypoints) {
    const int c = std::min(cols - 1, static_cast<int>(kp.pt.x / kWidth * static_cast<float>(cols)));
    const int r =
        std::min(rows - 1, static_cast<int>(kp.pt.y / kHeight * static_cast<float>(rows)));
    ++per_cell[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) +
               static_cast<std::size_t>(c)];
    octaves.insert(kp.octave);
    EXPECT_GE(kp.angle, 0.0f);
    EXPECT_LT(kp.angle, 360.0f);
  }
  for (std::size_t k = 0; k < per_cell.size(); ++k) {
    EXPECT_GE(per_cell[k], 10) << "cell " << k;
  }
  EXPECT_EQ(static_cast<int>(octaves.size()), params_.num_levels);
}

// With one level and one cell wanting more than there are, the keypoints are
// all FAST corners: the same positions and scores as cv::FAST with non-maximum
// suppression, inside the border.
TEST_F(FeaturesTest, FindsWhatCvFastFinds) {
  FeatureParams all = params_;
  all.num_levels = 1;
  all.grid_cols = 1;
  all.grid_rows = 1;
  all.num_features = 100000;
  for (const int threshold : {7, 20, 45}) {
    all.fast_threshold = threshold;
    all.min_fast_threshold = threshold;
    const Features f = extractOrb(image_, all);
    std::vector<cv::KeyPoint> reference;
    cv::FAST(image_, reference, threshold, true);
    std::set<std::tuple<float, float, float>> expected;
    for (const cv::KeyPoint& kp : reference) {
      if (kp.pt.x >= kBorder && kp.pt.x < kWidth - kBorder && kp.pt.y >= kBorder &&
          kp.pt.y < kHeight - kBorder) {
        expected.emplace(kp.pt.x, kp.pt.y, kp.response);
      }
    }
    std::set<std::tuple<float, float, float>> got;
    for (const cv::KeyPoint& kp : f.keypoints) got.emplace(kp.pt.x, kp.pt.y, kp.response);
    EXPECT_EQ(got, expected) << "threshold " << threshold;
    EXPECT_GT(got.size(), 1000u);
  }
}

// On one level, every cell keeps its share of the strongest cv::FAST corners
// at fast_threshold, at min_fast_threshold if it has fewer; the rest goes to
// the strongest left-overs (fast_threshold ones, or the poor cells'). The
// left half is so faint that its cells fall back and still leave most of
// their shares to the right half.
TEST_F(FeaturesTest, CellsKeepTheirStrongestCorners) {
  cv::Mat half = image_.clone();
  cv::Mat faint = half(cv::Rect(0, 0, kWidth / 2, kHeight));
  faint.convertTo(faint, CV_8U, 0.06, 100.0);
  FeatureParams one = params_;
  one.num_levels = 1;
  for (const int wanted : {2000, 300}) {
    one.num_features = wanted;
    const Features f = extractOrb(half, one);
    std::vector<cv::KeyPoint> strong;
    std::vector<cv::KeyPoint> weak;
    cv::FAST(half, strong, one.fast_threshold, true);
    cv::FAST(half, weak, one.min_fast_threshold, true);
    const int width = kWidth - 2 * kBorder;
    const int height = kHeight - 2 * kBorder;
    const int share = wanted / (one.grid_cols * one.grid_rows);
    const auto stronger = [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
      return std::tuple(-a.response, a.pt.y, a.pt.x) < std::tuple(-b.response, b.pt.y, b.pt.x);
    };
    std::vector<cv::KeyPoint> kept;
    std::vector<cv::KeyPoint> spare;
    for (int r = 0; r < one.grid_rows; ++r) {
      for (int c = 0; c < one.grid_cols; ++c) {
        const cv::Rect cell(kBorder + c * width / one.grid_cols,
                            kBorder + r * height / one.grid_rows, 0, 0);
        const cv::Point end(kBorder + (c + 1) * width / one.grid_cols,
                            kBorder + (r + 1) * height / one.grid_rows);
        const auto in_cell = [&](const std::vector<cv::KeyPoint>& corners) {
          std::vector<cv::KeyPoint> out;
          for (const cv::KeyPoint& kp : corners) {
            if (kp.pt.x >= cell.x && kp.pt.x < end.x && kp.pt.y >= cell.y && kp.pt.y < end.y) {
              out.push_back(kp);
            }
          }
          return out;
        };
        std::vector<cv::KeyPoint> corners = in_cell(strong);
        if (static_cast<int>(corners.size()) < std::max(share, 1)) corners = in_cell(weak);
        std::sort(corners.begin(), corners.end(), stronger);
        const std::size_t take = std::min(corners.size(), static_cast<std::size_t>(share));
        kept.insert(kept.end(), corners.begin(), corners.begin() + static_cast<long>(take));
        spare.insert(spare.end(), corners.begin() + static_cast<long>(take), corners.end());
      }
    }
    std::sort(spare.begin(), spare.end(), stronger);
    const std::size_t missing = static_cast<std::size_t>(wanted) - kept.size();
    kept.insert(kept.end(), spare.begin(),
                spare.begin() + static_cast<long>(std::min(missing, spare.size())));
    std::sort(kept.begin(), kept.end(), stronger);
    ASSERT_EQ(f.keypoints.size(), kept.size()) << wanted << " wanted";
    for (std::size_t i = 0; i < kept.size(); ++i) {
      EXPECT_EQ(f.keypoints[i].pt, kept[i].pt) << i;
      EXPECT_EQ(f.keypoints[i].response, kept[i].response) << i;
    }
  }
}

// A uniform image has no corners, at either threshold.
TEST_F(FeaturesTest, FlatImageHasNoFeatures) {
  const Features f = extractOrb(cv::Mat(480, 640, CV_8U, cv::Scalar(128)), params_);
  EXPECT_TRUE(f.keypoints.empty());
  EXPECT_TRUE(f.descriptors.empty());
}

// Images smaller than the descriptor's border have no features; small ones a few.
TEST_F(FeaturesTest, SmallImages) {
  EXPECT_TRUE(extractOrb(image_(cv::Rect(0, 0, 38, 200)).clone(), params_).keypoints.empty());
  const Features f = extractOrb(image_(cv::Rect(0, 0, 120, 90)).clone(), params_);
  EXPECT_GT(f.keypoints.size(), 50u);
  EXPECT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
}

// A weak texture still gets features through the fallback threshold.
TEST_F(FeaturesTest, WeakTextureFallsBackToTheLowThreshold) {
  cv::Mat weak;
  image_.convertTo(weak, CV_8U, 0.12, 100.0);
  FeatureParams no_fallback = params_;
  no_fallback.min_fast_threshold = no_fallback.fast_threshold;
  const std::size_t with = extractOrb(weak, params_).keypoints.size();
  const std::size_t without = extractOrb(weak, no_fallback).keypoints.size();
  EXPECT_GT(with, 2 * without);
  EXPECT_GT(with, static_cast<std::size_t>(params_.num_features / 2));
}

// The same image gives the same keypoints and descriptors, call after call and
// on any number of threads.
TEST_F(FeaturesTest, Deterministic) {
  const Features a = extractOrb(image_, params_);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const Features b = extractOrb(image_, params_);
  cv::setNumThreads(threads);
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  for (std::size_t i = 0; i < a.keypoints.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].pt, b.keypoints[i].pt);
    EXPECT_EQ(a.keypoints[i].angle, b.keypoints[i].angle);
    EXPECT_EQ(a.keypoints[i].octave, b.keypoints[i].octave);
    EXPECT_EQ(a.keypoints[i].response, b.keypoints[i].response);
  }
  EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_INF), 0.0);
}

// Bad input is refused with an exception, not a crash.
TEST_F(FeaturesTest, RefusesBadInput) {
  EXPECT_THROW(extractOrb(cv::Mat(), params_), std::invalid_argument);
  EXPECT_THROW(extractOrb(cv::Mat(100, 100, CV_8UC3), params_), std::invalid_argument);
  FeatureParams bad = params_;
  bad.min_fast_threshold = bad.fast_threshold + 1;
  EXPECT_THROW(extractOrb(image_, bad), std::invalid_argument);
  const Features f = extractOrb(image_, params_);
  EXPECT_THROW(matchByWindow(f, f, {}, 10.0f, 50, 0.8f), std::invalid_argument);
}

// Window matching with no motion prior finds the (+7, -4) px shift of a copy.
TEST_F(FeaturesTest, WindowMatchingRecoversAShift) {
  const Features a = extractOrb(image_, params_);
  const Features b = extractOrb(shifted(image_, 7.0, -4.0), params_);
  std::vector<cv::Point2f> predicted;
  for (const cv::KeyPoint& kp : a.keypoints) predicted.push_back(kp.pt);
  const std::vector<cv::DMatch> matches = matchByWindow(a, b, predicted, 16.0f, 50, 0.8f);
  EXPECT_GT(matches.size(), a.keypoints.size() / 2);
  EXPECT_GT(shareWithShift(a, b, matches, 7.0, -4.0, params_.scale_factor), 0.9);
  std::set<int> used;
  for (const cv::DMatch& m : matches) {
    EXPECT_TRUE(used.insert(m.trainIdx).second) << "feature " << m.trainIdx << " matched twice";
    EXPECT_LE(m.distance, 50.0f);
  }
}

// A prediction that is off by more than the radius finds nothing right.
TEST_F(FeaturesTest, WindowMatchingStaysInTheWindow) {
  const Features a = extractOrb(image_, params_);
  const Features b = extractOrb(shifted(image_, 7.0, -4.0), params_);
  std::vector<cv::Point2f> predicted;
  for (const cv::KeyPoint& kp : a.keypoints) predicted.push_back(kp.pt + cv::Point2f(-30, 30));
  const std::vector<cv::DMatch> matches = matchByWindow(a, b, predicted, 16.0f, 50, 0.8f);
  EXPECT_EQ(shareWithShift(a, b, matches, 7.0, -4.0, params_.scale_factor), 0.0);
}

// Brute-force matching finds the same shift without any prediction.
TEST_F(FeaturesTest, BruteForceMatchingRecoversAShift) {
  const Features a = extractOrb(image_, params_);
  const Features b = extractOrb(shifted(image_, 7.0, -4.0), params_);
  const std::vector<cv::DMatch> matches = matchBruteForce(a, b, 50, 0.8f);
  EXPECT_GT(matches.size(), a.keypoints.size() / 3);
  EXPECT_GT(shareWithShift(a, b, matches, 7.0, -4.0, params_.scale_factor), 0.9);
}

// The descriptors turn with the keypoint angle: a copy rotated by 30 degrees
// about the centre matches without any prediction, and the matches land where
// the rotation puts them.
TEST_F(FeaturesTest, MatchesAcrossAnInPlaneRotation) {
  const cv::Point2f centre(kWidth / 2.0f, kHeight / 2.0f);
  const cv::Mat rotation = cv::getRotationMatrix2D(centre, 30.0, 1.0);
  cv::Mat rotated;
  cv::warpAffine(image_, rotated, rotation, image_.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                 cv::Scalar(0));
  const Features a = extractOrb(image_, params_);
  const Features b = extractOrb(rotated, params_);
  const std::vector<cv::DMatch> matches = matchBruteForce(a, b, 64, 0.9f);
  int right = 0;
  for (const cv::DMatch& m : matches) {
    const cv::KeyPoint& ka = a.keypoints[static_cast<std::size_t>(m.queryIdx)];
    const cv::KeyPoint& kb = b.keypoints[static_cast<std::size_t>(m.trainIdx)];
    const cv::Point2d expected(rotation.at<double>(0, 0) * ka.pt.x +
                                   rotation.at<double>(0, 1) * ka.pt.y + rotation.at<double>(0, 2),
                               rotation.at<double>(1, 0) * ka.pt.x +
                                   rotation.at<double>(1, 1) * ka.pt.y + rotation.at<double>(1, 2));
    const double tolerance = 2.0 * std::pow(params_.scale_factor, std::max(ka.octave, kb.octave));
    if (cv::norm(expected - cv::Point2d(kb.pt)) <= tolerance) ++right;
  }
  // A fifth of the image or so turns out of view.
  EXPECT_GT(right, static_cast<int>(a.keypoints.size()) * 2 / 5);
  EXPECT_GT(static_cast<double>(right), 0.95 * static_cast<double>(matches.size()));
}

// The orientation histogram keeps the true matches and drops random pairings.
TEST_F(FeaturesTest, OrientationFilterDropsInconsistentMatches) {
  const Features a = extractOrb(image_, params_);
  const Features b = extractOrb(shifted(image_, 7.0, -4.0), params_);
  std::vector<cv::Point2f> predicted;
  for (const cv::KeyPoint& kp : a.keypoints) predicted.push_back(kp.pt + cv::Point2f(7, -4));
  const std::vector<cv::DMatch> good = matchByWindow(a, b, predicted, 4.0f, 50, 0.8f);
  std::vector<cv::DMatch> all = good;
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pick_a(0, static_cast<int>(a.keypoints.size()) - 1);
  std::uniform_int_distribution<int> pick_b(0, static_cast<int>(b.keypoints.size()) - 1);
  const int fakes = 300;
  // The fakes carry imgIdx 1.
  for (int k = 0; k < fakes; ++k) all.emplace_back(pick_a(rng), pick_b(rng), 1, 40.0f);

  const std::vector<cv::DMatch> kept = filterByOrientation(a, b, all);
  std::size_t fakes_kept = 0;
  for (const cv::DMatch& m : kept) fakes_kept += m.imgIdx == 1 ? 1 : 0;
  const std::size_t good_kept = kept.size() - fakes_kept;
  EXPECT_GT(static_cast<double>(good_kept), 0.95 * static_cast<double>(good.size()));
  EXPECT_LT(fakes_kept, static_cast<std::size_t>(fakes / 4));
}

}  // namespace
}  // namespace nadir::vo
