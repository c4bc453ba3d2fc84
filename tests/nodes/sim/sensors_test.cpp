#include "nodes/sim/sensors.h"

#include <gtest/gtest.h>
#include <GeographicLib/LocalCartesian.hpp>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>

namespace nadir::sim {
namespace {

using core::due;
using core::kDueAtFirstCall;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kG = 9.80665;

// Ground as a plane: up = up0 + slope_north * north + slope_east * east.
class PlaneWorld final : public terrain::World {
 public:
  PlaneWorld(double up0_m, double slope_north, double slope_east)
      : up0_m_(up0_m), slope_north_(slope_north), slope_east_(slope_east) {}
  double groundUp_m(double north_m, double east_m) const override {
    return up0_m_ + slope_north_ * north_m + slope_east_ * east_m;
  }
  void imagery(const terrain::GroundSquare&, int, cv::Mat&) const override {}
  double imageryResolution_m() const override { return 1.0; }
  double elevationResolution_m() const override { return 1.0; }
  terrain::WorldExtent extent() const override { return {-1e6, 1e6, -1e6, 1e6}; }

 private:
  double up0_m_;
  double slope_north_;
  double slope_east_;
};

// Rotation about one axis, written out by hand (not through core::frames).
Eigen::Quaterniond rollQuaternion(double roll_rad) {
  return Eigen::Quaterniond(std::cos(roll_rad / 2), std::sin(roll_rad / 2), 0, 0);
}

VehicleState stateAt(std::int64_t utime) {
  VehicleState state;
  state.utime = utime;
  return state;
}

struct Stats {
  double mean = 0.0;
  double std = 0.0;
};

Stats stats(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v;
  const double mean = sum / static_cast<double>(values.size());
  double sq = 0.0;
  for (double v : values) sq += (v - mean) * (v - mean);
  return {mean, std::sqrt(sq / static_cast<double>(values.size() - 1))};
}

ImuParams quietImu() {
  ImuParams params;
  params.gyro_noise_density_rps_rthz = 0.0;
  params.accel_noise_density_mps2_rthz = 0.0;
  params.gyro_bias_random_walk_rps_rts = 0.0;
  params.accel_bias_random_walk_mps2_rts = 0.0;
  params.gyro_initial_bias_rps = {0.0, 0.0, 0.0};
  params.accel_initial_bias_mps2 = {0.0, 0.0, 0.0};
  return params;
}

// A level IMU at rest without biases: mean (0, 0, -g) and zero rates, per-sample
// sigma = density * sqrt(rate).
TEST(ImuModel, LevelAtRestMeanAndNoise) {
  ImuParams params;
  params.gyro_initial_bias_rps = {0.0, 0.0, 0.0};
  params.accel_initial_bias_mps2 = {0.0, 0.0, 0.0};
  params.rate_hz = 200.0;
  params.gyro_noise_density_rps_rthz = 1e-3;
  params.accel_noise_density_mps2_rthz = 1e-2;
  params.gyro_bias_random_walk_rps_rts = 0.0;
  params.accel_bias_random_walk_mps2_rts = 0.0;
  const double gyro_sigma = 1e-3 * std::sqrt(200.0);
  const double accel_sigma = 1e-2 * std::sqrt(200.0);
  ImuModel imu(params);
  constexpr int kN = 20000;
  std::vector<std::vector<double>> gyro(3), accel(3);
  for (int i = 0; i < kN; ++i) {
    const ImuSample s = imu.sample(stateAt(i * 5000));
    EXPECT_EQ(s.utime, i * 5000);
    for (int k = 0; k < 3; ++k) {
      gyro[k].push_back(s.angular_velocity_rps[k]);
      accel[k].push_back(s.linear_acceleration_mps2[k]);
    }
  }
  const double expected_accel[3] = {0.0, 0.0, -kG};
  for (int k = 0; k < 3; ++k) {
    const Stats g = stats(gyro[k]);
    const Stats a = stats(accel[k]);
    EXPECT_NEAR(g.mean, 0.0, 4 * gyro_sigma / std::sqrt(kN)) << "axis " << k;
    EXPECT_NEAR(a.mean, expected_accel[k], 4 * accel_sigma / std::sqrt(kN)) << "axis " << k;
    EXPECT_NEAR(g.std, gyro_sigma, 0.03 * gyro_sigma) << "axis " << k;
    EXPECT_NEAR(a.std, accel_sigma, 0.03 * accel_sigma) << "axis " << k;
  }
}

// Rolled 30 deg at rest: R = Rx(roll), f = R^T (0, 0, -g) = (0, -g sin(roll), -g cos(roll)).
TEST(ImuModel, RolledAtRestSpecificForce) {
  // By hand: Rx(r) = [1 0 0; 0 c -s; 0 s c], so R^T (0, 0, -g) = (0, -g s, -g c):
  // the right wing dips and the upward reaction to gravity points to the left (-y).
  ImuModel imu(quietImu());
  VehicleState state = stateAt(0);
  state.q_world_body = rollQuaternion(30 * kDeg);
  state.omega_body_rps = Eigen::Vector3d(0.1, -0.2, 0.3);
  const ImuSample s = imu.sample(state);
  EXPECT_NEAR(s.linear_acceleration_mps2.x(), 0.0, 1e-12);
  EXPECT_NEAR(s.linear_acceleration_mps2.y(), -kG * 0.5, 1e-12);
  EXPECT_NEAR(s.linear_acceleration_mps2.z(), -kG * std::sqrt(3.0) / 2.0, 1e-12);
  EXPECT_NEAR(s.angular_velocity_rps.x(), 0.1, 1e-15);
  EXPECT_NEAR(s.angular_velocity_rps.y(), -0.2, 1e-15);
  EXPECT_NEAR(s.angular_velocity_rps.z(), 0.3, 1e-15);
}

// Accelerating north while facing east (yaw 90 deg): the push reads on body -y (left).
TEST(ImuModel, AccelerationRotatedIntoBody) {
  ImuModel imu(quietImu());
  VehicleState state = stateAt(0);
  // Rz(90 deg): body x (nose) = east, body y (right) = south.
  state.q_world_body = Eigen::Quaterniond(std::cos(kPi / 4), 0, 0, std::sin(kPi / 4));
  state.a_ned_mps2 = Eigen::Vector3d(1.0, 0.0, 0.0);
  const ImuSample s = imu.sample(state);
  EXPECT_NEAR(s.linear_acceleration_mps2.x(), 0.0, 1e-12);
  EXPECT_NEAR(s.linear_acceleration_mps2.y(), -1.0, 1e-12);
  EXPECT_NEAR(s.linear_acceleration_mps2.z(), -kG, 1e-12);
}

// A state that changes faster than the IMU samples it, read as each
// interval's mean. A 400 Hz simulation where one 2.5 ms step in four brakes a
// climb at 2 m/s^2 down and the others climb at 0.64 m/s^2 (as a climb
// controller does when its position fix steps at 50 Hz), sampled at 200 Hz:
// by hand, the samples alternate (2 - 0.64) / 2 = 0.68 and -0.64 m/s^2 down,
// so over each 10 ms they add up to the true change of velocity,
// (0.68 - 0.64) x 5 ms = 2 x 2.5 ms - 0.64 x 7.5 ms = +0.2 mm/s; the last
// step alone would read 2 and -0.64 (+6.8 mm/s per 10 ms). The roll rate
// (0.4 rad/s in the braking step) likewise reads 0.2 and 0.
TEST(ImuModel, SampleIsTheMeanOverItsInterval) {
  ImuModel imu(quietImu());
  for (int step = 0; step <= 40; ++step) {
    const bool braking = step % 4 == 1;
    VehicleState state = stateAt(step * 2500);
    state.a_ned_mps2 = Eigen::Vector3d(0.0, 0.0, braking ? 2.0 : -0.64);
    state.omega_body_rps = Eigen::Vector3d(braking ? 0.4 : 0.0, 0.0, 0.0);
    imu.accumulate(state);
    if (step % 2 == 0) continue;
    const ImuSample s = imu.sample(state);
    if (step == 1) continue;  // its interval is the first step alone
    // Level: the specific force down is a_down - g.
    EXPECT_NEAR(s.linear_acceleration_mps2.z() + kG, braking ? 0.68 : -0.64, 1e-12)
        << "step " << step;
    EXPECT_NEAR(s.angular_velocity_rps.x(), braking ? 0.2 : 0.0, 1e-12) << "step " << step;
  }
}

// Initial biases add to the truth; the first call takes no random-walk step.
TEST(ImuModel, InitialBiasAndNoStepAtFirstCall) {
  ImuParams params = quietImu();
  params.gyro_initial_bias_rps = {0.01, 0.02, 0.03};
  params.accel_initial_bias_mps2 = {0.1, 0.2, 0.3};
  params.gyro_bias_random_walk_rps_rts = 0.5;
  params.accel_bias_random_walk_mps2_rts = 0.5;
  ImuModel imu(params);
  const ImuSample s = imu.sample(stateAt(123456));
  EXPECT_DOUBLE_EQ(s.angular_velocity_rps.y(), 0.02);
  EXPECT_DOUBLE_EQ(s.linear_acceleration_mps2.z(), 0.3 - kG);
  // A second call at the same utime (dt = 0) takes no step either.
  EXPECT_DOUBLE_EQ(imu.sample(stateAt(123456)).angular_velocity_rps.x(), 0.01);
  EXPECT_THROW(imu.sample(stateAt(100000)), std::invalid_argument);
}

// Bias random walk: after N steps of dt the bias variance is N * sigma^2 * dt (over many seeds).
TEST(ImuModel, BiasRandomWalkVariance) {
  ImuParams params = quietImu();
  params.gyro_bias_random_walk_rps_rts = 0.01;
  params.accel_bias_random_walk_mps2_rts = 0.1;
  constexpr int kSeeds = 2000;
  constexpr int kSteps = 100;
  constexpr double kDt = 0.005;
  std::vector<double> gyro, accel;
  for (int seed = 0; seed < kSeeds; ++seed) {
    params.seed = 1000 + seed;
    ImuModel imu(params);
    ImuSample s;
    for (int i = 0; i <= kSteps; ++i) s = imu.sample(stateAt(i * 5000));
    for (int k = 0; k < 3; ++k) {
      gyro.push_back(s.angular_velocity_rps[k]);
      accel.push_back(s.linear_acceleration_mps2[k] - (k == 2 ? -kG : 0.0));
    }
  }
  const double gyro_var = kSteps * 0.01 * 0.01 * kDt;
  const double accel_var = kSteps * 0.1 * 0.1 * kDt;
  const Stats g = stats(gyro);
  const Stats a = stats(accel);
  EXPECT_NEAR(g.std * g.std, gyro_var, 0.1 * gyro_var);
  EXPECT_NEAR(a.std * a.std, accel_var, 0.1 * accel_var);
}

// The same seed gives identical sequences in every model; a different seed differs.
TEST(Sensors, DeterministicPerSeed) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(44.0, -71.0, 200.0));
  const PlaneWorld world(12.0, 0.0, 0.0);
  ImuParams imu_params;
  imu_params.gyro_initial_bias_rps = {0.001, 0.0, 0.0};
  RangefinderParams range_params;
  GpsParams gps_params;
  BarometerParams baro_params;
  ImuModel imu_a(imu_params), imu_b(imu_params);
  RangefinderModel range_a(range_params), range_b(range_params);
  GpsModel gps_a(gps_params), gps_b(gps_params);
  BarometerModel baro_a(baro_params), baro_b(baro_params);
  imu_params.seed += 1;
  range_params.seed += 1;
  gps_params.seed += 1;
  baro_params.seed += 1;
  ImuModel imu_c(imu_params);
  RangefinderModel range_c(range_params);
  GpsModel gps_c(gps_params);
  BarometerModel baro_c(baro_params);
  int imu_diff = 0, range_diff = 0, gps_diff = 0, baro_diff = 0;
  for (int i = 0; i < 100; ++i) {
    VehicleState state = stateAt(i * 10000);
    state.p_ned_m = Eigen::Vector3d(i, -2.0 * i, -50.0);
    const ImuSample ia = imu_a.sample(state), ib = imu_b.sample(state), ic = imu_c.sample(state);
    EXPECT_EQ(ia.angular_velocity_rps, ib.angular_velocity_rps);
    EXPECT_EQ(ia.linear_acceleration_mps2, ib.linear_acceleration_mps2);
    imu_diff += ia.angular_velocity_rps != ic.angular_velocity_rps;
    const RangeSample ra = range_a.sample(state, world), rb = range_b.sample(state, world),
                      rc = range_c.sample(state, world);
    EXPECT_EQ(ra.range_m, rb.range_m);
    range_diff += ra.range_m != rc.range_m;
    const GpsSample ga = gps_a.sample(state, frame), gb = gps_b.sample(state, frame),
                    gc = gps_c.sample(state, frame);
    EXPECT_EQ(ga.lat_rad, gb.lat_rad);
    EXPECT_EQ(ga.lon_rad, gb.lon_rad);
    EXPECT_EQ(ga.alt_m, gb.alt_m);
    EXPECT_EQ(ga.velocity_ned_mps, gb.velocity_ned_mps);
    gps_diff += ga.lat_rad != gc.lat_rad;
    const BaroSample ba = baro_a.sample(state, frame), bb = baro_b.sample(state, frame),
                     bc = baro_c.sample(state, frame);
    EXPECT_EQ(ba.altitude_m, bb.altitude_m);
    baro_diff += ba.altitude_m != bc.altitude_m;
  }
  EXPECT_EQ(imu_diff, 100);
  EXPECT_EQ(range_diff, 100);
  EXPECT_EQ(gps_diff, 100);
  EXPECT_EQ(baro_diff, 100);
}

