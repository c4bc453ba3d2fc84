#include "logs/eval/filter_metrics.h"

#include <cmath>
#include <optional>

#include <Eigen/Cholesky>

namespace nadir::eval {
namespace {

double nees(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance) {
  const Eigen::LLT<Eigen::Matrix3d> llt(covariance);
  if (llt.info() != Eigen::Success) return kNaN;
  const Eigen::Vector3d whitened = llt.matrixL().solve(error);
  return whitened.squaredNorm();
}

Eigen::Vector3d rotationLog(const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd angle_axis(q.normalized());
  return angle_axis.angle() * angle_axis.axis();
}

bool inBand(double value) { return value >= kNees3Low && value <= kNees3High; }

}  // namespace

double positionNees(const logs::FilterState& state, const Eigen::Vector3d& p_true_ned_m) {
  return nees(p_true_ned_m - state.p_ned_m, state.position_covariance_m2);
}

double attitudeNees(const logs::FilterState& state, const Eigen::Quaterniond& q_true_world_body) {
  return nees(rotationLog(state.q_world_body.conjugate() * q_true_world_body),
              state.attitude_covariance_rad2);
}

FilterMetrics evaluateFilter(const core::Trajectory& truth,
                             const std::vector<logs::FilterState>& states, double truth_max_gap_s) {
  FilterMetrics m;
  if (truth.empty() || states.empty()) return m;
  const double t0 = truth.front().t_s;
  const logs::FilterState& last = states.back();
  m.had_gps = std::isfinite(last.last_gps_t_s);
  const double denial_t = m.had_gps ? last.last_gps_t_s : states.front().t_s;
  m.denial_s = denial_t - t0;

  double position_sum = 0.0;
  double attitude_sum = 0.0;
  std::size_t position_count = 0;
  std::size_t attitude_count = 0;
  std::size_t position_in_band = 0;
  std::size_t attitude_in_band = 0;
  std::optional<double> error_60;
  std::optional<double> error_120;
  double error_last = kNaN;
  for (const logs::FilterState& state : states) {
    const std::optional<core::StampedPose> true_pose =
        core::interpolate(truth, state.t_s, truth_max_gap_s);
    if (!true_pose) continue;
    ++m.states_evaluated;
    const double error_m = (true_pose->p_ned_m - state.p_ned_m).norm();
    if (!error_60 && state.t_s >= denial_t + 60.0) error_60 = error_m;
    if (!error_120 && state.t_s >= denial_t + 120.0) error_120 = error_m;
    error_last = error_m;
    const double position = positionNees(state, true_pose->p_ned_m);
    if (std::isfinite(position)) {
      position_sum += position;
      ++position_count;
      position_in_band += inBand(position) ? 1 : 0;
    }
    const double attitude = attitudeNees(state, true_pose->q_world_body);
    if (std::isfinite(attitude)) {
      attitude_sum += attitude;
      ++attitude_count;
      attitude_in_band += inBand(attitude) ? 1 : 0;
    }
  }
  if (error_60) m.error_denial_60_m = *error_60;
  if (error_120) m.error_denial_120_m = *error_120;
  m.error_end_m = error_last;
  if (position_count > 0) {
    m.nees_position_mean = position_sum / static_cast<double>(position_count);
    m.nees_position_in_band_pct =
        100.0 * static_cast<double>(position_in_band) / static_cast<double>(position_count);
  }
  if (attitude_count > 0) {
    m.nees_attitude_mean = attitude_sum / static_cast<double>(attitude_count);
    m.nees_attitude_in_band_pct =
        100.0 * static_cast<double>(attitude_in_band) / static_cast<double>(attitude_count);
  }
  return m;
}

}  // namespace nadir::eval
