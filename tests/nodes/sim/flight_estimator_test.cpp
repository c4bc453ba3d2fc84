// The flight controller's filters against values worked out by hand: the
// attitude filter's response to a gyro bias (a second-order linear system for
// small errors), its steady states, the heading's errors from a wrong
// declination and a hard-iron offset, the accelerometer's tilt in a sustained
// acceleration with and without the GPS, and the position filter's step response.

#include "nodes/sim/flight_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "core/frames.h"
#include "nodes/sim/sensors.h"
#include "nodes/sim/vehicle_state.h"

namespace nadir::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr std::int64_t kImuStep_us = 5000;

const core::LocalNedFrame kFrame(core::Geodetic{39.3 * kDeg, -86.0 * kDeg, 250.0});

MagnetometerParams trueField() {
  MagnetometerParams field;
  field.hard_iron_ut = {0.0, 0.0, 0.0};
  field.noise_sigma_ut = 0.0;
  return field;
}

AhrsParams matchedParams() {
  AhrsParams params;
  params.declination_deg = trueField().declination_deg;
  return params;
}

// What the sensors read of a vehicle with attitude q_world_body, moving with
// NED acceleration a_ned; the gyro reads gyro_rps.
struct Flight {
  FlightEstimator estimator;
  MagnetometerParams field = trueField();
  std::int64_t utime = 0;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ned_mps = Eigen::Vector3d::Zero();

  explicit Flight(const AhrsParams& params) : estimator(params, kFrame) {}

  void step(const Eigen::Quaterniond& q_world_body, const Eigen::Vector3d& gyro_rps,
            const Eigen::Vector3d& a_ned, bool with_gps, bool with_mag = true) {
    const Eigen::Vector3d f_body =
        q_world_body.conjugate() * (a_ned - Eigen::Vector3d(0.0, 0.0, kGravity_mps2));
    estimator.addImu({utime, gyro_rps, f_body});
    if (with_mag && utime % 20000 == 0)
      estimator.addMagnetometer({utime, q_world_body.conjugate() * earthField_ned_ut(field) +
                                            vector(field.hard_iron_ut)});
    if (with_gps && utime % 200000 == 0) {
      msg::Gps gps;
      gps.utime = utime;
      const core::Geodetic at = kFrame.geodeticFromNed(p_ned_m);
      gps.lat_rad = at.lat_rad;
      gps.lon_rad = at.lon_rad;
      gps.alt_m = at.alt_m;
      gps.velocity_ned_mps = v_ned_mps;
      gps.fix = msg::GpsFix::FIX_3D;
      estimator.addGps(gps);
    }
    const double dt = kImuStep_us * 1e-6;
    p_ned_m += v_ned_mps * dt + 0.5 * a_ned * dt * dt;
    v_ned_mps += a_ned * dt;
    utime += kImuStep_us;
  }

  static Eigen::Vector3d vector(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }
  core::RollPitchYaw rpy() const { return core::rpyFromQuaternion(estimator.q_world_body()); }
};

const Eigen::Quaterniond kLevelNorth = Eigen::Quaterniond::Identity();

TEST(FlightEstimator, StartsFromTheAccelerometerAndTheMagnetometer) {
  const core::RollPitchYaw truth{10 * kDeg, -5 * kDeg, 120 * kDeg};
  Flight flight(matchedParams());
  flight.step(core::quaternionFromRpy(truth), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
              false);
  ASSERT_TRUE(flight.estimator.hasAttitude());
  EXPECT_NEAR(flight.rpy().roll_rad, truth.roll_rad, 1e-9);
  EXPECT_NEAR(flight.rpy().pitch_rad, truth.pitch_rad, 1e-9);
  EXPECT_NEAR(flight.rpy().yaw_rad, truth.yaw_rad, 1e-9);
}

