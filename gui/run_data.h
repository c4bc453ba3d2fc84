#pragma once
// The plot viewer's model of a run directory (as `nadir run` writes it), without Qt:
// the truth and every estimate source as plain time series, and the run's metrics.
//
// A run is a folder holding run.lcmlog, truth.tum or metrics.json, or an LCM log
// file. The poses come from the log when there is one (every estimate, with its
// status), else from truth.tum and <source>.tum (TRACKING estimates only, as TUM
// holds them). The metrics come from the run's metrics.json when it is there, else
// from eval::evaluate.

#include <cstddef>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "eval/run_metrics.h"

namespace nadir::gui {

// A run that cannot be found or read. The message names the file and says what
// is wrong, in one line.
class RunDataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One pose series, sample by sample. Positions are world NED, m; angles Z-Y-X
// (core/frames.h), deg. A sample without a pose (an estimate that is not TRACKING)
// is NaN in every pose field.
struct PoseSeries {
  std::vector<double> t_s;
  std::vector<double> x_m;  // north
  std::vector<double> y_m;  // east
  std::vector<double> z_m;  // down
  std::vector<double> roll_deg;
  std::vector<double> pitch_deg;
  std::vector<double> yaw_deg;
  std::size_t size() const { return t_s.size(); }
};

struct SourceSeries {
  // Yaw is taken on the truth's side of +-180 deg where the truth has a pose (so it
  // may lie outside [-180, 180]): a heading near south is drawn beside the truth's.
  PoseSeries pose;
  std::vector<int> status;  // eval::SourceEstimate::kInitializing, kTracking, kLost
  // |p_est - p_truth| with the truth interpolated at the estimate's stamp, m; NaN
  // where the estimate is not TRACKING or the truth has no pose there (outside its
  // span, or over a hole longer than EvalOptions::truth_max_gap_s).
  std::vector<double> position_error_m;
};

struct RunData {
  std::string dir;
  std::string poses_from;     // the file the poses were read from (run.lcmlog or truth.tum)
  std::string metrics_from;   // metrics.json, or empty if the metrics were computed here
  std::string damage;         // run.lcmlog's damage report; empty if clean
  double t0_s = 0;            // the truth's first stamp: plots show time since then
  eval::EvalOptions options;  // metrics.json's options, or the defaults used to compute
  PoseSeries truth;
  std::map<std::string, SourceSeries> sources;
  eval::RunMetrics metrics;
};

// True if dir holds run.lcmlog, truth.tum or metrics.json.
bool isRunDir(const std::string& dir);

// Every run in the tree under root, sorted by path: run directories (root itself
// included; their subfolders are not searched) and LCM logs (*.lcmlog) outside run
// directories. A root that is a log gives itself. Throws RunDataError if root is
// neither a folder nor a log.
std::vector<std::string> findRuns(const std::string& root);

// Loads one run: a run directory, or an LCM log file (its metrics.json is read
// only if it is a run directory's run.lcmlog; else the metrics are computed).
// RunData::dir is the path given. Throws RunDataError naming the file for a
// missing, damaged or foreign file (a file that is not an LCM log, a log with no
// truth, a TUM file that does not parse, a metrics.json of another schema) or a
// run with no poses.
RunData loadRun(const std::string& path);

// A run of poses already read (a live bus): the series of loadRun, named `name`
// (RunData::dir), with the metrics left empty. Throws RunDataError without truth.
RunData runFromPoses(const std::string& name, const eval::LogTrajectories& recorded,
                     const eval::EvalOptions& options = {});

// The error table, one row per source, as CSV with a header line:
//   source,position_rmse_m,rotation_rmse_deg,tracked_pct,ape_rmse_m,rpe_rmse_m
// Numbers in the shortest text that reads back to the same double (the values of
// metrics.json); a metric that does not exist is an empty field.
std::string resultsCsv(const eval::RunMetrics& metrics);

}  // namespace nadir::gui
