#include "nodes/nav/nav_node.h"

#include <cmath>
#include <numbers>
#include <utility>

#include "lcmtypes/bus_io.h"

namespace nadir::nav {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

core::Geodetic originOf(const NavNodeParams& params) {
  return core::geodeticFromDegrees(params.origin_lat_deg, params.origin_lon_deg,
                                   params.origin_alt_m);
}

}  // namespace

void NavSensorModel::visit(core::ParamVisitor& v) {
  v.field("gyro_noise_density_rps_rthz", &gyro_noise_density_rps_rthz,
          {.doc = "gyro white noise, rad/s/sqrt(Hz)", .min = 0.0});
  v.field("accel_noise_density_mps2_rthz", &accel_noise_density_mps2_rthz,
          {.doc = "accelerometer white noise, m/s^2/sqrt(Hz)", .min = 0.0});
  v.field("gyro_bias_random_walk_rps_rts", &gyro_bias_random_walk_rps_rts,
          {.doc = "gyro bias random walk, rad/s/sqrt(s)", .min = 0.0});
  v.field("accel_bias_random_walk_mps2_rts", &accel_bias_random_walk_mps2_rts,
          {.doc = "accelerometer bias random walk, m/s^2/sqrt(s)", .min = 0.0});
  v.field("baro_sigma_m", &baro_sigma_m, {.doc = "barometer noise, m", .min = 1e-6});
  v.field("baro_bias_random_walk_m_rts", &baro_bias_random_walk_m_rts,
          {.doc = "barometer bias random walk, m/sqrt(s)", .min = 0.0});
  v.field(
      "range_sigma_m", &range_sigma_m,
      {.doc = "rangefinder noise with what a flat ground leaves of the real one, m", .min = 1e-6});
  v.field("range_max_tilt_deg", &range_max_tilt_deg,
          {.doc = "ranges along a beam tilted more than this from vertical are not fused, deg",
           .min = 0.0,
           .max = 89.0});
  v.field("ground_random_walk_m_rtm", &ground_random_walk_m_rtm,
          {.doc = "how the ground's height wanders, m per sqrt(m) flown", .min = 0.0});
  v.field("gps_velocity_sigma_mps", &gps_velocity_sigma_mps,
          {.doc = "GPS velocity noise per axis, m/s", .min = 1e-6});
  v.field("heading_sigma_deg", &heading_sigma_deg,
          {.doc = "the magnetometer's heading from its white noise, 1 sigma, deg",
           .min = 1e-6,
           .max = 180.0});
  v.field("mag_bias_random_walk_ut_rts", &mag_bias_random_walk_ut_rts,
          {.doc = "how the airframe's own field wanders, uT/sqrt(s)", .min = 0.0});
  v.field("declination_deg", &declination_deg,
          {.doc = "the Earth's field: declination, east of true north, deg",
           .min = -180.0,
           .max = 180.0});
  v.field(
      "inclination_deg", &inclination_deg,
      {.doc = "the Earth's field: inclination below the horizon, deg", .min = -90.0, .max = 90.0});
  v.field("field_ut", &field_ut, {.doc = "the Earth's field strength, uT", .min = 1e-3});
}

void NavVoModel::visit(core::ParamVisitor& v) {
  v.field("interval_s", &interval_s,
          {.doc = "the VO's motion is fused over this much time, s (0: every frame)",
           .min = 0.0,
           .max = 3600.0});
  v.field(
      "translation_sigma_floor_m", &translation_sigma_floor_m,
      {.doc = "relative translation between fused frames, least 1 sigma per axis, m", .min = 1e-6});
  v.field("translation_sigma_share", &translation_sigma_share,
          {.doc = "relative translation, 1 sigma per axis as a share of the distance moved",
           .min = 0.0,
           .max = 10.0});
  v.field("rotation_sigma_deg", &rotation_sigma_deg,
          {.doc = "relative rotation between fused frames, 1 sigma per axis, deg",
           .min = 1e-6,
           .max = 180.0});
  v.field("log_scale_random_walk_rts", &log_scale_random_walk_rts,
          {.doc = "how the VO's log scale wanders, per sqrt(s)", .min = 0.0});
  v.field("initial_log_scale_sigma", &initial_log_scale_sigma,
          {.doc = "the VO's log scale at the start, 1 sigma", .min = 0.0, .max = 10.0});
}

