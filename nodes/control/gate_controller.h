#pragma once
// The rover's reactive controller of Liu et al. (2021), without LCM: each
// frame's pattern (the disks the PPA found) in, a steering angle and a speed
// out. Two PIDs, summed as the paper's equations 4-7:
//   D_y      the pattern centre's bearing from the reference centre, rad
//            (the reference: the pattern head-on, in the image's centre
//            column unless reference_x_px says otherwise);
//   delta_y  the pattern's deformation: its left column's height over its
//            right column's, minus 1 (0 head-on; > 0 seen from its left, so
//            steering right brings the rover onto its axis).
// Both steer right when positive; delta_y is low-passed first (it is a small
// difference of small heights). The speed is constant while a pattern is in
// view (the paper's remote-set speed). A gate's board leaves the top of the
// image before the rover reaches it (and the tracker may then find the next
// gate, further off): the rover then drives straight on through it (for the
// distance its disks last showed, plus pass_margin_m) whatever else it sees,
// so that the next gate cannot turn it into a post. Whenever nothing
// is in view it coasts straight on for coast_s, then brakes to a stop over
// stop_s: it never drives on blind at speed. A slalom board is tracked the same way until its
// distance (from its disk column's height in the image) falls to
// slalom.trigger_m; then the rover turns to the side the board shows by
// slalom.turn_deg (at full lock, or as tight as its tyres hold at its speed),
// goes straight for slalom.straight_m, all on its own commands (no other
// sensor), and turns back the other way until the next board is in view
// (blind no longer than coast_s and stop_s allow). A board whose single disk
// sits a quarter of its column below or above the column's middle asks for a
// turn of slalom.low_turn_deg or slalom.high_turn_deg instead: the rover turns
// by that much to its side and goes straight on until it sees the next board
// (the number 8), again blind no longer than coast_s and stop_s allow.
// docs/closed_loop.md has the method and the figures.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/params.h"

namespace nadir::control {

struct PidGains {
  double kp = 0.0;
  double ki = 0.0;  // per second of the error's integral
  double kd = 0.0;  // seconds: times the error's rate
  // The integral term's share of the output at most, rad.
  double integral_limit_rad = 0.1;

  void visit(core::ParamVisitor& v);
};

struct SlalomParams {
  // Distance from the board at which the turn starts, m.
  double trigger_m = 0.8;
  // Heading change of the turn and of the turn back, deg.
  double turn_deg = 45.0;
  // Straight between the turn and the turn back, m.
  double straight_m = 0.35;
  // The board's disk column: its disks' centres are this share of the board's side apart.
  double column_share = 0.26;
  // The turns a board's single disk asks for below and above its column's
  // middle, deg (turn and go on).
  double low_turn_deg = 45.0;
  double high_turn_deg = 135.0;

  void visit(core::ParamVisitor& v);
};

struct GateControllerParams {
  double cruise_speed_mps = 2.4;
  // D_y and delta_y to steering, rad.
  PidGains lateral{.kp = 1.2, .ki = 0.0, .kd = 0.02, .integral_limit_rad = 0.1};
  PidGains deformation{.kp = 2.0, .ki = 0.0, .kd = 0.0, .integral_limit_rad = 0.1};
  // delta_y's low-pass time constant, s.
  double deformation_filter_s = 0.05;
  // The reference pattern's centre column, px; < 0: the image's centre.
  double reference_x_px = -1.0;
  // The vehicle: its steering lock and wheelbase (for the slalom's turns).
  double max_steer_deg = 30.0;
  double wheelbase_m = 0.26;
  // The tyres' grip, m/s^2: the slalom's turns are planned no tighter than
  // speed^2 / this; 0: as tight as the lock allows.
  double max_lateral_acceleration_mps2 = 0.0;
  // Pattern lost: straight on at speed for coast_s, then to a stop over stop_s.
  double coast_s = 0.4;
  double stop_s = 0.5;
  // The patterns' boards: side, m; a gate's disk rows are gate_row_share of it apart.
  double board_m = 0.45;
  double gate_row_share = 0.24;
  // A gate lost within commit_m is driven through: straight on for its
  // distance plus pass_margin_m, m.
  double commit_m = 1.5;
  double pass_margin_m = 0.3;
  SlalomParams slalom;