TEST(FlightEstimator, RollErrorAfterAGyroBiasStepIsTheSecondOrderResponseWorkedOutByHand) {
  // x = roll estimate - truth: x'' + kP x' + kI x = 0, x(0) = 0, x'(0) = b, so
  // x(t) = b (e^(s1 t) - e^(s2 t)) / (s1 - s2), s = (-kP +- sqrt(kP^2 - 4 kI)) / 2.
  // kP = 0.2, kI = 0.0087: s1 = -0.063944, s2 = -0.136056; the peak, 3.763 b,
  // at ln(s2 / s1) / (s1 - s2) = 10.47 s.
  const AhrsParams params = matchedParams();
  const double b = 0.5 * kDeg;
  const double s1 = -0.063944, s2 = -0.136056;
  const auto expected = [&](double t) {
    return b * (std::exp(s1 * t) - std::exp(s2 * t)) / (s1 - s2);
  };
  Flight flight(params);
  flight.step(kLevelNorth, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), false);
  for (const double t_s : {2.0, 5.0, 10.47, 20.0, 60.0}) {
    while (flight.utime < static_cast<std::int64_t>(std::llround(t_s * 1e6)) + kImuStep_us)
      flight.step(kLevelNorth, Eigen::Vector3d(b, 0, 0), Eigen::Vector3d::Zero(), false);
    EXPECT_NEAR(flight.rpy().roll_rad, expected(t_s), 0.01 * 3.763 * b) << "t = " << t_s << " s";
  }
  EXPECT_NEAR(expected(10.47) / b, 3.763, 0.001);
}

TEST(FlightEstimator, WithoutTheIntegralASteadyBiasLeavesBiasOverGain) {
  // sin(x) = b / kP = 0.01 / 0.2: x = 2.866 deg.
  AhrsParams params = matchedParams();
  params.bias_gain_per_s2 = 0.0;
  Flight flight(params);
  while (flight.utime < 60'000'000)
    flight.step(kLevelNorth, Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d::Zero(), false);
  EXPECT_NEAR(flight.rpy().roll_rad / kDeg, 2.866, 0.005);
}

TEST(FlightEstimator, TheBiasEstimateSettlesOnTheGyroBias) {
  const Eigen::Vector3d bias(0.01, -0.005, 0.003);
  Flight flight(matchedParams());
  while (flight.utime < 400'000'000) flight.step(kLevelNorth, bias, Eigen::Vector3d::Zero(), false);
  EXPECT_LT((flight.estimator.gyroBias_rps() - bias).norm(), 1e-5);
  EXPECT_NEAR(flight.rpy().roll_rad, 0.0, 1e-4);
  EXPECT_NEAR(flight.rpy().yaw_rad, 0.0, 1e-4);
}

TEST(FlightEstimator, HeadingIsOffByTheDeclinationError) {
  // The field says psi + (D_assumed - D_true): 0.6 deg east of the truth.
  AhrsParams params = matchedParams();
  params.declination_deg = -4.0;
  const Eigen::Quaterniond east = core::quaternionFromRpy({0, 0, 90 * kDeg});
  Flight flight(params);
  while (flight.utime < 30'000'000)
    flight.step(east, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), false);
  EXPECT_NEAR(flight.rpy().yaw_rad / kDeg, 90.6, 1e-6);
}

TEST(FlightEstimator, HeadingErrorOfAHardIronOffsetWorkedOutByHand) {
  // Level, nose north, declination 0: the body sees (H, 1 uT, Z), so the
  // heading reads -atan(1 / H), H = 52 cos(66.5 deg) = 20.736 uT: -2.762 deg.
  AhrsParams params = matchedParams();
  params.declination_deg = 0.0;
  Flight flight(params);
  flight.field.declination_deg = 0.0;
  flight.field.hard_iron_ut = {0.0, 1.0, 0.0};
  while (flight.utime < 30'000'000)
    flight.step(kLevelNorth, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), false);
  EXPECT_NEAR(flight.rpy().yaw_rad / kDeg, -2.762, 0.001);
}

