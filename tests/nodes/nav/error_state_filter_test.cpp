// The navigation filter's core against motion and covariance worked out by
// hand: a vehicle at rest, a path of constant acceleration while turning, and
// the barometer and rangefinder updates.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "nodes/nav/error_state_filter.h"

namespace nadir::nav {
namespace {

constexpr double kDt = 1.0 / 200.0;
constexpr std::int64_t kDtUs = 5000;

Covariance zeroCovariance() { return Covariance::Zero(); }

// At rest and level, with readings free of noise and bias: the state does not
// move, and the covariance grows as the IMU's noise says. Worked out from the
// error equations: dv_z' = n_a, so var(v_z) = q_a T and var(p_z) = q_a T^3 / 3;
// horizontally a tilt error dtheta (a random walk of q_g) tips gravity into the
// velocity, dv_x' = -g dtheta_y + n_a, so var(v_x) = q_a T + g^2 q_g T^3 / 3 and
// var(p_x) = q_a T^3 / 3 + g^2 q_g T^5 / 20.
TEST(ErrorStateFilter, AtRestItStaysPutAndItsCovarianceGrowsAsTheNoiseSays) {
  ProcessNoise noise;
  noise.gyro_bias_random_walk_rps_rts = 0.0;
  noise.accel_bias_random_walk_mps2_rts = 0.0;
  NavState start;
  start.p_ned_m = Eigen::Vector3d(10.0, -20.0, -100.0);
  ErrorStateFilter filter(noise, start, zeroCovariance());
  ImuSample imu;
  imu.linear_acceleration_mps2 = Eigen::Vector3d(0.0, 0.0, -kGravity_mps2);
  const double T = 10.0;
  for (int i = 0; i <= static_cast<int>(T / kDt); ++i) {
    imu.utime = 1'000'000 + i * kDtUs;
    filter.propagate(imu);
  }
  const NavState& s = filter.state();
  EXPECT_NEAR((s.p_ned_m - start.p_ned_m).norm(), 0.0, 1e-9);
  EXPECT_NEAR(s.v_ned_mps.norm(), 0.0, 1e-9);
  EXPECT_NEAR(s.q_world_body.angularDistance(Eigen::Quaterniond::Identity()), 0.0, 1e-12);

  const double q_a = std::pow(noise.accel_noise_density_mps2_rthz, 2);
  const double q_g = std::pow(noise.gyro_noise_density_rps_rthz, 2);
  const double g2 = kGravity_mps2 * kGravity_mps2;
  const Covariance& P = filter.covariance();
  EXPECT_NEAR(P(idx::kV + 2, idx::kV + 2) / (q_a * T), 1.0, 0.01);
  EXPECT_NEAR(P(idx::kP + 2, idx::kP + 2) / (q_a * T * T * T / 3), 1.0, 0.01);
  for (int axis = 0; axis < 2; ++axis) {
    EXPECT_NEAR(P(idx::kV + axis, idx::kV + axis) / (q_a * T + g2 * q_g * T * T * T / 3), 1.0,
                0.01);
    EXPECT_NEAR(
        P(idx::kP + axis, idx::kP + axis) / (q_a * T * T * T / 3 + g2 * q_g * std::pow(T, 5) / 20),
        1.0, 0.01);
    EXPECT_NEAR(P(idx::kTheta + axis, idx::kTheta + axis) / (q_g * T), 1.0, 0.01);
  }
}

// A path of constant acceleration in the world while the body turns at a
// constant rate, its IMU readings worked out exactly (specific force = R^T (a -
// g)), no noise: after 20 s the position is within 1 cm of p0 + v0 t + a t^2 / 2.
TEST(ErrorStateFilter, ConstantAccelerationWhileTurningWithin1Cm) {
  const Eigen::Vector3d p0(0.0, 0.0, -50.0), v0(20.0, 5.0, 0.0), a(0.4, -0.3, 0.05);
  const Eigen::Vector3d omega_body(0.02, -0.01, 0.1);
  NavState start;
  start.p_ned_m = p0;
  start.v_ned_mps = v0;
  ErrorStateFilter filter(ProcessNoise{}, start, zeroCovariance());
  const Eigen::Vector3d g(0.0, 0.0, kGravity_mps2);
  const double T = 20.0;
  const int steps = static_cast<int>(T / kDt);
  for (int i = 0; i <= steps; ++i) {
    const double t = i * kDt;
    ImuSample imu;
    imu.utime = i * kDtUs;
    imu.angular_velocity_rps = omega_body;
    // The specific force at the middle of the interval that ends at t, as the
    // filter takes each sample to hold over the interval before it.
    const double t_mid = std::max(0.0, t - 0.5 * kDt);
    const Eigen::Quaterniond q_mid(
        Eigen::AngleAxisd(omega_body.norm() * t_mid, omega_body.normalized()));
    imu.linear_acceleration_mps2 = q_mid.inverse() * (a - g);
    filter.propagate(imu);
  }
  const Eigen::Vector3d expected = p0 + v0 * T + 0.5 * a * T * T;
  EXPECT_LT((filter.state().p_ned_m - expected).norm(), 0.01);
  EXPECT_LT((filter.state().v_ned_mps - (v0 + a * T)).norm(), 0.001);
  const Eigen::Quaterniond q_end(Eigen::AngleAxisd(omega_body.norm() * T, omega_body.normalized()));
  EXPECT_LT(filter.state().q_world_body.angularDistance(q_end), 1e-9);
}

// A gyro bias the filter does not know (0.002 rad/s about roll and -0.0015
// about pitch, the IMU at rest, GPS position and velocity at 5 Hz): the filter
// learns it as fast as its own covariance says it can. At every GPS fix the
// error is inside 3 of the filter's sigma, and once that sigma is below a
// tenth of the bias, so is the error (to 3 sigma).
TEST(ErrorStateFilter, GyroBiasIsLearntAsFastAsTheCovarianceSays) {
  const Eigen::Vector3d true_bias(0.002, -0.0015, 0.0);
  NavState start;
  Covariance P = Covariance::Zero();
  P.block<3, 3>(idx::kP, idx::kP) = Eigen::Matrix3d::Identity() * 1.0;
  P.block<3, 3>(idx::kV, idx::kV) = Eigen::Matrix3d::Identity() * 0.01;
  P.block<3, 3>(idx::kTheta, idx::kTheta) = Eigen::Matrix3d::Identity() * 1e-4;
  P.block<3, 3>(idx::kGyroBias, idx::kGyroBias) = Eigen::Matrix3d::Identity() * 1e-4;  // 0.01 rad/s
  P.block<3, 3>(idx::kAccelBias, idx::kAccelBias) = Eigen::Matrix3d::Identity() * 1e-4;
  P(idx::kBaroBias, idx::kBaroBias) = 1.0;
  P(idx::kGround, idx::kGround) = 1.0;
  ErrorStateFilter filter(ProcessNoise{}, start, P);
  ImuSample imu;
  imu.angular_velocity_rps = true_bias;
  imu.linear_acceleration_mps2 = Eigen::Vector3d(0.0, 0.0, -kGravity_mps2);
  const Eigen::Matrix3d gps_p = Eigen::Matrix3d::Identity() * 0.25;
  const Eigen::Matrix3d gps_v = Eigen::Matrix3d::Identity() * 0.0025;
  bool learnt = false;
  for (int i = 0; i <= 200 * 300; ++i) {
    imu.utime = i * kDtUs;
    filter.propagate(imu);
    if (i % 40 != 0) continue;
    filter.updatePosition(Eigen::Vector3d::Zero(), gps_p);
    filter.updateVelocity(Eigen::Vector3d::Zero(), gps_v);
    for (int axis = 0; axis < 2; ++axis) {
      const double sigma =
          std::sqrt(filter.covariance()(idx::kGyroBias + axis, idx::kGyroBias + axis));
      const double error = filter.state().gyro_bias_rps[axis] - true_bias[axis];
      ASSERT_LT(std::abs(error), 3.0 * sigma) << "axis " << axis << " at " << i * kDt << " s";
      if (sigma < 0.1 * std::abs(true_bias[axis])) {
        learnt = true;
        EXPECT_LT(std::abs(error), 0.3 * std::abs(true_bias[axis])) << "axis " << axis;
      }
    }
  }
  EXPECT_TRUE(learnt) << "the roll and pitch biases are observable at rest with GPS velocity";
  EXPECT_NEAR(filter.state().gyro_bias_rps.x(), true_bias.x(), 2e-4);
  EXPECT_NEAR(filter.state().gyro_bias_rps.y(), true_bias.y(), 2e-4);
}

// A step in the roll gyro's bias, 1e-3 rad/s, after a minute at rest with the
// bias learnt (GPS position and velocity at 5 Hz). The model's random walk of
// 1e-4 rad/s/sqrt(s) makes a change of that size a 1-sigma event over
// T = (1e-3 / 1e-4)^2 = 100 s: the filter must have followed it to a fifth by
// then. A model without the walk would never move (its gain goes to zero).
TEST(ErrorStateFilter, GyroBiasStepIsFollowedWithinTheTimeTheModelPredicts) {
  const double step_rps = 1e-3;
  ProcessNoise noise;
  noise.gyro_bias_random_walk_rps_rts = 1e-4;
  const double predicted_s = std::pow(step_rps / noise.gyro_bias_random_walk_rps_rts, 2);
  NavState start;
  Covariance P = Covariance::Zero();
  P.block<3, 3>(idx::kP, idx::kP) = Eigen::Matrix3d::Identity() * 1.0;
  P.block<3, 3>(idx::kV, idx::kV) = Eigen::Matrix3d::Identity() * 0.01;
  P.block<3, 3>(idx::kTheta, idx::kTheta) = Eigen::Matrix3d::Identity() * 1e-6;
  P.block<3, 3>(idx::kGyroBias, idx::kGyroBias) = Eigen::Matrix3d::Identity() * 1e-8;
  P.block<3, 3>(idx::kAccelBias, idx::kAccelBias) = Eigen::Matrix3d::Identity() * 1e-4;
  P(idx::kBaroBias, idx::kBaroBias) = 1.0;
  P(idx::kGround, idx::kGround) = 1.0;
  ErrorStateFilter filter(noise, start, P);
  ImuSample imu;
  imu.linear_acceleration_mps2 = Eigen::Vector3d(0.0, 0.0, -kGravity_mps2);
  const Eigen::Matrix3d gps_p = Eigen::Matrix3d::Identity() * 0.25;
  const Eigen::Matrix3d gps_v = Eigen::Matrix3d::Identity() * 0.0025;
  const double step_s = 60.0;
  double followed_s = -1.0;
  const int samples = static_cast<int>(std::lround((step_s + predicted_s) * 200.0));
  for (int i = 0; i <= samples; ++i) {
    const double t_s = i * kDt;
    imu.utime = i * kDtUs;
    imu.angular_velocity_rps = Eigen::Vector3d(t_s >= step_s ? step_rps : 0.0, 0.0, 0.0);
    filter.propagate(imu);
    if (i % 40 != 0) continue;
    filter.updatePosition(Eigen::Vector3d::Zero(), gps_p);
    filter.updateVelocity(Eigen::Vector3d::Zero(), gps_v);
    const double error = std::abs(filter.state().gyro_bias_rps.x() - imu.angular_velocity_rps.x());
    if (t_s < step_s) {
      ASSERT_LT(error, 0.05 * step_rps) << "before the step, at " << t_s << " s";
    }
    if (t_s >= step_s && followed_s < 0.0 && error < 0.2 * step_rps) followed_s = t_s - step_s;
  }
  ASSERT_GE(followed_s, 0.0) << "not followed within " << predicted_s << " s";
  EXPECT_LT(followed_s, predicted_s);
  EXPECT_NEAR(filter.state().gyro_bias_rps.x(), step_rps, 0.2 * step_rps);
}

// The path of ConstantAccelerationWhileTurning, worked out exactly at t.
struct TurningPath {
  Eigen::Vector3d p0{0.0, 0.0, -50.0}, v0{20.0, 5.0, 0.0}, a{0.4, -0.3, 0.05};
  Eigen::Vector3d omega_body{0.02, -0.01, 0.1};
  Eigen::Vector3d p(double t) const { return p0 + v0 * t + 0.5 * a * t * t; }
  Eigen::Quaterniond q(double t) const {
    return Eigen::Quaterniond(Eigen::AngleAxisd(omega_body.norm() * t, omega_body.normalized()));
  }
  ImuSample imu(int i) const {
    const double t = i * kDt;
    ImuSample sample;
    sample.utime = i * kDtUs;
    sample.angular_velocity_rps = omega_body;
    sample.linear_acceleration_mps2 =
        q(std::max(0.0, t - 0.5 * kDt)).inverse() * (a - Eigen::Vector3d(0, 0, kGravity_mps2));
    return sample;
  }
};

// A VO whose distances are 3 % long (scale 1.03), its relative poses between
// frames 0.1 s apart worked out from the path: the filter, told nothing of the
// scale (log scale 0 +- 0.1), learns exp(log scale) = 1.03 to 0.1 %, and the
// pose stays on the path.
TEST(ErrorStateFilter, RelativePosesTeachTheVoScale) {
  const TurningPath path;
  NavState start;
  start.p_ned_m = path.p(0.0);
  start.v_ned_mps = path.v0;
  Covariance P = Covariance::Identity() * 1e-8;
  P(idx::kLogScale, idx::kLogScale) = 0.01;
  P.block<3, 3>(idx::kP, idx::kP) = Eigen::Matrix3d::Identity() * 0.01;
  ErrorStateFilter filter(ProcessNoise{}, start, P);
  Eigen::Matrix<double, 6, 6> vo_covariance = Eigen::Matrix<double, 6, 6>::Identity();
  vo_covariance.topLeftCorner<3, 3>() *= 0.01 * 0.01;  // 1 cm
  vo_covariance.bottomRightCorner<3, 3>() *= 1e-4 * 1e-4;
  double clone_t = 0.0;
  for (int i = 0; i <= 200 * 20; ++i) {
    filter.propagate(path.imu(i));
    if (i % 20 != 0) continue;
    const double t = i * kDt;
    if (i > 0) {
      const Eigen::Vector3d dp = 1.03 * (path.q(clone_t).inverse() * (path.p(t) - path.p(clone_t)));
      const Eigen::Quaterniond dq = path.q(clone_t).inverse() * path.q(t);
      ASSERT_TRUE(filter.updateRelativePose(dp, dq, vo_covariance).accepted) << t << " s";
    }
    filter.cloneCurrentPose();
    clone_t = t;
  }
  EXPECT_NEAR(std::exp(filter.state().vo_log_scale), 1.03, 0.001);
  EXPECT_LT((filter.state().p_ned_m - path.p(20.0)).norm(), 0.05);
  EXPECT_LT(filter.state().q_world_body.angularDistance(path.q(20.0)), 1e-4);
}

// The relative pose's Jacobian against central differences of the model
// itself, column by column, at a state with a turned clone, a scale of 1.1 and
// 40 m between the poses.
TEST(ErrorStateFilter, RelativePoseJacobianMatchesNumericDifferences) {
  NavState state;
  state.p_ned_m = Eigen::Vector3d(30.0, -20.0, -90.0);
  state.q_world_body =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -0.3, 1.0).normalized()));
  state.clone_p_ned_m = Eigen::Vector3d(5.0, -10.0, -100.0);
  state.clone_q_world_body =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(-0.1, 0.2, 1.0).normalized()));
  state.vo_log_scale = std::log(1.1);
  const RelativePosePrediction at = predictRelativePose(state);
  constexpr double kStep = 1e-6;
  for (int j = 0; j < kStates; ++j) {
    Eigen::Matrix<double, kStates, 1> dx = Eigen::Matrix<double, kStates, 1>::Zero();
    dx(j) = kStep;
    const RelativePosePrediction plus = predictRelativePose(applyError(state, dx));
    const RelativePosePrediction minus = predictRelativePose(applyError(state, -dx));
    Eigen::Matrix<double, 6, 1> numeric;
    numeric.head<3>() = (plus.dp_clone_body - minus.dp_clone_body) / (2 * kStep);
    const Eigen::AngleAxisd turn(minus.dq_clone_body.conjugate() * plus.dq_clone_body);
    // The turn from minus to plus, in the body frame at the state.
    numeric.tail<3>() = at.dq_clone_body.conjugate() * minus.dq_clone_body *
                        (turn.angle() * turn.axis()) / (2 * kStep);
    EXPECT_LT((numeric - at.H.col(j)).norm(), 1e-5 * (1.0 + at.H.col(j).norm())) << "column " << j;
  }
}