  void visit(core::ParamVisitor& v);
};

// A pinhole lens, px.
struct Lens {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
};

enum class Pattern { kNone, kGate, kSlalomLeft, kSlalomRight };

struct PatternObservation {
  std::int64_t utime = 0;
  Pattern kind = Pattern::kNone;
  // A gate's top-left, top-right, bottom-left, bottom-right; a slalom
  // board's column top, column bottom, tip; px.
  std::vector<Eigen::Vector2d> disks_px;
};

enum class DriveMode { kTracking, kCoasting, kStopping, kManoeuvre, kStopped };

struct SteeringCommand {
  double steer_rad = 0.0;  // positive: right
  double speed_mps = 0.0;
  DriveMode mode = DriveMode::kStopped;
  double lateral_error_rad = 0.0;  // D_y
  double deformation = 0.0;        // delta_y
  // The pattern's distance from its disks' spacing, m (0 for nothing).
  double board_distance_m = 0.0;
};

// The pattern's distance from the spacing of its disks (a gate's rows, a
// slalom board's column), m; 0 when it cannot tell.
double patternDistance_m(const PatternObservation& pattern, const Lens& lens,
                         const GateControllerParams& params);
// The pattern's D_y (rad) and delta_y for a lens and reference column.
double lateralError_rad(const PatternObservation& pattern, const Lens& lens, double reference_x_px);
double deformationOf(const PatternObservation& pattern);
// What a slalom board asks for: 0 to pass it (the single disk level with the
// column's middle, within an eighth of the column), else the turn in deg.
double boardTurn_deg(const PatternObservation& pattern, const SlalomParams& params);

class GateController {
 public:
  // Throws core::ParamError for invalid parameters.
  explicit GateController(const GateControllerParams& params);

  // One frame's pattern (kind kNone when nothing was found), in time order.
  SteeringCommand update(const PatternObservation& pattern, const Lens& lens);
  const GateControllerParams& params() const { return params_; }

 private:
  struct Pid {
    double integral = 0.0;
    double previous = 0.0;
    bool has_previous = false;
    double step(const PidGains& gains, double error, double dt_s);
    void reset() { *this = Pid{}; }
  };
  SteeringCommand manoeuvre(std::int64_t utime);
  SteeringCommand lost(std::int64_t utime);
  SteeringCommand throughGate(std::int64_t utime);
  SteeringCommand returnTurn(std::int64_t utime);

  GateControllerParams params_;
  Pid lateral_, deformation_;
  std::int64_t previous_utime_ = -1;
  // When the pattern was last seen (or the last manoeuvre ended).
  std::int64_t last_seen_utime_ = -1;
  bool moving_ = false;
  double deformation_filtered_ = 0.0;
  // The gate tracked in the last frame and its distance then; driving through
  // a lost gate until commit_until_.
  bool tracking_gate_ = false;
  double gate_distance_m_ = 0.0;
  std::int64_t commit_until_ = -1;
  // The slalom manoeuvre under way: its start, direction (+1 right) and phase times.
  bool in_manoeuvre_ = false;
  std::int64_t manoeuvre_start_ = 0;
  double manoeuvre_side_ = 0.0;
  double turn_s_ = 0.0, straight_s_ = 0.0;
  double manoeuvre_steer_rad_ = 0.0;
  // After a slalom turn: turning back until the next board is in view.
  bool returning_ = false;
  // The manoeuvre is a turn that goes straight on after it (no turn back).
  bool go_on_ = false;
};

}  // namespace nadir::control