void NavInitialSigmas::visit(core::ParamVisitor& v) {
  v.field("position_m", &position_m, {.doc = "position, m", .min = 1e-6});
  v.field("velocity_mps", &velocity_mps, {.doc = "velocity, m/s", .min = 1e-6});
  v.field("tilt_deg", &tilt_deg, {.doc = "roll and pitch, deg", .min = 1e-6, .max = 180.0});
  v.field("heading_deg", &heading_deg, {.doc = "heading, deg", .min = 1e-6, .max = 180.0});
  v.field("gyro_bias_rps", &gyro_bias_rps, {.doc = "gyro bias, rad/s", .min = 1e-9});
  v.field("accel_bias_mps2", &accel_bias_mps2, {.doc = "accelerometer bias, m/s^2", .min = 1e-9});
  v.field("baro_bias_m", &baro_bias_m, {.doc = "barometer bias, m", .min = 1e-6});
  v.field("mag_bias_ut", &mag_bias_ut,
          {.doc = "the airframe's field left by calibration, per axis, uT", .min = 1e-6});
}

void NavNodeParams::visit(core::ParamVisitor& v) {
  v.field("enabled", &enabled, {.doc = "run the navigation filter in this scenario"});
  v.field(
      "source", &source,
      {.doc = "what the vehicle's guidance flies on after the GPS denial: truth, gps, nav (this "
              "filter), vo_feature, vo_direct or ppa",
       .choices = {"truth", "gps", "nav", "vo_feature", "vo_direct", "ppa"}});
  v.field("imu_channel", &imu_channel, {.doc = "imu_t in: drives the filter"});
  v.field("baro_channel", &baro_channel, {.doc = "baro_t in"});
  v.field("range_channel", &range_channel, {.doc = "range_t in"});
  v.field("gps_channel", &gps_channel, {.doc = "gps_t in"});
  v.field("mag_channel", &mag_channel, {.doc = "magnetometer_t in"});
  v.field("vo_channel", &vo_channel,
          {.doc = "vo_estimate_t in: the VO node whose relative poses are fused"});
  v.field("truth_channel", &truth_channel, {.doc = "pose_t read once: the start pose"});
  v.field("pose_channel", &pose_channel, {.doc = "vo_estimate_t out: the present solution"});
  v.field("state_channel", &state_channel,
          {.doc = "nav_state_t out: the fused state with its covariance"});
  v.field("use_baro", &use_baro, {.doc = "fuse the barometer"});
  v.field("use_range", &use_range, {.doc = "fuse the rangefinder"});
  v.field("use_gps", &use_gps, {.doc = "fuse GPS fixes (position and velocity)"});
  v.field("use_mag", &use_mag, {.doc = "fuse the magnetometer's heading"});
  v.field("use_vo", &use_vo, {.doc = "fuse the VO's relative poses"});
  v.field(
      "range_against_map", &range_against_map,
      {.doc = "the rangefinder against the scenario's map of the ground, not the ground state"});
  v.field("publish_rate_hz", &publish_rate_hz,
          {.doc = "output rate in message time, Hz (0: every IMU sample)",
           .min = 0.0,
           .max = 100000.0});
  v.field(
      "delay_s", &delay_s,
      {.doc = "how far the filter runs behind the newest IMU sample, s", .min = 0.0, .max = 10.0});
  v.field("gate_probability", &gate_probability,
          {.doc = "innovations beyond this chi-square quantile are refused (1: none)",
           .min = 0.5,
           .max = 1.0});
  v.field("origin_lat_deg", &origin_lat_deg,
          {.doc = "world frame origin: latitude, deg", .min = -90.0, .max = 90.0});
  v.field("origin_lon_deg", &origin_lon_deg,
          {.doc = "world frame origin: longitude, deg", .min = -180.0, .max = 180.0});
  v.field("origin_alt_m", &origin_alt_m,
          {.doc = "world frame origin: height above the ellipsoid, m"});
  v.field("match_scenario_sensors", &match_scenario_sensors,
          {.doc = "take the sensor figures and the origin from the scenario"});
  core::visitGroup(v, "sensors", "the sensors as the filter models them", sensors);
  core::visitGroup(v, "vo", "the VO's relative poses as the filter models them", vo);
  core::visitGroup(v, "initial", "the uncertainty around the start pose, 1 sigma", initial);
}