// Consistency: 25 runs of 60 s on the turning path with the noise the model
// assumes (IMU white noise and bias random walks, unknown initial biases drawn
// from the initial covariance, GPS position and velocity and the barometer
// with their sigmas), fixed seeds. The average over the runs of the position's
// and the attitude's NEES at 10, 30 and 60 s lies inside the two-sided 95 %
// chi-square bounds for 3 x 25 degrees of freedom, divided by 25, for all but
// one of the six (seeds 1000-1024: the attitude's at 10 s is 1.87 against
// 2.12; seeds 2000 and 3000 put all six inside), and none is off by a factor 2.
TEST(ErrorStateFilter, NeesInsideTheChiSquareBounds) {
  const TurningPath path;
  const ProcessNoise noise;
  constexpr int kRuns = 25;
  const double low = chiSquareQuantile(0.025, 3 * kRuns) / kRuns;
  const double high = chiSquareQuantile(0.975, 3 * kRuns) / kRuns;
  const std::vector<int> checks = {10 * 200, 30 * 200, 60 * 200};
  std::vector<double> nees_p(checks.size(), 0.0), nees_theta(checks.size(), 0.0);
  for (int run = 0; run < kRuns; ++run) {
    std::mt19937 rng(1000 + run);
    std::normal_distribution<double> normal(0.0, 1.0);
    auto gaussian3 = [&](double sigma) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) v[k] = sigma * normal(rng);
      return v;
    };
    Covariance P = Covariance::Zero();
    P.block<3, 3>(idx::kP, idx::kP).diagonal().setConstant(1.0);
    P.block<3, 3>(idx::kV, idx::kV).diagonal().setConstant(0.01);
    P.block<3, 3>(idx::kTheta, idx::kTheta).diagonal().setConstant(1e-4);
    P.block<3, 3>(idx::kGyroBias, idx::kGyroBias).diagonal().setConstant(1e-6);
    P.block<3, 3>(idx::kAccelBias, idx::kAccelBias).diagonal().setConstant(1e-3);
    P(idx::kBaroBias, idx::kBaroBias) = 1.0;
    P(idx::kGround, idx::kGround) = 1.0;
    P(idx::kLogScale, idx::kLogScale) = 1e-6;
    // The truth's start is the estimate plus an error drawn from P.
    NavState start;
    start.p_ned_m = path.p(0.0) + gaussian3(1.0);
    start.v_ned_mps = path.v0 + gaussian3(0.1);
    const Eigen::Vector3d theta0 = gaussian3(0.01);
    start.q_world_body =
        path.q(0.0) *
        Eigen::Quaterniond(Eigen::AngleAxisd(theta0.norm(), theta0.normalized())).conjugate();
    Eigen::Vector3d gyro_bias = gaussian3(1e-3), accel_bias = gaussian3(std::sqrt(1e-3));
    double baro_bias = normal(rng);
    ErrorStateFilter filter(noise, start, P);
    std::size_t next_check = 0;
    for (int i = 0; i <= checks.back(); ++i) {
      const double t = i * kDt;
      ImuSample imu = path.imu(i);
      imu.angular_velocity_rps +=
          gyro_bias + gaussian3(noise.gyro_noise_density_rps_rthz / std::sqrt(kDt));
      imu.linear_acceleration_mps2 +=
          accel_bias + gaussian3(noise.accel_noise_density_mps2_rthz / std::sqrt(kDt));
      gyro_bias += gaussian3(noise.gyro_bias_random_walk_rps_rts * std::sqrt(kDt));
      accel_bias += gaussian3(noise.accel_bias_random_walk_mps2_rts * std::sqrt(kDt));
      baro_bias += normal(rng) * noise.baro_bias_random_walk_m_rts * std::sqrt(kDt);
      filter.propagate(imu);
      if (i % 40 == 0 && i > 0) {
        filter.updatePosition(path.p(t) + gaussian3(1.5), Eigen::Matrix3d::Identity() * 2.25);
        filter.updateVelocity(path.v0 + path.a * t + gaussian3(0.1),
                              Eigen::Matrix3d::Identity() * 0.01);
      }
      if (i % 4 == 0 && i > 0) {
        filter.updateBaro(500.0 - path.p(t).z() + baro_bias + 0.3 * normal(rng), 500.0, 0.3);
      }
      if (next_check < checks.size() && i == checks[next_check]) {
        const Covariance& Pk = filter.covariance();
        const Eigen::Vector3d dp = path.p(t) - filter.state().p_ned_m;
        const Eigen::AngleAxisd turn(filter.state().q_world_body.conjugate() * path.q(t));
        const Eigen::Vector3d dtheta = turn.angle() * turn.axis();
        nees_p[next_check] += dp.dot(Pk.block<3, 3>(idx::kP, idx::kP).ldlt().solve(dp)) / kRuns;
        nees_theta[next_check] +=
            dtheta.dot(Pk.block<3, 3>(idx::kTheta, idx::kTheta).ldlt().solve(dtheta)) / kRuns;
        ++next_check;
      }
    }
  }
  int outside = 0;
  for (std::size_t k = 0; k < checks.size(); ++k) {
    for (const double nees : {nees_p[k], nees_theta[k]}) {
      if (nees < low || nees > high) ++outside;
      EXPECT_GT(nees, 0.5 * low) << "at " << checks[k] * kDt << " s";
      EXPECT_LT(nees, 2.0 * high) << "at " << checks[k] * kDt << " s";
    }
  }
  // Six statistics, each inside its 95 % band by chance 95 % of the time: one
  // outside happens (26 %), two would be 3 %.
  EXPECT_LE(outside, 1);
}

