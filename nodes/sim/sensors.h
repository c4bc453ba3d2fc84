#pragma once
// Sensor models of the simulator: IMU, rangefinder, GPS, barometer and
// magnetometer. Plain
// structs in, the messages' plain structs (lcmtypes/messages.h) out, no LCM.
//
// Every model is deterministic: it owns a std::mt19937_64 seeded from its
// params (a fixed default seed) and draws Gaussian noise with its own
// Box-Muller transform (std::normal_distribution is implementation-defined),
// so the same seed and the same sequence of sample() calls give the same
// outputs on every standard library. Each sample() draws the same number of
// random numbers whatever the state (also without a fix or out of range), so
// the noise of one sample never depends on the status of an earlier one.
//
// sample() computes a measurement whenever it is called; the caller decides
// when with due(), at the model's rate_hz.

#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "core/clock.h"
#include "core/geodesy.h"
#include "core/params.h"
#include "lcmtypes/messages.h"
#include "nodes/sim/noise.h"
#include "nodes/sim/vehicle_state.h"
#include "terrain/world.h"

namespace nadir::sim {

// ---------------------------------------------------------------- IMU

struct ImuParams {
  double rate_hz = 200.0;
  std::int64_t seed = 1;
  double gyro_noise_density_rps_rthz = 2.0e-4;
  double accel_noise_density_mps2_rthz = 2.0e-3;
  double gyro_bias_random_walk_rps_rts = 2.0e-5;
  double accel_bias_random_walk_mps2_rts = 2.0e-4;
  // What a MEMS IMU keeps after its calibration at power-on: a few hundredths
  // of a deg/s and a few mg.
  std::vector<double> gyro_initial_bias_rps = {0.0012, -0.0009, 0.0007};
  std::vector<double> accel_initial_bias_mps2 = {0.06, -0.04, 0.08};

  void visit(core::ParamVisitor& v);
};

using ImuSample = msg::Imu;

// Gyro and accelerometer: truth + bias + white noise. The white noise has the
// per-sample sigma density * sqrt(rate_hz); the biases start at the initial
// biases and take a random-walk step of sigma * sqrt(dt) at every call, dt
// from the utime difference to the previous call (none at the first call).
// The truth is the mean over the sample's interval of the states given to
// accumulate() (as a real IMU's anti-aliasing filter and delta-velocity
// output give it): a sample of the last state alone would alias motion that
// changes faster than the IMU's rate (a controller's step at each position
// fix). Without accumulated states it is the state sampled.
class ImuModel {
 public:
  // Throws core::ParamError if a parameter is out of its range.
  explicit ImuModel(const ImuParams& params);

  // One step of the truth: its rates and specific force, held over the time
  // since the previous accumulated state (the simulator's step). Throws
  // std::invalid_argument if state.utime is before the previous one's.
  void accumulate(const VehicleState& state);
  // Throws std::invalid_argument if state.utime is before the previous call's.
  ImuSample sample(const VehicleState& state);

  const Eigen::Vector3d& gyroBias_rps() const { return gyro_bias_rps_; }
  const Eigen::Vector3d& accelBias_mps2() const { return accel_bias_mps2_; }

 private:
  ImuParams params_;
  GaussianNoise noise_;
  Eigen::Vector3d gyro_bias_rps_;
  Eigen::Vector3d accel_bias_mps2_;
  bool has_previous_ = false;
  std::int64_t previous_utime_ = 0;
  // The truth accumulated since the last sample: rates and specific force
  // times their steps' durations, and the steps' total.
  Eigen::Vector3d rate_sum_rad_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_sum_mps_ = Eigen::Vector3d::Zero();
  double accumulated_s_ = 0.0;
  bool has_accumulated_ = false;
  std::int64_t accumulated_utime_ = 0;
};

// True specific force in body FRD: R_world_body^T (a_ned - g_ned), g_ned = (0, 0, +g).
Eigen::Vector3d trueSpecificForce_mps2(const VehicleState& state);

// ---------------------------------------------------------------- rangefinder

struct RangefinderParams {
  double rate_hz = 50.0;
  std::int64_t seed = 2;
  double min_range_m = 0.1;
  double max_range_m = 100.0;
  double noise_sigma_m = 0.02;
  std::vector<double> direction_body = {0.0, 0.0, 1.0};
  double march_step_m = 0.5;

  void visit(core::ParamVisitor& v);
};

using RangeStatus = msg::RangeStatus;

// With TOO_CLOSE the range is min_range_m, with OUT_OF_RANGE max_range_m (no
// noise); the sample carries the model's limits.
using RangeSample = msg::Range;

// A beam from the body origin along direction_body to the ground of a
// terrain::World. The first crossing is found by marching along the ray in
// march_step_m steps (a ridge thinner than a step can be missed) and then
// bisection to 1 mm. A body origin at or under the ground reads TOO_CLOSE.
class RangefinderModel {
 public:
  // Throws core::ParamError if a parameter is out of its range, min_range_m >=
  // max_range_m or direction_body is (nearly) zero.
  explicit RangefinderModel(const RangefinderParams& params);

  RangeSample sample(const VehicleState& state, const terrain::World& world);

