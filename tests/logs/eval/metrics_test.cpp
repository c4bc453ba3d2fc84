// evo's statistics, APE and RPE (frames and metres), the thesis RMSEs and the
// `--ref/--est` report, with every expected number worked out by hand.

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/frames.h"
#include "logs/eval/metrics.h"

namespace nadir::eval {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

core::StampedPose pose(double t, const Eigen::Vector3d& p, double roll_deg = 0,
                       double pitch_deg = 0, double yaw_deg = 0) {
  core::StampedPose out;
  out.t_s = t;
  out.p_ned_m = p;
  out.q_world_body = core::quaternionFromRpy({roll_deg * kDeg, pitch_deg * kDeg, yaw_deg * kDeg});
  return out;
}

// Poses along x at the given positions, identity attitude, 1 s apart.
core::Trajectory alongX(const std::vector<double>& xs) {
  core::Trajectory out;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    out.push_back(pose(static_cast<double>(i), Eigen::Vector3d(xs[i], 0, 0)));
  }
  return out;
}

// {4, 1, 3, 2}: median of an even count is the mean of the middle two; std is the population one.
TEST(EvalStatistics, FixedVector) {
  const Statistics s = computeStatistics({4, 1, 3, 2});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));  // (16 + 1 + 9 + 4) / 4
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));         // (2.25 + 2.25 + 0.25 + 0.25) / 4
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(computeStatistics({3, 1, 2}).median, 2);
  const Statistics none = computeStatistics({});
  EXPECT_TRUE(std::isnan(none.rmse));
  EXPECT_EQ(none.count, 0u);
}

// APE rotation is the angle of P_est^-1 P_ref: a 10 deg yaw error gives 10 deg at any attitude.
TEST(EvalApe, RotationAngle) {
  const core::Trajectory ref = {pose(0, {0, 0, 0}, 20, -10, 100)};
  const core::Trajectory est = {core::StampedPose{
      0, {0, 0, 0}, Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitZ()) * ref[0].q_world_body}};
  EXPECT_NEAR(apeRotationErrorsDeg(ref, est)[0], 10.0, 1e-9);
  EXPECT_NEAR(apeTranslationErrors(ref, est)[0], 0.0, 1e-15);
}

// RPE in frames: x truth 0 1 2 3 4, estimate 0 1 2.5 3.5 4.5; delta 1 -> errors 0 .5 0 0.
TEST(EvalRpe, FramesHandExample) {
  const core::Trajectory ref = alongX({0, 1, 2, 3, 4});
  const core::Trajectory est = alongX({0, 1, 2.5, 3.5, 4.5});
  const IndexPairs pairs = rpePairs(est, 1, DeltaUnit::kFrames);
  ASSERT_EQ(pairs.size(), 4u);
  const Statistics s = computeStatistics(rpeErrors(ref, est, pairs).translation_m);
  EXPECT_NEAR(s.max, 0.5, 1e-12);
  EXPECT_NEAR(s.mean, 0.125, 1e-12);
  EXPECT_NEAR(s.median, 0.0, 1e-12);
  EXPECT_NEAR(s.rmse, 0.25, 1e-12);  // sqrt(0.25 / 4)
  // delta 2: pairs (0,2), (2,4) with est steps 2.5 and 2 against 2 and 2.
  const IndexPairs two = rpePairs(est, 2, DeltaUnit::kFrames);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[1], (std::pair<std::size_t, std::size_t>{2, 4}));
  const RelativeErrors e = rpeErrors(ref, est, two);
  EXPECT_NEAR(e.translation_m[0], 0.5, 1e-12);
  EXPECT_NEAR(e.translation_m[1], 0.0, 1e-12);
}

// RPE with a 5 deg yaw step at pose 2: rotation error 5 deg on (1,2); the following
// step is then seen 5 deg off, a translation error of 2 sin(2.5 deg) on a 1 m step.
TEST(EvalRpe, RotationHandExample) {
  const core::Trajectory ref = alongX({0, 1, 2, 3, 4});
  core::Trajectory est = ref;
  for (std::size_t i = 2; i < est.size(); ++i) est[i] = pose(est[i].t_s, est[i].p_ned_m, 0, 0, 5);
  const RelativeErrors e = rpeErrors(ref, est, rpePairs(est, 1, DeltaUnit::kFrames));
  ASSERT_EQ(e.rotation_deg.size(), 4u);
  EXPECT_NEAR(e.rotation_deg[0], 0.0, 1e-9);
  EXPECT_NEAR(e.rotation_deg[1], 5.0, 1e-9);
  EXPECT_NEAR(e.rotation_deg[2], 0.0, 1e-9);
  EXPECT_NEAR(e.translation_m[1], 0.0, 1e-12);
  EXPECT_NEAR(e.translation_m[2], 2 * std::sin(2.5 * kDeg), 1e-12);
}