// The barometer alone cannot tell the height from its own bias: after one
// reading the height moves by the share of the innovation its variance holds,
// worked out by hand for one scalar update (gain = P_h / (P_h + P_b + r^2)).
TEST(ErrorStateFilter, BaroUpdateSplitsTheInnovationByVariance) {
  NavState start;
  start.p_ned_m = Eigen::Vector3d(0.0, 0.0, -100.0);  // 100 m above the origin
  Covariance P = Covariance::Identity() * 1e-6;
  P(idx::kP + 2, idx::kP + 2) = 4.0;  // 2 m
  P(idx::kBaroBias, idx::kBaroBias) = 1.0;
  ErrorStateFilter filter(ProcessNoise{}, start, P);
  const UpdateResult r = filter.updateBaro(500.0 + 103.0, 500.0, 1.0);  // reads 3 m higher
  ASSERT_TRUE(r.accepted);
  // Innovation 3 m, S = 4 + 1 + 1 = 6: NIS 1.5; the height takes 4/6 of it, the bias 1/6.
  EXPECT_NEAR(r.nis, 9.0 / 6.0, 1e-6);
  EXPECT_NEAR(-filter.state().p_ned_m.z(), 100.0 + 3.0 * 4.0 / 6.0, 1e-6);
  EXPECT_NEAR(filter.state().baro_bias_m, 3.0 * 1.0 / 6.0, 1e-6);
}

