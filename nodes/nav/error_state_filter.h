#pragma once
// The navigation filter's core: an error-state Kalman filter (Sola, "Quaternion
// kinematics for the error-state Kalman filter", 2017) driven by the IMU, with
// the barometer's bias and the ground's height under the vehicle as states, so
// that the barometer and the rangefinder correct it without a map. Plain
// structs in and out; no LCM. docs/nav.md gives the states, the equations and
// the noise models.

#include <cstdint>
#include <functional>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nadir::nav {

inline constexpr double kGravity_mps2 = 9.80665;

// The error state: position, velocity, attitude (local, body frame), gyro and
// accelerometer biases, barometer bias, ground height (down coordinate), a
// clone of the pose at the last VO frame (stochastic cloning), the VO's log
// scale, and the magnetometer's hard-iron offset (body frame).
inline constexpr int kStates = 27;
namespace idx {
inline constexpr int kP = 0;
inline constexpr int kV = 3;
inline constexpr int kTheta = 6;
inline constexpr int kGyroBias = 9;
inline constexpr int kAccelBias = 12;
inline constexpr int kBaroBias = 15;
inline constexpr int kGround = 16;
inline constexpr int kCloneP = 17;
inline constexpr int kCloneTheta = 20;
inline constexpr int kLogScale = 23;
inline constexpr int kMagBias = 24;
}  // namespace idx

using Covariance = Eigen::Matrix<double, kStates, kStates>;

struct NavState {
  std::int64_t utime = 0;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ned_mps = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d gyro_bias_rps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
  // The barometer reads the altitude plus this, m.
  double baro_bias_m = 0.0;
  // The ground under the vehicle, down coordinate in the world frame, m.
  double ground_down_m = 0.0;
  // The pose at the last VO frame (cloneCurrentPose), world frame.
  Eigen::Vector3d clone_p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond clone_q_world_body = Eigen::Quaterniond::Identity();
  // The VO's distances are exp(vo_log_scale) times the true ones.
  double vo_log_scale = 0.0;
  // What the magnetometer reads besides the Earth's field: the airframe's own
  // (hard iron), body frame, uT.
  Eigen::Vector3d mag_bias_ut = Eigen::Vector3d::Zero();
};

// Process noise, in the IMU's datasheet units (as sim::ImuParams).
struct ProcessNoise {
  double gyro_noise_density_rps_rthz = 2.0e-4;
  double accel_noise_density_mps2_rthz = 2.0e-3;
  double gyro_bias_random_walk_rps_rts = 2.0e-5;
  double accel_bias_random_walk_mps2_rts = 2.0e-4;
  double baro_bias_random_walk_m_rts = 0.01;
  // How the ground's height wanders as the vehicle flies over it, m per
  // sqrt(m) flown horizontally.
  double ground_random_walk_m_rtm = 0.1;
  // How the VO's scale wanders, per sqrt(s) of log scale.
  double vo_log_scale_random_walk_rts = 1e-3;
  // How the airframe's own field wanders, uT per sqrt(s).
  double mag_bias_random_walk_ut_rts = 1e-3;
};

struct ImuSample {
  std::int64_t utime = 0;
  Eigen::Vector3d angular_velocity_rps = Eigen::Vector3d::Zero();
  // Specific force, body FRD: (0, 0, -g) for a level vehicle at rest.
  Eigen::Vector3d linear_acceleration_mps2 = Eigen::Vector3d::Zero();
};

// What an update did: the innovation's normalised square (NIS), and whether
// it passed the gate (a NIS above the gate leaves the filter untouched).
struct UpdateResult {
  bool accepted = false;
  double nis = 0.0;
  int dimension = 0;
};

// The ground's down coordinate at a north, east position, m (a known map).
using GroundDown = std::function<double(double north_m, double east_m)>;

class ErrorStateFilter {
 public:
  // Throws std::invalid_argument for a covariance that is not symmetric
  // positive semi-definite or a negative noise figure.
  ErrorStateFilter(const ProcessNoise& noise, const NavState& initial,
                   const Covariance& initial_covariance);

  // IMU samples in time order: the first sets the time; each next one moves
  // the state from the previous sample's time to its own with its readings
  // (attitude at the interval's middle for the acceleration). Throws
  // std::invalid_argument for a sample before the previous one.
  void propagate(const ImuSample& imu);

