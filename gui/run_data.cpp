#include "gui/run_data.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <system_error>
#include <utility>

#include "core/frames.h"
#include "eval/trajectory.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr char kLogName[] = "run.lcmlog";
constexpr char kLogExtension[] = ".lcmlog";
constexpr char kTruthName[] = "truth.tum";
constexpr char kMetricsName[] = "metrics.json";

bool isFile(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

void appendPose(PoseSeries& series, double t_s, const Eigen::Vector3d& p_m,
                const Eigen::Quaterniond& q) {
  const core::RollPitchYaw rpy = core::rpyFromQuaternion(q);
  series.t_s.push_back(t_s);
  series.x_m.push_back(p_m.x());
  series.y_m.push_back(p_m.y());
  series.z_m.push_back(p_m.z());
  series.roll_deg.push_back(rpy.roll_rad * kDegPerRad);
  series.pitch_deg.push_back(rpy.pitch_rad * kDegPerRad);
  series.yaw_deg.push_back(rpy.yaw_rad * kDegPerRad);
}

void appendEmpty(PoseSeries& series, double t_s) {
  series.t_s.push_back(t_s);
  for (std::vector<double>* v : {&series.x_m, &series.y_m, &series.z_m, &series.roll_deg,
                                 &series.pitch_deg, &series.yaw_deg}) {
    v->push_back(kNaN);
  }
}

SourceSeries sourceSeries(const eval::PoseTrajectory& truth,
                          const std::vector<eval::SourceEstimate>& estimates,
                          double truth_max_gap_s) {
  SourceSeries series;
  for (const eval::SourceEstimate& e : estimates) {
    series.status.push_back(e.status);
    if (e.status != eval::SourceEstimate::kTracking) {
      appendEmpty(series.pose, e.t_s);
      series.position_error_m.push_back(kNaN);
      continue;
    }
    appendPose(series.pose, e.t_s, e.p_m, e.q);
    const std::optional<eval::StampedPose> reference =
        eval::interpolate(truth, e.t_s, truth_max_gap_s);
    series.position_error_m.push_back(reference ? (e.p_m - reference->p_m).norm() : kNaN);
    if (reference) {
      // The yaw on the truth's side of +-180 deg, so that a heading near south is
      // drawn beside the truth's rather than a full turn away.
      const double truth_yaw_deg = core::rpyFromQuaternion(reference->q).yaw_rad * kDegPerRad;
      double& yaw_deg = series.pose.yaw_deg.back();
      yaw_deg += 360.0 * std::round((truth_yaw_deg - yaw_deg) / 360.0);
    }
  }
  return series;
}

std::vector<eval::SourceEstimate> trackingEstimates(const eval::PoseTrajectory& trajectory) {
  std::vector<eval::SourceEstimate> estimates;
  estimates.reserve(trajectory.size());
  for (const eval::StampedPose& pose : trajectory) {
    estimates.push_back({pose.t_s, eval::SourceEstimate::kTracking, pose.p_m, pose.q});
  }
  return estimates;
}

eval::PoseTrajectory readTumFile(const fs::path& path) {
  eval::PoseTrajectory trajectory = eval::readTum(path.string());
  if (trajectory.empty()) throw RunDataError(path.string() + ": no pose in the file");
  return trajectory;
}

void appendNumber(std::string& out, double value) {
  if (!std::isfinite(value)) return;
  char text[32];
  const std::to_chars_result result = std::to_chars(text, text + sizeof text, value);
  out.append(text, result.ptr);
}

}  // namespace

bool isRunDir(const std::string& dir) {
  const fs::path path(dir);
  return isFile(path / kLogName) || isFile(path / kTruthName) || isFile(path / kMetricsName);
}

std::vector<std::string> findRuns(const std::string& root) {
  std::error_code error;
  if (fs::is_regular_file(root, error) && fs::path(root).extension() == kLogExtension) {
    return {root};
  }
  if (!fs::is_directory(root, error)) {
    throw RunDataError(root + ": neither a folder nor an LCM log (*.lcmlog)");
  }
  if (isRunDir(root)) return {root};
  std::vector<std::string> runs;
  fs::recursive_directory_iterator it(root, fs::directory_options::skip_permission_denied, error);
  if (error) throw RunDataError(root + ": cannot list the directory: " + error.message());
  for (; it != fs::recursive_directory_iterator(); it.increment(error)) {
    if (error) throw RunDataError(root + ": cannot list the directory: " + error.message());
    if (it->is_directory(error)) {
      if (!isRunDir(it->path().string())) continue;
      runs.push_back(it->path().string());
      it.disable_recursion_pending();  // a run's subfolders are not runs of their own
    } else if (it->path().extension() == kLogExtension && it->is_regular_file(error)) {
      // A log on its own (not a run folder's run.lcmlog: its folder is listed instead).
      runs.push_back(it->path().string());
    }
  }
  std::sort(runs.begin(), runs.end());
  return runs;
}

