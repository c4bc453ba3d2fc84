#pragma once
// nadir-nav's work on a bus, the same in the live node and in `nadir run`: the
// IMU drives the error-state filter (nodes/nav/error_state_filter.h) on a
// delayed horizon (delayed_fusion.h); the barometer, the rangefinder, GPS, the
// magnetometer and one VO node's estimates are fused as they come. The present
// solution goes out on POSE_NAV (vo_estimate_t, source "nav"), the fused state
// with its covariance on POSE_NAV_STATE (nav_state_t). Bad messages are
// dropped and counted. docs/nav.md says what is modelled and why.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/geodesy.h"
#include "core/params.h"
#include "lcmtypes/messages.h"
#include "nodes/nav/delayed_fusion.h"

namespace nadir::nav {

// The node's name: its scenario group, its source name in vo_estimate_t and the metrics.
inline constexpr char kNavSourceName[] = "nav";

// The sensors as the filter models them: datasheet figures, as the scenario's
// sensor models take them (nadir run copies the scenario's when
// match_scenario_sensors is on).
struct NavSensorModel {
  double gyro_noise_density_rps_rthz = 2.0e-4;
  double accel_noise_density_mps2_rthz = 2.0e-3;
  double gyro_bias_random_walk_rps_rts = 2.0e-5;
  double accel_bias_random_walk_mps2_rts = 2.0e-4;
  double baro_sigma_m = 0.3;
  double baro_bias_random_walk_m_rts = 0.01;
  // The rangefinder's noise and what a flat ground under the vehicle leaves
  // of the real one between updates.
  double range_sigma_m = 0.3;
  // The beam's largest tilt from vertical at which a range is fused, deg: off
  // vertical the flat ground is the ground somewhere else.
  double range_max_tilt_deg = 15.0;
  double ground_random_walk_m_rtm = 0.1;
  double gps_velocity_sigma_mps = 0.1;
  // The heading the magnetometer gives, from its white noise, deg (what
  // calibration left of the airframe's field is a state of the filter).
  double heading_sigma_deg = 1.0;
  double mag_bias_random_walk_ut_rts = 1e-3;
  // The Earth's field where the vehicle flies (a World Magnetic Model figure).
  double declination_deg = -4.6;
  double inclination_deg = 66.5;
  double field_ut = 52.0;

  void visit(core::ParamVisitor& v);
};

// A VO node's relative pose between two of its frames as the filter models
// it: translation sigma = max(floor, share of the distance moved), per axis.
// A VO's pose jitters from frame to frame (the feature VO's 0.2 m at 300 m)
// but drifts slowly: its motion is taken over interval_s, where the jitter of
// the two ends (the floors) is small against the distance.
struct NavVoModel {
  double interval_s = 0.5;
  double translation_sigma_floor_m = 0.3;
  double translation_sigma_share = 0.01;
  double rotation_sigma_deg = 0.05;
  // How the VO's scale wanders, per sqrt(s) of log scale; and how far it
  // may be off at the start (log scale, 1 sigma).
  double log_scale_random_walk_rts = 1e-3;
  double initial_log_scale_sigma = 0.05;

  void visit(core::ParamVisitor& v);
};

// The initial uncertainty (1 sigma) around the start pose.
struct NavInitialSigmas {
  double position_m = 1.0;
  double velocity_mps = 0.3;
  double tilt_deg = 1.0;
  double heading_deg = 3.0;
  double gyro_bias_rps = 2e-3;
  double accel_bias_mps2 = 0.1;
  double baro_bias_m = 5.0;
  double mag_bias_ut = 1.0;