  // Barometric altitude: altitude_m = origin_alt_m - p_down + baro_bias.
  UpdateResult updateBaro(double altitude_m, double origin_alt_m, double sigma_m);
  // A position or velocity in the world frame (GPS) with its covariance.
  UpdateResult updatePosition(const Eigen::Vector3d& p_ned_m, const Eigen::Matrix3d& covariance);
  UpdateResult updateVelocity(const Eigen::Vector3d& v_ned_mps, const Eigen::Matrix3d& covariance);
  // A rangefinder's distance along direction_body to flat ground: the ground
  // state, or ground_down (the map) when given, under the estimate. The
  // attitude's uncertainty widens the range's; the range does not correct it.
  UpdateResult updateRange(double range_m, const Eigen::Vector3d& direction_body, double sigma_m,
                           const GroundDown& ground_down = {});

  // The heading a magnetometer gives: the measured field less the estimated
  // hard-iron offset, turned into the world by the estimated attitude,
  // against the Earth's field there (field_world_ut, NED), compared in the
  // horizontal plane only, so that a disturbed field cannot tilt the
  // estimate. The offset is learnt as the heading is known otherwise (GPS, the
  // VO's motion) while the attitude changes. sigma_rad is the heading's 1-sigma
  // from the sensor's white noise. Refused when either horizontal
  // component is under a tenth of its vector (near the magnetic poles).
  UpdateResult updateHeading(const Eigen::Vector3d& field_body_ut,
                             const Eigen::Vector3d& field_world_ut, double sigma_rad);

  // Takes the present pose as the clone: the pose a VO's next relative pose
  // starts from. Called at each VO frame after its update, and at a VO's first
  // frame or after its reset (no update then, so nothing jumps).
  void cloneCurrentPose();
  // A VO's motion from the cloned pose to the present one, in the cloned body
  // frame: dp_body (VO scale) = exp(log scale) R_clone^T (p - p_clone), and
  // dR = R_clone^T R, with their covariance (translation first, then the
  // rotation's small angle, body frame).
  UpdateResult updateRelativePose(const Eigen::Vector3d& dp_clone_body,
                                  const Eigen::Quaterniond& dq_clone_body,
                                  const Eigen::Matrix<double, 6, 6>& covariance);

  // Innovations whose NIS exceeds the chi-square quantile of this probability
  // for their dimension are refused. 1 = no gate.
  void setGateProbability(double probability);

  const NavState& state() const { return state_; }
  // Whether an IMU sample has set the filter's time.
  bool hasTime() const { return has_time_; }
  const Covariance& covariance() const { return P_; }

 private:
  template <int M>
  UpdateResult update(const Eigen::Matrix<double, M, 1>& residual,
                      const Eigen::Matrix<double, M, kStates>& H,
                      const Eigen::Matrix<double, M, M>& R);
  void inject(const Eigen::Matrix<double, kStates, 1>& dx);

  ProcessNoise noise_;
  NavState state_;
  Covariance P_;
  bool has_time_ = false;
  ImuSample last_imu_;
  double gate_probability_ = 0.9999;
};

// The nominal state carried over dt with one IMU sample's readings (its time
// becomes the sample's): the filter's propagation without the covariance.
void propagateNominal(NavState& state, const ImuSample& imu, double dt);

// The nominal state moved by an error (as an update injects it): additive
// for vectors, q Exp(dtheta) for attitudes.
NavState applyError(const NavState& state, const Eigen::Matrix<double, kStates, 1>& dx);

// The relative pose a VO would measure in this state (translation in the VO's
// scale, then the rotation) and its Jacobian with respect to the error state
// (rows: translation, then the rotation's small angle).
struct RelativePosePrediction {
  Eigen::Vector3d dp_clone_body = Eigen::Vector3d::Zero();
  Eigen::Quaterniond dq_clone_body = Eigen::Quaterniond::Identity();
  Eigen::Matrix<double, 6, kStates> H = Eigen::Matrix<double, 6, kStates>::Zero();
};
RelativePosePrediction predictRelativePose(const NavState& state);

// The chi-square quantile of probability p with k degrees of freedom.
double chiSquareQuantile(double p, int k);

}  // namespace nadir::nav