RunData loadRun(const std::string& path) {
  const fs::path given(path);
  std::error_code error;
  const bool is_log_file = fs::is_regular_file(given, error);
  if (!fs::exists(given, error)) throw RunDataError(path + ": no such folder or file");
  if (!is_log_file && !fs::is_directory(given, error)) {
    throw RunDataError(path + ": neither a run folder nor an LCM log");
  }
  // A log file's metrics.json is its run's only if it is that run's run.lcmlog.
  const fs::path root = is_log_file ? given.parent_path() : given;
  const bool own_metrics = !is_log_file || given.filename() == kLogName;
  try {
    eval::EvalOptions options;
    eval::RunMetrics metrics;
    std::string metrics_from;
    const fs::path metrics_path = root / kMetricsName;
    if (own_metrics && isFile(metrics_path)) {
      metrics = eval::readMetricsJson(metrics_path.string(), &options);
      metrics_from = metrics_path.string();
    }

    eval::LogTrajectories recorded;
    std::string poses_from;
    const fs::path log_path = is_log_file ? given : root / kLogName;
    const fs::path truth_path = root / kTruthName;
    if (isFile(log_path)) {
      recorded = eval::readRunLog(log_path.string());
      poses_from = log_path.string();
    } else if (isFile(truth_path)) {
      recorded.truth = readTumFile(truth_path);
      for (const fs::directory_entry& entry : fs::directory_iterator(root)) {
        const fs::path& file = entry.path();
        if (file.extension() != ".tum" || file.filename() == kTruthName) continue;
        if (!entry.is_regular_file()) continue;
        recorded.sources[file.stem().string()] = trackingEstimates(readTumFile(file));
      }
      poses_from = truth_path.string();
    } else {
      throw RunDataError(path + ": neither " + kLogName + " nor " + kTruthName +
                         ": no poses to plot");
    }

    if (metrics_from.empty()) {
      try {
        metrics = eval::evaluate(recorded.truth, recorded.sources, options);
      } catch (const eval::EvalError& e) {
        throw RunDataError(poses_from + ": cannot evaluate: " + e.what());
      }
    }
    RunData run = runFromPoses(path, recorded, options);
    run.poses_from = std::move(poses_from);
    run.metrics_from = std::move(metrics_from);
    run.metrics = std::move(metrics);
    return run;
  } catch (const eval::EvalError& e) {
    throw RunDataError(e.what());
  } catch (const fs::filesystem_error& e) {
    throw RunDataError(path + ": " + e.what());
  }
}

RunData runFromPoses(const std::string& name, const eval::LogTrajectories& recorded,
                     const eval::EvalOptions& options) {
  if (recorded.truth.empty()) throw RunDataError(name + ": no truth pose");
  RunData run;
  run.dir = name;
  run.damage = recorded.damage;
  run.options = options;
  run.t0_s = recorded.truth.front().t_s;
  for (const eval::StampedPose& pose : recorded.truth) {
    appendPose(run.truth, pose.t_s, pose.p_m, pose.q);
  }
  for (const auto& [source, estimates] : recorded.sources) {
    run.sources[source] = sourceSeries(recorded.truth, estimates, options.truth_max_gap_s);
  }
  return run;
}

std::string resultsCsv(const eval::RunMetrics& metrics) {
  std::string out = "source,position_rmse_m,rotation_rmse_deg,tracked_pct,ape_rmse_m,rpe_rmse_m\n";
  for (const auto& [name, m] : metrics.sources) {
    out += name;
    for (const double value : {m.position_rmse_m, m.rotation_rmse_deg, m.tracked_pct,
                               m.ape_translation_m.rmse, m.rpe_translation_m.rmse}) {
      out += ',';
      appendNumber(out, value);
    }
    out += '\n';
  }
  return out;
}

}  // namespace nadir::gui
