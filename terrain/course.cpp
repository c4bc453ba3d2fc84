#include "terrain/course.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <opencv2/core.hpp>

namespace nadir::terrain {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kWhite = 235.0;
constexpr double kBlack = 20.0;

// The bands of the two concentric squares, as distances from the board's edge
// (fractions of its side): outer square [0.04, 0.11), inner square [0.17, 0.24).
constexpr double kOuterFrom = 0.04, kOuterTo = 0.11;
constexpr double kInnerFrom = 0.17, kInnerTo = 0.24;
constexpr double kDiskRadius = 0.075;

// What a pattern is drawn of: disks, and which of the two squares are there
// (the outer one possibly cut on its right side).
struct PatternSpec {
  std::vector<std::array<double, 2>> disks;
  double disk_radius = kDiskRadius;
  bool outer = true;
  bool inner = true;
  bool outer_cut = false;
};

PatternSpec gateSpec() { return {{{0.38, 0.38}, {0.62, 0.38}, {0.38, 0.62}, {0.62, 0.62}}}; }

// Turn right: two disks on the left, the single one on the right (an arrow
// head), beside the column's middle to pass the board, a quarter of the
// column lower for a 45 deg turn, higher for 135 deg.
PatternSpec slalomSpec(bool right, double turn_deg) {
  const double near = right ? 0.37 : 0.63, tip = right ? 0.63 : 0.37;
  const double tip_y = turn_deg == 45.0 ? 0.565 : turn_deg == 135.0 ? 0.435 : 0.5;
  return {{{near, 0.37}, {near, 0.63}, {tip, tip_y}}};
}

PatternSpec decoySpec(const CourseBoard& board) {
  std::mt19937_64 rng(static_cast<std::uint64_t>(board.seed));
  if (board.decoy_pattern == "similar") {
    PatternSpec spec = gateSpec();
    switch (board.seed % 5) {
      case 0:  // one square only
        spec.inner = false;
        break;
      case 1:  // two disks on a diagonal
        spec.disks = {spec.disks[0], spec.disks[3]};
        break;
      case 2:  // no squares
        spec.outer = spec.inner = false;
        break;
      case 3:  // the outer square cut open
        spec.outer_cut = true;
        break;
      default:  // four disks in a row
        spec.disks = {{0.31, 0.5}, {0.437, 0.5}, {0.563, 0.5}, {0.69, 0.5}};
        spec.disk_radius = 0.05;
        break;
    }
    return spec;
  }
  // Random: 3 to 7 disks of one random size that do not touch, and at most one
  // square, so that nothing on it lies inside two boundaries.
  PatternSpec spec;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  spec.disk_radius = 0.04 + 0.05 * unit(rng);
  spec.outer = unit(rng) < 0.5;
  spec.inner = false;
  const int wanted = 3 + static_cast<int>(rng() % 5);
  const double lo = (spec.outer ? kOuterTo : 0.04) + spec.disk_radius + 0.03;
  for (int attempt = 0; attempt < 200 && static_cast<int>(spec.disks.size()) < wanted; ++attempt) {
    const std::array<double, 2> c = {lo + (1.0 - 2.0 * lo) * unit(rng),
                                     lo + (1.0 - 2.0 * lo) * unit(rng)};
    const bool clear = std::all_of(spec.disks.begin(), spec.disks.end(), [&](const auto& d) {
      return std::hypot(d[0] - c[0], d[1] - c[1]) > 2.0 * spec.disk_radius + 0.04;
    });
    if (clear) spec.disks.push_back(c);
  }
  return spec;
}

PatternSpec specOf(const CourseBoard& board) {
  if (board.kind == "gate") return gateSpec();
  if (board.kind == "slalom_right") return slalomSpec(true, board.turn_deg);
  if (board.kind == "slalom_left") return slalomSpec(false, board.turn_deg);
  return decoySpec(board);
}

double reflectance(const PatternSpec& spec, double x, double y) {
  const double from_edge = std::min({x, y, 1.0 - x, 1.0 - y});
  if (spec.outer && from_edge >= kOuterFrom && from_edge < kOuterTo &&
      !(spec.outer_cut && x > 0.5 && y > 0.42 && y < 0.58)) {
    return kBlack;
  }
  if (spec.inner && from_edge >= kInnerFrom && from_edge < kInnerTo) return kBlack;
  for (const auto& d : spec.disks) {
    if (std::hypot(x - d[0], y - d[1]) < spec.disk_radius) return kBlack;
  }
  return kWhite;
}

// The gates layout: eight gates on a sine through the arena, a quarter period
// apart, so that the next gate is never more than about 15 deg off the way a
// vehicle leaves the last one.
constexpr int kGates = 8;
constexpr double kGateSpacing_m = 3.0;
constexpr double kGateWave_m = 0.35;

}  // namespace

