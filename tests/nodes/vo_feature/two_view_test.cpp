// Two-view initialisation on synthetic points seen by two cameras with a known
// motion: the motion that projected the points is what must come back.

#include "nodes/vo_feature/two_view.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>

namespace nadir::vo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kWidth = 1280;
constexpr int kHeight = 960;
const cv::Matx33d kK(800, 0, 640, 0, 800, 480, 0, 0, 1);

struct Motion {
  Eigen::Matrix3d R_21;
  Eigen::Vector3d t_21;
};

// Camera 2 at p_2_in_1 (camera 1's frame), rotated from camera 1 by angle_deg about axis.
Motion motion(const Eigen::Vector3d& p_2_in_1, double angle_deg, const Eigen::Vector3d& axis) {
  const Eigen::Matrix3d R_1_2 = Eigen::AngleAxisd(angle_deg * kDeg, axis.normalized()).matrix();
  return {R_1_2.transpose(), -R_1_2.transpose() * p_2_in_1};
}

Eigen::Vector2d project(const Eigen::Vector3d& p_cam) {
  return {kK(0, 0) * p_cam.x() / p_cam.z() + kK(0, 2), kK(1, 1) * p_cam.y() / p_cam.z() + kK(1, 2)};
}

bool inImage(const Eigen::Vector2d& px) {
  return px.x() >= 0 && px.x() < kWidth && px.y() >= 0 && px.y() < kHeight;
}

struct Views {
  std::vector<Eigen::Vector3d> points_1;  // truth, camera 1
  std::vector<cv::Point2f> px1, px2;
};

// Points through random pixels of camera 1 at depth depth_of(ray), kept when
// camera 2 sees them too; pixel noise of noise_px (Gaussian).
template <class DepthOf>
Views observe(const Motion& m, int count, double noise_px, unsigned seed, DepthOf depth_of) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, kWidth);
  std::uniform_real_distribution<double> v(0.0, kHeight);
  std::normal_distribution<double> noise(0.0, noise_px);
  Views views;
  while (static_cast<int>(views.points_1.size()) < count) {
    const Eigen::Vector3d ray((u(rng) - kK(0, 2)) / kK(0, 0), (v(rng) - kK(1, 2)) / kK(1, 1), 1.0);
    const Eigen::Vector3d p_1 = ray * depth_of(rng);
    const Eigen::Vector3d p_2 = m.R_21 * p_1 + m.t_21;
    if (p_2.z() <= 0.0 || !inImage(project(p_2))) continue;
    const Eigen::Vector2d a = project(p_1) + Eigen::Vector2d(noise(rng), noise(rng));
    const Eigen::Vector2d b = project(p_2) + Eigen::Vector2d(noise(rng), noise(rng));
    views.points_1.push_back(p_1);
    views.px1.emplace_back(static_cast<float>(a.x()), static_cast<float>(a.y()));
    views.px2.emplace_back(static_cast<float>(b.x()), static_cast<float>(b.y()));
  }
  return views;
}

// Ground 120 m below a downward camera, +-1 m of relief.
Views groundViews(const Motion& m, int count, unsigned seed) {
  return observe(m, count, 0.5, seed, [](std::mt19937& rng) {
    return 120.0 + std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
  });
}

double rotationErrorDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() / kDeg;
}

double directionErrorDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) / kDeg;
}

// The median angle between the two cameras' rays to the true points.
double trueMedianParallaxDeg(const Views& views, const Motion& m) {
  const Eigen::Vector3d centre_2_in_1 = -m.R_21.transpose() * m.t_21;
  std::vector<double> parallax;
  for (const Eigen::Vector3d& p : views.points_1) {
    parallax.push_back(directionErrorDeg(p, p - centre_2_in_1));
  }
  std::nth_element(parallax.begin(), parallax.begin() + static_cast<long>(parallax.size() / 2),
                   parallax.end());
  return parallax[parallax.size() / 2];
}

