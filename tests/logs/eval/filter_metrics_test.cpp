// A filter's figures against values worked out by hand: the NEES of known
// errors and covariances, the denial from the last GPS fix fused, and the
// errors 60 s and 120 s after it.

#include "logs/eval/filter_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace nadir::eval {
namespace {

// Position error (1, 2, 2) m against variances (1, 4, 4) m^2: 1 + 1 + 1 = 3.
// Attitude error 0.02 rad about the body's x against 1e-4 rad^2: 4.
TEST(FilterMetrics, NeesOfKnownErrors) {
  logs::FilterState state;
  state.p_ned_m = Eigen::Vector3d(10, 20, -100);
  state.position_covariance_m2 = Eigen::Vector3d(1, 4, 4).asDiagonal();
  state.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  state.attitude_covariance_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
  EXPECT_NEAR(positionNees(state, Eigen::Vector3d(11, 22, -98)), 3.0, 1e-12);
  // R_true = R_est Exp(0.02 x): the error is in the body frame, whatever the heading.
  const Eigen::Quaterniond q_true =
      state.q_world_body * Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(attitudeNees(state, q_true), 4.0, 1e-9);
  // A correlation: errors (1, 1) with covariance [[1, 0.5], [0.5, 1]] give
  // e^T P^-1 e = 2 / 1.5 = 4/3 (the third axis exact).
  state.position_covariance_m2 << 1, 0.5, 0, 0.5, 1, 0, 0, 0, 1;
  EXPECT_NEAR(positionNees(state, Eigen::Vector3d(11, 21, -100)), 4.0 / 3.0, 1e-12);
  state.position_covariance_m2 = Eigen::Matrix3d::Zero();
  EXPECT_TRUE(std::isnan(positionNees(state, Eigen::Vector3d(11, 21, -100))));
}

// A straight truth at 10 m/s from t = 100 s; the filter's states every second
// run east of it by 0.1 m per second after the last fix at t = 110 s, with a
// position variance of 0.01 m^2 per axis: the denial is at 10 s, the errors at
// +60 s and +120 s are 6 m and 12 m, the end's (t = 300 s) 19 m.
TEST(FilterMetrics, ErrorsAfterTheDenial) {
  core::Trajectory truth;
  for (int k = 0; k <= 2000; ++k) {
    const double t = 100.0 + 0.1 * k;
    truth.push_back(
        {t, Eigen::Vector3d(10.0 * (t - 100.0), 0, -50), Eigen::Quaterniond::Identity()});
  }
  std::vector<logs::FilterState> states;
  for (int k = 0; k <= 200; ++k) {
    const double t = 100.0 + k;
    logs::FilterState state;
    state.t_s = t;
    const double drift = std::max(0.0, t - 110.0) * 0.1;
    state.p_ned_m = Eigen::Vector3d(10.0 * (t - 100.0), drift, -50);
    state.position_covariance_m2 = Eigen::Matrix3d::Identity() * 0.01;
    state.attitude_covariance_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
    state.last_gps_t_s = t <= 110.0 ? t : 110.0;
    states.push_back(state);
  }
  const FilterMetrics m = evaluateFilter(truth, states, 0.5);
  EXPECT_TRUE(m.had_gps);
  EXPECT_EQ(m.states_evaluated, 201u);
  EXPECT_NEAR(m.denial_s, 10.0, 1e-9);
  EXPECT_NEAR(m.error_denial_60_m, 6.0, 1e-9);
  EXPECT_NEAR(m.error_denial_120_m, 12.0, 1e-9);
  EXPECT_NEAR(m.error_end_m, 19.0, 1e-9);
  // The NEES is the squared drift over 0.01: 0 up to t = 110 s, then (0.1 k)^2 / 0.01 = k^2.
  double sum = 0.0;
  int inside = 0;
  for (int k = 0; k <= 190; ++k) {
    sum += k * k;
    inside += (k * k >= kNees3Low && k * k <= kNees3High) ? 1 : 0;  // k = 1, 2, 3
  }
  EXPECT_NEAR(m.nees_position_mean, sum / 201.0, 1e-6);
  EXPECT_NEAR(m.nees_position_in_band_pct, 100.0 * inside / 201.0, 1e-9);
  EXPECT_NEAR(m.nees_attitude_mean, 0.0, 1e-12);
  EXPECT_NEAR(m.nees_attitude_in_band_pct, 0.0, 1e-12);

  // Without any fix the denial is the filter's start, and a flight shorter than
  // 120 s after it has no +120 s error.
  for (logs::FilterState& state : states) state.last_gps_t_s = std::nan("");
  states.resize(150);  // to t = 249 s
  const FilterMetrics without = evaluateFilter(truth, states, 0.5);
  EXPECT_FALSE(without.had_gps);
  EXPECT_NEAR(without.denial_s, 0.0, 1e-9);
  EXPECT_NEAR(without.error_denial_60_m, 5.0, 1e-9);
  EXPECT_NEAR(without.error_denial_120_m, 11.0, 1e-9);
  EXPECT_NEAR(without.error_end_m, 13.9, 1e-9);
}

}  // namespace
}  // namespace nadir::eval
