#pragma once
// The plot viewer's model of a run directory (as `nadir run` writes it), without Qt:
// the truth and every estimate source as plain time series, and the run's metrics.
//
// A run is a folder holding run.lcmlog, metrics.json or TUM files (*.tum), or an
// LCM log file. The poses come from the log when there is one (every estimate, with
// its status), else from the *.tum files (TRACKING estimates only, as TUM holds
// them). Any of a run's trajectories can be the truth the others are compared with
// (compareWithTruth); by default it is the recorded one. The metrics come from the
// run's metrics.json when it is there and the truth is the recorded one, else from
// eval::evaluate.

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/trajectory.h"
#include "logs/eval/run_metrics.h"
#include "logs/run_log.h"

namespace nadir::gui {

// A run that cannot be found or read. The message names the file and says what
// is wrong, in one line.
class RunDataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One estimate source of a run, against the run's truth.
struct SourceSeries {
  // Every estimate in stamp order; its pose means something only when TRACKING.
  std::vector<logs::SourceEstimate> estimates;
  // |p_est - p_truth| at each estimate with the truth interpolated at its stamp, m;
  // NaN where the estimate is not TRACKING or the truth has no pose there (outside
  // its span, or over a hole longer than EvalOptions::truth_max_gap_s).
  std::vector<double> position_error_m;
  // The truth's yaw at each estimate, rad; NaN where position_error_m is.
  std::vector<double> truth_yaw_rad;
  // The TRACKING stretches (a stretch ends at any other status), as drawn in 3D.
  std::vector<core::Trajectory> tracked;
  // A navigation filter's own bound on that error, from its states
  // (nav_state_t): 3 sqrt(trace of the position covariance) at their stamps
  // (absolute, s), m. Empty for a VO node.
  std::vector<double> sigma3_t_s;
  std::vector<double> sigma3_m;
  std::size_t size() const { return estimates.size(); }
};

// A trajectory's samples as a figure plots them: stamps (absolute, s), north,
// east, down (m) and Z-Y-X angles (core/frames.h, deg), NaN where a sample has
// no pose. A source's yaw is taken on its truth's side of +-180 deg (so it may
// lie outside [-180, 180]): a heading near south is drawn beside the truth's.
struct FigureColumns {
  std::vector<double> t_s, x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg;
  std::size_t size() const { return t_s.size(); }
};
FigureColumns figureColumns(const core::Trajectory& trajectory);
FigureColumns figureColumns(const SourceSeries& source);

// The name of the truth as recorded: the pose_t of a log, truth.tum in a folder.
inline constexpr char kRecordedTruthName[] = "truth";

// Every trajectory of a run as it was read, before one is chosen as the truth.
struct RunTrajectories {
  // By name: the recorded truth and each estimate source, in stamp order, with
  // the estimates' statuses (a truth and a TUM file's poses are all TRACKING).
  std::map<std::string, std::vector<logs::SourceEstimate>> by_name;
  // A navigation filter's states with their covariance, by source name (logs only).
  std::map<std::string, std::vector<logs::FilterState>> filters;
  // The one that is the truth unless another is chosen: kRecordedTruthName when
  // the run recorded one, else a guess (see recorded_truth_note).
  std::string recorded_truth;
  std::string recorded_truth_note;  // why recorded_truth was guessed; empty if it was not
  eval::EvalOptions options;        // metrics.json's options, or the defaults
  std::optional<eval::RunMetrics> recorded_metrics;  // metrics.json's, against recorded_truth
  std::string metrics_file;                          // metrics.json's path, if read
};

struct RunData {
  std::string dir;
  std::string poses_from;    // the file the poses were read from (run.lcmlog or a *.tum)
  std::string metrics_from;  // metrics.json, or empty if the metrics were computed here
  std::string damage;        // run.lcmlog's damage report; empty if clean
  std::string truth_name = kRecordedTruthName;  // the trajectory the others are compared with
  std::string truth_note;                       // why truth_name is the truth, when it was guessed
  double t0_s = 0;            // the truth's first stamp: plots show time since then
  eval::EvalOptions options;  // metrics.json's options, or the defaults used to compute
  core::Trajectory truth;
  std::map<std::string, SourceSeries> sources;  // every trajectory but the truth
  eval::RunMetrics metrics;
  // What was read, shared by the runs compareWithTruth makes of this one.
  std::shared_ptr<const RunTrajectories> trajectories;
};

// Every trajectory of the run, the truth's included: the recorded truth first,
// then the others by name.
std::vector<std::string> trajectoryNames(const RunData& run);

// The run compared with another of its trajectories as the truth (any name of
// trajectoryNames): the time axis starts at its first pose, the others' errors
// are taken against it, the recorded truth becomes one of the sources, and the
// metrics are computed (metrics.json's only hold against the recorded truth),
// unless compute_metrics is false (the live plots' series without the cost).
// Throws RunDataError naming the run for a name it does not have, or a
// trajectory without a tracked pose.
RunData compareWithTruth(const RunData& run, const std::string& truth_name,
                         bool compute_metrics = true);

// Sets the run's metrics against its truth: metrics.json's when the truth is the
// recorded one and the run has them, else computed from its trajectories with its
// options. Throws RunDataError naming the run if they cannot be (a truth of one
// pose), the run then left without metrics.
void computeMetrics(RunData& run);

// True if dir holds run.lcmlog, metrics.json or a TUM file (*.tum).
bool isRunDir(const std::string& dir);

// Every run in the tree under root, sorted by path: run directories (root itself
// included; their subfolders are not searched) and LCM logs (*.lcmlog) outside run
// directories. A root that is a log gives itself. Throws RunDataError if root is
// neither a folder nor a log.
std::vector<std::string> findRuns(const std::string& root);

// Loads one run: a run directory, or an LCM log file (its metrics.json is read
// only if it is a run directory's run.lcmlog; else the metrics are computed).
// RunData::dir is the path given. The truth is truth_name, or if that is empty the
// recorded one: the pose_t in a log; in a folder of TUM files truth.tum, else the
// file whose name says groundtruth, gt or truth, else the first by name (and
// RunData::truth_note says it was guessed). Throws RunDataError naming the file
// for a missing, damaged or foreign file (a file that is not an LCM log, a log
// with no truth, a TUM file that does not parse, a metrics.json of another
// schema), a run with no poses, or a truth_name it does not have.
RunData loadRun(const std::string& path, const std::string& truth_name = {});

// A run of poses already read (a live bus): the series of loadRun, named `name`
// (RunData::dir), with the metrics left empty. Throws RunDataError without truth.
RunData runFromPoses(const std::string& name, const logs::LogTrajectories& recorded,
                     const eval::EvalOptions& options = {});

// The error table, one row per source, as CSV with a header line:
//   source,position_rmse_m,rotation_rmse_deg,tracked_pct,ape_rmse_m,rpe_rmse_m
// Numbers in the shortest text that reads back to the same double (the values of
// metrics.json); a metric that does not exist is an empty field.
std::string resultsCsv(const eval::RunMetrics& metrics);

// The data behind a figure (position, attitude, error or top_view) as CSV, at
// full rate: a header line, then a row per sample with a pose of each trajectory
// plotted (the truth first, then the sources by name; those in `hidden` left
// out), time in s since the truth's first pose:
//   position  trajectory,time_s,north_m,east_m,down_m
//   attitude  trajectory,time_s,roll_deg,pitch_deg,yaw_deg
//   error     trajectory,time_s,position_error_m   (sources only)
//   top_view  trajectory,time_s,north_m,east_m
// Throws RunDataError for another figure name.
std::string figureDataCsv(const RunData& run, const std::string& figure,
                          const std::set<std::string>& hidden = {});

}  // namespace nadir::gui