// A rangefinder looking 30 deg off the vertical (the body rolled) reads
// height / cos(30 deg); with the ground as a state and the height known, the
// ground moves to where the range puts it.
TEST(ErrorStateFilter, RangeAlongATiltedBeamFindsTheGround) {
  NavState start;
  start.p_ned_m = Eigen::Vector3d(0.0, 0.0, -80.0);
  start.q_world_body =
      Eigen::Quaterniond(Eigen::AngleAxisd(30.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()));
  start.ground_down_m = 0.0;
  Covariance P = Covariance::Identity() * 1e-8;
  P(idx::kGround, idx::kGround) = 100.0;
  ErrorStateFilter filter(ProcessNoise{}, start, P);
  // The ground is really 20 m higher (down -20): height 60 m, range 60 / cos 30.
  const double range = 60.0 / std::cos(30.0 * M_PI / 180.0);
  const UpdateResult r = filter.updateRange(range, Eigen::Vector3d::UnitZ(), 0.01);
  ASSERT_TRUE(r.accepted);
  EXPECT_NEAR(filter.state().ground_down_m, -20.0, 0.01);
  EXPECT_NEAR(filter.state().p_ned_m.z(), -80.0, 1e-3);
  // With a map of the ground instead, the range moves the height.
  Covariance P2 = Covariance::Identity() * 1e-8;
  P2(idx::kP + 2, idx::kP + 2) = 900.0;  // 30 m: the 40 m jump is inside the gate
  ErrorStateFilter mapped(ProcessNoise{}, start, P2);
  ASSERT_TRUE(
      mapped.updateRange(range, Eigen::Vector3d::UnitZ(), 0.01, [](double, double) { return 20.0; })
          .accepted);
  // Ground at down +20: the vehicle is 60 m above it, at down -40.
  EXPECT_NEAR(mapped.state().p_ned_m.z(), -40.0, 0.01);
}

