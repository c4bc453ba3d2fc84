// The course layouts' boards against hand-worked places: the slalom's line,
// the number 8's eight turn boards (each the trigger distance beyond where a
// car turning on the set radius starts its turn before the path's corner),
// the gates with their decoys, and a board asking for a turn its pattern
// cannot say refused by name.

#include "terrain/course.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace nadir::terrain {
namespace {

// Six boards 2.4 m apart north of (1, 2), alternately right and left.
TEST(Course, TheSlalomIsALine) {
  CourseParams params;
  params.layout = "slalom";
  params.north_m = 1.0;
  params.east_m = 2.0;
  const std::vector<CourseBoard> boards = courseBoards(params);
  ASSERT_EQ(boards.size(), 6u);
  for (std::size_t i = 0; i < boards.size(); ++i) {
    EXPECT_NEAR(boards[i].north_m, 1.0 + 2.4 * (i + 1), 1e-12);
    EXPECT_NEAR(boards[i].east_m, 2.0, 1e-12);
    EXPECT_EQ(boards[i].kind, i % 2 == 0 ? "slalom_right" : "slalom_left");
    EXPECT_EQ(boards[i].turn_deg, 0.0);
  }
}

// The number 8 with loop a = 2.5 m, side s = 1.5 m, radius 0.45 m, trigger
// 0.8 m, laid out north from the origin. The path: north to (2.5, 0), two
// 135 deg left turns back through the origin heading east to (0, 2.5607)
// (the long leg (1 + 1/sqrt 2) s = 2.5607 m), six 45 deg right turns. A 135
// deg turn starts 0.45 tan(67.5 deg) = 1.0864 m before its corner, a 45 deg
// one 0.45 tan(22.5 deg) = 0.1864 m: the first board stands at 2.5 - 1.0864 +
// 0.8 = 2.2136 m north facing north, the third at 2.5607 - 0.1864 + 0.8 =
// 3.1743 m east facing east.
TEST(Course, TheNumberEight) {
  CourseParams params;
  params.layout = "number8";
  const std::vector<CourseBoard> boards = courseBoards(params);
  ASSERT_EQ(boards.size(), 8u);
  int left = 0, right = 0;
  for (const CourseBoard& board : boards) {
    left += board.kind == "slalom_left" ? 1 : 0;
    right += board.kind == "slalom_right" ? 1 : 0;
    EXPECT_EQ(board.turn_deg, board.kind == "slalom_left" ? 135.0 : 45.0);
  }
  EXPECT_EQ(left, 2);
  EXPECT_EQ(right, 6);
  EXPECT_NEAR(boards[0].north_m, 2.2136, 1e-4);
  EXPECT_NEAR(boards[0].east_m, 0.0, 1e-12);
  EXPECT_NEAR(boards[0].heading_deg, 0.0, 1e-12);
  EXPECT_NEAR(boards[2].north_m, 0.0, 1e-12);
  EXPECT_NEAR(boards[2].east_m, 3.1743, 1e-4);
  EXPECT_NEAR(boards[2].heading_deg, 90.0, 1e-12);
  // The second corner is (0, -2.5), reached heading -135 deg: its board
  // stands 1.0864 - 0.8 = 0.2864 m before it along that heading.
  const double back = 0.2864 * std::sqrt(0.5);
  EXPECT_NEAR(boards[1].north_m, back, 1e-4);
  EXPECT_NEAR(boards[1].east_m, -2.5 + back, 1e-4);
  // The last corner is on the start line, 2.5607 m south of the crossing,
  // reached heading 315 deg: its board 0.6136 m beyond it that way.
  EXPECT_NEAR(boards[7].north_m, -2.5607 + 0.6136 * std::sqrt(0.5), 1e-4);
  EXPECT_NEAR(boards[7].east_m, -0.6136 * std::sqrt(0.5), 1e-4);
  // The 135 deg boards' single disk a quarter of the column (0.065 of the
  // board) above its middle, the 45 deg ones' below.
  EXPECT_NEAR(patternDisks(boards[0])[2][1], 0.435, 1e-12);
  EXPECT_NEAR(patternDisks(boards[2])[2][1], 0.565, 1e-12);
}

// Eight gates, each with its two decoys.
TEST(Course, TheGatesWithTheirDecoys) {
  CourseParams params;
  params.layout = "gates";
  const std::vector<CourseBoard> boards = courseBoards(params);
  int gates = 0, decoys = 0;
  for (const CourseBoard& board : boards) {
    gates += board.kind == "gate" ? 1 : 0;
    decoys += board.kind == "decoy" ? 1 : 0;
  }
  EXPECT_EQ(gates, 8);
  EXPECT_EQ(decoys, 16);
}

TEST(Course, ATurnAPatternCannotSayIsRefused) {
  CourseParams params;
  CourseBoard board;
  board.kind = "slalom_right";
  board.turn_deg = 90.0;
  params.boards["odd"] = board;
  try {
    courseBoards(params);
    FAIL() << "no error";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find("turn_deg"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace nadir::terrain