// The relative error of the triangulated points, scaled by the true baseline:
// returns the median and the largest.
std::pair<double, double> pointErrors(const TwoViewResult& r, const Views& views, const Motion& m) {
  std::vector<double> errors;
  for (std::size_t k = 0; k < r.points_1.size(); ++k) {
    const Eigen::Vector3d& truth =
        views.points_1[static_cast<std::size_t>(r.inlier_match_index[k])];
    errors.push_back((r.points_1[k] * m.t_21.norm() - truth).norm() / truth.norm());
  }
  std::sort(errors.begin(), errors.end());
  return {errors[errors.size() / 2], errors.back()};
}

// Flat ground from altitude, sideways motion and a small rotation: the homography
// is chosen and gives the motion back.
TEST(TwoViewTest, PlanarGroundPicksTheHomography) {
  const Motion m = motion({10.0, 4.0, 0.0}, 1.5, {0.3, -0.5, 0.8});
  const Views views = groundViews(m, 400, 1);
  const TwoViewResult r = initialiseTwoView(views.px1, views.px2, kK, {});
  ASSERT_TRUE(r.ok) << r.why_not;
  EXPECT_TRUE(r.used_homography) << "R_H " << r.homography_score_ratio;
  EXPECT_GT(r.homography_score_ratio, 0.45);
  EXPECT_LT(rotationErrorDeg(r.R_21, m.R_21), 0.2);
  EXPECT_LT(directionErrorDeg(r.t_21, m.t_21), 1.0);
  EXPECT_NEAR(r.t_21.norm(), 1.0, 1e-9);
  EXPECT_GT(r.points_1.size(), 360u);
  ASSERT_EQ(r.points_1.size(), r.inlier_match_index.size());
  EXPECT_NEAR(r.median_parallax_deg, trueMedianParallaxDeg(views, m), 0.05);
  // 0.5 px on each side is 0.7 px of disparity out of f b / z = 72 px: 1 % of depth.
  const auto [median_error, max_error] = pointErrors(r, views, m);
  EXPECT_LT(median_error, 0.015);
  EXPECT_LT(max_error, 0.05);
}

// Points spread in depth: the essential matrix is chosen and gives the motion back.
TEST(TwoViewTest, DepthSpreadScenePicksTheEssentialMatrix) {
  const Motion m = motion({1.5, -0.5, 0.8}, 4.0, {-0.2, 0.9, 0.3});
  const Views views = observe(m, 400, 0.5, 2, [](std::mt19937& rng) {
    return std::uniform_real_distribution<double>(8.0, 40.0)(rng);
  });
  const TwoViewResult r = initialiseTwoView(views.px1, views.px2, kK, {});
  ASSERT_TRUE(r.ok) << r.why_not;
  EXPECT_FALSE(r.used_homography) << "R_H " << r.homography_score_ratio;
  EXPECT_LT(r.homography_score_ratio, 0.45);
  EXPECT_LT(rotationErrorDeg(r.R_21, m.R_21), 0.2);
  EXPECT_LT(directionErrorDeg(r.t_21, m.t_21), 1.0);
  EXPECT_GT(r.points_1.size(), 300u);
  // The farthest points (40 m) see f b / z = 36 px of disparity: 2 % of depth.
  const auto [median_error, max_error] = pointErrors(r, views, m);
  EXPECT_LT(median_error, 0.02);
  EXPECT_LT(max_error, 0.1);
}

// A pure rotation shows no depth: refused for its parallax.
TEST(TwoViewTest, PureRotationIsRefused) {
  const Motion m = motion({0.0, 0.0, 0.0}, 3.0, {0.2, 1.0, 0.1});
  const Views views = groundViews(m, 400, 3);
  const TwoViewResult r = initialiseTwoView(views.px1, views.px2, kK, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.why_not.find("parallax"), std::string::npos) << r.why_not;
  EXPECT_TRUE(r.points_1.empty());
}

// A 0.11 m baseline at 120 m (0.05 deg of parallax) is refused for its parallax.
TEST(TwoViewTest, TinyBaselineIsRefused) {
  const Motion m = motion({0.1, 0.05, 0.0}, 1.0, {0.0, 0.0, 1.0});
  const Views views = groundViews(m, 400, 4);
  const TwoViewResult r = initialiseTwoView(views.px1, views.px2, kK, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.why_not.find("parallax"), std::string::npos) << r.why_not;
}