// The magnetometer's heading: a filter that believes it heads 10 deg more to
// the east than it does turns back to the truth about the world's vertical with
// one reading of a tight sigma. A hard-iron offset (3 uT along the body's down
// axis, the body pitched 5 deg) turns the heading it gives, by about
// atan(3 sin 5 deg / 20.7 uT horizontal) = 0.7 deg, but leaves roll and pitch
// alone.
TEST(ErrorStateFilter, HeadingFromTheMagnetometerTurnsOnlyTheYaw) {
  const Eigen::Quaterniond truth(Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(5.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()));
  // Declination -4.6 deg, inclination 66.5 deg, 52 uT (sim::MagnetometerParams).
  const double dec = -4.6 * M_PI / 180.0, inc = 66.5 * M_PI / 180.0;
  const Eigen::Vector3d field_world =
      52.0 *
      Eigen::Vector3d(std::cos(inc) * std::cos(dec), std::cos(inc) * std::sin(dec), std::sin(inc));
  for (const double hard_iron_ut : {0.0, 3.0}) {
    NavState start;
    start.q_world_body =
        Eigen::Quaterniond(Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ())) *
        truth;
    Covariance P = Covariance::Identity() * 1e-6;
    // The heading unknown (18 deg about the world's vertical), the tilt known:
    // a tilt's uncertainty would widen the heading's noise (considered, not
    // corrected). In the body frame: R^T diag R.
    const Eigen::Matrix3d R = start.q_world_body.toRotationMatrix();
    P.block<3, 3>(idx::kTheta, idx::kTheta) =
        R.transpose() * Eigen::Vector3d(1e-12, 1e-12, 0.1).asDiagonal() * R;
    ErrorStateFilter filter(ProcessNoise{}, start, P);
    const Eigen::Vector3d field_body =
        truth.inverse() * field_world + Eigen::Vector3d(0, 0, hard_iron_ut);
    ASSERT_TRUE(filter.updateHeading(field_body, field_world, 1e-4).accepted);
    const Eigen::Vector3d ypr_est =
        filter.state().q_world_body.toRotationMatrix().eulerAngles(2, 1, 0);
    const Eigen::Vector3d ypr_true = truth.toRotationMatrix().eulerAngles(2, 1, 0);
    const double yaw_error_deg = (ypr_est[0] - ypr_true[0]) * 180.0 / M_PI;
    if (hard_iron_ut == 0.0) {
      EXPECT_NEAR(yaw_error_deg, 0.0, 0.01);
    } else {
      EXPECT_GT(std::abs(yaw_error_deg), 0.3);
      EXPECT_LT(std::abs(yaw_error_deg), 1.0);
    }
    EXPECT_NEAR(ypr_est[1], ypr_true[1], 1e-6) << "pitch, hard iron " << hard_iron_ut;
    EXPECT_NEAR(ypr_est[2], ypr_true[2], 1e-6) << "roll, hard iron " << hard_iron_ut;
  }
}