// RPE in metres follows evo: ids where the path from the last id reaches delta; pose 0 is not one.
TEST(EvalRpe, MetersHandExample) {
  // 0.5 m steps: path reaches 1 m at ids 2, 4, 6 -> pairs (2,4), (4,6).
  const IndexPairs half = rpePairs(alongX({0, 0.5, 1, 1.5, 2, 2.5, 3}), 1.0, DeltaUnit::kMeters);
  ASSERT_EQ(half.size(), 2u);
  EXPECT_EQ(half[0], (std::pair<std::size_t, std::size_t>{2, 4}));
  EXPECT_EQ(half[1], (std::pair<std::size_t, std::size_t>{4, 6}));
  // 0.4 m steps: 1.2 m at ids 3 and 6, the rest (0.8 m) never reaches 1 -> one pair.
  const IndexPairs tenths =
      rpePairs(alongX({0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.4, 2.8, 3.2}), 1.0, DeltaUnit::kMeters);
  ASSERT_EQ(tenths.size(), 1u);
  EXPECT_EQ(tenths[0], (std::pair<std::size_t, std::size_t>{3, 6}));
  // An estimate stretched 10 %: pairs chosen on it (ids 2, 4, 6), each 1.1 m against 1 m.
  const core::Trajectory ref = alongX({0, 0.5, 1, 1.5, 2, 2.5, 3});
  const core::Trajectory est = alongX({0, 0.55, 1.1, 1.65, 2.2, 2.75, 3.3});
  const IndexPairs pairs = rpePairs(est, 1.0, DeltaUnit::kMeters);
  ASSERT_EQ(pairs.size(), 2u);
  const RelativeErrors e = rpeErrors(ref, est, pairs);
  EXPECT_NEAR(e.translation_m[0], 0.1, 1e-12);
  EXPECT_NEAR(e.translation_m[1], 0.1, 1e-12);
}

// Thesis eq. 13 and 14 on a constant error of (1, 2, 2) m and (1, 2, 2) deg: both RMSEs are 3.
TEST(EvalThesis, ConstantKnownError) {
  core::Trajectory ref;
  core::Trajectory est;
  const double attitudes[4][3] = {{0, 0, 0}, {10, -20, 45}, {-30, 15, 178.5}, {5, 30, -120}};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d p(100.0 * i, -50.0 * i, -300);
    const double* a = attitudes[i];
    ref.push_back(pose(i, p, a[0], a[1], a[2]));
    est.push_back(pose(i, p + Eigen::Vector3d(1, 2, 2), a[0] + 1, a[1] + 2, a[2] + 2));
  }
  EXPECT_NEAR(thesisPositionRmse(ref, est), 3.0, 1e-12);
  // 178.5 + 2 wraps to -179.5: still a 2 deg yaw error.
  EXPECT_NEAR(thesisRotationRmseDeg(ref, est), 3.0, 1e-9);
  EXPECT_NEAR(meanAbsoluteError(ref, est), 3.0, 1e-12);
}

// The --ref/--est evaluation: offset APE without alignment, and the last-line contract.
TEST(EvalReport, LastLineIsApeTranslationRmse) {
  core::Trajectory ref;
  core::Trajectory est;
  for (int i = 0; i < 10; ++i) {
    ref.push_back(pose(i, Eigen::Vector3d(i, i * i * 0.1, std::sin(i))));
    est.push_back(pose(i + 0.003, ref.back().p_ned_m + Eigen::Vector3d(0.3, 0, 0.4)));
  }
  EvalOptions options;
  const TrajectoryEvaluation none = evaluateTrajectories(ref, est, options);
  EXPECT_EQ(none.matched_poses, 10u);
  EXPECT_NEAR(none.ape_translation_m.rmse, 0.5, 1e-12);
  const std::string report = formatTrajectoryReport(none, options);
  ASSERT_FALSE(report.empty());
  ASSERT_EQ(report.back(), '\n');
  const std::string without_newline = report.substr(0, report.size() - 1);
  const std::string last = without_newline.substr(without_newline.rfind('\n') + 1);
  EXPECT_EQ(last, "0.500000");
  EXPECT_NE(report.find("APE w.r.t. translation part (m)"), std::string::npos);
  EXPECT_NE(report.find("RPE w.r.t. rotation angle (deg) for delta = 1 (frames)"),
            std::string::npos);

  options.align = "se3";
  const TrajectoryEvaluation se3 = evaluateTrajectories(ref, est, options);
  EXPECT_NEAR(se3.ape_translation_m.rmse, 0.0, 1e-9);
}

// Too few associated poses and bad options are one-line errors saying what is wrong.
TEST(EvalReport, ErrorsAreClear) {
  const core::Trajectory ref = alongX({0, 1, 2});
  core::Trajectory late = ref;
  for (core::StampedPose& p : late) p.t_s += 0.5;
  try {
    evaluateTrajectories(ref, late, EvalOptions{});
    FAIL() << "expected an error";
  } catch (const EvalError& error) {
    EXPECT_NE(std::string(error.what()).find("too few associated poses: 0"), std::string::npos)
        << error.what();
  }
  EvalOptions fractional;
  fractional.rpe_delta = 1.5;
  EXPECT_THROW(validateOptions(fractional), EvalError);
  EvalOptions unit;
  unit.rpe_delta_unit = "seconds";
  EXPECT_THROW(validateOptions(unit), EvalError);
  EvalOptions far;
  far.rpe_delta = 100;
  EXPECT_THROW(evaluateTrajectories(ref, ref, far), EvalError);  // no RPE pair
}

}  // namespace
}  // namespace nadir::eval
