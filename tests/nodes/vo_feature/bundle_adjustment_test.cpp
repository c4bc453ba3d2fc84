// Local bundle adjustment on synthetic scenes: downward cameras over nearly
// planar ground, observations = exact projections + Gaussian noise. Every
// expected value comes from the synthetic ground truth and the noise model.

#include "nodes/vo_feature/bundle_adjustment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <random>
#include <vector>

namespace nadir::vo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kWidth = 1280;
constexpr int kHeight = 960;
constexpr double kAltitudeM = 100.0;
constexpr double kNoisePx = 0.5;

const BaIntrinsics kK{.fx = 700.0, .fy = 700.0, .cx = 640.0, .cy = 480.0};

// A downward camera, top of the image to the north (camera x = east,
// y = south, z = down), tilted by small roll and pitch.
Eigen::Isometry3d downCamera(const Eigen::Vector3d& p_world_m, double roll_rad, double pitch_rad) {
  Eigen::Matrix3d R_level;
  R_level << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix() *
               R_level;
  T.translation() = p_world_m;
  return T;
}

// The exact projection of p_world_m, or false when it is behind or off the
// image.
bool project(const Eigen::Isometry3d& T_world_cam, const Eigen::Vector3d& p_world_m,
             Eigen::Vector2d& px) {
  const Eigen::Vector3d p_cam = T_world_cam.inverse() * p_world_m;
  if (p_cam.z() <= 0.0) {
    return false;
  }
  px =
      Eigen::Vector2d(kK.fx * p_cam.x() / p_cam.z() + kK.cx, kK.fy * p_cam.y() / p_cam.z() + kK.cy);
  return px.x() >= 0 && px.x() < kWidth && px.y() >= 0 && px.y() < kHeight;
}

double rotationErrorRad(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.rotation().transpose() * b.rotation()).angle();
}

Eigen::Vector3d randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
}

struct SceneSpec {
  int num_cameras = 5;
  double spacing_m = 15.0;
  int num_points = 200;
  // Ground area the points are drawn from (this default is seen by all five cameras).
  double north_min_m = -5.0;
  double north_max_m = 65.0;
  double east_half_width_m = 80.0;
  double relief_m = 3.0;          // ground heights uniform in [-relief, relief]
  double noise_px = kNoisePx;     // Gaussian, per image coordinate
  double sigma_px = 1.0;          // given to the BA
  double outlier_fraction = 0.0;  // of the observations, displaced by 30 px
  unsigned seed = 1;
};

struct Scene {
  BaProblem truth;          // true cameras and points, noisy observations
  BaProblem problem;        // the same with the free cameras and points perturbed
  std::vector<bool> gross;  // per observation: displaced by 30 px
};

// Cameras along a line to the north at 100 m altitude (the first two fixed:
// gauge and scale), points on the ground, every visible point observed. Then
// outlier_fraction of the observations displaced by 30 px, each of a different
// point (several wrong observations of one point are a wrong track: nothing
// tells which are right), and the free cameras perturbed by 1 m and 0.5 deg and
// the points by 2 m, in random directions. Each step draws from its own stream,
// so scenes that differ only in outliers share the noise and the perturbation.
Scene makeScene(const SceneSpec& spec) {
  std::mt19937 rng(spec.seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  Scene scene;
  BaProblem& truth = scene.truth;
  truth.K = kK;
  for (int i = 0; i < spec.num_cameras; ++i) {
    const double roll = (u01(rng) - 0.5) * 4.0 * kDeg;
    const double pitch = (u01(rng) - 0.5) * 4.0 * kDeg;
    truth.cameras.push_back(
        {downCamera(Eigen::Vector3d(i * spec.spacing_m, 0.0, -kAltitudeM), roll, pitch), i < 2});
  }
  std::vector<std::vector<int>> observations_of(spec.num_points);
  for (int j = 0; j < spec.num_points; ++j) {
    const Eigen::Vector3d p(spec.north_min_m + (spec.north_max_m - spec.north_min_m) * u01(rng),
                            spec.east_half_width_m * (2.0 * u01(rng) - 1.0),
                            spec.relief_m * (2.0 * u01(rng) - 1.0));
    truth.points.push_back({p, false});
    for (int i = 0; i < spec.num_cameras; ++i) {
      Eigen::Vector2d px;
      if (project(truth.cameras[i].T_world_cam, p, px)) {
        px += spec.noise_px * Eigen::Vector2d(noise(rng), noise(rng));
        observations_of[j].push_back(static_cast<int>(truth.observations.size()));
        truth.observations.push_back({i, j, px, spec.sigma_px});
      }
    }
  }

  scene.gross.assign(truth.observations.size(), false);
  std::mt19937 outlier_rng(spec.seed + 1000);
  std::vector<int> order(spec.num_points);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), outlier_rng);
  const auto num_gross =
      static_cast<std::size_t>(std::lround(spec.outlier_fraction * truth.observations.size()));
  for (std::size_t k = 0; k < num_gross && k < order.size(); ++k) {
    const std::vector<int>& candidates = observations_of[order[k]];
    const int o = candidates[outlier_rng() % candidates.size()];
    const double angle = 2.0 * std::numbers::pi * u01(outlier_rng);
    truth.observations[o].px += 30.0 * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    scene.gross[o] = true;
  }

  std::mt19937 perturb_rng(spec.seed + 2000);
  scene.problem = truth;
  for (BaCamera& cam : scene.problem.cameras) {
    if (!cam.fixed) {
      cam.T_world_cam.translation() += 1.0 * randomUnit(perturb_rng);
      cam.T_world_cam.linear() =
          Eigen::AngleAxisd(0.5 * kDeg, randomUnit(perturb_rng)).toRotationMatrix() *
          cam.T_world_cam.linear();
    }
  }
  for (BaPoint& point : scene.problem.points) {
    point.p_world_m += 2.0 * randomUnit(perturb_rng);
  }
  return scene;
}

