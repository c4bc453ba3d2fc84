// The course's scoring against hand-worked cases: the footprints' overlap, a
// gate passed through its opening or beside it, a post touched, a slalom board
// passed on its side, a turn board turned at its way, the speeds, and the
// pipeline's means.

#include "nodes/control/course_results.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/frames.h"

namespace nadir::control {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A straight drive north along east = east_m at speed_mps for duration_s, at 400 Hz.
core::Trajectory straightNorth(double east_m, double speed_mps, double duration_s,
                               double heading_deg = 0.0) {
  core::Trajectory truth;
  const double h = heading_deg * kDeg;
  for (int i = 0; i <= static_cast<int>(duration_s * 400.0); ++i) {
    const double t = i / 400.0;
    core::StampedPose pose;
    pose.t_s = 10.0 + t;
    pose.p_ned_m =
        Eigen::Vector3d(speed_mps * t * std::cos(h), east_m + speed_mps * t * std::sin(h), 0.0);
    pose.q_world_body = core::quaternionFromRpy({0.0, 0.0, h});
    truth.push_back(pose);
  }
  return truth;
}

terrain::CourseBoard gateAt(double north_m) {
  terrain::CourseBoard gate;
  gate.north_m = north_m;
  return gate;  // 0.36 m opening, 0.03 m posts: post centres at east +-0.195 m
}

TEST(CourseResultsTest, RectanglesOverlapByTheirSides) {
  const FloorRectangle a{0.0, 0.0, 0.0, 1.0, 0.5};
  EXPECT_TRUE(overlap(a, {1.9, 0.0, 0.0, 1.0, 0.5}));
  EXPECT_FALSE(overlap(a, {2.1, 0.0, 0.0, 1.0, 0.5}));
  EXPECT_FALSE(overlap(a, {0.0, 1.01, 0.0, 1.0, 0.5}));
  // A square of half side 0.1 m turned 45 deg has its corners 0.1 sqrt(2) =
  // 0.1414 m from its centre along a's axes: its west corner reaches a's east
  // edge (north 1 m) when its centre is 1.1414 m north.
  const double reach = 0.1 * std::sqrt(2.0);
  EXPECT_TRUE(overlap(a, {1.0 + reach - 0.01, 0.0, 45.0 * kDeg, 0.1, 0.1}));
  EXPECT_FALSE(overlap(a, {1.0 + reach + 0.01, 0.0, 45.0 * kDeg, 0.1, 0.1}));
}

// Driving north 5 cm right of a gate's centre at 2 m/s: passed, 0.05 m off
// centre, on its axis; the body (0.18 m wide) misses the posts (inner faces at
// +-0.18 m: the body spans -0.04..0.14 m).
TEST(CourseResultsTest, AGatePassedThroughItsOpening) {
  CourseRunInput input;
  input.truth = straightNorth(0.05, 2.0, 3.0);
  input.boards = {gateAt(3.0)};
  const logs::CourseMetrics m = courseResults(input);
  ASSERT_EQ(m.passages.size(), 1u);
  EXPECT_TRUE(m.passages[0].passed);
  EXPECT_FALSE(m.passages[0].hit);
  EXPECT_NEAR(m.passages[0].offset_m, 0.05, 1e-9);
  EXPECT_NEAR(m.passages[0].heading_error_deg, 0.0, 1e-9);
  // The body's centre (0.135 m ahead of the rear axle) reaches 3 m at
  // (3 - 0.135) / 2 = 1.4325 s.
  EXPECT_NEAR(m.passages[0].time_s, 1.4325, 1e-6);
  EXPECT_EQ(m.gates, 1);
  EXPECT_EQ(m.gates_passed, 1);
  EXPECT_EQ(m.gates_hit, 0);
  // Moving throughout: average and peak 2 m/s, up to the crossing.
  EXPECT_NEAR(m.peak_speed_mps, 2.0, 1e-9);
  EXPECT_NEAR(m.average_speed_mps, 2.0, 1e-6);
  EXPECT_NEAR(m.duration_s, 1.4325, 1e-6);
}

// 0.12 m right of the centre the body spans 0.03..0.21 m and touches the right
// post (0.18..0.21 m): passed (the centre is in the opening) and hit. 0.25 m
// right: outside the opening and through the post: missed and hit. 0.6 m
// right: missed, untouched.
TEST(CourseResultsTest, PostsTouchedAndGatesMissed) {
  for (const auto& [east, passed, hit] :
       {std::tuple{0.12, true, true}, {0.25, false, true}, {0.6, false, false}}) {
    CourseRunInput input;
    input.truth = straightNorth(east, 2.0, 3.0);
    input.boards = {gateAt(3.0)};
    const logs::CourseMetrics m = courseResults(input);
    EXPECT_EQ(m.passages[0].passed, passed) << east;
    EXPECT_EQ(m.passages[0].hit, hit) << east;
    EXPECT_EQ(m.gates_missed, passed ? 0 : 1) << east;
    EXPECT_EQ(m.gates_hit, hit ? 1 : 0) << east;
  }
}

// A slalom_right board is passed on its right (east of it for a northward
// drive), a slalom_left one on its left; a decoy's post touched is counted.
TEST(CourseResultsTest, SlalomBoardsByTheirSide) {
  terrain::CourseBoard right = gateAt(2.0), left = gateAt(4.0), decoy = gateAt(5.0);
  right.kind = "slalom_right";
  left.kind = "slalom_left";
  decoy.kind = "decoy";
  decoy.east_m = 0.4;
  CourseRunInput input;
  input.truth = straightNorth(0.4, 2.0, 3.0);
  input.boards = {right, left, decoy};
  const logs::CourseMetrics m = courseResults(input);
  EXPECT_EQ(m.slalom_boards, 2);
  EXPECT_EQ(m.slalom_passed, 1);
  EXPECT_EQ(m.slalom_wrong_side, 1);
  EXPECT_TRUE(m.passages[0].passed);
  EXPECT_FALSE(m.passages[1].passed);
  EXPECT_NEAR(m.passages[1].offset_m, 0.4, 1e-9);
  EXPECT_EQ(m.decoys_hit, 1);
}

// A crossing 20 deg off the gate's axis reports it.
// A drive north at 2 m/s that, 1 m short of a board, turns on a 0.5 m
// radius by turn_deg (+ right) and goes straight on; 400 Hz.
core::Trajectory northThenTurn(double turn_deg) {
  core::Trajectory truth;
  constexpr double kSpeed = 2.0, kRadius = 0.5, kTurnAt = 1.0;
  const double turn = std::abs(turn_deg) * kDeg, side = turn_deg > 0.0 ? 1.0 : -1.0;
  const double arc_s = turn * kRadius / kSpeed;
  for (int i = 0; i <= 1600; ++i) {
    const double t = i / 400.0, along = kSpeed * t;
    core::StampedPose pose;
    pose.t_s = t;
    double heading = 0.0;
    Eigen::Vector2d p(along - 2.0, 0.0);
    if (p.x() > -kTurnAt) {
      const double since = t - (2.0 - kTurnAt) / kSpeed;
      const double angle = std::min(since, arc_s) * kSpeed / kRadius;
      heading = side * angle;
      // On the arc: centre kRadius to the turn's side of the turn's start.
      p = Eigen::Vector2d(-kTurnAt + kRadius * std::sin(angle),
                          side * kRadius * (1.0 - std::cos(angle)));
      if (since > arc_s)
        p += kSpeed * (since - arc_s) * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    }
    pose.p_ned_m = Eigen::Vector3d(p.x(), p.y(), 0.0);
    pose.q_world_body = core::quaternionFromRpy({0.0, 0.0, heading});
    truth.push_back(pose);
  }
  return truth;
}

// Turn boards at the origin facing north: turning 45 deg right at a board
// that asks for 45 right is its way (turned 0 deg beyond it, half the turn
// reached at 0.5 s + 22.5 deg x 0.5 m / 2 m/s = 0.5982 s); turning left is the
// wrong way; a 45 deg turn at a 135 deg board is missed (under 0.7 x 135);
// a board never approached is missed.
TEST(CourseResultsTest, TurnBoardsByTheTurnMade) {
  terrain::CourseBoard right;
  right.kind = "slalom_right";
  right.turn_deg = 45.0;
  CourseRunInput input;
  input.truth = northThenTurn(45.0);
  input.boards = {right};
  logs::CourseMetrics m = courseResults(input);
  ASSERT_EQ(m.passages.size(), 1u);
  EXPECT_EQ(m.passages[0].kind, "turn_right");
  EXPECT_TRUE(m.passages[0].passed);
  EXPECT_NEAR(m.passages[0].heading_error_deg, 0.0, 1e-6);
  EXPECT_NEAR(m.passages[0].time_s, 0.5 + 22.5 * kDeg * 0.5 / 2.0, 2.5e-3);
  EXPECT_EQ(m.slalom_passed, 1);

  input.truth = northThenTurn(-45.0);
  m = courseResults(input);
  EXPECT_TRUE(m.passages[0].crossed);
  EXPECT_FALSE(m.passages[0].passed);
  EXPECT_EQ(m.slalom_wrong_side, 1);

  right.turn_deg = 135.0;
  input.truth = northThenTurn(45.0);
  input.boards = {right};
  m = courseResults(input);
  EXPECT_FALSE(m.passages[0].crossed);
  EXPECT_EQ(m.slalom_missed, 1);

  right.north_m = 20.0;
  input.boards = {right};
  m = courseResults(input);
  EXPECT_FALSE(m.passages[0].crossed);
  EXPECT_EQ(m.slalom_missed, 1);
}

TEST(CourseResultsTest, HeadingOffTheAxis) {
  CourseRunInput input;
  input.truth = straightNorth(-0.5, 2.0, 3.0, 20.0);
  terrain::CourseBoard gate = gateAt(2.0);
  input.boards = {gate};
  const logs::CourseMetrics m = courseResults(input);
  EXPECT_NEAR(m.passages[0].heading_error_deg, 20.0, 1e-6);
}

// Stage means over frames and the chip time at 10 MHz; latency from the commands.
TEST(CourseResultsTest, PipelineMeansAndLatency) {
  CourseRunInput input;
  input.truth = straightNorth(0.0, 1.0, 1.0);
  input.frames = {{0, 10, 20, 30, 40, 1e-5}, {5000, 20, 40, 50, 60, 1.7e-5}};
  input.commands = {{0, 35}, {5000, 5042}};
  const logs::CourseMetrics m = courseResults(input);
  ASSERT_EQ(m.stages.size(), 6u);
  EXPECT_DOUBLE_EQ(m.stages[0].instructions, 15.0);
  EXPECT_DOUBLE_EQ(m.stages[1].instructions, 30.0);
  EXPECT_DOUBLE_EQ(m.stages[3].instructions, 50.0);
  EXPECT_NEAR(m.stages[3].chip_us, 5.0, 1e-9);
  EXPECT_NEAR(m.stages[4].chip_us, 24.0, 1e-9);
  EXPECT_DOUBLE_EQ(m.stages[3].paper_us, 328.0);
  EXPECT_NEAR(m.chip_time_us, 13.5, 1e-9);
  EXPECT_NEAR(m.emulated_fps, 1e6 / 13.5, 1e-6);
  EXPECT_DOUBLE_EQ(m.latency_mean_us, 38.5);
  EXPECT_DOUBLE_EQ(m.latency_max_us, 42.0);
  EXPECT_THROW(courseResults(CourseRunInput{}), std::invalid_argument);
}

}  // namespace
}  // namespace nadir::control