RangefinderParams exactRangefinder() {
  RangefinderParams params;
  params.noise_sigma_m = 0.0;
  params.max_range_m = 200.0;
  return params;
}

// Flat ground at up = 12 m, vehicle level at down = -100: the beam reads 88 m.
TEST(RangefinderModel, FlatGroundLevel) {
  const PlaneWorld world(12.0, 0.0, 0.0);
  RangefinderModel rangefinder(exactRangefinder());
  VehicleState state = stateAt(42);
  state.p_ned_m = Eigen::Vector3d(30.0, -40.0, -100.0);
  const RangeSample s = rangefinder.sample(state, world);
  EXPECT_EQ(s.utime, 42);
  EXPECT_EQ(s.status, RangeStatus::VALID);
  EXPECT_NEAR(s.range_m, 88.0, 1e-3);
  EXPECT_EQ(s.direction_body, Eigen::Vector3d(0, 0, 1));
}

// Rolled 30 deg over flat ground the slanted beam reads 88 / cos(30 deg).
TEST(RangefinderModel, FlatGroundRolled) {
  const PlaneWorld world(12.0, 0.0, 0.0);
  RangefinderModel rangefinder(exactRangefinder());
  VehicleState state = stateAt(0);
  state.p_ned_m = Eigen::Vector3d(0.0, 0.0, -100.0);
  state.q_world_body = rollQuaternion(30 * kDeg);
  const RangeSample s = rangefinder.sample(state, world);
  EXPECT_EQ(s.status, RangeStatus::VALID);
  EXPECT_NEAR(s.range_m, 88.0 / std::cos(30 * kDeg), 1e-3);
}