void CourseBoard::visit(core::ParamVisitor& v) {
  v.field("kind", &kind,
          {.doc = "gate, slalom_left, slalom_right or decoy",
           .choices = {"gate", "slalom_left", "slalom_right", "decoy"}});
  v.field("decoy_pattern", &decoy_pattern,
          {.doc = "decoy: similar (a gate's pattern with one thing wrong) or random",
           .choices = {"similar", "random"}});
  v.field("north_m", &north_m, {.doc = "centre north of the origin, m", .min = -1e6, .max = 1e6});
  v.field("east_m", &east_m, {.doc = "centre east of the origin, m", .min = -1e6, .max = 1e6});
  v.field("heading_deg", &heading_deg,
          {.doc = "the way a vehicle drives through or past it, deg from north towards east",
           .min = -360,
           .max = 360});
  v.field("board_m", &board_m, {.doc = "side of the square board, m", .min = 0.05, .max = 10});
  v.field("opening_m", &opening_m,
          {.doc = "gate: between the posts' inner faces, m", .min = 0.05, .max = 10});
  v.field("clearance_m", &clearance_m,
          {.doc = "the board's lower edge above the floor, m", .min = 0.0, .max = 10});
  v.field("post_m", &post_m, {.doc = "side of a post's square section, m", .min = 0.005, .max = 1});
  v.field("seed", &seed, {.doc = "decoy: which pattern of its kind", .min = 0});
  v.field(
      "turn_deg", &turn_deg,
      {.doc = "slalom board: 0 pass it, 45 or 135 turn by that and go on", .min = 0, .max = 135});
}

void CourseParams::visit(core::ParamVisitor& v) {
  v.field("layout", &layout,
          {.doc = "none, gates (eight on an S), slalom (a line) or number8",
           .choices = {"none", "gates", "slalom", "number8"}});
  v.field("north_m", &north_m,
          {.doc = "where the layout starts, north, m", .min = -1e6, .max = 1e6});
  v.field("east_m", &east_m, {.doc = "where the layout starts, east, m", .min = -1e6, .max = 1e6});
  v.field("heading_deg", &heading_deg,
          {.doc = "the direction the layout runs, deg from north towards east",
           .min = -360,
           .max = 360});
  v.field("decoys_per_gate", &decoys_per_gate,
          {.doc = "gates: decoy boards beside each gate", .min = 0, .max = 8});
  v.field("decoy_seed", &decoy_seed,
          {.doc = "gates: seed of the decoys' places and patterns", .min = 0});
  v.field("slalom_spacing_m", &slalom_spacing_m,
          {.doc = "slalom: distance between boards, m", .min = 0.5, .max = 100});
  v.field("slalom_boards", &slalom_boards,
          {.doc = "slalom: number of boards", .min = 1, .max = 100});
  v.field("number8_side_m", &number8_side_m,
          {.doc = "number8: the octagon's side, m", .min = 0.5, .max = 100});
  v.field("number8_loop_m", &number8_loop_m,
          {.doc = "number8: the triangle's short sides, m", .min = 0.5, .max = 100});
  v.field(
      "number8_turn_radius_m", &number8_turn_radius_m,
      {.doc = "number8: the turn the boards are set for, its radius, m", .min = 0.05, .max = 100});
  v.field("number8_trigger_m", &number8_trigger_m,
          {.doc = "number8: and how far before a board it starts, m", .min = 0.05, .max = 100});
  v.field("board_m", &board_m, {.doc = "side of the layout's boards, m", .min = 0.05, .max = 10});
  core::visitGroupMap(v, "boards", "more boards by name", boards);
}

