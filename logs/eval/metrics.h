#pragma once
// Trajectory error metrics:
//  - APE and RPE exactly as the evo tool defines them (evo/core/metrics.py),
//  - the thesis's position and rotation RMSEs (Kim 2019, section 3.3.6),
//  - McConville et al.'s (2020) mean absolute error (track length: trajectory.h's trackLength),
//  - evo's statistics over an error vector.
// Poses are T_world_body (trajectory.h). "ref" is the truth, "est" the estimate;
// the two trajectories passed to a metric are associated pose by pose (same size).

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/axes.h"
#include "logs/eval/alignment.h"
#include "logs/eval/trajectory.h"

namespace nadir::eval {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// evo's statistics of an error vector: rmse = sqrt(mean(e^2)); median = the
// middle value, or the mean of the two middle values for an even count (numpy);
// std = population standard deviation (numpy's default, ddof = 0). With no
// values every field is NaN ("does not exist") and count is 0.
struct Statistics {
  double rmse = kNaN;
  double mean = kNaN;
  double median = kNaN;
  double std = kNaN;
  double min = kNaN;
  double max = kNaN;
  std::size_t count = 0;
};
Statistics computeStatistics(std::vector<double> values);

// Options of an evaluation (the flags of `nadir eval`).
struct EvalOptions {
  std::string align = "none";  // none | se3 | sim3: alignment of the estimate before APE and RPE
  double t_max_diff_s = 0.01;  // TUM association: largest stamp difference of a pair, s
  double rpe_delta = 1.0;      // RPE pair spacing, in rpe_delta_unit
  std::string rpe_delta_unit = "frames";  // frames | meters
  // Run metrics: a TRACKING estimate counts as tracked until the next estimate,
  // for at most this many nominal periods (the median estimate interval).
  double tracked_hold_periods = 3.0;
  // Run metrics: an estimate is not compared if the truth samples around it are
  // further apart than this (a hole in a damaged log), s.
  double truth_max_gap_s = 0.5;
  // Run metrics: path lengths (McConville et al.'s (2020) track length) sum the distances
  // between samples at least this far apart in time (and each segment's last),
  // s; 0 uses every estimate. Sampled finely, a pixel's jitter in a 200 Hz
  // estimate adds to its path what the flight did not fly.
  double track_length_interval_s = 1.0;
  // The axes of the TUM files a run's evaluation writes (the metrics are the
  // same in either): nadir's NED/FRD or REP-103's ENU/FLU (core/axes.h).
  core::Axes tum_axes = core::Axes::kNed;
};
// Throws EvalError naming the bad option (unknown align or unit, delta <= 0,
// a fractional delta in frames, t_max_diff_s < 0, ...).
void validateOptions(const EvalOptions& options);

// Angle of a rotation, degrees in [0, 180].
double rotationAngleDeg(const Eigen::Quaterniond& q);

// APE translation part (evo PoseRelation.translation_part): |p_est,i - p_ref,i|, m.
std::vector<double> apeTranslationErrors(const core::Trajectory& ref, const core::Trajectory& est);
// APE rotation angle (evo PoseRelation.rotation_angle_deg): the angle of the
// rotation of E_i = P_est,i^-1 P_ref,i (evo's ape_base), degrees.
std::vector<double> apeRotationErrorsDeg(const core::Trajectory& ref, const core::Trajectory& est);

enum class DeltaUnit { kFrames, kMeters };
DeltaUnit parseDeltaUnit(const std::string& name);  // "frames" | "meters"; else EvalError

using IndexPairs = std::vector<std::pair<std::size_t, std::size_t>>;
// evo's consecutive RPE pairs (filters.filter_pairs_by_index / _by_path, all_pairs off):
//  frames: ids 0, d, 2d, ... (d = delta), pairs (id_k, id_k+1);
//  meters: walking along `poses`, the path length is accumulated from the last
//    chosen id and an id is chosen where it reaches delta (>=), then restarts;
//    pairs are consecutive chosen ids. As in evo, the first chosen id is the
//    first pose at path distance >= delta from pose 0 (pose 0 itself is not one).
// Pairs are chosen on the estimate (evo's default, pairs_from_reference off).
IndexPairs rpePairs(const core::Trajectory& poses, double delta, DeltaUnit unit);

// RPE for pairs (i, j) (evo's rpe_base):
//   E = (P_ref,i^-1 P_ref,j)^-1 (P_est,i^-1 P_est,j)
// translation_m = |translation of E|, rotation_deg = angle of E's rotation.
struct RelativeErrors {
  std::vector<double> translation_m;
  std::vector<double> rotation_deg;
};
RelativeErrors rpeErrors(const core::Trajectory& ref, const core::Trajectory& est,
                         const IndexPairs& pairs);

// Thesis (Kim 2019) eq. 13: sqrt( sum_i [(x'_i-x_i)^2 + (y'_i-y_i)^2 + (z'_i-z_i)^2] / n ),
// the sum of the three squared axis errors over n poses: the RMSE of the norm
// of the position error vector (not the per-axis RMSE, which is sqrt(3) smaller). m.
double thesisPositionRmse(const core::Trajectory& ref, const core::Trajectory& est);
// Thesis eq. 14: the same over the Z-Y-X Euler angle differences (roll, pitch,
// yaw from core::rpyFromQuaternion), each wrapped to (-180, 180] deg. Like any
// Euler difference it is ill-conditioned near pitch +-90 deg; APE rotation is the
// frame-independent alternative. Degrees.
double thesisRotationRmseDeg(const core::Trajectory& ref, const core::Trajectory& est);

// McConville et al.'s (2020) mean absolute error: mean over poses of |p_est,i - p_ref,i|, m.
double meanAbsoluteError(const core::Trajectory& ref, const core::Trajectory& est);

// The `--ref/--est` evaluation: associate (t_max_diff_s), align, APE and RPE.
struct TrajectoryEvaluation {
  std::size_t ref_poses = 0;
  std::size_t est_poses = 0;
  std::size_t matched_poses = 0;
  AlignMode align = AlignMode::kNone;
  Alignment alignment;
  Statistics ape_translation_m;
  Statistics ape_rotation_deg;
  Statistics rpe_translation_m;
  Statistics rpe_rotation_deg;
};
// Throws EvalError if fewer than 2 poses associate (saying how many and the
// t_max_diff used), if the alignment is degenerate, or if the RPE delta gives no pair.
TrajectoryEvaluation evaluateTrajectories(const core::Trajectory& ref, const core::Trajectory& est,
                                          const EvalOptions& options);

// evo-like text: each metric's statistics, then the APE translation RMSE in
// metres alone as the last line (what scripts read).
std::string formatTrajectoryReport(const TrajectoryEvaluation& evaluation,
                                   const EvalOptions& options);

}  // namespace nadir::eval