NavNode::NavNode(core::Bus& bus, const NavNodeParams& params, GroundDown ground_down)
    : bus_(bus),
      params_(params),
      frame_(originOf(params)),
      ground_down_(params.range_against_map ? std::move(ground_down) : GroundDown{}),
      earth_field_ned_ut_(core::magneticField_ned(params.sensors.declination_deg,
                                                  params.sensors.inclination_deg,
                                                  params.sensors.field_ut)) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "nav");
  if (params_.range_against_map && !ground_down_)
    throw core::ParamError("nav.range_against_map: no map of the ground was given");
  auto on_invalid = [this](const std::string& reason) { drop(reason); };
  subscriptions_.push_back(msg::subscribe<msg::Pose>(
      bus_, params_.truth_channel,
      [this](const msg::Pose& truth) {
        if (!fusion_) start(truth);
      },
      on_invalid));
  subscriptions_.push_back(msg::subscribe<msg::Imu>(
      bus_, params_.imu_channel, [this](const msg::Imu& imu) { onImu(imu); }, on_invalid));

  const NavSensorModel& model = params_.sensors;
  if (params_.use_baro) {
    subscriptions_.push_back(msg::subscribe<msg::Baro>(
        bus_, params_.baro_channel,
        [this, sigma = model.baro_sigma_m](const msg::Baro& baro) {
          measure(baro.utime, &NavCounts::baro, [this, baro, sigma](ErrorStateFilter& filter) {
            return filter.updateBaro(baro.altitude_m, params_.origin_alt_m, sigma);
          });
        },
        on_invalid));
  }
  if (params_.use_range) {
    subscriptions_.push_back(msg::subscribe<msg::Range>(
        bus_, params_.range_channel,
        [this, sigma = model.range_sigma_m,
         min_down = std::cos(model.range_max_tilt_deg * kDegToRad)](const msg::Range& range) {
          if (range.status != msg::RangeStatus::VALID) return;
          measure(range.utime, &NavCounts::range,
                  [this, range, sigma, min_down](ErrorStateFilter& filter) {
                    const Eigen::Vector3d beam_world =
                        filter.state().q_world_body * range.direction_body.normalized();
                    if (beam_world.z() < min_down) return UpdateResult{};  // not tried
                    return filter.updateRange(range.range_m, range.direction_body, sigma,
                                              ground_down_);
                  });
        },
        on_invalid));
  }
  if (params_.use_gps) {
    subscriptions_.push_back(msg::subscribe<msg::Gps>(
        bus_, params_.gps_channel,
        [this, velocity_sigma = model.gps_velocity_sigma_mps](const msg::Gps& gps) {
          if (gps.fix == msg::GpsFix::NONE) return;
          if (!(gps.horizontal_accuracy_m > 0.0) || !(gps.vertical_accuracy_m > 0.0)) {
            drop("gps_t at utime " + std::to_string(gps.utime) +
                 ": a fix without a positive accuracy");
            return;
          }
          const Eigen::Vector3d p_ned_m =
              frame_.nedFromGeodetic({gps.lat_rad, gps.lon_rad, gps.alt_m});
          const double h2 = gps.horizontal_accuracy_m * gps.horizontal_accuracy_m;
          // A 2D fix says nothing of the height.
          const double v2 = gps.fix == msg::GpsFix::FIX_2D
                                ? 1e8
                                : gps.vertical_accuracy_m * gps.vertical_accuracy_m;
          const Eigen::Matrix3d position_covariance = Eigen::Vector3d(h2, h2, v2).asDiagonal();
          const Eigen::Matrix3d velocity_covariance =
              Eigen::Matrix3d::Identity() * velocity_sigma * velocity_sigma;
          measure(gps.utime, &NavCounts::gps,
                  [this, gps, p_ned_m, position_covariance,
                   velocity_covariance](ErrorStateFilter& filter) {
                    const UpdateResult position =
                        filter.updatePosition(p_ned_m, position_covariance);
                    filter.updateVelocity(gps.velocity_ned_mps, velocity_covariance);
                    if (position.accepted) last_gps_utime_ = gps.utime;
                    return position;
                  });
        },
        on_invalid));
  }
  if (params_.use_mag) {
    subscriptions_.push_back(msg::subscribe<msg::Magnetometer>(
        bus_, params_.mag_channel,
        [this, sigma = model.heading_sigma_deg * kDegToRad](const msg::Magnetometer& mag) {
          measure(mag.utime, &NavCounts::mag, [this, mag, sigma](ErrorStateFilter& filter) {
            return filter.updateHeading(mag.field_body_ut, earth_field_ned_ut_, sigma);
          });
        },
        on_invalid));
  }
  if (params_.use_vo && !params_.vo_channel.empty()) {
    subscriptions_.push_back(msg::subscribe<msg::VoEstimate>(
        bus_, params_.vo_channel, [this](const msg::VoEstimate& estimate) { onVo(estimate); },
        on_invalid));
  }
}

