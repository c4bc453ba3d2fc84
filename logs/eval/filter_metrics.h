#pragma once
// A navigation filter evaluated as a filter, not only as a trajectory: its
// position error at fixed times after GPS was denied, and its consistency, the
// normalised estimation error squared (NEES) of position and of attitude
// against the chi-square band its own covariance implies. Definitions in
// docs/evaluation.md ("A filter's figures").

#include <cstddef>
#include <vector>

#include "core/trajectory.h"
#include "logs/eval/metrics.h"
#include "logs/run_log.h"

namespace nadir::eval {

// The two-sided 95 % band of a chi-square variable with 3 degrees of freedom:
// the NEES of a 3-vector from a consistent filter falls inside it 95 % of the time.
inline constexpr double kNees3Low = 0.2158;
inline constexpr double kNees3High = 9.3484;

struct FilterMetrics {
  std::size_t states_evaluated = 0;
  // Whether the filter ever fused a GPS fix, and when the last was, s after
  // the truth's start: the denial. Without any fix, the denial is the start.
  bool had_gps = false;
  double denial_s = kNaN;
  // Position error of the fused state at denial + 60 s, + 120 s and at the
  // end; NaN where the flight ended before.
  double error_denial_60_m = kNaN;
  double error_denial_120_m = kNaN;
  double error_end_m = kNaN;
  // The NEES averaged over the flight, and the share of states inside the band.
  double nees_position_mean = kNaN;
  double nees_attitude_mean = kNaN;
  double nees_position_in_band_pct = kNaN;
  double nees_attitude_in_band_pct = kNaN;
};

// The position NEES e^T P^-1 e of e = p_true - p_estimate, and the attitude's
// of dtheta = Log(R_estimate^T R_true) against the body-frame covariance. NaN
// for a covariance that is not positive definite.
double positionNees(const logs::FilterState& state, const Eigen::Vector3d& p_true_ned_m);
double attitudeNees(const logs::FilterState& state, const Eigen::Quaterniond& q_true_world_body);

// States compared with the truth interpolated at their stamps (none where the
// truth's samples are further apart than truth_max_gap_s).
FilterMetrics evaluateFilter(const core::Trajectory& truth,
                             const std::vector<logs::FilterState>& states, double truth_max_gap_s);

}  // namespace nadir::eval