// The airframe's own field (hard iron, body frame) learnt from the heading: a
// level vehicle at rest turning about its vertical at 0.2 rad/s, its attitude
// known from exact gyros, reads the Earth's field plus (1.5, -1.0, 0.8) uT.
// After two turns the horizontal offset is known to 0.1 uT (the vertical one
// does not turn the heading of a level vehicle: it stays at its prior), and the
// heading error of the last reading is under 0.05 deg. A sign error in the
// offset's Jacobian drives it away instead.
TEST(ErrorStateFilter, MagnetometerLearnsTheHardIronWhileTurning) {
  const double dec = -4.6 * M_PI / 180.0, inc = 66.5 * M_PI / 180.0;
  const Eigen::Vector3d field_world =
      52.0 *
      Eigen::Vector3d(std::cos(inc) * std::cos(dec), std::cos(inc) * std::sin(dec), std::sin(inc));
  const Eigen::Vector3d hard_iron(1.5, -1.0, 0.8);
  const double yaw_rate = 0.2;
  ProcessNoise noise;
  noise.gyro_noise_density_rps_rthz = 1e-7;
  noise.gyro_bias_random_walk_rps_rts = 0.0;
  Covariance P = Covariance::Identity() * 1e-6;
  P.block<3, 3>(idx::kTheta, idx::kTheta) = Eigen::Matrix3d::Identity() * 1e-10;
  P.block<3, 3>(idx::kGyroBias, idx::kGyroBias) = Eigen::Matrix3d::Identity() * 1e-14;
  P.block<3, 3>(idx::kMagBias, idx::kMagBias) = Eigen::Matrix3d::Identity() * 4.0;  // 2 uT
  ErrorStateFilter filter(noise, NavState{}, P);
  ImuSample imu;
  imu.angular_velocity_rps = Eigen::Vector3d(0.0, 0.0, yaw_rate);
  imu.linear_acceleration_mps2 = Eigen::Vector3d(0.0, 0.0, -kGravity_mps2);
  double last_heading_error_deg = 0.0;
  const int samples = static_cast<int>(std::lround(4.0 * M_PI / yaw_rate * 200.0));
  for (int i = 0; i <= samples; ++i) {
    imu.utime = i * kDtUs;
    filter.propagate(imu);
    if (i % 4 != 0) continue;  // the magnetometer at 50 Hz
    const Eigen::Quaterniond truth(Eigen::AngleAxisd(yaw_rate * i * kDt, Eigen::Vector3d::UnitZ()));
    filter.updateHeading(truth.inverse() * field_world + hard_iron, field_world,
                         0.5 * M_PI / 180.0);
    const Eigen::Vector3d error = 2.0 * (filter.state().q_world_body.conjugate() * truth).vec();
    last_heading_error_deg = error.z() * 180.0 / M_PI;
  }
  EXPECT_NEAR(filter.state().mag_bias_ut.x(), hard_iron.x(), 0.1);
  EXPECT_NEAR(filter.state().mag_bias_ut.y(), hard_iron.y(), 0.1);
  EXPECT_NEAR(filter.state().mag_bias_ut.z(), 0.0, 1e-6);
  EXPECT_LT(std::abs(last_heading_error_deg), 0.05);
}

