#include "nodes/nav/error_state_filter.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace nadir::nav {
namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// The rotation of a rotation vector (its exponential).
Eigen::Quaterniond expQuaternion(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (angle < 1e-12)
    return Eigen::Quaterniond(1.0, 0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z()).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle));
}

// The regularised lower incomplete gamma function P(a, x), by its series
// (x < a + 1) or its continued fraction (Numerical Recipes, 6.2).
double regularisedGammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 1000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return sum * std::exp(log_prefix);
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int n = 1; n < 1000; ++n) {
    const double an = -n * (n - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return 1.0 - std::exp(log_prefix) * h;
}

}  // namespace

double chiSquareQuantile(double p, int k) {
  if (!(p > 0.0 && p < 1.0) || k < 1)
    throw std::invalid_argument("chiSquareQuantile: needs 0 < p < 1 and k >= 1");
  // Bisection on the distribution function P(k/2, x/2).
  double lo = 0.0, hi = k + 10.0 * std::sqrt(2.0 * k) + 50.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (regularisedGammaP(0.5 * k, 0.5 * mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

ErrorStateFilter::ErrorStateFilter(const ProcessNoise& noise, const NavState& initial,
                                   const Covariance& initial_covariance)
    : noise_(noise), state_(initial), P_(initial_covariance) {
  for (const double figure :
       {noise.gyro_noise_density_rps_rthz, noise.accel_noise_density_mps2_rthz,
        noise.gyro_bias_random_walk_rps_rts, noise.accel_bias_random_walk_mps2_rts,
        noise.baro_bias_random_walk_m_rts, noise.ground_random_walk_m_rtm,
        noise.vo_log_scale_random_walk_rts}) {
    if (!(figure >= 0.0) || !std::isfinite(figure))
      throw std::invalid_argument("the filter's process noise must be finite and >= 0");
  }
  if (!P_.allFinite() ||
      (P_ - P_.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1.0 + P_.cwiseAbs().maxCoeff()))
    throw std::invalid_argument("the filter's initial covariance must be finite and symmetric");
  const Eigen::SelfAdjointEigenSolver<Covariance> eigen(P_);
  if (eigen.eigenvalues().minCoeff() < -1e-12 * (1.0 + eigen.eigenvalues().maxCoeff()))
    throw std::invalid_argument("the filter's initial covariance must be positive semi-definite");
  state_.q_world_body.normalize();
}

void ErrorStateFilter::setGateProbability(double probability) {
  if (!(probability > 0.0 && probability <= 1.0))
    throw std::invalid_argument("gate probability must be in (0, 1]");
  gate_probability_ = probability;
}

void propagateNominal(NavState& state, const ImuSample& imu, double dt) {
  const Eigen::Vector3d omega = imu.angular_velocity_rps - state.gyro_bias_rps;
  const Eigen::Vector3d f_body = imu.linear_acceleration_mps2 - state.accel_bias_mps2;
  const Eigen::Quaterniond q_mid = state.q_world_body * expQuaternion(0.5 * dt * omega);
  const Eigen::Vector3d a_world = q_mid * f_body + Eigen::Vector3d(0.0, 0.0, kGravity_mps2);
  state.p_ned_m += state.v_ned_mps * dt + 0.5 * a_world * dt * dt;
  state.v_ned_mps += a_world * dt;
  state.q_world_body = (state.q_world_body * expQuaternion(omega * dt)).normalized();
  state.utime = imu.utime;
}

void ErrorStateFilter::propagate(const ImuSample& imu) {
  if (!has_time_) {
    has_time_ = true;
    last_imu_ = imu;
    state_.utime = imu.utime;
    return;
  }
  if (imu.utime < last_imu_.utime)
    throw std::invalid_argument("IMU sample at " + std::to_string(imu.utime) +
                                " us is before the previous one at " +
                                std::to_string(last_imu_.utime) + " us");
  const double dt = 1e-6 * static_cast<double>(imu.utime - last_imu_.utime);
  last_imu_ = imu;
  state_.utime = imu.utime;
  if (dt <= 0.0) return;

  const Eigen::Vector3d omega = imu.angular_velocity_rps - state_.gyro_bias_rps;
  const Eigen::Vector3d f_body = imu.linear_acceleration_mps2 - state_.accel_bias_mps2;
  const Eigen::Matrix3d R = state_.q_world_body.toRotationMatrix();
  const double horizontal_speed = state_.v_ned_mps.head<2>().norm();
  propagateNominal(state_, imu, dt);

  // The error state's transition over dt (Sola 2017, eq. 269, local angle).
  Covariance F = Covariance::Identity();
  F.block<3, 3>(idx::kP, idx::kV) = Eigen::Matrix3d::Identity() * dt;
  F.block<3, 3>(idx::kV, idx::kTheta) = -R * skew(f_body) * dt;
  F.block<3, 3>(idx::kV, idx::kAccelBias) = -R * dt;
  F.block<3, 3>(idx::kTheta, idx::kTheta) =
      expQuaternion(omega * dt).toRotationMatrix().transpose();
  F.block<3, 3>(idx::kTheta, idx::kGyroBias) = -Eigen::Matrix3d::Identity() * dt;

  Eigen::Matrix<double, kStates, 1> q = Eigen::Matrix<double, kStates, 1>::Zero();
  const auto square = [](double x) { return x * x; };
  q.segment<3>(idx::kV).setConstant(square(noise_.accel_noise_density_mps2_rthz) * dt);
  q.segment<3>(idx::kTheta).setConstant(square(noise_.gyro_noise_density_rps_rthz) * dt);
  q.segment<3>(idx::kGyroBias).setConstant(square(noise_.gyro_bias_random_walk_rps_rts) * dt);
  q.segment<3>(idx::kAccelBias).setConstant(square(noise_.accel_bias_random_walk_mps2_rts) * dt);
  q(idx::kBaroBias) = square(noise_.baro_bias_random_walk_m_rts) * dt;
  q(idx::kGround) = square(noise_.ground_random_walk_m_rtm) * horizontal_speed * dt;
  q(idx::kLogScale) = square(noise_.vo_log_scale_random_walk_rts) * dt;
  q.segment<3>(idx::kMagBias).setConstant(square(noise_.mag_bias_random_walk_ut_rts) * dt);
  P_ = F * P_ * F.transpose();
  P_.diagonal() += q;
  P_ = 0.5 * (P_ + P_.transpose());
}

template <int M>
UpdateResult ErrorStateFilter::update(const Eigen::Matrix<double, M, 1>& residual,
                                      const Eigen::Matrix<double, M, kStates>& H,
                                      const Eigen::Matrix<double, M, M>& R) {
  UpdateResult result;
  result.dimension = M;
  const Eigen::Matrix<double, kStates, M> PHt = P_ * H.transpose();
  const Eigen::Matrix<double, M, M> S = H * PHt + R;
  // M is at most 6: a fixed-size inverse, after checking S is positive definite.
  if (!residual.allFinite() || !S.allFinite() || S.llt().info() != Eigen::Success) return result;
  const Eigen::Matrix<double, M, M> S_inv = S.llt().solve(Eigen::Matrix<double, M, M>::Identity());
  result.nis = residual.dot(S_inv * residual);
  if (gate_probability_ < 1.0 && result.nis > chiSquareQuantile(gate_probability_, M))
    return result;
  const Eigen::Matrix<double, kStates, M> K = PHt * S_inv;
  const Eigen::Matrix<double, kStates, 1> dx = K * residual;
  const Covariance I_KH = Covariance::Identity() - K * H;
  P_ = I_KH * P_ * I_KH.transpose() + K * R * K.transpose();
  inject(dx);
  result.accepted = true;
  return result;
}

void ErrorStateFilter::inject(const Eigen::Matrix<double, kStates, 1>& dx) {
  state_ = applyError(state_, dx);
  const Eigen::Vector3d dtheta = dx.segment<3>(idx::kTheta);
  const Eigen::Vector3d dtheta_clone = dx.segment<3>(idx::kCloneTheta);
  // The covariance of the error about the new nominal state (Sola 2017, 7.2).
  Covariance G = Covariance::Identity();
  G.block<3, 3>(idx::kTheta, idx::kTheta) -= skew(0.5 * dtheta);
  G.block<3, 3>(idx::kCloneTheta, idx::kCloneTheta) -= skew(0.5 * dtheta_clone);
  P_ = G * P_ * G.transpose();
  P_ = 0.5 * (P_ + P_.transpose());
}

UpdateResult ErrorStateFilter::updateBaro(double altitude_m, double origin_alt_m, double sigma_m) {
  Eigen::Matrix<double, 1, kStates> H = Eigen::Matrix<double, 1, kStates>::Zero();
  H(0, idx::kP + 2) = -1.0;
  H(0, idx::kBaroBias) = 1.0;
  const double predicted = origin_alt_m - state_.p_ned_m.z() + state_.baro_bias_m;
  return update<1>(Eigen::Matrix<double, 1, 1>(altitude_m - predicted), H,
                   Eigen::Matrix<double, 1, 1>(sigma_m * sigma_m));
}

UpdateResult ErrorStateFilter::updatePosition(const Eigen::Vector3d& p_ned_m,
                                              const Eigen::Matrix3d& covariance) {
  Eigen::Matrix<double, 3, kStates> H = Eigen::Matrix<double, 3, kStates>::Zero();
  H.block<3, 3>(0, idx::kP).setIdentity();
  return update<3>(p_ned_m - state_.p_ned_m, H, covariance);
}

UpdateResult ErrorStateFilter::updateVelocity(const Eigen::Vector3d& v_ned_mps,
                                              const Eigen::Matrix3d& covariance) {
  Eigen::Matrix<double, 3, kStates> H = Eigen::Matrix<double, 3, kStates>::Zero();
  H.block<3, 3>(0, idx::kV).setIdentity();
  return update<3>(v_ned_mps - state_.v_ned_mps, H, covariance);
}

UpdateResult ErrorStateFilter::updateRange(double range_m, const Eigen::Vector3d& direction_body,
                                           double sigma_m, const GroundDown& ground_down) {
  const Eigen::Matrix3d R = state_.q_world_body.toRotationMatrix();
  const Eigen::Vector3d d_body = direction_body.normalized();
  const Eigen::Vector3d d_world = R * d_body;
  const double c = d_world.z();  // the beam's downward share
  UpdateResult refused;
  refused.dimension = 1;
  if (c < 0.1) return refused;  // the beam nearly level: no flat-ground range
  const double ground =
      ground_down ? ground_down(state_.p_ned_m.x(), state_.p_ned_m.y()) : state_.ground_down_m;
  const double height = ground - state_.p_ned_m.z();
  Eigen::Matrix<double, 1, kStates> H = Eigen::Matrix<double, 1, kStates>::Zero();
  H(0, idx::kP + 2) = -1.0 / c;
  if (ground_down) {
    // The map's slope under the estimate, by central differences over 1 m.
    const double n = state_.p_ned_m.x(), e = state_.p_ned_m.y();
    H(0, idx::kP + 0) = 0.5 * (ground_down(n + 1.0, e) - ground_down(n - 1.0, e)) / c;
    H(0, idx::kP + 1) = 0.5 * (ground_down(n, e + 1.0) - ground_down(n, e - 1.0)) / c;
  } else {
    H(0, idx::kGround) = 1.0 / c;
  }
  // d_world moves with the attitude error: R Exp(dtheta) d = d_world - R [d]x dtheta.
  // The attitude is considered, not corrected: its uncertainty widens the
  // range's, but the range does not turn it. Off vertical, the ground the
  // beam meets is not the ground under the vehicle, and the flat ground's
  // error would be read as a tilt (at 300 m and 45 deg of bank, 3 m of relief
  // is 0.4 deg).
  const Eigen::RowVector3d dc_dtheta = -(R * skew(d_body)).row(2);
  const Eigen::RowVector3d dr_dtheta = -height / (c * c) * dc_dtheta;
  const double attitude_variance =
      dr_dtheta * P_.block<3, 3>(idx::kTheta, idx::kTheta) * dr_dtheta.transpose();
  return update<1>(Eigen::Matrix<double, 1, 1>(range_m - height / c), H,
                   Eigen::Matrix<double, 1, 1>(sigma_m * sigma_m + attitude_variance));
}

void ErrorStateFilter::cloneCurrentPose() {
  state_.clone_p_ned_m = state_.p_ned_m;
  state_.clone_q_world_body = state_.q_world_body;
  // The clone's error is the present pose's: its rows and columns copied.
  Covariance J = Covariance::Identity();
  J.block<3, 3>(idx::kCloneP, idx::kCloneP).setZero();
  J.block<3, 3>(idx::kCloneTheta, idx::kCloneTheta).setZero();
  J.block<3, 3>(idx::kCloneP, idx::kP).setIdentity();
  J.block<3, 3>(idx::kCloneTheta, idx::kTheta).setIdentity();
  P_ = J * P_ * J.transpose();
  P_ = 0.5 * (P_ + P_.transpose());
}

NavState applyError(const NavState& state, const Eigen::Matrix<double, kStates, 1>& dx) {
  NavState out = state;
  out.p_ned_m += dx.segment<3>(idx::kP);
  out.v_ned_mps += dx.segment<3>(idx::kV);
  out.q_world_body = (state.q_world_body * expQuaternion(dx.segment<3>(idx::kTheta))).normalized();
  out.gyro_bias_rps += dx.segment<3>(idx::kGyroBias);
  out.accel_bias_mps2 += dx.segment<3>(idx::kAccelBias);
  out.baro_bias_m += dx(idx::kBaroBias);
  out.ground_down_m += dx(idx::kGround);
  out.clone_p_ned_m += dx.segment<3>(idx::kCloneP);
  out.clone_q_world_body =
      (state.clone_q_world_body * expQuaternion(dx.segment<3>(idx::kCloneTheta))).normalized();
  out.vo_log_scale += dx(idx::kLogScale);
  out.mag_bias_ut += dx.segment<3>(idx::kMagBias);
  return out;
}

RelativePosePrediction predictRelativePose(const NavState& state) {
  const Eigen::Matrix3d R_clone = state.clone_q_world_body.toRotationMatrix();
  const Eigen::Matrix3d R = state.q_world_body.toRotationMatrix();
  const double scale = std::exp(state.vo_log_scale);
  const Eigen::Vector3d d_clone = R_clone.transpose() * (state.p_ned_m - state.clone_p_ned_m);
  const Eigen::Matrix3d dR = R_clone.transpose() * R;
  RelativePosePrediction out;
  out.dp_clone_body = scale * d_clone;
  out.dq_clone_body = Eigen::Quaterniond(dR).normalized();
  out.H.block<3, 3>(0, idx::kP) = scale * R_clone.transpose();
  out.H.block<3, 3>(0, idx::kCloneP) = -scale * R_clone.transpose();
  // R_clone_true^T = Exp(-dtheta_c) R_clone^T: the clone's angle turns d_clone.
  out.H.block<3, 3>(0, idx::kCloneTheta) = scale * skew(d_clone);
  out.H.block<3, 1>(0, idx::kLogScale) = scale * d_clone;
  // dR_true = dR Exp(dtheta - dR^T dtheta_c), to first order.
  out.H.block<3, 3>(3, idx::kTheta).setIdentity();
  out.H.block<3, 3>(3, idx::kCloneTheta) = -dR.transpose();
  return out;
}

UpdateResult ErrorStateFilter::updateRelativePose(const Eigen::Vector3d& dp_clone_body,
                                                  const Eigen::Quaterniond& dq_clone_body,
                                                  const Eigen::Matrix<double, 6, 6>& covariance) {
  const RelativePosePrediction predicted = predictRelativePose(state_);
  Eigen::Matrix<double, 6, 1> residual;
  residual.head<3>() = dp_clone_body - predicted.dp_clone_body;
  // The rotation's residual as a small angle in the present body frame.
  const Eigen::AngleAxisd rotation_residual(predicted.dq_clone_body.conjugate() *
                                            dq_clone_body.normalized());
  residual.tail<3>() = rotation_residual.angle() * rotation_residual.axis();
  return update<6>(residual, predicted.H, covariance);
}

UpdateResult ErrorStateFilter::updateHeading(const Eigen::Vector3d& field_body_ut,
                                             const Eigen::Vector3d& field_world_ut,
                                             double sigma_rad) {
  UpdateResult refused;
  refused.dimension = 1;
  const Eigen::Matrix3d R = state_.q_world_body.toRotationMatrix();
  const Eigen::Vector3d measured_world = R * (field_body_ut - state_.mag_bias_ut);
  if (measured_world.head<2>().norm() < 0.1 * measured_world.norm() ||
      field_world_ut.head<2>().norm() < 0.1 * field_world_ut.norm())
    return refused;
  // A heading error e (true = Rz(e) R) turns the measured field by -e in the world.
  const double expected = std::atan2(field_world_ut.y(), field_world_ut.x());
  const double seen = std::atan2(measured_world.y(), measured_world.x());
  double residual = expected - seen;
  residual = std::atan2(std::sin(residual), std::cos(residual));
  Eigen::Matrix<double, 1, kStates> H = Eigen::Matrix<double, 1, kStates>::Zero();
  // A body-frame angle error turns the heading by its world z component.
  H.block<1, 3>(0, idx::kTheta) = R.row(2);
  // An offset error db moves the field seen in the world by -R db. The
  // heading's derivative is taken at the field expected, not the one measured:
  // at the measured one it would follow the noise, and the noise's share of it
  // would drive the offset steadily along the field (8 uT in 20 s at rest).
  const double expected_horizontal2 = field_world_ut.head<2>().squaredNorm();
  const Eigen::RowVector3d d_seen_d_world(-field_world_ut.y() / expected_horizontal2,
                                          field_world_ut.x() / expected_horizontal2, 0.0);
  H.block<1, 3>(0, idx::kMagBias) = -d_seen_d_world * R;
  // A tilt error turns the field's steep vertical part into the horizontal
  // plane (at 66.5 deg of inclination, 0.1 deg of tilt is 0.23 deg of
  // heading): considered, it widens the heading's noise without tilting the
  // estimate. The world rotation phi = R dtheta moves the field by phi x F.
  const Eigen::RowVector3d d_seen_d_phi = d_seen_d_world * (-skew(field_world_ut));
  const Eigen::RowVector3d tilt_part(d_seen_d_phi.x(), d_seen_d_phi.y(), 0.0);
  const Eigen::RowVector3d d_seen_d_tilt = tilt_part * R;
  const double tilt_variance =
      d_seen_d_tilt * P_.block<3, 3>(idx::kTheta, idx::kTheta) * d_seen_d_tilt.transpose();
  return update<1>(Eigen::Matrix<double, 1, 1>(residual), H,
                   Eigen::Matrix<double, 1, 1>(sigma_rad * sigma_rad + tilt_variance));
}

}  // namespace nadir::nav