// Pose errors of the cameras against a reference.
void expectCamerasNear(const BaProblem& result, const BaProblem& reference, double tolerance_m,
                       double tolerance_rad) {
  for (std::size_t i = 0; i < reference.cameras.size(); ++i) {
    const Eigen::Isometry3d& T = result.cameras[i].T_world_cam;
    const Eigen::Isometry3d& T_ref = reference.cameras[i].T_world_cam;
    EXPECT_LT((T.translation() - T_ref.translation()).norm(), tolerance_m) << "camera " << i;
    EXPECT_LT(rotationErrorRad(T, T_ref), tolerance_rad) << "camera " << i;
  }
}

// The accuracy the geometry allows at 0.5 px noise, measured over seeds 1..100
// of the default scene: per free camera the rotation error has median 0.03 deg
// and 95th percentile 0.076 deg (largest 0.11 deg), the position error 0.06 m
// and 0.15 m (largest 0.20 m): the two fixed cameras' attitudes, as seen
// through the noise, carry into the others. A 0.05 deg bound is exceeded by
// some camera in about half of the seeds, hence these.
constexpr double kToleranceM = 0.3;
constexpr double kToleranceRad = 0.12 * kDeg;

// Exact observations: BA returns to the ground truth itself.
TEST(BundleAdjustmentTest, RecoversTheTruthFromExactObservations) {
  SceneSpec spec;
  spec.noise_px = 0.0;
  Scene scene = makeScene(spec);
  BundleAdjustmentParams params;
  params.max_iterations = 50;
  const BaResult result = bundleAdjust(scene.problem, params);
  EXPECT_TRUE(result.converged);
  EXPECT_GT(result.initial_rmse_px, 5.0);
  EXPECT_LT(result.final_rmse_px, 1e-6);
  expectCamerasNear(scene.problem, scene.truth, 1e-6, 1e-8);
  for (std::size_t j = 0; j < scene.truth.points.size(); ++j) {
    EXPECT_LT((scene.problem.points[j].p_world_m - scene.truth.points[j].p_world_m).norm(), 1e-5);
  }
}

// With 0.5 px noise BA brings the reprojection error down to the noise level
// (sqrt(1 - 618 unknowns / ~2000 residuals) * 0.5 px = 0.42 px expected) and the
// cameras back to the truth.
TEST(BundleAdjustmentTest, ConvergesToTruthAtNoiseLevel) {
  Scene scene = makeScene({});
  ASSERT_GT(scene.problem.observations.size(),
            990u);  // 200 points x 5 cameras, a few off the image
  const BaResult result = bundleAdjust(scene.problem, {});
  std::printf("%s\n", result.summary.c_str());
  EXPECT_TRUE(result.converged);
  EXPECT_GT(result.initial_rmse_px, 5.0);
  EXPECT_GT(result.final_rmse_px, 0.3);
  EXPECT_LT(result.final_rmse_px, 0.7);
  EXPECT_EQ(result.num_outliers, 0);
  expectCamerasNear(scene.problem, scene.truth, kToleranceM, kToleranceRad);
}