  void visit(core::ParamVisitor& v);
};

struct NavNodeParams {
  // In a scenario: run the navigation filter (nadir run composes it, nadir
  // launch starts nadir-nav).
  bool enabled = false;
  // Not the filter's: what the vehicle's guidance flies on from the GPS denial
  // on (truth, gps, nav, vo_feature, vo_direct, ppa); the scenario hands it to
  // the simulator (sim::GuidanceParams). The filter ignores it.
  std::string source = "truth";
  std::string imu_channel = "IMU";
  std::string baro_channel = "BARO";
  std::string range_channel = "RANGE";
  std::string gps_channel = "GPS";
  std::string mag_channel = "MAG";
  // The VO node whose estimates are fused (vo_estimate_t).
  std::string vo_channel = "POSE_VO_FEATURE";
  // Read once: the start pose the filter starts from (as the VO nodes do).
  std::string truth_channel = "POSE_TRUTH";
  std::string pose_channel = "POSE_NAV";
  std::string state_channel = "POSE_NAV_STATE";
  bool use_baro = true;
  bool use_range = true;
  bool use_gps = true;
  // Off by default: with the airframe's field unlearnt in straight flight the
  // heading it gives was 0.2 deg off, which cost more than it gave (docs/nav.md).
  bool use_mag = false;
  bool use_vo = true;
  // Take the rangefinder against a known map of the ground under the estimate
  // (the scenario's world in nadir run and launch) instead of the ground state.
  bool range_against_map = false;
  // POSE_NAV and POSE_NAV_STATE this often, in message time (0: at every IMU sample).
  double publish_rate_hz = 50.0;
  // How far the filter runs behind the newest IMU sample, s: a measurement
  // older than that is refused.
  double delay_s = 0.2;
  // Innovations beyond the chi-square quantile of this probability are refused.
  double gate_probability = 0.9999;
  // The world frame's origin (GPS fixes and the barometer's altitude are turned into it).
  double origin_lat_deg = 0.0;
  double origin_lon_deg = 0.0;
  double origin_alt_m = 0.0;
  // Take the sensor figures from the scenario's sensor models (nadir run, launch, sweep).
  bool match_scenario_sensors = true;
  NavSensorModel sensors;
  NavVoModel vo;
  NavInitialSigmas initial;

  void visit(core::ParamVisitor& v);
};

// What the node fused, refused and dropped, by sensor.
struct NavCounts {
  std::uint64_t imu = 0;
  std::uint64_t baro = 0;
  std::uint64_t range = 0;
  std::uint64_t gps = 0;
  std::uint64_t mag = 0;
  std::uint64_t vo = 0;
  std::uint64_t vo_restarts = 0;  // VO frames the filter restarted the VO's chain on
  std::uint64_t refused = 0;      // by the gate
  std::uint64_t dropped = 0;      // messages that did not decode or were out of order
  std::uint64_t published = 0;
};

class NavNode {
 public:
  // ground_down: the ground's down coordinate at a north, east (a known map),
  // for range_against_map. Throws core::ParamError for parameters out of their
  // range, or range_against_map without a map.
  NavNode(core::Bus& bus, const NavNodeParams& params, GroundDown ground_down = {});

  bool started() const { return fusion_ != nullptr; }
  const NavCounts& counts() const { return counts_; }
  std::int64_t late() const { return fusion_ ? fusion_->late() : 0; }
  const std::string& firstDropReason() const { return first_drop_reason_; }
  // The delayed filter (its state and covariance); null before the start.
  const ErrorStateFilter* filter() const { return fusion_ ? &fusion_->delayed() : nullptr; }

 private:
  void start(const msg::Pose& truth);
  void onImu(const msg::Imu& imu);
  void onVo(const msg::VoEstimate& estimate);
  using Fuse = std::function<UpdateResult(ErrorStateFilter&)>;
  // Queues a measurement; when fused, counts it under counter or as refused.
  void measure(std::int64_t utime, std::uint64_t NavCounts::*counter, Fuse fuse);
  void publish();
  void drop(const std::string& reason);

  core::Bus& bus_;
  NavNodeParams params_;
  core::LocalNedFrame frame_;
  GroundDown ground_down_;
  Eigen::Vector3d earth_field_ned_ut_;
  std::unique_ptr<DelayedFusion> fusion_;
  NavCounts counts_;
  std::int64_t start_utime_ = 0;
  std::int64_t last_imu_utime_ = 0;
  std::int64_t next_publish_utime_ = 0;
  std::int64_t last_gps_utime_ = -1;
  // The VO's last fused frame: its pose and reset count, for the next relative pose.
  std::optional<msg::VoEstimate> vo_previous_;
  std::string first_drop_reason_;
  std::vector<core::Subscription> subscriptions_;
};

}  // namespace nadir::nav