 private:
  RangefinderParams params_;
  Eigen::Vector3d direction_body_;
  GaussianNoise noise_;
};

// Noise-free distance from p_ned_m along the unit world direction to the
// first ground crossing, within max_range_m (march and bisection to 1 mm).
// Returns a negative value if there is none; 0 if p_ned_m is at or under the ground.
double rayGroundDistance_m(const terrain::World& world, const Eigen::Vector3d& p_ned_m,
                           const Eigen::Vector3d& direction_world, double max_range_m,
                           double march_step_m);

// ---------------------------------------------------------------- GPS

struct GpsParams {
  double rate_hz = 5.0;
  std::int64_t seed = 3;
  double horizontal_sigma_m = 1.5;
  double vertical_sigma_m = 3.0;
  double velocity_sigma_mps = 0.1;
  int num_satellites = 12;
  // Outage windows in sim time, s: flat [start_s, end_s, start_s, end_s, ...].
  std::vector<double> outages_s = {};
  // GPS denial: no fix from this sim time on, s; -1: never.
  double denied_after_s = -1.0;

  // Throws core::ParamError (from the walk) if outages_s has an odd length or
  // a window ends before it starts.
  void visit(core::ParamVisitor& v);
};

// Zero position and accuracy without a fix (NONE); the model gives NONE or FIX_3D.
using GpsFix = msg::GpsFix;

using GpsSample = msg::Gps;

// Position (white noise in metres, north/east with horizontal_sigma_m, down
// with vertical_sigma_m, converted exactly with the LocalNedFrame) and NED
// velocity with white noise. Inside an outage window (start_s <= t < end_s,
// t the seconds since start_utime, the run's first instant: 0 for a
// simulated flight, a replayed real flight's own first time stamp) and from
// denied_after_s on, the fix is NONE and the other fields are zero.
class GpsModel {
 public:
  // Throws core::ParamError if a parameter is invalid.
  explicit GpsModel(const GpsParams& params, std::int64_t start_utime = 0);

  GpsSample sample(const VehicleState& state, const core::LocalNedFrame& frame);
  bool inOutage(std::int64_t utime) const;

 private:
  GpsParams params_;
  std::int64_t start_utime_ = 0;
  GaussianNoise noise_;
};

// ---------------------------------------------------------------- barometer

struct BarometerParams {
  double rate_hz = 50.0;
  std::int64_t seed = 4;
  double noise_sigma_m = 0.3;
  double bias_random_walk_m_rts = 0.01;
  double initial_bias_m = 0.0;

  void visit(core::ParamVisitor& v);
};

// The altitude is the origin's height above the ellipsoid minus the down
// coordinate; pressure_pa is standardAtmospherePressure_pa of it.
using BaroSample = msg::Baro;

// Static pressure of the ICAO standard atmosphere, Pa, at altitude_m:
// troposphere p = 101325 (1 - 2.25577e-5 h)^5.25588 up to 11 km, then the
// isothermal layer p = 22632.06 exp(-1.576883e-4 (h - 11000)) (valid to 20 km).
double standardAtmospherePressure_pa(double altitude_m);

// Altitude with white noise and a bias random walk (sigma * sqrt(dt) per call,
// dt from the utime difference; none at the first call).
class BarometerModel {
 public:
  // Throws core::ParamError if a parameter is out of its range.
  explicit BarometerModel(const BarometerParams& params);

  // Throws std::invalid_argument if state.utime is before the previous call's.
  BaroSample sample(const VehicleState& state, const core::LocalNedFrame& frame);

  double bias_m() const { return bias_m_; }

 private:
  BarometerParams params_;
  GaussianNoise noise_;
  double bias_m_;
  bool has_previous_ = false;
  std::int64_t previous_utime_ = 0;
};

// ---------------------------------------------------------------- magnetometer

// The Earth's field as a constant over the flight (a few km of the World
// Magnetic Model's field differ by far less than a sensor's errors). The
// defaults are central Indiana's (the area of Kim (2019)'s flights), 2025.
struct MagnetometerParams {
  double rate_hz = 50.0;
  std::int64_t seed = 5;
  double declination_deg = -4.6;  // east of true north positive
  double inclination_deg = 66.5;  // below the horizon positive
  double field_ut = 52.0;
  double noise_sigma_ut = 0.3;
  // What calibration leaves of the airframe's own field, body FRD, uT.
  std::vector<double> hard_iron_ut = {0.6, -0.4, 0.5};

  void visit(core::ParamVisitor& v);
};

using MagSample = msg::Magnetometer;

// The field in NED, F (cos I cos D, cos I sin D, sin I).
Eigen::Vector3d earthField_ned_ut(const MagnetometerParams& params);

// R_world_body^T times the Earth's field, plus the hard-iron offset and white noise.
class MagnetometerModel {
 public:
  // Throws core::ParamError if a parameter is out of its range.
  explicit MagnetometerModel(const MagnetometerParams& params);

  MagSample sample(const VehicleState& state);

 private:
  MagnetometerParams params_;
  Eigen::Vector3d field_ned_ut_;
  Eigen::Vector3d hard_iron_ut_;
  GaussianNoise noise_;
};

}  // namespace nadir::sim