// 5 % of the observations displaced by 30 px (one per point) are all flagged
// and hardly anything else (sigma_px = 1 against 0.5 px noise makes a false
// alarm of a good observation a 6e-6 event; an observation of a point that its
// displaced one dragged away in the robust first solve can stay flagged: 15 in
// 100,000 over seeds 1..100); the cameras end where the BA of the same scene
// without the displaced observations takes them.
TEST(BundleAdjustmentTest, FlagsGrossOutliersWithoutSpoilingTheResult) {
  SceneSpec spec;
  spec.seed = 2;
  spec.outlier_fraction = 0.05;
  Scene scene = makeScene(spec);
  const long num_gross = std::count(scene.gross.begin(), scene.gross.end(), true);
  ASSERT_EQ(num_gross, 50);
  BaProblem without_outliers = scene.problem;
  without_outliers.observations.clear();
  for (std::size_t k = 0; k < scene.gross.size(); ++k) {
    if (!scene.gross[k]) {
      without_outliers.observations.push_back(scene.problem.observations[k]);
    }
  }

  const BaResult result = bundleAdjust(scene.problem, {});
  std::printf("%s\n", result.summary.c_str());
  ASSERT_EQ(result.outlier.size(), scene.gross.size());
  int false_alarms = 0;
  for (std::size_t k = 0; k < scene.gross.size(); ++k) {
    if (scene.gross[k]) {
      EXPECT_TRUE(result.outlier[k]) << "observation " << k;
    } else {
      false_alarms += result.outlier[k] ? 1 : 0;
    }
  }
  EXPECT_LE(false_alarms, 2);
  EXPECT_EQ(result.num_outliers, num_gross + false_alarms);
  EXPECT_GT(result.final_rmse_px, 0.3);
  EXPECT_LT(result.final_rmse_px, 0.7);
  expectCamerasNear(scene.problem, scene.truth, kToleranceM, kToleranceRad);

  const BaResult reference = bundleAdjust(without_outliers, {});
  EXPECT_EQ(reference.num_outliers, 0);
  expectCamerasNear(scene.problem, without_outliers, 0.04, 0.02 * kDeg);
}

// Two runs, and runs on one thread and on four (the residuals evaluated in
// chunks, the sums taken in one order), give the same bits.
TEST(BundleAdjustmentTest, TwoRunsAreBitIdentical) {
  SceneSpec spec;
  spec.outlier_fraction = 0.05;
  spec.seed = 3;
  const Scene scene = makeScene(spec);
  BaProblem a = scene.problem;
  BaProblem b = scene.problem;
  BaProblem threaded = scene.problem;
  BundleAdjustmentParams four_threads;
  four_threads.num_threads = 4;
  const BaResult ra = bundleAdjust(a, {});
  const BaResult rb = bundleAdjust(b, {});
  const BaResult rt = bundleAdjust(threaded, four_threads);
  for (const auto& [other, r] : {std::pair{&b, &rb}, std::pair{&threaded, &rt}}) {
    EXPECT_EQ(ra.final_rmse_px, r->final_rmse_px);
    EXPECT_EQ(ra.iterations, r->iterations);
    EXPECT_EQ(ra.outlier, r->outlier);
    for (std::size_t i = 0; i < a.cameras.size(); ++i) {
      EXPECT_TRUE(a.cameras[i].T_world_cam.matrix() == other->cameras[i].T_world_cam.matrix());
    }
    for (std::size_t j = 0; j < a.points.size(); ++j) {
      EXPECT_TRUE(a.points[j].p_world_m == other->points[j].p_world_m);
    }
  }
}

// Fixed cameras and fixed points keep their exact values; the free ones move.
TEST(BundleAdjustmentTest, FixedCamerasAndPointsDoNotMove) {
  SceneSpec spec;
  spec.seed = 4;
  Scene scene = makeScene(spec);
  for (int j = 0; j < 20; ++j) {
    scene.problem.points[j].fixed = true;
  }
  const BaProblem before = scene.problem;
  bundleAdjust(scene.problem, {});
  for (std::size_t i = 0; i < before.cameras.size(); ++i) {
    const bool same =
        scene.problem.cameras[i].T_world_cam.matrix() == before.cameras[i].T_world_cam.matrix();
    EXPECT_EQ(same, before.cameras[i].fixed) << "camera " << i;
  }
  for (std::size_t j = 0; j < before.points.size(); ++j) {
    const bool same = scene.problem.points[j].p_world_m == before.points[j].p_world_m;
    EXPECT_EQ(same, before.points[j].fixed) << "point " << j;
  }
}