// Ground beyond max_range_m reads OUT_OF_RANGE; closer than min_range_m TOO_CLOSE.
TEST(RangefinderModel, OutOfRangeAndTooClose) {
  const PlaneWorld world(12.0, 0.0, 0.0);
  RangefinderParams params = exactRangefinder();
  params.max_range_m = 50.0;
  params.min_range_m = 0.3;
  RangefinderModel rangefinder(params);
  VehicleState state = stateAt(0);
  state.p_ned_m = Eigen::Vector3d(0.0, 0.0, -100.0);
  EXPECT_EQ(rangefinder.sample(state, world).status, RangeStatus::OUT_OF_RANGE);
  state.p_ned_m.z() = -12.2;  // 0.2 m above the ground
  EXPECT_EQ(rangefinder.sample(state, world).status, RangeStatus::TOO_CLOSE);
  state.p_ned_m.z() = -11.0;  // under the ground
  EXPECT_EQ(rangefinder.sample(state, world).status, RangeStatus::TOO_CLOSE);
  state.p_ned_m.z() = -55.0;  // 43 m: in range
  const RangeSample s = rangefinder.sample(state, world);
  EXPECT_EQ(s.status, RangeStatus::VALID);
  EXPECT_NEAR(s.range_m, 43.0, 1e-3);
  // Pointing up never meets the ground.
  state.q_world_body = rollQuaternion(kPi);
  EXPECT_EQ(rangefinder.sample(state, world).status, RangeStatus::OUT_OF_RANGE);
}