// One match in five replaced by a random pixel: still the right motion, no outlier kept.
TEST(TwoViewTest, SurvivesTwentyPercentOutliers) {
  const Motion m = motion({-6.0, 9.0, 0.0}, 2.0, {0.6, 0.2, -0.7});
  Views views = groundViews(m, 500, 5);
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(0.0f, kWidth);
  std::uniform_real_distribution<float> v(0.0f, kHeight);
  std::set<int> outliers;
  for (int i = 0; i < 500; i += 5) {
    views.px2[static_cast<std::size_t>(i)] = {u(rng), v(rng)};
    outliers.insert(i);
  }
  const TwoViewResult r = initialiseTwoView(views.px1, views.px2, kK, {});
  ASSERT_TRUE(r.ok) << r.why_not;
  EXPECT_TRUE(r.used_homography);
  EXPECT_LT(rotationErrorDeg(r.R_21, m.R_21), 0.2);
  EXPECT_LT(directionErrorDeg(r.t_21, m.t_21), 1.0);
  EXPECT_GT(r.points_1.size(), 360u);
  for (int index : r.inlier_match_index) EXPECT_EQ(outliers.count(index), 0u) << index;
}

// Too few matches are refused before any fitting.
TEST(TwoViewTest, TooFewMatchesAreRefused) {
  const Motion m = motion({10.0, 4.0, 0.0}, 1.5, {0.3, -0.5, 0.8});
  const Views views = groundViews(m, 30, 7);
  const TwoViewResult r = initialiseTwoView(views.px1, views.px2, kK, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.why_not.find("too few matches"), std::string::npos) << r.why_not;
}

// The triangulation helper: an exact match gives the point back; a point behind
// the cameras, one at 100 km and a match off its epipolar line are refused.
TEST(TwoViewTest, TriangulateChecksEachPoint) {
  const Motion m = motion({2.0, 0.5, 0.3}, 3.0, {0.1, 1.0, 0.2});
  const TriangulationChecks checks;
  auto pixels = [&m](const Eigen::Vector3d& p_1) {
    const Eigen::Vector2d a = project(p_1);
    const Eigen::Vector2d b = project(m.R_21 * p_1 + m.t_21);
    return std::pair{cv::Point2f(static_cast<float>(a.x()), static_cast<float>(a.y())),
                     cv::Point2f(static_cast<float>(b.x()), static_cast<float>(b.y()))};
  };
  const Eigen::Vector3d p_1(1.5, -2.0, 30.0);
  auto [a, b] = pixels(p_1);
  Triangulation tri = triangulate(a, b, m.R_21, m.t_21, kK, checks);
  EXPECT_EQ(tri.status, TriangulationStatus::kOk);
  EXPECT_LT((tri.p_1 - p_1).norm(), 1e-3 * p_1.norm());  // float pixels
  EXPECT_NEAR(tri.depth_1, 30.0, 0.03);
  EXPECT_LT(tri.reprojection_error_px, 0.01);
  EXPECT_NEAR(tri.parallax_deg, directionErrorDeg(p_1, p_1 + m.R_21.transpose() * m.t_21), 1e-3);

  std::tie(a, b) = pixels({-1.0, 2.0, -30.0});
  EXPECT_EQ(triangulate(a, b, m.R_21, m.t_21, kK, checks).status,
            TriangulationStatus::kBehindCamera);

  std::tie(a, b) = pixels({100.0, 50.0, 1e5});
  EXPECT_EQ(triangulate(a, b, m.R_21, m.t_21, kK, checks).status,
            TriangulationStatus::kLowParallax);

  std::tie(a, b) = pixels(p_1);
  b.y += 12.0f;
  tri = triangulate(a, b, m.R_21, m.t_21, kK, checks);
  EXPECT_EQ(tri.status, TriangulationStatus::kReprojectionError);
  EXPECT_GT(tri.reprojection_error_px, checks.max_reprojection_error_px);
}

}  // namespace
}  // namespace nadir::vo
