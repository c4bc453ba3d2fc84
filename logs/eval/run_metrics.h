#pragma once
// The evaluation of one run: the truth (pose_t on POSE_TRUTH) against each VO
// source (vo_estimate_t on POSE_PPA, POSE_VO_FEATURE, POSE_VO_DIRECT), its
// metrics.json and its results table. docs/evaluation.md is the reference for
// every definition here and for the metrics.json schema.
//
// How an estimate is compared: each TRACKING estimate at its own stamp t is
// compared with the truth interpolated at t (position linear, attitude SLERP).
// Estimates outside the truth's time span, or over a hole in it longer than
// EvalOptions::truth_max_gap_s, are skipped. INITIALIZING and LOST estimates
// only count for the rate and for robustness. These "evaluated" pairs feed:
//
//  position_rmse_m     thesis eq. 13 (metrics.h thesisPositionRmse): RMSE of the
//                      norm of the position error, raw (never aligned), m.
//  rotation_rmse_deg   thesis eq. 14 (thesisRotationRmseDeg): RMSE over the roll,
//                      pitch and yaw differences, raw, deg.
//  tracked_pct         thesis robustness, "the percentage of the total trajectory
//                      time that the VO algorithm is able to successfully track":
//                      100 * tracked time / truth duration (first to last truth
//                      pose). A TRACKING estimate at t_k counts as tracked on
//                      [t_k, t_k+1) (t_k+1: the source's next estimate, whatever
//                      its status), for at most tracked_hold_periods nominal periods
//                      (the median interval between the source's estimates); the
//                      last estimate holds one nominal period. Clipped to the truth
//                      span. Time before the first estimate (initialisation) is not
//                      tracked.
//  track_length_m      the estimate's path length, summed within tracking segments
//                      (a segment ends at an INITIALIZING or LOST estimate, so a
//                      re-initialisation jump is not counted as travel).
//  truth_track_length_m  the truth's path length over the same segments, sampled at
//                      the same stamps (so the sampling rate does not bias the
//                      comparison).
//  track_length_diff_pct seed 000: 100 * (track_length_m - truth_track_length_m) /
//                      truth_track_length_m (negative: the estimate is too short).
//  mean_abs_error_m    seed 000: mean of |p_est - p_truth|, raw, m.
//  end_point_m         seed 000: |p_est - p_truth| at the last evaluated estimate, m;
//  end_point_pct       and as a percentage of truth_track_length_m.
//  rate_hz             (number of estimates - 1) / (last stamp - first stamp), all
//                      statuses: how fast the source produced output.
//  ape, rpe            evo's APE and RPE (metrics.h) after the EvalOptions::align
//                      alignment of the evaluated estimates; RPE pairs are chosen
//                      within each tracking segment, never across a re-initialisation.
//
// A metric that does not exist (a source that never tracked, a zero-length
// truth path) is NaN here and null in metrics.json.

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "logs/eval/metrics.h"
#include "logs/eval/trajectory.h"