// An observation of a point behind its camera is skipped and flagged.
TEST(BundleAdjustmentTest, SkipsPointsBehindTheCamera) {
  SceneSpec spec;
  spec.seed = 5;
  Scene scene = makeScene(spec);
  const int behind = static_cast<int>(scene.problem.points.size());
  scene.problem.points.push_back({Eigen::Vector3d(30.0, 0.0, -200.0), false});  // above the cameras
  scene.problem.observations.push_back({2, behind, Eigen::Vector2d(640.0, 480.0), 1.0});
  const BaResult result = bundleAdjust(scene.problem, {});
  EXPECT_TRUE(result.outlier.back());
  EXPECT_EQ(result.num_outliers, 1);
  EXPECT_EQ(scene.problem.points.back().p_world_m, Eigen::Vector3d(30.0, 0.0, -200.0));
  expectCamerasNear(scene.problem, scene.truth, kToleranceM, kToleranceRad);
}

// A camera that sees only two points can turn about the line through them at
// no cost: the BA leaves it 2 deg off, a rotation prior relative to a fixed
// camera brings it back to the truth.
TEST(BundleAdjustmentTest, RotationPriorConstrainsAnUnderdeterminedCamera) {
  SceneSpec spec;
  spec.num_cameras = 3;
  spec.num_points = 30;
  spec.seed = 6;
  Scene scene = makeScene(spec);
  BaProblem truth = scene.truth;
  // Noise-free observations; camera 2 keeps only those of points 0 and 1.
  truth.observations.clear();
  for (int j = 0; j < spec.num_points; ++j) {
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector2d px;
      if ((i < 2 || j < 2) &&
          project(truth.cameras[i].T_world_cam, truth.points[j].p_world_m, px)) {
        truth.observations.push_back({i, j, px, 1.0});
      }
    }
  }
  BaProblem problem = truth;
  // Camera 2 turned 2 deg about the line through points 0 and 1.
  const Eigen::Vector3d p0 = truth.points[0].p_world_m;
  const Eigen::Vector3d axis = (truth.points[1].p_world_m - p0).normalized();
  const Eigen::Isometry3d turn =
      Eigen::Translation3d(p0) * Eigen::AngleAxisd(2.0 * kDeg, axis) * Eigen::Translation3d(-p0);
  problem.cameras[2].T_world_cam = turn * truth.cameras[2].T_world_cam;

  BaProblem without_prior = problem;
  const BaResult r0 = bundleAdjust(without_prior, {});
  EXPECT_LT(r0.final_rmse_px, 1e-6);
  EXPECT_GT(rotationErrorRad(without_prior.cameras[2].T_world_cam, truth.cameras[2].T_world_cam),
            1.9 * kDeg);

  BaProblem with_prior = problem;
  const Eigen::Quaterniond R_02(truth.cameras[0].T_world_cam.rotation().transpose() *
                                truth.cameras[2].T_world_cam.rotation());
  with_prior.rotation_priors.push_back({0, 2, R_02, 0.1 * kDeg});
  const BaResult r1 = bundleAdjust(with_prior, {});
  std::printf("%s\n", r1.summary.c_str());
  EXPECT_LT(r1.final_rmse_px, 1e-3);
  EXPECT_LT(rotationErrorRad(with_prior.cameras[2].T_world_cam, truth.cameras[2].T_world_cam),
            0.05 * kDeg);
  EXPECT_LT(
      (with_prior.cameras[2].T_world_cam.translation() - truth.cameras[2].T_world_cam.translation())
          .norm(),
      0.2);
}