// Over a sloped plane a tilted, off-axis beam matches the analytic ray-plane intersection.
TEST(RangefinderModel, SlopedPlaneMatchesRayPlaneIntersection) {
  constexpr double kUp0 = 5.0, kSn = 0.2, kSe = -0.1;
  const PlaneWorld world(kUp0, kSn, kSe);
  RangefinderParams params = exactRangefinder();
  params.direction_body = {0.2, -0.1, 1.0};
  RangefinderModel rangefinder(params);
  VehicleState state = stateAt(0);
  state.p_ned_m = Eigen::Vector3d(40.0, 25.0, -70.0);
  // Yaw 40 deg, pitch 10 deg, roll -15 deg, composed by hand as Rz * Ry * Rx.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(40 * kDeg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(-15 * kDeg, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  state.q_world_body = Eigen::Quaterniond(R);
  const Eigen::Vector3d d = R * Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const Eigen::Vector3d& p = state.p_ned_m;
  // Ground: -down = up0 + sn * north + se * east. Ray point p + t d on it:
  // -(p_d + t d_d) = up0 + sn (p_n + t d_n) + se (p_e + t d_e).
  const double t =
      -(p.z() + kUp0 + kSn * p.x() + kSe * p.y()) / (d.z() + kSn * d.x() + kSe * d.y());
  ASSERT_GT(t, 0.0);
  const RangeSample s = rangefinder.sample(state, world);
  EXPECT_EQ(s.status, RangeStatus::VALID);
  EXPECT_NEAR(s.range_m, t, 1e-3);
  EXPECT_NEAR((s.direction_body - Eigen::Vector3d(0.2, -0.1, 1.0).normalized()).norm(), 0.0, 1e-15);
}