std::vector<CourseBoard> courseBoards(const CourseParams& params) {
  CourseParams checked = params;
  core::validateParams([&checked](core::ParamVisitor& v) { checked.visit(v); }, "course");
  std::vector<CourseBoard> boards;
  const double h = params.heading_deg * kDeg;
  const Eigen::Vector2d start(params.north_m, params.east_m);
  const Eigen::Vector2d forward(std::cos(h), std::sin(h)), right(-std::sin(h), std::cos(h));
  const auto place = [&](double along_m, double across_m, double heading_deg, const char* kind) {
    CourseBoard board;
    board.kind = kind;
    const Eigen::Vector2d p = start + along_m * forward + across_m * right;
    board.north_m = p.x();
    board.east_m = p.y();
    board.heading_deg = params.heading_deg + heading_deg;
    board.board_m = params.board_m;
    return board;
  };
  if (params.layout == "gates") {
    std::mt19937_64 rng(static_cast<std::uint64_t>(params.decoy_seed));
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<CourseBoard> decoys;
    const double slope = 2.0 * std::numbers::pi * kGateWave_m / (4.0 * kGateSpacing_m);
    for (int i = 0; i < kGates; ++i) {
      const double phase = 0.5 * std::numbers::pi * i;
      const double along = kGateSpacing_m * (i + 1);
      const double across = kGateWave_m * std::sin(phase);
      const double heading = std::atan(slope * std::cos(phase)) / kDeg;
      const CourseBoard gate = place(along, across, heading, "gate");
      boards.push_back(gate);
      const double gh = gate.heading_deg * kDeg;
      const Eigen::Vector2d gate_right(-std::sin(gh), std::cos(gh)),
          gate_fwd(std::cos(gh), std::sin(gh));
      const double first_side = unit(rng) < 0.5 ? -1.0 : 1.0;
      for (int k = 0; k < params.decoys_per_gate; ++k) {
        // Alternate sides, each further out than the last on its side.
        const double side = k % 2 == 0 ? first_side : -first_side;
        const double out_m = 0.8 + 0.5 * unit(rng) + 0.7 * (k / 2);
        const double back_m = -0.3 + 0.6 * unit(rng);
        CourseBoard decoy = gate;
        decoy.kind = "decoy";
        decoy.decoy_pattern = unit(rng) < 0.5 ? "similar" : "random";
        decoy.seed = static_cast<std::int64_t>(rng() % 1000000);
        const Eigen::Vector2d p = Eigen::Vector2d(gate.north_m, gate.east_m) +
                                  side * out_m * gate_right + back_m * gate_fwd;
        decoy.north_m = p.x();
        decoy.east_m = p.y();
        decoy.heading_deg = gate.heading_deg - 15.0 + 30.0 * unit(rng);
        decoys.push_back(decoy);
      }
    }
    boards.insert(boards.end(), decoys.begin(), decoys.end());
  } else if (params.layout == "slalom") {
    for (int i = 0; i < params.slalom_boards; ++i) {
      boards.push_back(place(params.slalom_spacing_m * (i + 1), 0.0, 0.0,
                             i % 2 == 0 ? "slalom_right" : "slalom_left"));
    }
  } else if (params.layout == "number8") {
    // The path's corners in the layout's frame (along, across to the right):
    // the triangle's two 135 deg left turns, then the octagon's six 45 deg
    // right turns; each leg's heading from the last and its length. The
    // octagon closes on the crossing when its two long legs are
    // (1 + 1 / sqrt(2)) sides.
    const double a = params.number8_loop_m, s = params.number8_side_m;
    const double long_leg = (1.0 + std::sqrt(0.5)) * s;
    struct Turn {
      double leg_m;
      double heading_deg;  // of the leg that ends at the corner
      double turn_deg;     // + right
    };
    const std::array<Turn, 8> turns = {{{a, 0, -135},
                                        {a * std::sqrt(2.0), -135, -135},
                                        {a + long_leg, 90, 45},
                                        {s, 135, 45},
                                        {s, 180, 45},
                                        {s, 225, 45},
                                        {s, 270, 45},
                                        {s, 315, 45}}};
    Eigen::Vector2d corner(0.0, 0.0);
    for (const Turn& turn : turns) {
      const double hd = turn.heading_deg * kDeg;
      const Eigen::Vector2d along(std::cos(hd), std::sin(hd));
      corner += turn.leg_m * along;
      // The turn starts r tan(turn / 2) before the corner; the board stands
      // the trigger distance beyond that start, facing the car.
      const double lead_m =
          params.number8_turn_radius_m * std::tan(0.5 * std::abs(turn.turn_deg) * kDeg);
      const Eigen::Vector2d at = corner + (params.number8_trigger_m - lead_m) * along;
      CourseBoard board = place(at.x(), at.y(), turn.heading_deg,
                                turn.turn_deg > 0 ? "slalom_right" : "slalom_left");
      board.turn_deg = std::abs(turn.turn_deg);
      boards.push_back(board);
    }
  }
  for (const auto& [name, board] : params.boards) boards.push_back(board);
  for (const CourseBoard& board : boards) {
    if (board.turn_deg != 0.0 && board.turn_deg != 45.0 && board.turn_deg != 135.0) {
      throw core::ParamError("course: a board's turn_deg is " + std::to_string(board.turn_deg) +
                             ": its pattern says 0 (pass it), 45 or 135");
    }
  }
  return boards;
}

