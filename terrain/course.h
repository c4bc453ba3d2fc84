#pragma once
// Upright boards standing on the floor of a course for a ground rover, after
// Liu et al. (2021): gates (two posts and a pattern board across their tops,
// driven through), slalom boards (a board on one post whose pattern says which
// side to pass it on) and decoys (a board on one post with a pattern that is
// not a gate's). A course is a layout (the gate course, the slalom line, the
// number 8) with seeded decoys, plus boards given one by one. World frame
// (local NED), metres; the floor is taken as the world's ground at each board.

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/params.h"

namespace nadir::terrain {

struct CourseBoard {
  // gate, slalom_left, slalom_right or decoy.
  std::string kind = "gate";
  // decoy: "similar" (a gate's pattern with one thing wrong) or "random".
  std::string decoy_pattern = "similar";
  // The board's centre line on the floor, world frame, m.
  double north_m = 0.0;
  double east_m = 0.0;
  // The direction a vehicle drives through or past it, deg from north towards
  // east; the pattern faces a vehicle coming that way.
  double heading_deg = 0.0;
  // Side of the square board, m.
  double board_m = 0.45;
  // Gate: between the posts' inner faces, m.
  double opening_m = 0.36;
  // The board's lower edge above the floor, m (a gate's opening height).
  double clearance_m = 0.2;
  // Side of a post's square section, m.
  double post_m = 0.03;
  // decoy: which pattern of its kind.
  std::int64_t seed = 1;
  // Slalom boards: 0 asks to pass the board on its side and come back (the
  // single disk beside the column's middle); 45 or 135 asks to turn by that
  // much to its side and go on to the next board (the disk a quarter of the
  // column below or above its middle), as the number 8 of Liu et al. (2021).
  double turn_deg = 0.0;

  void visit(core::ParamVisitor& v);
};

struct CourseParams {
  // none, gates (eight gates on an S through the arena), slalom (boards in
  // a line, alternately passed on the right and the left) or number8 (eight
  // turn boards: two 135 deg left turns around a triangle, six 45 deg right
  // turns around a cut octagon, crossing where the layout starts).
  std::string layout = "none";
  // Where the layout starts and the direction it runs, world frame.
  double north_m = 0.0;
  double east_m = 0.0;
  double heading_deg = 0.0;
  // gates: decoys beside each gate, on seeded sides and distances, with
  // seeded patterns.
  int decoys_per_gate = 2;
  std::int64_t decoy_seed = 1;
  // slalom: boards this far apart, m, and how many.
  double slalom_spacing_m = 2.4;
  int slalom_boards = 6;
  // number8: the octagon's side and the triangle's short sides, m; and the
  // turn the boards are set for: a car turning on turn_radius_m that starts
  // its turn trigger_m before a board.
  double number8_side_m = 1.5;
  double number8_loop_m = 2.5;
  double number8_turn_radius_m = 0.45;
  double number8_trigger_m = 0.8;
  // The boards' size, for every board of the layout.
  double board_m = 0.45;
  // More boards by name (after the layout's, in name order).
  std::map<std::string, CourseBoard> boards;

  void visit(core::ParamVisitor& v);
};

// The layout's boards, then the named ones; throws core::ParamError for a
// value out of range.
std::vector<CourseBoard> courseBoards(const CourseParams& params);

// A board's pattern as 8-bit gray (CV_8UC1), size_px square, row 0 at the top
// as a vehicle in front of it sees it. Edges area-averaged.
cv::Mat boardPattern(const CourseBoard& board, int size_px);

// Where the pattern's disks are, as fractions of the board (x right, y down as
// seen from the front): a gate's four (top-left, top-right, bottom-left,
// bottom-right), a slalom board's three, a decoy's whatever it has.
std::vector<std::array<double, 2>> patternDisks(const CourseBoard& board);
// Radius of the pattern's disks as a fraction of the board's side.
double patternDiskRadius(const CourseBoard& board);

// The board's geometry in the world frame.
struct BoardFrame {
  // Centre of the board's face.
  Eigen::Vector3d centre_ned = Eigen::Vector3d::Zero();
  // Unit vectors: to the board's right and up as seen from the front, and the
  // way the vehicle drives (from the front to the back).
  Eigen::Vector3d right_ned = Eigen::Vector3d::UnitY();
  Eigen::Vector3d up_ned = -Eigen::Vector3d::UnitZ();
  Eigen::Vector3d forward_ned = Eigen::Vector3d::UnitX();
};
BoardFrame boardFrame(const CourseBoard& board, double floor_up_m);
// A point of the board's face at pattern fractions (x right, y down), world frame.
Eigen::Vector3d boardPoint(const BoardFrame& frame, double board_m, double x, double y);

// A post's footprint on the floor: a square of side size_m about (north, east),
// turned with the board, standing height_m.
struct Post {
  double north_m = 0.0;
  double east_m = 0.0;
  double size_m = 0.0;
  double height_m = 0.0;
  double heading_deg = 0.0;
};
// A gate's two posts (left then right as seen from the front); one for other boards.
std::vector<Post> boardPosts(const CourseBoard& board);

}  // namespace nadir::terrain