// Inconsistent rangefinder parameters are refused.
TEST(RangefinderModel, RejectsBadParams) {
  RangefinderParams params;
  params.direction_body = {0.0, 0.0, 0.0};
  EXPECT_THROW(RangefinderModel{params}, core::ParamError);
  params = RangefinderParams{};
  params.min_range_m = 200.0;
  EXPECT_THROW(RangefinderModel{params}, core::ParamError);
  params = RangefinderParams{};
  params.direction_body = {0.0, 1.0};
  EXPECT_THROW(RangefinderModel{params}, core::ParamError);
}

GpsParams exactGps() {
  GpsParams params;
  params.horizontal_sigma_m = 0.0;
  params.vertical_sigma_m = 0.0;
  params.velocity_sigma_mps = 0.0;
  return params;
}

// A zero-noise fix equals GeographicLib's LocalCartesian Reverse of the NED position.
TEST(GpsModel, ZeroNoiseFixMatchesGeographicLib) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(44.0, -71.0, 200.0));
  GpsModel gps(exactGps());
  VehicleState state = stateAt(7000000);
  state.p_ned_m = Eigen::Vector3d(1000.0, -500.0, -50.0);
  state.v_ned_mps = Eigen::Vector3d(3.0, -4.0, 0.5);
  const GpsSample s = gps.sample(state, frame);
  // LocalCartesian is ENU: east = -500, north = 1000, up = 50.
  const GeographicLib::LocalCartesian enu(44.0, -71.0, 200.0);
  double lat_deg = 0.0, lon_deg = 0.0, alt_m = 0.0;
  enu.Reverse(-500.0, 1000.0, 50.0, lat_deg, lon_deg, alt_m);
  EXPECT_EQ(s.fix, GpsFix::FIX_3D);
  EXPECT_EQ(s.utime, 7000000);
  EXPECT_NEAR(s.lat_rad, lat_deg * kDeg, 1e-11);
  EXPECT_NEAR(s.lon_rad, lon_deg * kDeg, 1e-11);
  EXPECT_NEAR(s.alt_m, alt_m, 1e-6);
  EXPECT_EQ(s.velocity_ned_mps, Eigen::Vector3d(3.0, -4.0, 0.5));
  EXPECT_EQ(s.num_satellites, 12);
}