cv::Mat boardPattern(const CourseBoard& board, int size_px) {
  const PatternSpec spec = specOf(board);
  cv::Mat gray(size_px, size_px, CV_8UC1);
  constexpr int kSamples = 3;
  for (int row = 0; row < size_px; ++row) {
    auto* out = gray.ptr<std::uint8_t>(row);
    for (int col = 0; col < size_px; ++col) {
      double sum = 0.0;
      for (int i = 0; i < kSamples; ++i) {
        for (int j = 0; j < kSamples; ++j) {
          sum += reflectance(spec, (col + (j + 0.5) / kSamples) / size_px,
                             (row + (i + 0.5) / kSamples) / size_px);
        }
      }
      out[col] = static_cast<std::uint8_t>(std::lround(sum / (kSamples * kSamples)));
    }
  }
  return gray;
}

std::vector<std::array<double, 2>> patternDisks(const CourseBoard& board) {
  return specOf(board).disks;
}

double patternDiskRadius(const CourseBoard& board) { return specOf(board).disk_radius; }

BoardFrame boardFrame(const CourseBoard& board, double floor_up_m) {
  const double h = board.heading_deg * kDeg;
  BoardFrame frame;
  frame.forward_ned = Eigen::Vector3d(std::cos(h), std::sin(h), 0.0);
  frame.right_ned = Eigen::Vector3d(-std::sin(h), std::cos(h), 0.0);
  frame.up_ned = -Eigen::Vector3d::UnitZ();
  // The face stands just in front of the posts.
  frame.centre_ned = Eigen::Vector3d(board.north_m, board.east_m,
                                     -(floor_up_m + board.clearance_m + 0.5 * board.board_m)) -
                     (0.5 * board.post_m + 0.002) * frame.forward_ned;
  return frame;
}

Eigen::Vector3d boardPoint(const BoardFrame& frame, double board_m, double x, double y) {
  return frame.centre_ned + (x - 0.5) * board_m * frame.right_ned +
         (0.5 - y) * board_m * frame.up_ned;
}

std::vector<Post> boardPosts(const CourseBoard& board) {
  const double h = board.heading_deg * kDeg;
  const Eigen::Vector2d right(-std::sin(h), std::cos(h));
  const Eigen::Vector2d centre(board.north_m, board.east_m);
  std::vector<Post> posts;
  const auto post = [&](double across_m, double height_m) {
    const Eigen::Vector2d p = centre + across_m * right;
    posts.push_back({p.x(), p.y(), board.post_m, height_m, board.heading_deg});
  };
  if (board.kind == "gate") {
    const double across = 0.5 * (board.opening_m + board.post_m);
    post(-across, board.clearance_m + board.board_m);
    post(across, board.clearance_m + board.board_m);
  } else {
    post(0.0, board.clearance_m + 0.5 * board.board_m);
  }
  return posts;
}

}  // namespace nadir::terrain
