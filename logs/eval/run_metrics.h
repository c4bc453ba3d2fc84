#pragma once
// The evaluation of one run: the truth against each VO source, its
// metrics.json and its results table. Every metric's definition, and the
// metrics.json schema, are in docs/evaluation.md. A metric that does not exist
// (a source that never tracked, a zero-length truth path) is NaN here and null
// in metrics.json.

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "logs/course_metrics.h"
#include "logs/eval/filter_metrics.h"
#include "logs/eval/metrics.h"
#include "logs/eval/trajectory.h"
#include "logs/run_log.h"

namespace nadir::eval {

using logs::SourceEstimate;

struct SourceMetrics {
  bool initialised = false;             // ever TRACKING
  std::size_t estimates = 0;            // all statuses
  std::size_t estimates_tracking = 0;   // TRACKING
  std::size_t estimates_evaluated = 0;  // TRACKING and compared with the truth
  std::size_t tracking_segments = 0;    // runs of consecutive TRACKING estimates
  // The most resets (num_resets) the source reported; none without estimates
  // or from a metrics.json written before it was recorded.
  std::optional<std::size_t> resets;
  double first_tracking_s = kNaN;  // first TRACKING stamp minus the truth start, s
  double rate_hz = kNaN;
  // The longest time between two estimates, s (a node that died or stalled);
  // NaN with fewer than two, or from a metrics.json written before it was.
  double longest_gap_s = kNaN;
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
  // A navigation filter's own figures (its nav_state_t); none for a VO node.
  std::optional<FilterMetrics> filter;
};

// The vehicle's guidance on a navigation source: how far the truth was from
// where the guidance believed the vehicle was, each time it took a waypoint as
// reached (docs/closed_loop.md).
struct GuidancePassage {
  int index = 0;
  double t_s = kNaN;  // from the truth's start
  std::string source;
  double miss_m = kNaN;           // |true - believed|
  double from_waypoint_m = kNaN;  // |true - waypoint| (a fixed-wing turns before it)
};
struct GuidanceMetrics {
  std::string source;  // the source the guidance flew on last
  int waypoints = 0;
  int waypoints_on_source = 0;  // reached while flying on a source other than the truth
  double max_miss_m = kNaN;     // over those
  double mean_miss_m = kNaN;
  double end_miss_m = kNaN;  // at the last waypoint
  std::vector<GuidancePassage> passages;
};

// Throws nothing: no waypoints, no metrics (waypoints 0).
GuidanceMetrics evaluateGuidance(const std::vector<logs::WaypointPassage>& waypoints,
                                 double truth_start_s);

struct RunMetrics {
  double truth_track_length_m = 0;
  double truth_duration_s = 0;
  std::size_t truth_poses = 0;
  std::map<std::string, SourceMetrics> sources;
  // A ground vehicle's course (gates, slalom boards), when the run had one.
  std::optional<logs::CourseMetrics> course;
  // The guidance's waypoints, when the run reported any.
  std::optional<GuidanceMetrics> guidance;
};

// One source against the truth (time-sorted, >= 2 poses, else EvalError).
// Estimates may come in any order; they are sorted by stamp (stable).
SourceMetrics evaluateSource(const core::Trajectory& truth,
                             const std::vector<SourceEstimate>& estimates,
                             const EvalOptions& options);
// A filter's states (filters, by source name) add its FilterMetrics to the
// source of the same name.
RunMetrics evaluate(const core::Trajectory& truth,
                    const std::map<std::string, std::vector<SourceEstimate>>& sources,
                    const EvalOptions& options,
                    const std::map<std::string, std::vector<logs::FilterState>>& filters = {});

// A run's log evaluated, with what was written for it.
struct RunEvaluation {
  logs::LogTrajectories recorded;
  RunMetrics metrics;
  std::string metrics_path;
  // truth.tum, then <source>.tum for every source that ever tracked.
  std::vector<std::string> tum_paths;
  // The TRACKING estimates of those sources, by name.
  std::map<std::string, core::Trajectory> tracked;
};

// Reads log_path (truth_channel as logs::readRunLog takes it), evaluates every
// source and writes metrics.json, truth.tum and <source>.tum into out_dir.
// progress is told how far the reading of the log has come.
RunEvaluation evaluateRunLog(const std::string& log_path, const std::string& out_dir,
                             const EvalOptions& options, const std::string& truth_channel = {},
                             const core::ReadProgress& progress = {});

// metrics.json (schema in docs/evaluation.md); NaN is written as null and read
// back as NaN. Both throw EvalError naming the file.
void writeMetricsJson(const std::string& path, const RunMetrics& metrics,
                      const EvalOptions& options);
RunMetrics readMetricsJson(const std::string& path, EvalOptions* options = nullptr);

// A plain-text table, one row per source, "-" where a metric does not exist.
std::string formatResultsTable(const RunMetrics& metrics);

}  // namespace nadir::eval
