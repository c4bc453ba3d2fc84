// The rover's controller against hand-worked cases: a gate off axis steers
// towards its axis by the PIDs' sum; a lost or missing pattern slows the rover
// to a stop and never lets it drive on blind at speed; a gate lost close by
// is driven through straight; a slalom board within the trigger turns the
// rover to the side it shows; a turn board turns it by what it asks and lets
// it go on.

#include "nodes/control/gate_controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace nadir::control {
namespace {

// A 256 x 256 camera of 50 deg: fx = 128 / tan(25 deg) = 274.4947 px.
const Lens kLens{274.4947, 274.4947, 127.5, 127.5};

// A gate whose disk centre columns are at x_left and x_right, its left column
// left_px tall and its right column right_px tall, centred on row 128.
PatternObservation gate(std::int64_t utime, double x_left, double x_right, double left_px,
                        double right_px) {
  PatternObservation p;
  p.utime = utime;
  p.kind = Pattern::kGate;
  p.disks_px = {{x_left, 128.0 - 0.5 * left_px},
                {x_right, 128.0 - 0.5 * right_px},
                {x_left, 128.0 + 0.5 * left_px},
                {x_right, 128.0 + 0.5 * right_px}};
  return p;
}

PatternObservation nothing(std::int64_t utime) {
  PatternObservation p;
  p.utime = utime;
  return p;
}

// A slalom board (column 0.26 x 0.45 m tall) distance_m ahead, its column at
// x = 120 px centred on row 128, its single disk on side (+1 right) at
// tip_share of the column from its top.
PatternObservation slalomBoard(Pattern kind, double side, std::int64_t utime, double distance_m,
                               double tip_share) {
  PatternObservation p;
  p.utime = utime;
  p.kind = kind;
  const double column_px = 0.26 * 0.45 * kLens.fy / distance_m;
  p.disks_px = {{120.0, 128.0 - 0.5 * column_px},
                {120.0, 128.0 + 0.5 * column_px},
                {120.0 + side * 0.5 * column_px, 128.0 + (tip_share - 0.5) * column_px}};
  return p;
}

GateControllerParams plainParams() {
  GateControllerParams params;
  params.lateral = {.kp = 1.2, .ki = 0.0, .kd = 0.0, .integral_limit_rad = 0.1};
  params.deformation = {.kp = 2.0, .ki = 0.0, .kd = 0.0, .integral_limit_rad = 0.1};
  params.deformation_filter_s = 0.0;
  return params;
}

// Centre 20 px right of the image centre (D_y = atan(20 / 274.4947) =
// 0.072732 rad) and the left column 40 px tall against the right's 36 px
// (delta_y = 40 / 36 - 1 = 0.111111: seen from the gate's left): both steer
// right, by 1.2 x 0.072732 + 2.0 x 0.111111 = 0.309501 rad.
TEST(GateControllerTest, AGateOffAxisSteersTowardsItsAxis) {
  GateController controller(plainParams());
  const SteeringCommand command =
      controller.update(gate(1'000'000, 127.5, 167.5, 40.0, 36.0), kLens);
  EXPECT_EQ(command.mode, DriveMode::kTracking);
  EXPECT_NEAR(command.lateral_error_rad, 0.072732, 1e-6);
  EXPECT_NEAR(command.deformation, 0.111111, 1e-6);
  EXPECT_NEAR(command.steer_rad, 0.309501, 1e-5);
  EXPECT_DOUBLE_EQ(command.speed_mps, 2.4);

  // Mirrored: centred 20 px left, seen from its right: steer left as much.
  GateController mirrored(plainParams());
  const SteeringCommand left = mirrored.update(gate(1'000'000, 87.5, 127.5, 36.0, 40.0), kLens);
  EXPECT_NEAR(left.lateral_error_rad, -0.072732, 1e-6);
  EXPECT_NEAR(left.deformation, 36.0 / 40.0 - 1.0, 1e-9);
  EXPECT_NEAR(left.steer_rad, -1.2 * 0.072732 + 2.0 * (36.0 / 40.0 - 1.0), 1e-6);
}

// The derivative acts on the error's rate per second; steering is held to the lock.
TEST(GateControllerTest, DerivativeAndLock) {
  GateControllerParams params = plainParams();
  params.lateral.kd = 0.05;
  params.deformation.kp = 0.0;
  GateController controller(params);
  controller.update(gate(0, 127.5, 127.5, 30.0, 30.0), kLens);
  // 5 ms later the centre is 10 px right: D_y = atan(10 / 274.4947) = 0.036414
  // rad, its rate 7.2828 rad/s: 1.2 x 0.036414 + 0.05 x 7.2828 = 0.407838 rad.
  const SteeringCommand command = controller.update(gate(5'000, 137.5, 137.5, 30.0, 30.0), kLens);
  EXPECT_NEAR(command.steer_rad, 0.407838, 1e-5);
  GateController hard(plainParams());
  EXPECT_NEAR(hard.update(gate(0, 250.0, 254.0, 30.0, 10.0), kLens).steer_rad,
              30.0 * std::numbers::pi / 180.0, 1e-12);
}

// Before any pattern the rover stays; after the last one it coasts straight
// for coast_s, brakes linearly over stop_s and stops: speed at 0.2 s after the
// pattern 2.4, at 0.65 s 2.4 x (1 - 0.25 / 0.5) = 1.2, from 0.9 s on 0.
TEST(GateControllerTest, AMissingPatternSlowsTheRoverToAStop) {
  GateControllerParams params = plainParams();
  params.commit_m = 0.0;  // no drive-through: only the watchdog
  GateController controller(params);
  EXPECT_EQ(controller.update(nothing(0), kLens).speed_mps, 0.0);
  EXPECT_EQ(controller.update(nothing(100'000), kLens).mode, DriveMode::kStopped);
  controller.update(gate(1'000'000, 127.5, 127.5, 30.0, 30.0), kLens);
  double previous = 2.4;
  for (std::int64_t t = 1'005'000; t <= 2'500'000; t += 5'000) {
    const SteeringCommand command = controller.update(nothing(t), kLens);
    const double since_s = (t - 1'000'000) * 1e-6;
    EXPECT_EQ(command.steer_rad, 0.0);
    EXPECT_LE(command.speed_mps, previous + 1e-12) << "at " << since_s << " s";
    if (since_s <= 0.4) {
      EXPECT_DOUBLE_EQ(command.speed_mps, 2.4);
      EXPECT_EQ(command.mode, DriveMode::kCoasting);
    }
    if (std::abs(since_s - 0.65) < 1e-9) {
      EXPECT_NEAR(command.speed_mps, 1.2, 1e-9);
    }
    if (since_s >= 0.9) {
      EXPECT_EQ(command.speed_mps, 0.0) << "at " << since_s << " s";
    }
    previous = command.speed_mps;
  }
}

// A gate at 1 m (rows 0.24 x 0.45 m apart: 0.108 x 274.4947 / 1 = 29.65 px)
// that leaves the image is driven through: straight at cruise for
// (1 + 0.3) / 2.4 = 0.5417 s, even when the next gate (further, smaller)
// shows off to the side, then tracked again.
TEST(GateControllerTest, ALostGateCloseByIsDrivenThrough) {
  GateController controller(plainParams());
  const double rows_px = 0.24 * 0.45 * kLens.fy / 1.0;
  const SteeringCommand tracking =
      controller.update(gate(0, 120.0, 135.0, rows_px, rows_px), kLens);
  EXPECT_NEAR(tracking.board_distance_m, 1.0, 1e-9);
  for (std::int64_t t = 5'000; t <= 545'000; t += 5'000) {
    // The next gate, 3 m off and 40 px right.
    const SteeringCommand command =
        controller.update(gate(t, 160.0, 170.0, rows_px / 3.0, rows_px / 3.0), kLens);
    EXPECT_EQ(command.mode, DriveMode::kCoasting) << t;
    EXPECT_EQ(command.steer_rad, 0.0) << t;
    EXPECT_DOUBLE_EQ(command.speed_mps, 2.4);
  }
  controller.update(gate(550'000, 160.0, 170.0, rows_px / 3.0, rows_px / 3.0), kLens);
  const SteeringCommand after =
      controller.update(gate(555'000, 160.0, 170.0, rows_px / 3.0, rows_px / 3.0), kLens);
  EXPECT_EQ(after.mode, DriveMode::kTracking);
  EXPECT_GT(after.steer_rad, 0.0);
}

// A slalom board (column 0.26 x 0.45 m tall) within the trigger turns the
// rover to the side it shows, at the lock or the grip's limit: at 4 m/s and
// 10 m/s^2 a radius of 1.6 m, steering atan(0.26 / 1.6) = 0.161092 rad, for
// 30 deg x 1.6 m / 4 m/s = 0.20944 s; then back the other way.
TEST(GateControllerTest, ASlalomBoardTurnsTheRoverToItsSide) {
  GateControllerParams params = plainParams();
  params.cruise_speed_mps = 4.0;
  params.max_lateral_acceleration_mps2 = 10.0;
  params.slalom.trigger_m = 1.3;
  params.slalom.turn_deg = 30.0;
  params.slalom.straight_m = 0.0;
  for (const auto& entry :
       {std::pair{Pattern::kSlalomRight, 1.0}, std::pair{Pattern::kSlalomLeft, -1.0}}) {
    const Pattern kind = entry.first;
    const double side = entry.second;
    GateController controller(params);
    const auto board = [&](std::int64_t utime, double distance_m) {
      return slalomBoard(kind, side, utime, distance_m, 0.5);
    };
    EXPECT_EQ(controller.update(board(0, 2.0), kLens).mode, DriveMode::kTracking);
    const SteeringCommand turn = controller.update(board(5'000, 1.25), kLens);
    EXPECT_EQ(turn.mode, DriveMode::kManoeuvre);
    EXPECT_NEAR(turn.steer_rad, side * 0.161092, 1e-6);
    EXPECT_NEAR(turn.board_distance_m, 1.25, 1e-9);
    // Still turning at 0.2 s, turning back at 0.215 s whatever is seen.
    EXPECT_NEAR(controller.update(board(205'000, 0.5), kLens).steer_rad, side * 0.161092, 1e-6);
    const SteeringCommand back = controller.update(nothing(220'000), kLens);
    EXPECT_EQ(back.mode, DriveMode::kManoeuvre);
    EXPECT_NEAR(back.steer_rad, -side * 0.161092, 1e-6);
  }
}

// A turn board's single disk a quarter of its 40 px column above its middle
// (row 100 + 10 = 110 of 100..140) asks for 135 deg, a quarter below (130)
// for 45 deg, level (120) to pass; within an eighth of the column (115 and
// 125) still level.
TEST(GateControllerTest, ATurnBoardsSingleDiskSaysHowFar) {
  const SlalomParams params;  // 45 and 135 deg
  const auto board = [](Pattern kind, double tip_y) {
    PatternObservation p;
    p.kind = kind;
    p.disks_px = {{100.0, 100.0}, {100.0, 140.0}, {120.0, tip_y}};
    return p;
  };
  EXPECT_EQ(boardTurn_deg(board(Pattern::kSlalomRight, 110.0), params), 135.0);
  EXPECT_EQ(boardTurn_deg(board(Pattern::kSlalomRight, 130.0), params), 45.0);
  EXPECT_EQ(boardTurn_deg(board(Pattern::kSlalomLeft, 120.0), params), 0.0);
  EXPECT_EQ(boardTurn_deg(board(Pattern::kSlalomLeft, 115.5), params), 0.0);
  EXPECT_EQ(boardTurn_deg(board(Pattern::kSlalomLeft, 124.5), params), 0.0);
  EXPECT_EQ(boardTurn_deg(board(Pattern::kGate, 110.0), params), 0.0);
}

// A 45 deg board within the trigger at 2 m/s: at full lock (30 deg, radius
// 0.26 / tan(30 deg) = 0.450333 m; the grip's 2^2 / 10 = 0.4 m is wider)
// the rover turns to the board's side for 45 deg x 0.450333 m / 2 m/s =
// 0.176819 s, then goes straight on at speed (no turn back) until it sees the
// next board, and coasts then stops when it sees none.
TEST(GateControllerTest, ATurnBoardTurnsTheRoverAndGoesOn) {
  GateControllerParams params = plainParams();
  params.cruise_speed_mps = 2.0;
  params.max_lateral_acceleration_mps2 = 10.0;
  params.slalom.trigger_m = 0.8;
  for (const auto& entry :
       {std::pair{Pattern::kSlalomRight, 1.0}, std::pair{Pattern::kSlalomLeft, -1.0}}) {
    const Pattern kind = entry.first;
    const double side = entry.second;
    GateController controller(params);
    const auto board = [&](std::int64_t utime, double distance_m) {
      return slalomBoard(kind, side, utime, distance_m, 0.75);
    };
    EXPECT_EQ(controller.update(board(0, 2.0), kLens).mode, DriveMode::kTracking);
    const SteeringCommand turn = controller.update(board(5'000, 0.78), kLens);
    EXPECT_EQ(turn.mode, DriveMode::kManoeuvre);
    const double lock = 30.0 * std::numbers::pi / 180.0;
    EXPECT_NEAR(turn.steer_rad, side * lock, 1e-9);
    EXPECT_NEAR(controller.update(nothing(5'000 + 175'000), kLens).steer_rad, side * lock, 1e-9);
    const SteeringCommand on = controller.update(nothing(5'000 + 178'000), kLens);
    EXPECT_EQ(on.mode, DriveMode::kCoasting);
    EXPECT_EQ(on.steer_rad, 0.0);
    EXPECT_EQ(on.speed_mps, 2.0);
    // Blind: coasting 0.4 s from the turn's end, then stopping over 0.5 s.
    EXPECT_EQ(controller.update(nothing(5'000 + 178'000 + 600'000), kLens).mode,
              DriveMode::kStopping);
    EXPECT_EQ(controller.update(nothing(5'000 + 178'000 + 1'000'000), kLens).speed_mps, 0.0);
  }
}

TEST(GateControllerTest, BadParametersAreNamed) {
  GateControllerParams params;
  params.cruise_speed_mps = -1.0;
  try {
    GateController controller(params);
    FAIL() << "a negative speed was accepted";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find("cruise_speed_mps"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace nadir::control