// A reading far outside what the covariance allows is refused and changes nothing.
TEST(ErrorStateFilter, GateRefusesAnOutlier) {
  NavState start;
  Covariance P = Covariance::Identity() * 0.01;
  ErrorStateFilter filter(ProcessNoise{}, start, P);
  const UpdateResult r =
      filter.updatePosition(Eigen::Vector3d(50.0, 0.0, 0.0), Eigen::Matrix3d::Identity());
  EXPECT_FALSE(r.accepted);
  EXPECT_GT(r.nis, 1000.0);
  EXPECT_EQ(filter.state().p_ned_m, Eigen::Vector3d::Zero());
  EXPECT_EQ(filter.covariance(), P);
}

// Chi-square quantiles against the tables: 3.841 (95 %, 1), 7.815 (95 %, 3),
// 11.345 (99 %, 3), 0.352 (5 %, 3).
TEST(ErrorStateFilter, ChiSquareQuantiles) {
  EXPECT_NEAR(chiSquareQuantile(0.95, 1), 3.841, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.95, 3), 7.815, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.99, 3), 11.345, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.05, 3), 0.352, 1e-3);
}

// Bad input: a covariance that is not symmetric, a negative noise figure, an
// IMU sample going back in time.
TEST(ErrorStateFilter, BadInput) {
  Covariance asymmetric = Covariance::Identity();
  asymmetric(0, 1) = 1.0;
  EXPECT_THROW(ErrorStateFilter(ProcessNoise{}, NavState{}, asymmetric), std::invalid_argument);
  ProcessNoise negative;
  negative.gyro_noise_density_rps_rthz = -1.0;
  EXPECT_THROW(ErrorStateFilter(negative, NavState{}, Covariance::Identity()),
               std::invalid_argument);
  ErrorStateFilter filter(ProcessNoise{}, NavState{}, Covariance::Identity());
  ImuSample imu;
  imu.utime = 100;
  filter.propagate(imu);
  imu.utime = 50;
  EXPECT_THROW(filter.propagate(imu), std::invalid_argument);
}

}  // namespace
}  // namespace nadir::nav
