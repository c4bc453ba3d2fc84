#pragma once
// What nadir's messages carry, as plain structs: one per lcmtypes/*.lcm type,
// in the project's frames and units (world local NED, body FRD, camera OpenCV
// optical; Hamilton quaternions). No LCM here: lcmtypes/codec.h turns these
// into bytes and back, and only it knows the generated types. The camera
// image is in lcmtypes/image.h (it holds OpenCV pixels).

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nadir::msg {

// pose_t: the body's pose and motion (POSE_TRUTH; the simulator's state).
struct Pose {
  std::int64_t utime = 0;
  // Body origin in the world frame and its velocity and acceleration, m, m/s, m/s^2.
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ned_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_ned_mps2 = Eigen::Vector3d::Zero();
  // R_world_body, and the body's angular velocity in the body frame, rad/s.
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d omega_body_rps = Eigen::Vector3d::Zero();
};

// imu_t: gyro and accelerometer in body FRD.
struct Imu {
  std::int64_t utime = 0;
  Eigen::Vector3d angular_velocity_rps = Eigen::Vector3d::Zero();
  // Specific force, m/s^2: a level vehicle at rest reads (0, 0, -g).
  Eigen::Vector3d linear_acceleration_mps2 = Eigen::Vector3d::Zero();
};

enum class RangeStatus { VALID, TOO_CLOSE, OUT_OF_RANGE };

// range_t: a rangefinder's distance along its beam.
struct Range {
  std::int64_t utime = 0;
  // From the body origin along direction_body, m; min_range_m with TOO_CLOSE,
  // max_range_m with OUT_OF_RANGE.
  double range_m = 0.0;
  RangeStatus status = RangeStatus::OUT_OF_RANGE;
  // Unit direction of the beam in body FRD.
  Eigen::Vector3d direction_body = Eigen::Vector3d::UnitZ();
  double min_range_m = 0.0;
  double max_range_m = 0.0;
};

enum class GpsFix { NONE, FIX_2D, FIX_3D, DGPS, RTK };

// gps_t: a GNSS fix (WGS-84, ellipsoid height).
struct Gps {
  std::int64_t utime = 0;
  double lat_rad = 0.0;
  double lon_rad = 0.0;
  double alt_m = 0.0;
  Eigen::Vector3d velocity_ned_mps = Eigen::Vector3d::Zero();
  // 1-sigma error per horizontal axis and vertically, m.
  double horizontal_accuracy_m = 0.0;
  double vertical_accuracy_m = 0.0;
  int num_satellites = 0;
  GpsFix fix = GpsFix::NONE;
};

// baro_t: barometric altitude and the static pressure it stands for.
struct Baro {
  std::int64_t utime = 0;
  double altitude_m = 0.0;
  double pressure_pa = 0.0;
};

// magnetometer_t: the magnetic field in the body frame.
struct Magnetometer {
  std::int64_t utime = 0;
  Eigen::Vector3d field_body_ut = Eigen::Vector3d::Zero();
};

// geodetic_position_t (NAV_POSITION): WGS-84, ellipsoid height; altitude_rel_m
// above the start.
struct GeodeticPosition {
  std::int64_t utime = 0;
  double lat_rad = 0.0;
  double lon_rad = 0.0;
  double alt_m = 0.0;
  double alt_rel_m = 0.0;
};

// attitude_t (NAV_ATTITUDE): R_world_body and its Z-Y-X angles (core/frames.h).
struct Attitude {
  std::int64_t utime = 0;
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  double yaw_rad = 0.0;
};

// velocity_t (NAV_VELOCITY).
struct Velocity {
  std::int64_t utime = 0;
  Eigen::Vector3d v_ned_mps = Eigen::Vector3d::Zero();
};

// body_rates_t (NAV_RATES): angular velocity in body FRD, deg/s (as flight stacks send it).
struct BodyRates {
  std::int64_t utime = 0;
  Eigen::Vector3d omega_body_dps = Eigen::Vector3d::Zero();
};

enum class Distortion { NONE, RADTAN, EQUIDISTANT };

// camera_info_t: a camera's lens and mount. Pixel coordinates have the top-left
// pixel's centre at (0, 0).
struct CameraInfo {
  std::int64_t utime = 0;
  std::string camera_name;
  int width = 0;
  int height = 0;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
  // RADTAN: k1 k2 p1 p2 [k3]; EQUIDISTANT: k1 k2 k3 k4.
  Distortion distortion_model = Distortion::NONE;
  std::vector<double> distortion;
  double fps = 0.0;
  Eigen::Vector3d p_cam_in_body_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_body_cam = Eigen::Quaterniond::Identity();
  // Timing (camera_info_t says how): all zero for an exact, global, instant shutter.
  double time_offset_s = 0.0;
  double timestamp_jitter_s = 0.0;
  double exposure_s = 0.0;
  double readout_s = 0.0;

  Eigen::Isometry3d T_body_cam() const;
  // True when any distortion coefficient is not zero.
  bool distorted() const;
};

enum class VoStatus { INITIALIZING, TRACKING, LOST };

// vo_estimate_t: a VO node's pose of the body. The pose means something only
// when TRACKING; otherwise it is what the node last had (identity if not a rotation).
struct VoEstimate {
  std::int64_t utime = 0;
  // The node's name in the registry: ppa, vo_feature, ...
  std::string source;
  VoStatus status = VoStatus::INITIALIZING;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  int num_features = 0;
  int num_resets = 0;
  double processing_time_s = 0.0;
};

// nav_state_t: the navigation filter's fused state and its uncertainty.
struct NavState {
  std::int64_t utime = 0;
  std::string source;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ned_mps = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d position_covariance_m2 = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d velocity_covariance_m2ps2 = Eigen::Matrix3d::Zero();
  // Small rotation in the body frame: R_true = R_estimate Exp(dtheta).
  Eigen::Matrix3d attitude_covariance_rad2 = Eigen::Matrix3d::Zero();
  Eigen::Vector3d gyro_bias_rps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
  double baro_bias_m = 0.0;
  double ground_down_m = 0.0;
  double vo_scale = 1.0;
  std::int64_t last_gps_utime = -1;  // -1: no fix fused yet
  int updates_fused = 0;
  int updates_refused = 0;
  int updates_late = 0;
};

// ppa_odometry_t: the SCAMP-5 chip's image alignment for one frame.
struct PpaOdometry {
  std::int64_t utime = 0;
  std::int64_t frame_index = 0;
  double translation_x_px = 0.0;
  double translation_y_px = 0.0;
  double rotation_rad = 0.0;
  double scale = 1.0;
  double strength = 0.0;
  bool new_keyframe = false;
  int keyframe_edge_count = 0;
  std::int64_t instruction_count = 0;
};

enum class TargetKind { CONCENTRIC, GATE };

// target_detection_t: a target found on the chip, in image pixels.
struct TargetDetection {
  std::int64_t utime = 0;
  TargetKind kind = TargetKind::CONCENTRIC;
  bool detected = false;
  int x_min_px = 0;
  int y_min_px = 0;
  int x_max_px = 0;
  int y_max_px = 0;
  double center_x_px = 0.0;
  double center_y_px = 0.0;
  int num_boundaries = 0;
  std::vector<Eigen::Vector2d> points_px;
};

enum class PatternKind { NONE, GATE, SLALOM_LEFT, SLALOM_RIGHT };

// gate_pattern_t: the gate or slalom pattern the PPA found in one frame.
struct GatePattern {
  std::int64_t utime = 0;
  PatternKind kind = PatternKind::NONE;
  // A gate's four disk centres (top-left, top-right, bottom-left,
  // bottom-right) or a slalom board's three (column top, bottom, tip), px.
  std::vector<Eigen::Vector2d> disks_px;
  bool squares_intact = false;
  int patterns_in_view = 0;
  std::int64_t threshold_instructions = 0;
  std::int64_t flood_instructions = 0;
  std::int64_t denoise_instructions = 0;
  std::int64_t coordinates_instructions = 0;
  double chip_time_s = 0.0;
};

// drive_command_t: steering and speed for a ground vehicle.
struct DriveCommand {
  enum class Mode { TRACKING, COASTING, STOPPING, MANOEUVRE, STOPPED };
  std::int64_t utime = 0;        // takes effect
  std::int64_t frame_utime = 0;  // the frame it came from
  double steer_rad = 0.0;        // positive turns right
  double speed_mps = 0.0;
  Mode mode = Mode::STOPPED;
  double lateral_error_rad = 0.0;
  double deformation = 0.0;
};

// waypoint_reached_t: the guidance took a waypoint as reached (world frame, m).
struct WaypointReached {
  std::int64_t utime = 0;
  int index = 0;
  int count = 0;
  Eigen::Vector3d waypoint_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d believed_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d true_ned_m = Eigen::Vector3d::Zero();
  std::string source;
};

// vo_command_t: a command to the VO nodes (target: a source name, or empty for all).
struct VoCommand {
  enum class Kind { RESET };
  std::int64_t utime = 0;
  std::string target;
  Kind command = Kind::RESET;
  // RESET: restart from this pose (T_world_body); none: from the pose the node
  // estimates now (its map dropped, the estimate does not jump).
  std::optional<Pose> initial_pose;
};

// heartbeat_t: a live node's sign of life, once a second of wall time.
struct Heartbeat {
  std::int64_t utime = 0;  // wall clock, us since the Unix epoch
  std::string node;        // the registry name: sim, camera, ppa, vo_feature, ...
  std::int32_t pid = 0;
  std::int64_t sequence = 0;                 // 0 for the first, then one more each time
  bool done = false;                         // the last one, as the node stops
  std::string summary;                       // what the node has done so far, one line
  std::map<std::string, std::int64_t> sent;  // messages published so far, by channel
};

// bus_check_t: one host's word in nadir launch's check of the bus.
struct BusCheck {
  std::int64_t utime = 0;      // wall clock, us since the Unix epoch
  std::int64_t launch_id = 0;  // the launch it belongs to
  std::string host;
  std::int32_t pid = 0;
  std::set<std::string> heard;  // the hosts it has heard
};

}  // namespace nadir::msg