// A prior's heading sigma: camera 1, free and seen by nothing, between two
// priors from the fixed world-axes camera 0: one turned 2 deg about north
// and 2 deg about down with sigma 0.5 deg (tilt) and 3 deg (heading), one at
// no turn with sigma 1 deg. By hand (weighted means, small angles): about
// north (2/0.5^2) / (1/0.5^2 + 1/1^2) = 1.6 deg, about down (2/3^2) /
// (1/3^2 + 1/1^2) = 0.2 deg, about east 0 to second order (the two turns'
// product, 2 x 2 deg in radians over 2: 0.035 deg).
TEST(BundleAdjustmentTest, ARotationPriorWeighsItsHeadingByItsOwnSigma) {
  BaProblem problem;
  problem.cameras = {{Eigen::Isometry3d::Identity(), true}, {Eigen::Isometry3d::Identity(), false}};
  const Eigen::Vector3d turn_rad(2.0 * kDeg, 0.0, 2.0 * kDeg);
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(turn_rad.norm(), turn_rad.normalized()));
  problem.rotation_priors.push_back({0, 1, turned, 0.5 * kDeg, 3.0 * kDeg});
  problem.rotation_priors.push_back({0, 1, Eigen::Quaterniond::Identity(), 1.0 * kDeg});
  bundleAdjust(problem, {});
  const Eigen::AngleAxisd estimated(problem.cameras[1].T_world_cam.rotation());
  const Eigen::Vector3d rotation_deg = estimated.angle() * estimated.axis() / kDeg;
  std::printf("rotation vector %.4f %.4f %.4f deg\n", rotation_deg.x(), rotation_deg.y(),
              rotation_deg.z());
  EXPECT_NEAR(rotation_deg.x(), 1.6, 0.01);
  EXPECT_NEAR(rotation_deg.y(), 0.0, 0.035);
  EXPECT_NEAR(rotation_deg.z(), 0.2, 0.01);
}

// Bad input is refused.
TEST(BundleAdjustmentTest, RejectsBadIndicesAndSigmas) {
  Scene scene = makeScene({});
  BaProblem bad_camera = scene.problem;
  bad_camera.observations[0].camera = 5;
  EXPECT_THROW(bundleAdjust(bad_camera, {}), std::invalid_argument);
  BaProblem bad_sigma = scene.problem;
  bad_sigma.observations[0].sigma_px = 0.0;
  EXPECT_THROW(bundleAdjust(bad_sigma, {}), std::invalid_argument);
  BaProblem bad_prior = scene.problem;
  bad_prior.rotation_priors.push_back({0, 7, Eigen::Quaterniond::Identity(), 0.01});
  EXPECT_THROW(bundleAdjust(bad_prior, {}), std::invalid_argument);
}

// The parameters load from YAML and their defaults are within their ranges.
TEST(BundleAdjustmentTest, ParamsLoadAndValidate) {
  BundleAdjustmentParams params;
  const auto visit = [&params](core::ParamVisitor& v) { params.visit(v); };
  EXPECT_NO_THROW(core::validateParams(visit, "defaults"));
  core::applyYamlText("max_iterations: 20\nhuber_px: 2.447\noutlier_rounds: 0\n", "test", visit);
  EXPECT_EQ(params.max_iterations, 20);
  EXPECT_EQ(params.huber_px, 2.447);
  EXPECT_EQ(params.outlier_rounds, 0);
  EXPECT_THROW(core::applyYamlText("num_threads: 0\n", "test", visit), core::ParamError);
}

// Timing (printed, not asserted): 10 key-frames x 300 points x ~1900 observations.
TEST(BundleAdjustmentTest, TimingTenKeyframes) {
  SceneSpec spec;
  spec.num_cameras = 10;
  spec.spacing_m = 20.0;
  spec.num_points = 300;
  spec.north_min_m = 25.0;
  spec.north_max_m = 155.0;
  spec.outlier_fraction = 0.05;
  spec.seed = 7;
  const Scene scene = makeScene(spec);
  constexpr int kRuns = 20;
  double total_ms = 0.0;
  BaResult result;
  for (int run = 0; run < kRuns; ++run) {
    BaProblem problem = scene.problem;
    const auto start = std::chrono::steady_clock::now();
    result = bundleAdjust(problem, {});
    total_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  std::printf(
      "BA of %zu key-frames x %zu points x %zu observations: %.2f ms per call "
      "(%d iterations, rmse %.3f -> %.3f px, %d outliers)\n",
      scene.problem.cameras.size(), scene.problem.points.size(), scene.problem.observations.size(),
      total_ms / kRuns, result.iterations, result.initial_rmse_px, result.final_rmse_px,
      result.num_outliers);
  EXPECT_GT(result.iterations, 0);
}

}  // namespace
}  // namespace nadir::vo