// Position and velocity noise have the configured sigmas (within 3 %).
TEST(GpsModel, NoiseMatchesSigma) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(44.0, -71.0, 200.0));
  GpsParams params;
  params.horizontal_sigma_m = 2.0;
  params.vertical_sigma_m = 5.0;
  params.velocity_sigma_mps = 0.3;
  GpsModel gps(params);
  const GeographicLib::LocalCartesian enu(44.0, -71.0, 200.0);
  std::vector<double> north, east, down, vel_east;
  VehicleState state = stateAt(0);
  state.p_ned_m = Eigen::Vector3d(100.0, 200.0, -30.0);
  for (int i = 0; i < 20000; ++i) {
    state.utime = std::int64_t{i} * 200000;
    const GpsSample s = gps.sample(state, frame);
    ASSERT_EQ(s.fix, GpsFix::FIX_3D);
    double x = 0.0, y = 0.0, z = 0.0;
    enu.Forward(s.lat_rad / kDeg, s.lon_rad / kDeg, s.alt_m, x, y, z);
    north.push_back(y);
    east.push_back(x);
    down.push_back(-z);
    vel_east.push_back(s.velocity_ned_mps.y());
  }
  const Stats n = stats(north), e = stats(east), d = stats(down), v = stats(vel_east);
  EXPECT_NEAR(n.std, 2.0, 0.06);
  EXPECT_NEAR(e.std, 2.0, 0.06);
  EXPECT_NEAR(d.std, 5.0, 0.15);
  EXPECT_NEAR(v.std, 0.3, 0.009);
  EXPECT_NEAR(n.mean, 100.0, 4 * 2.0 / std::sqrt(20000.0));
  EXPECT_NEAR(d.mean, -30.0, 4 * 5.0 / std::sqrt(20000.0));
}

// Inside an outage window the fix is NONE; before and after it FIX_3D.
TEST(GpsModel, OutageWindow) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(44.0, -71.0, 200.0));
  GpsParams params;
  params.outages_s = {10.0, 20.0, 30.0, 31.0};
  GpsModel gps(params);
  const auto fixAt = [&](double t_s) {
    return gps.sample(stateAt(std::llround(t_s * 1e6)), frame).fix;
  };
  EXPECT_EQ(fixAt(0.0), GpsFix::FIX_3D);
  EXPECT_EQ(fixAt(9.8), GpsFix::FIX_3D);
  EXPECT_EQ(fixAt(10.0), GpsFix::NONE);
  EXPECT_EQ(fixAt(15.0), GpsFix::NONE);
  EXPECT_EQ(fixAt(19.8), GpsFix::NONE);
  EXPECT_EQ(fixAt(20.0), GpsFix::FIX_3D);
  EXPECT_EQ(fixAt(30.4), GpsFix::NONE);
  EXPECT_EQ(fixAt(31.2), GpsFix::FIX_3D);
  const GpsSample none = gps.sample(stateAt(12000000), frame);
  EXPECT_EQ(none.num_satellites, 0);
}

// A replayed real flight starts at its own time stamp (here 2023-11-14
// 22:13:20 UTC, 1.7e15 us): outage windows and the denial count from there,
// not from 1970 (which would deny every fix of a real flight).
TEST(GpsModel, WindowsCountFromTheRunsStart) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(44.0, -71.0, 200.0));
  constexpr std::int64_t kStart_us = 1'700'000'000'000'000;
  GpsParams params;
  params.outages_s = {10.0, 20.0};
  params.denied_after_s = 40.0;
  GpsModel gps(params, kStart_us);
  const auto fixAt = [&](double t_s) {
    return gps.sample(stateAt(kStart_us + std::llround(t_s * 1e6)), frame).fix;
  };
  EXPECT_EQ(fixAt(0.0), GpsFix::FIX_3D);
  EXPECT_EQ(fixAt(15.0), GpsFix::NONE);
  EXPECT_EQ(fixAt(25.0), GpsFix::FIX_3D);
  EXPECT_EQ(fixAt(39.8), GpsFix::FIX_3D);
  EXPECT_EQ(fixAt(40.0), GpsFix::NONE);
}