void NavNode::drop(const std::string& reason) {
  if (counts_.dropped++ == 0) first_drop_reason_ = reason;
}

void NavNode::start(const msg::Pose& truth) {
  NavState initial;
  initial.utime = truth.utime;
  initial.p_ned_m = truth.p_ned_m;
  initial.v_ned_mps = truth.v_ned_mps;
  initial.q_world_body = truth.q_world_body;
  // The ground is unknown until the first range: far below with a wide sigma.
  initial.ground_down_m = truth.p_ned_m.z();
  initial.clone_p_ned_m = truth.p_ned_m;
  initial.clone_q_world_body = truth.q_world_body;

  const NavInitialSigmas& sigma = params_.initial;
  Covariance P = Covariance::Zero();
  const auto set = [&P](int index, int size, double s) {
    P.block(index, index, size, size) = Eigen::MatrixXd::Identity(size, size) * s * s;
  };
  set(idx::kP, 3, sigma.position_m);
  set(idx::kV, 3, sigma.velocity_mps);
  set(idx::kTheta, 2, sigma.tilt_deg * kDegToRad);
  set(idx::kTheta + 2, 1, sigma.heading_deg * kDegToRad);
  set(idx::kGyroBias, 3, sigma.gyro_bias_rps);
  set(idx::kAccelBias, 3, sigma.accel_bias_mps2);
  set(idx::kBaroBias, 1, sigma.baro_bias_m);
  set(idx::kGround, 1, 100.0);
  set(idx::kLogScale, 1, params_.vo.initial_log_scale_sigma);
  set(idx::kMagBias, 3, sigma.mag_bias_ut);

  const NavSensorModel& model = params_.sensors;
  ProcessNoise noise;
  noise.gyro_noise_density_rps_rthz = model.gyro_noise_density_rps_rthz;
  noise.accel_noise_density_mps2_rthz = model.accel_noise_density_mps2_rthz;
  noise.gyro_bias_random_walk_rps_rts = model.gyro_bias_random_walk_rps_rts;
  noise.accel_bias_random_walk_mps2_rts = model.accel_bias_random_walk_mps2_rts;
  noise.baro_bias_random_walk_m_rts = model.baro_bias_random_walk_m_rts;
  noise.ground_random_walk_m_rtm = model.ground_random_walk_m_rtm;
  noise.vo_log_scale_random_walk_rts = params_.vo.log_scale_random_walk_rts;
  noise.mag_bias_random_walk_ut_rts = model.mag_bias_random_walk_ut_rts;

  start_utime_ = truth.utime;
  ErrorStateFilter filter(noise, initial, P);
  filter.cloneCurrentPose();  // the clone is the start pose itself, its rows the pose's
  filter.setGateProbability(params_.gate_probability);
  fusion_ = std::make_unique<DelayedFusion>(std::move(filter), params_.delay_s);
}

void NavNode::onImu(const msg::Imu& imu) {
  if (!fusion_) return;
  if (imu.utime < start_utime_) return;  // before the start pose
  if (counts_.imu > 0 && imu.utime < last_imu_utime_) {
    drop("imu_t at utime " + std::to_string(imu.utime) + " comes before the previous one at " +
         std::to_string(last_imu_utime_));
    return;
  }
  last_imu_utime_ = imu.utime;
  ++counts_.imu;
  fusion_->addImu({.utime = imu.utime,
                   .angular_velocity_rps = imu.angular_velocity_rps,
                   .linear_acceleration_mps2 = imu.linear_acceleration_mps2});
  if (imu.utime >= next_publish_utime_) {
    publish();
    if (params_.publish_rate_hz > 0.0) {
      const auto period_us = static_cast<std::int64_t>(std::llround(1e6 / params_.publish_rate_hz));
      next_publish_utime_ = (imu.utime / period_us + 1) * period_us;
    }
  }
}

void NavNode::measure(std::int64_t utime, std::uint64_t NavCounts::*counter, Fuse fuse) {
  if (!fusion_ || counts_.imu == 0) return;
  fusion_->addMeasurement(utime, [this, counter, fuse = std::move(fuse)](ErrorStateFilter& filter) {
    const UpdateResult result = fuse(filter);
    if (result.dimension == 0) return;  // not tried (a tilted beam)
    ++(result.accepted ? counts_.*counter : counts_.refused);
  });
}

