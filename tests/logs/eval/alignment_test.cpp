// Umeyama alignment (none / SE(3) / Sim(3)) on small synthetic trajectories
// whose true misalignment is known: a pure offset, a pure rotation about the
// origin and a pure scale.

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "logs/eval/alignment.h"
#include "logs/eval/metrics.h"

namespace nadir::eval {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Five non-coplanar positions with varied attitudes.
core::Trajectory reference() {
  const double xyz[5][3] = {{0, 0, 0}, {10, 0, 0}, {10, 5, 0}, {0, 5, 2}, {3, 1, -1}};
  const double yaw_deg[5] = {0, 30, 60, -45, 170};
  core::Trajectory ref;
  for (int i = 0; i < 5; ++i) {
    core::StampedPose pose;
    pose.t_s = i;
    pose.p_ned_m = Eigen::Vector3d(xyz[i][0], xyz[i][1], xyz[i][2]);
    pose.q_world_body = Eigen::AngleAxisd(yaw_deg[i] * kDeg, Eigen::Vector3d::UnitZ()) *
                        Eigen::AngleAxisd(5.0 * i * kDeg, Eigen::Vector3d::UnitX());
    ref.push_back(pose);
  }
  return ref;
}

Statistics apeAfter(const core::Trajectory& ref, core::Trajectory est, AlignMode mode,
                    Alignment* used = nullptr) {
  const Alignment alignment = alignTrajectories(ref, est, mode);
  applyAlignment(alignment, est);
  if (used != nullptr) *used = alignment;
  return computeStatistics(apeTranslationErrors(ref, est));
}

// Estimate = truth + (1, 2, 3): no alignment reports the offset, SE(3) and Sim(3) remove it.
TEST(EvalAlignment, PureOffset) {
  const core::Trajectory ref = reference();
  core::Trajectory est = ref;
  for (core::StampedPose& pose : est) pose.p_ned_m += Eigen::Vector3d(1, 2, 3);
  EXPECT_NEAR(apeAfter(ref, est, AlignMode::kNone).rmse, std::sqrt(14.0), 1e-12);
  EXPECT_NEAR(apeAfter(ref, est, AlignMode::kNone).std, 0.0, 1e-12);
  Alignment se3;
  EXPECT_NEAR(apeAfter(ref, est, AlignMode::kSe3, &se3).rmse, 0.0, 1e-9);
  EXPECT_NEAR((se3.t - Eigen::Vector3d(-1, -2, -3)).norm(), 0.0, 1e-9);
  Alignment sim3;
  EXPECT_NEAR(apeAfter(ref, est, AlignMode::kSim3, &sim3).rmse, 0.0, 1e-9);
  EXPECT_NEAR(sim3.scale, 1.0, 1e-12);
}

// Estimate = the truth rotated 30 deg about z through the origin: SE(3) finds the inverse rotation.
TEST(EvalAlignment, PureRotationAboutOrigin) {
  const core::Trajectory ref = reference();
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitZ()));
  core::Trajectory est = ref;
  for (core::StampedPose& pose : est) {
    pose.p_ned_m = rotation * pose.p_ned_m;
    pose.q_world_body = rotation * pose.q_world_body;
  }
  // Unaligned, every attitude is 30 deg off.
  const std::vector<double> raw_rotation = apeRotationErrorsDeg(ref, est);
  for (const double e : raw_rotation) EXPECT_NEAR(e, 30.0, 1e-9);
  EXPECT_GT(apeAfter(ref, est, AlignMode::kNone).rmse, 1.0);
  Alignment se3;
  EXPECT_NEAR(apeAfter(ref, est, AlignMode::kSe3, &se3).rmse, 0.0, 1e-9);
  EXPECT_NEAR(Eigen::Quaterniond(se3.R).angularDistance(rotation.conjugate()), 0.0, 1e-9);
  EXPECT_NEAR(se3.t.norm(), 0.0, 1e-9);
  core::Trajectory aligned = est;
  applyAlignment(se3, aligned);
  for (const double e : apeRotationErrorsDeg(ref, aligned)) EXPECT_NEAR(e, 0.0, 1e-6);
}

// Estimate = truth positions at half scale: only Sim(3) removes it, reporting scale 2.
TEST(EvalAlignment, ScaleOnlySim3Recovers) {
  const core::Trajectory ref = reference();
  core::Trajectory est = ref;
  for (core::StampedPose& pose : est) pose.p_ned_m *= 0.5;
  EXPECT_GT(apeAfter(ref, est, AlignMode::kNone).rmse, 1.0);
  EXPECT_GT(apeAfter(ref, est, AlignMode::kSe3).rmse, 1.0);
  Alignment sim3;
  EXPECT_NEAR(apeAfter(ref, est, AlignMode::kSim3, &sim3).rmse, 0.0, 1e-9);
  EXPECT_NEAR(sim3.scale, 2.0, 1e-12);
  EXPECT_NEAR(Eigen::Quaterniond(sim3.R).angularDistance(Eigen::Quaterniond::Identity()), 0, 1e-9);
}

// Points on a line cannot fix a rotation: refused, like evo; sizes must match; names parse.
TEST(EvalAlignment, DegenerateAndBadInputsAreRefused) {
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  EXPECT_THROW(umeyamaAlignment(line, line, false), EvalError);
  EXPECT_THROW(umeyamaAlignment(line, {{0, 0, 0}}, false), EvalError);
  EXPECT_THROW(parseAlignMode("se2"), EvalError);
  EXPECT_EQ(parseAlignMode("sim3"), AlignMode::kSim3);
  EXPECT_EQ(alignModeName(AlignMode::kSe3), "se3");
  // A planar (rank 2) set is fine.
  const std::vector<Eigen::Vector3d> plane = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  EXPECT_NO_THROW(umeyamaAlignment(plane, plane, true));
}

// On noisy random points (seed 7) the result equals Eigen's independent Eigen::umeyama.
TEST(EvalAlignment, MatchesEigenUmeyamaOnNoisyPoints) {
  std::mt19937 rng(7);
  std::normal_distribution<double> spread(0.0, 20.0);
  std::normal_distribution<double> noise(0.0, 0.3);
  const Eigen::Matrix3d R_true =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  std::vector<Eigen::Vector3d> est;
  std::vector<Eigen::Vector3d> ref;
  Eigen::Matrix3Xd est_m(3, 50);
  Eigen::Matrix3Xd ref_m(3, 50);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d p(spread(rng), spread(rng), spread(rng));
    const Eigen::Vector3d q = 1.7 * R_true * p + Eigen::Vector3d(5, -3, 8) +
                              Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    est.push_back(p);
    ref.push_back(q);
    est_m.col(i) = p;
    ref_m.col(i) = q;
  }
  for (const bool with_scale : {false, true}) {
    SCOPED_TRACE(with_scale);
    const Alignment mine = umeyamaAlignment(est, ref, with_scale);
    const Eigen::Matrix4d eigen = Eigen::umeyama(est_m, ref_m, with_scale);
    EXPECT_NEAR((mine.scale * mine.R - eigen.topLeftCorner<3, 3>()).norm(), 0.0, 1e-9);
    EXPECT_NEAR((mine.t - eigen.topRightCorner<3, 1>()).norm(), 0.0, 1e-9);
  }
}

}  // namespace
}  // namespace nadir::eval