// An odd-length outage list (or a window ending before it starts) fails validation.
TEST(GpsModel, OutageListValidated) {
  GpsParams params;
  params.outages_s = {10.0, 20.0, 30.0};
  EXPECT_THROW(core::validateParams([&](core::ParamVisitor& v) { params.visit(v); }, "gps"),
               core::ParamError);
  EXPECT_THROW(GpsModel{params}, core::ParamError);
  params.outages_s = {20.0, 10.0};
  EXPECT_THROW(core::validateParams([&](core::ParamVisitor& v) { params.visit(v); }, "gps"),
               core::ParamError);
  params.outages_s = {10.0, 20.0};
  EXPECT_NO_THROW(core::validateParams([&](core::ParamVisitor& v) { params.visit(v); }, "gps"));
}

// The barometer reads origin height - down, with the configured noise sigma.
TEST(BarometerModel, AltitudeAndNoise) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(44.0, -71.0, 200.0));
  BarometerParams params;
  params.noise_sigma_m = 0.5;
  params.bias_random_walk_m_rts = 0.0;
  params.initial_bias_m = 1.5;
  BarometerModel baro(params);
  VehicleState state = stateAt(0);
  state.p_ned_m = Eigen::Vector3d(10.0, 20.0, -80.0);
  std::vector<double> altitudes;
  for (int i = 0; i < 20000; ++i) {
    state.utime = i * 20000;
    altitudes.push_back(baro.sample(state, frame).altitude_m);
  }
  const Stats a = stats(altitudes);
  EXPECT_NEAR(a.mean, 281.5, 4 * 0.5 / std::sqrt(20000.0));
  EXPECT_NEAR(a.std, 0.5, 0.015);
}

// The barometer bias random walk has variance N * sigma^2 * dt after N steps.
TEST(BarometerModel, BiasRandomWalkVariance) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(44.0, -71.0, 200.0));
  BarometerParams params;
  params.noise_sigma_m = 0.0;
  params.bias_random_walk_m_rts = 0.05;
  std::vector<double> finals;
  for (int seed = 0; seed < 4000; ++seed) {
    params.seed = seed;
    BarometerModel baro(params);
    double altitude = 0.0;
    for (int i = 0; i <= 50; ++i) altitude = baro.sample(stateAt(i * 20000), frame).altitude_m;
    finals.push_back(altitude - 200.0);
  }
  const double expected_var = 50 * 0.05 * 0.05 * 0.02;
  const Stats f = stats(finals);
  EXPECT_NEAR(f.std * f.std, expected_var, 0.1 * expected_var);
}

// 200 Hz with poses every 1 ms for one second: exactly 200 samples, 5 ms apart.
TEST(Due, FixedGridCount) {
  std::int64_t next_due = kDueAtFirstCall;
  std::vector<std::int64_t> due_times;
  for (std::int64_t utime = 0; utime < 1000000; utime += 1000) {
    if (due(utime, 200.0, next_due)) due_times.push_back(utime);
  }
  ASSERT_EQ(due_times.size(), 200u);
  for (std::size_t i = 0; i < due_times.size(); ++i) {
    EXPECT_EQ(due_times[i], static_cast<std::int64_t>(i) * 5000);
  }
}

// The grid is anchored at the first call and survives skipped and uneven poses.
TEST(Due, GridAnchoredAndNoDrift) {
  constexpr std::int64_t kStart = 1700000000123456;
  std::int64_t next_due = kDueAtFirstCall;
  EXPECT_TRUE(due(kStart, 100.0, next_due));
  EXPECT_EQ(next_due, kStart + 10000);
  EXPECT_FALSE(due(kStart + 9999, 100.0, next_due));
  EXPECT_TRUE(due(kStart + 10700, 100.0, next_due));  // late pose: the grid stays
  EXPECT_EQ(next_due, kStart + 20000);
  EXPECT_TRUE(due(kStart + 55000, 100.0, next_due));  // skipped grid points
  EXPECT_EQ(next_due, kStart + 60000);
  // 30 Hz from a UNIX-time start with 3 ms poses: 30 samples in one second.
  next_due = kDueAtFirstCall;
  int count = 0;
  for (std::int64_t utime = kStart; utime < kStart + 1000000; utime += 3000) {
    count += due(utime, 30.0, next_due) ? 1 : 0;
  }
  EXPECT_EQ(count, 30);
  EXPECT_THROW(due(0, 0.0, next_due), std::invalid_argument);
}

}  // namespace
}  // namespace nadir::sim