void NavNode::onVo(const msg::VoEstimate& estimate) {
  if (!fusion_ || counts_.imu == 0 || estimate.source == kNavSourceName) return;
  if (estimate.status != msg::VoStatus::TRACKING) {
    vo_previous_.reset();
    return;
  }
  const bool restart = !vo_previous_ || estimate.num_resets != vo_previous_->num_resets;
  if (!restart && estimate.utime - vo_previous_->utime < std::llround(params_.vo.interval_s * 1e6))
    return;

  bool queued = false;
  if (restart) {
    // The VO's first frame or its first after a reset: the chain starts here,
    // with no update, so that nothing jumps.
    queued = fusion_->addMeasurement(estimate.utime, [this](ErrorStateFilter& filter) {
      filter.cloneCurrentPose();
      ++counts_.vo_restarts;
    });
  } else {
    const msg::VoEstimate& previous = *vo_previous_;
    const Eigen::Matrix3d R_previous = previous.q_world_body.toRotationMatrix();
    const Eigen::Vector3d dp_clone_body =
        R_previous.transpose() * (estimate.p_ned_m - previous.p_ned_m);
    const Eigen::Quaterniond dq_clone_body =
        (previous.q_world_body.conjugate() * estimate.q_world_body).normalized();
    const NavVoModel& model = params_.vo;
    const double translation_sigma = std::max(model.translation_sigma_floor_m,
                                              model.translation_sigma_share * dp_clone_body.norm());
    const double rotation_sigma = model.rotation_sigma_deg * kDegToRad;
    Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
    covariance.diagonal() << Eigen::Vector3d::Constant(translation_sigma * translation_sigma),
        Eigen::Vector3d::Constant(rotation_sigma * rotation_sigma);
    queued = fusion_->addMeasurement(
        estimate.utime, [this, dp_clone_body, dq_clone_body, covariance](ErrorStateFilter& filter) {
          const UpdateResult result =
              filter.updateRelativePose(dp_clone_body, dq_clone_body, covariance);
          filter.cloneCurrentPose();
          ++(result.accepted ? counts_.vo : counts_.refused);
        });
  }
  if (queued) {
    vo_previous_ = estimate;
  } else {
    vo_previous_.reset();  // too late: the next frame starts a new chain
  }
}

void NavNode::publish() {
  const NavState present = fusion_->present();
  msg::VoEstimate estimate;
  estimate.utime = present.utime;
  estimate.source = kNavSourceName;
  estimate.status = msg::VoStatus::TRACKING;
  estimate.p_ned_m = present.p_ned_m;
  estimate.q_world_body = present.q_world_body;
  msg::publish(bus_, params_.pose_channel, estimate);

  const ErrorStateFilter& filter = fusion_->delayed();
  const NavState& fused = filter.state();
  const Covariance& P = filter.covariance();
  msg::NavState state;
  state.utime = fused.utime;
  state.source = kNavSourceName;
  state.p_ned_m = fused.p_ned_m;
  state.v_ned_mps = fused.v_ned_mps;
  state.q_world_body = fused.q_world_body;
  const auto block = [&P](int index) -> Eigen::Matrix3d {
    const Eigen::Matrix3d b = P.block<3, 3>(index, index);
    return 0.5 * (b + b.transpose());
  };
  state.position_covariance_m2 = block(idx::kP);
  state.velocity_covariance_m2ps2 = block(idx::kV);
  state.attitude_covariance_rad2 = block(idx::kTheta);
  state.gyro_bias_rps = fused.gyro_bias_rps;
  state.accel_bias_mps2 = fused.accel_bias_mps2;
  state.baro_bias_m = fused.baro_bias_m;
  state.ground_down_m = fused.ground_down_m;
  state.vo_scale = std::exp(fused.vo_log_scale);
  state.last_gps_utime = last_gps_utime_;
  state.updates_fused =
      static_cast<int>(counts_.baro + counts_.range + counts_.gps + counts_.mag + counts_.vo);
  state.updates_refused = static_cast<int>(counts_.refused);
  state.updates_late = static_cast<int>(fusion_->late());
  msg::publish(bus_, params_.state_channel, state);
  ++counts_.published;
}

}  // namespace nadir::nav