TEST(FlightEstimator, ASustainedAccelerationTiltsTheEstimateUnlessTheGpsTakesItOut) {
  // 2 m/s^2 forward, level: the accelerometer's vertical leans atan(2 / g) =
  // 11.53 deg nose up. Alone, the filter settles there; with the GPS's
  // velocity it stays level.
  const Eigen::Vector3d forward(2.0, 0.0, 0.0);
  Flight alone(matchedParams());
  Flight with_gps(matchedParams());
  while (alone.utime < 200'000'000) {
    alone.step(kLevelNorth, Eigen::Vector3d::Zero(), forward, false);
    with_gps.step(kLevelNorth, Eigen::Vector3d::Zero(), forward, true);
  }
  EXPECT_NEAR(alone.rpy().pitch_rad / kDeg, std::atan2(2.0, kGravity_mps2) / kDeg, 0.01);
  EXPECT_NEAR(with_gps.rpy().pitch_rad / kDeg, 0.0, 0.01);
}

TEST(FlightEstimator, PositionFollowsAGpsStepAsTheThirdOrderFilterWorkedOutByHand) {
  // Gains 3a, 3a^2, a^3 (a = 1/tau) put the poles at -a; a step of the
  // measurement gives 1 - e^(-at) (1 - 2at + (at)^2 / 2) (partial fractions
  // of (3a s^2 + 3a^2 s + a^3) / (s (s + a)^3)): 1.135 at at = 2.
  AhrsParams params = matchedParams();
  const double tau = params.horizontal_time_constant_s;
  Flight flight(params);
  // Fixes every IMU step so that the discrete filter is close to the continuous one.
  const auto fix = [&](double north_m) {
    msg::Gps gps;
    gps.utime = flight.utime;
    const core::Geodetic at = kFrame.geodeticFromNed({north_m, 0.0, 0.0});
    gps.lat_rad = at.lat_rad;
    gps.lon_rad = at.lon_rad;
    gps.alt_m = at.alt_m;
    gps.fix = msg::GpsFix::FIX_3D;
    flight.estimator.addGps(gps);
  };
  flight.step(kLevelNorth, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), false);
  fix(0.0);
  ASSERT_TRUE(flight.estimator.hasPosition());
  const std::int64_t start = flight.utime;
  for (const double at : {0.5, 1.0, 2.0, 4.0}) {
    while (flight.utime < start + static_cast<std::int64_t>(std::llround(at * tau * 1e6))) {
      flight.step(kLevelNorth, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), false);
      fix(10.0);
    }
    const double expected = 10.0 * (1.0 - std::exp(-at) * (1.0 - 2.0 * at + 0.5 * at * at));
    EXPECT_NEAR(flight.estimator.p_ned_m().x(), expected, 0.05) << "at = " << at;
  }
}

TEST(FlightEstimator, AVerticalAccelerometerOffsetIsLearnedFromTheBarometer) {
  // The accelerometer reads 0.2 m/s^2 too little gravity; the barometer says
  // the height is constant: the filter's correction settles on -0.2 and the
  // height error on 0.
  Flight flight(matchedParams());
  const Eigen::Quaterniond level = kLevelNorth;
  flight.step(level, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), true);
  ASSERT_TRUE(flight.estimator.hasPosition());
  while (flight.utime < 300'000'000) {
    const Eigen::Vector3d f_body(0.0, 0.0, -kGravity_mps2 + 0.2);
    flight.estimator.addImu({flight.utime, Eigen::Vector3d::Zero(), f_body});
    if (flight.utime % 20000 == 0)
      flight.estimator.addBaro({flight.utime, kFrame.origin().alt_m, 0});
    flight.utime += kImuStep_us;
  }
  EXPECT_NEAR(flight.estimator.accelCorrection_ned_mps2().z(), -0.2, 1e-3);
  EXPECT_NEAR(flight.estimator.p_ned_m().z(), 0.0, 1e-3);
}

}  // namespace
}  // namespace nadir::sim
