#include "nodes/sim/sensors.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>

#include <Eigen/Geometry>

namespace nadir::sim {
namespace {

constexpr double kMaxSeed = 9007199254740992.0;  // 2^53, exact in a double
constexpr double kBisectionTolerance_m = 1e-3;

template <class P>
P validated(P params, std::string_view source) {
  core::validateParams([&params](core::ParamVisitor& v) { params.visit(v); }, source);
  return params;
}

Eigen::Vector3d vector3(const std::vector<double>& values) {
  return Eigen::Vector3d(values.at(0), values.at(1), values.at(2));
}

// Seconds since the previous call (0 at the first), updating the bookkeeping.
double stepSeconds(std::int64_t utime, bool& has_previous, std::int64_t& previous_utime) {
  double dt_s = 0.0;
  if (has_previous) {
    if (utime < previous_utime) {
      throw std::invalid_argument("sensor sample: utime " + std::to_string(utime) +
                                  " is before the previous sample's " +
                                  std::to_string(previous_utime));
    }
    dt_s = static_cast<double>(utime - previous_utime) * 1e-6;
  }
  has_previous = true;
  previous_utime = utime;
  return dt_s;
}

Eigen::Vector3d normal3(GaussianNoise& noise, double sigma) {
  const double x = noise.normal(sigma);
  const double y = noise.normal(sigma);
  const double z = noise.normal(sigma);
  return Eigen::Vector3d(x, y, z);
}

}  // namespace

// ---------------------------------------------------------------- IMU

void ImuParams::visit(core::ParamVisitor& v) {
  v.field("rate_hz", &rate_hz, {.doc = "sample rate, Hz", .min = 1, .max = 10000});
  v.field("seed", &seed, {.doc = "noise seed", .min = 0, .max = kMaxSeed});
  v.field("gyro_noise_density_rps_rthz", &gyro_noise_density_rps_rthz,
          {.doc = "gyro white noise density, rad/s/sqrt(Hz)", .min = 0, .max = 1});
  v.field("accel_noise_density_mps2_rthz", &accel_noise_density_mps2_rthz,
          {.doc = "accelerometer white noise density, m/s^2/sqrt(Hz)", .min = 0, .max = 10});
  v.field("gyro_bias_random_walk_rps_rts", &gyro_bias_random_walk_rps_rts,
          {.doc = "gyro bias random walk, rad/s/sqrt(s)", .min = 0, .max = 1});
  v.field("accel_bias_random_walk_mps2_rts", &accel_bias_random_walk_mps2_rts,
          {.doc = "accelerometer bias random walk, m/s^2/sqrt(s)", .min = 0, .max = 10});
  v.field("gyro_initial_bias_rps", &gyro_initial_bias_rps,
          {.doc = "gyro bias at the start, body FRD, rad/s", .min = -1, .max = 1, .list_size = 3});
  v.field("accel_initial_bias_mps2", &accel_initial_bias_mps2,
          {.doc = "accelerometer bias at the start, body FRD, m/s^2",
           .min = -10,
           .max = 10,
           .list_size = 3});
}

Eigen::Vector3d trueSpecificForce_mps2(const VehicleState& state) {
  const Eigen::Vector3d g_ned(0.0, 0.0, kGravity_mps2);
  return state.q_world_body.normalized().toRotationMatrix().transpose() *
         (state.a_ned_mps2 - g_ned);
}

ImuModel::ImuModel(const ImuParams& params)
    : params_(validated(params, "imu")),
      noise_(static_cast<std::uint64_t>(params_.seed)),
      gyro_bias_rps_(vector3(params_.gyro_initial_bias_rps)),
      accel_bias_mps2_(vector3(params_.accel_initial_bias_mps2)) {}

void ImuModel::accumulate(const VehicleState& state) {
  const double dt_s = stepSeconds(state.utime, has_accumulated_, accumulated_utime_);
  rate_sum_rad_ += dt_s * state.omega_body_rps;
  force_sum_mps_ += dt_s * trueSpecificForce_mps2(state);
  accumulated_s_ += dt_s;
}

ImuSample ImuModel::sample(const VehicleState& state) {
  const double dt_s = stepSeconds(state.utime, has_previous_, previous_utime_);
  const double sqrt_dt = std::sqrt(dt_s);
  gyro_bias_rps_ += normal3(noise_, params_.gyro_bias_random_walk_rps_rts * sqrt_dt);
  accel_bias_mps2_ += normal3(noise_, params_.accel_bias_random_walk_mps2_rts * sqrt_dt);
  Eigen::Vector3d rate_rps = state.omega_body_rps;
  Eigen::Vector3d force_mps2 = trueSpecificForce_mps2(state);
  if (accumulated_s_ > 0.0) {
    rate_rps = rate_sum_rad_ / accumulated_s_;
    force_mps2 = force_sum_mps_ / accumulated_s_;
  }
  rate_sum_rad_.setZero();
  force_sum_mps_.setZero();
  accumulated_s_ = 0.0;
  const double sqrt_rate = std::sqrt(params_.rate_hz);
  ImuSample out;
  out.utime = state.utime;
  out.angular_velocity_rps =
      rate_rps + gyro_bias_rps_ + normal3(noise_, params_.gyro_noise_density_rps_rthz * sqrt_rate);
  out.linear_acceleration_mps2 = force_mps2 + accel_bias_mps2_ +
                                 normal3(noise_, params_.accel_noise_density_mps2_rthz * sqrt_rate);
  return out;
}

// ---------------------------------------------------------------- rangefinder

void RangefinderParams::visit(core::ParamVisitor& v) {
  v.field("rate_hz", &rate_hz, {.doc = "sample rate, Hz", .min = 0.1, .max = 10000});
  v.field("seed", &seed, {.doc = "noise seed", .min = 0, .max = kMaxSeed});
  v.field("min_range_m", &min_range_m,
          {.doc = "shortest measurable range, m (closer reads TOO_CLOSE)", .min = 0, .max = 1000});
  v.field("max_range_m", &max_range_m,
          {.doc = "longest measurable range, m (farther reads OUT_OF_RANGE)",
           .min = 0.01,
           .max = 10000});
  v.field("noise_sigma_m", &noise_sigma_m,
          {.doc = "white noise on the range, 1-sigma, m", .min = 0, .max = 100});
  v.field("direction_body", &direction_body,
          {.doc = "beam direction in body FRD (normalised; default straight down)",
           .min = -1,
           .max = 1,
           .list_size = 3});
  v.field("march_step_m", &march_step_m,
          {.doc = "step of the ray march before bisection, m; finer finds thinner ridges",
           .min = 0.001,
           .max = 100});
}

double rayGroundDistance_m(const terrain::World& world, const Eigen::Vector3d& p_ned_m,
                           const Eigen::Vector3d& direction_world, double max_range_m,
                           double march_step_m) {
  // Height of the ray point above the ground; the ray hits where it turns <= 0.
  const auto height = [&](double t) {
    const Eigen::Vector3d p = p_ned_m + t * direction_world;
    return -p.z() - world.groundUp_m(p.x(), p.y());
  };
  if (height(0.0) <= 0.0) return 0.0;
  double below = -1.0;
  double above = 0.0;
  for (double t = 0.0; t < max_range_m;) {
    const double next = std::min(t + march_step_m, max_range_m);
    if (height(next) <= 0.0) {
      below = next;
      above = t;
      break;
    }
    t = next;
  }
  if (below < 0.0) return -1.0;
  while (below - above > kBisectionTolerance_m) {
    const double mid = 0.5 * (above + below);
    (height(mid) <= 0.0 ? below : above) = mid;
  }
  return 0.5 * (above + below);
}

RangefinderModel::RangefinderModel(const RangefinderParams& params)
    : params_(validated(params, "rangefinder")),
      direction_body_(vector3(params_.direction_body)),
      noise_(static_cast<std::uint64_t>(params_.seed)) {
  if (params_.min_range_m >= params_.max_range_m) {
    throw core::ParamError("rangefinder: min_range_m must be below max_range_m");
  }
  if (direction_body_.norm() < 1e-6) {
    throw core::ParamError("rangefinder.direction_body: must not be zero");
  }
  direction_body_.normalize();
}

RangeSample RangefinderModel::sample(const VehicleState& state, const terrain::World& world) {
  const Eigen::Vector3d direction_world =
      state.q_world_body.normalized().toRotationMatrix() * direction_body_;
  const double true_range_m = rayGroundDistance_m(world, state.p_ned_m, direction_world,
                                                  params_.max_range_m, params_.march_step_m);
  const double noise_m = noise_.normal(params_.noise_sigma_m);
  RangeSample out;
  out.utime = state.utime;
  out.direction_body = direction_body_;
  out.min_range_m = params_.min_range_m;
  out.max_range_m = params_.max_range_m;
  if (true_range_m < 0.0) {
    out.status = RangeStatus::OUT_OF_RANGE;
    out.range_m = params_.max_range_m;
  } else if (true_range_m < params_.min_range_m) {
    out.status = RangeStatus::TOO_CLOSE;
    out.range_m = params_.min_range_m;
  } else {
    out.status = RangeStatus::VALID;
    out.range_m = std::max(0.0, true_range_m + noise_m);
  }
  return out;
}

// ---------------------------------------------------------------- GPS

void GpsParams::visit(core::ParamVisitor& v) {
  v.field("rate_hz", &rate_hz, {.doc = "fix rate, Hz", .min = 0.1, .max = 100});
  v.field("seed", &seed, {.doc = "noise seed", .min = 0, .max = kMaxSeed});
  v.field("horizontal_sigma_m", &horizontal_sigma_m,
          {.doc = "white position noise per horizontal axis, 1-sigma, m", .min = 0, .max = 1000});
  v.field("vertical_sigma_m", &vertical_sigma_m,
          {.doc = "white vertical position noise, 1-sigma, m", .min = 0, .max = 1000});
  v.field("velocity_sigma_mps", &velocity_sigma_mps,
          {.doc = "white NED velocity noise per axis, 1-sigma, m/s", .min = 0, .max = 100});
  v.field("num_satellites", &num_satellites,
          {.doc = "satellites reported with a fix", .min = 0, .max = 64});
  v.field("outages_s", &outages_s,
          {.doc = "outage windows in sim time, s: [start_s, end_s, start_s, end_s, ...]",
           .min = 0,
           .max = 1e9});
  v.field(
      "denied_after_s", &denied_after_s,
      {.doc = "no fix from this sim time on, s (-1: never): GPS denial", .min = -1, .max = 1e9});
  // Checked on every walk (validation included): the list's shape, which a
  // field spec cannot express.
  if (outages_s.size() % 2 != 0) {
    throw core::ParamError("outages_s: expected [start_s, end_s] pairs, got an odd count (" +
                           std::to_string(outages_s.size()) + ")");
  }
  for (std::size_t i = 0; i + 1 < outages_s.size(); i += 2) {
    if (outages_s[i + 1] < outages_s[i]) {
      throw core::ParamError("outages_s: window " + std::to_string(i / 2) +
                             " ends before it starts");
    }
  }
}

GpsModel::GpsModel(const GpsParams& params, std::int64_t start_utime)
    : params_(validated(params, "gps")),
      start_utime_(start_utime),
      noise_(static_cast<std::uint64_t>(params_.seed)) {}

bool GpsModel::inOutage(std::int64_t utime) const {
  const double t_s = static_cast<double>(utime - start_utime_) * 1e-6;
  if (params_.denied_after_s >= 0.0 && t_s >= params_.denied_after_s) return true;
  for (std::size_t i = 0; i + 1 < params_.outages_s.size(); i += 2) {
    if (t_s >= params_.outages_s[i] && t_s < params_.outages_s[i + 1]) return true;
  }
  return false;
}

GpsSample GpsModel::sample(const VehicleState& state, const core::LocalNedFrame& frame) {
  const double north_m = noise_.normal(params_.horizontal_sigma_m);
  const double east_m = noise_.normal(params_.horizontal_sigma_m);
  const double down_m = noise_.normal(params_.vertical_sigma_m);
  const Eigen::Vector3d velocity_noise_mps = normal3(noise_, params_.velocity_sigma_mps);
  GpsSample out;
  out.utime = state.utime;
  if (inOutage(state.utime)) return out;
  const core::Geodetic position =
      frame.geodeticFromNed(state.p_ned_m + Eigen::Vector3d(north_m, east_m, down_m));
  out.lat_rad = position.lat_rad;
  out.lon_rad = position.lon_rad;
  out.alt_m = position.alt_m;
  out.velocity_ned_mps = state.v_ned_mps + velocity_noise_mps;
  out.horizontal_accuracy_m = params_.horizontal_sigma_m;
  out.vertical_accuracy_m = params_.vertical_sigma_m;
  out.num_satellites = params_.num_satellites;
  out.fix = GpsFix::FIX_3D;
  return out;
}

// ---------------------------------------------------------------- barometer

void BarometerParams::visit(core::ParamVisitor& v) {
  v.field("rate_hz", &rate_hz, {.doc = "sample rate, Hz", .min = 0.1, .max = 1000});
  v.field("seed", &seed, {.doc = "noise seed", .min = 0, .max = kMaxSeed});
  v.field("noise_sigma_m", &noise_sigma_m,
          {.doc = "white altitude noise, 1-sigma, m", .min = 0, .max = 100});
  v.field("bias_random_walk_m_rts", &bias_random_walk_m_rts,
          {.doc = "altitude bias random walk, m/sqrt(s)", .min = 0, .max = 10});
  v.field("initial_bias_m", &initial_bias_m,
          {.doc = "altitude bias at the start, m", .min = -1000, .max = 1000});
}

BarometerModel::BarometerModel(const BarometerParams& params)
    : params_(validated(params, "baro")),
      noise_(static_cast<std::uint64_t>(params_.seed)),
      bias_m_(params_.initial_bias_m) {}

BaroSample BarometerModel::sample(const VehicleState& state, const core::LocalNedFrame& frame) {
  const double dt_s = stepSeconds(state.utime, has_previous_, previous_utime_);
  bias_m_ += noise_.normal(params_.bias_random_walk_m_rts * std::sqrt(dt_s));
  BaroSample out;
  out.utime = state.utime;
  out.altitude_m =
      frame.origin().alt_m - state.p_ned_m.z() + bias_m_ + noise_.normal(params_.noise_sigma_m);
  out.pressure_pa = standardAtmospherePressure_pa(out.altitude_m);
  return out;
}

double standardAtmospherePressure_pa(double altitude_m) {
  constexpr double kTropopause_m = 11000.0;
  if (altitude_m <= kTropopause_m) {
    return 101325.0 * std::pow(1.0 - 2.25577e-5 * altitude_m, 5.25588);
  }
  return 22632.06 * std::exp(-1.576883e-4 * (altitude_m - kTropopause_m));
}

// ---------------------------------------------------------------- magnetometer

void MagnetometerParams::visit(core::ParamVisitor& v) {
  v.field("rate_hz", &rate_hz, {.doc = "sample rate, Hz", .min = 0.1, .max = 1000});
  v.field("seed", &seed, {.doc = "noise seed", .min = 0, .max = kMaxSeed});
  v.field("declination_deg", &declination_deg,
          {.doc = "the field's declination, east of true north, deg", .min = -180, .max = 180});
  v.field("inclination_deg", &inclination_deg,
          {.doc = "the field's inclination, below the horizon, deg", .min = -90, .max = 90});
  v.field("field_ut", &field_ut, {.doc = "the field's strength, uT", .min = 1, .max = 1000});
  v.field("noise_sigma_ut", &noise_sigma_ut,
          {.doc = "white noise per axis, 1-sigma, uT", .min = 0, .max = 100});
  v.field("hard_iron_ut", &hard_iron_ut,
          {.doc = "uncalibrated airframe field, body FRD, uT",
           .min = -1000,
           .max = 1000,
           .list_size = 3});
}

Eigen::Vector3d earthField_ned_ut(const MagnetometerParams& params) {
  return core::magneticField_ned(params.declination_deg, params.inclination_deg, params.field_ut);
}

MagnetometerModel::MagnetometerModel(const MagnetometerParams& params)
    : params_(validated(params, "magnetometer")),
      field_ned_ut_(earthField_ned_ut(params_)),
      hard_iron_ut_(vector3(params_.hard_iron_ut)),
      noise_(static_cast<std::uint64_t>(params_.seed)) {}

MagSample MagnetometerModel::sample(const VehicleState& state) {
  MagSample out;
  out.utime = state.utime;
  out.field_body_ut = state.q_world_body.conjugate() * field_ned_ut_ + hard_iron_ut_ +
                      normal3(noise_, params_.noise_sigma_ut);
  return out;
}

}  // namespace nadir::sim