namespace nadir::eval {

// One estimate of a pose source as it arrived. status is vo_estimate_t's:
// 0 INITIALIZING, 1 TRACKING, 2 LOST; the pose is meaningful only when TRACKING.
struct SourceEstimate {
  static constexpr int kInitializing = 0;
  static constexpr int kTracking = 1;
  static constexpr int kLost = 2;
  double t_s = 0;
  int status = kInitializing;
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
};

struct SourceMetrics {
  bool initialised = false;             // ever TRACKING
  std::size_t estimates = 0;            // all statuses
  std::size_t estimates_tracking = 0;   // TRACKING
  std::size_t estimates_evaluated = 0;  // TRACKING and compared with the truth
  std::size_t tracking_segments = 0;    // runs of consecutive TRACKING estimates
  double first_tracking_s = kNaN;       // first TRACKING stamp minus the truth start, s
  double rate_hz = kNaN;
  double tracked_pct = 0;
  double position_rmse_m = kNaN;
  double rotation_rmse_deg = kNaN;
  double track_length_m = kNaN;
  double truth_track_length_m = kNaN;
  double track_length_diff_pct = kNaN;
  double mean_abs_error_m = kNaN;
  double end_point_m = kNaN;
  double end_point_pct = kNaN;
  std::string alignment = "none";  // EvalOptions::align used for ape and rpe
  double alignment_scale = kNaN;   // the Sim(3) scale (1 for none and se3)
  Statistics ape_translation_m;
  Statistics ape_rotation_deg;
  double rpe_delta = 1.0;
  std::string rpe_delta_unit = "frames";
  Statistics rpe_translation_m;
  Statistics rpe_rotation_deg;
  std::string note;  // why something is missing; empty if nothing is
};

struct RunMetrics {
  double truth_track_length_m = 0;
  double truth_duration_s = 0;
  std::size_t truth_poses = 0;
  std::map<std::string, SourceMetrics> sources;
};

// One source against the truth (time-sorted, >= 2 poses, else EvalError).
// Estimates may come in any order; they are sorted by stamp (stable).
SourceMetrics evaluateSource(const PoseTrajectory& truth,
                             const std::vector<SourceEstimate>& estimates,
                             const EvalOptions& options);
RunMetrics evaluate(const PoseTrajectory& truth,
                    const std::map<std::string, std::vector<SourceEstimate>>& sources,
                    const EvalOptions& options);

// Channel -> source name: POSE_PPA ppa, POSE_VO_FEATURE vo_feature, POSE_VO_DIRECT vo_direct.
std::map<std::string, std::string> defaultSourceChannels();

struct LogTrajectories {
  PoseTrajectory truth;  // sorted by stamp, one pose per stamp
  std::map<std::string, std::vector<SourceEstimate>> sources;  // sources seen in the log
  std::string damage;  // the reader's damage report and undecodable messages; empty if clean
};
// The channel of the truth, pose_t.
inline constexpr char kTruthChannel[] = "POSE_TRUTH";

// Gathers the truth (pose_t on kTruthChannel) and the estimates (vo_estimate_t on
// source_channels) one message at a time, stamped with the messages' utime: from
// the events of a log (readRunLog) or from a live bus (nadir-viewer --live).
class TrajectoryCollector {
 public:
  explicit TrajectoryCollector(
      std::map<std::string, std::string> source_channels = defaultSourceChannels());
  // Takes one message; false if its channel is neither the truth's nor a source's.
  // A message on those channels that does not decode, or holds a non-finite
  // position or a quaternion that is not a rotation, is counted and left out.
  bool add(const std::string& channel, const void* data, std::size_t size);
  std::size_t truthPoses() const { return truth_.size(); }
  // What was gathered so far, sorted as LogTrajectories says; `damage` counts the
  // messages left out, per channel.
  LogTrajectories trajectories() const;

 private:
  std::string undecodableReport() const;

  std::map<std::string, std::string> source_channels_;
  PoseTrajectory truth_;
  std::map<std::string, std::vector<SourceEstimate>> sources_;
  std::map<std::string, std::size_t> undecodable_;  // channel -> count
};

// Reads pose_t on POSE_TRUTH and vo_estimate_t on source_channels, stamped with
// the messages' utime. A damaged log gives what could be read, and says what was
// wrong in `damage`. Throws EvalError naming the log if it cannot be opened, is
// empty, or holds no decodable truth.
LogTrajectories readRunLog(
    const std::string& log_path,
    const std::map<std::string, std::string>& source_channels = defaultSourceChannels());

// The TRACKING estimates of a source as a trajectory (for writing <source>.tum).
PoseTrajectory trackingTrajectory(const std::vector<SourceEstimate>& estimates);

// A run's log evaluated, with what was written for it.
struct RunEvaluation {
  LogTrajectories recorded;
  RunMetrics metrics;
  std::string metrics_path;
  // truth.tum, then <source>.tum for every source that ever tracked.
  std::vector<std::string> tum_paths;
  // The TRACKING estimates of those sources, by name.
  std::map<std::string, PoseTrajectory> tracked;
};

// Reads log_path, evaluates every source and writes metrics.json, truth.tum
// and <source>.tum into out_dir (nadir run and nadir eval RUN_DIR).
RunEvaluation evaluateRunLog(const std::string& log_path, const std::string& out_dir,
                             const EvalOptions& options);

// metrics.json (schema in docs/evaluation.md); NaN is written as null and read
// back as NaN. Both throw EvalError naming the file.
void writeMetricsJson(const std::string& path, const RunMetrics& metrics,
                      const EvalOptions& options);
RunMetrics readMetricsJson(const std::string& path, EvalOptions* options = nullptr);

// A plain-text table, one row per source, "-" where a metric does not exist.
std::string formatResultsTable(const RunMetrics& metrics);

}  // namespace nadir::eval
