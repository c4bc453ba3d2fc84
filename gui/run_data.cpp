#include "gui/run_data.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <system_error>
#include <utility>

#include "core/csv.h"
#include "core/frames.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr char kLogName[] = "run.lcmlog";
constexpr char kLogExtension[] = ".lcmlog";
constexpr char kTruthName[] = "truth.tum";
constexpr char kTumExtension[] = ".tum";
constexpr char kMetricsName[] = "metrics.json";

bool isFile(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

void appendPose(FigureColumns& columns, const core::StampedPose& pose, double yaw_near_rad) {
  const core::RollPitchYaw rpy = core::rpyFromQuaternion(pose.q_world_body);
  columns.t_s.push_back(pose.t_s);
  columns.x_m.push_back(pose.p_ned_m.x());
  columns.y_m.push_back(pose.p_ned_m.y());
  columns.z_m.push_back(pose.p_ned_m.z());
  columns.roll_deg.push_back(rpy.roll_rad * kDegPerRad);
  columns.pitch_deg.push_back(rpy.pitch_rad * kDegPerRad);
  double yaw_deg = rpy.yaw_rad * kDegPerRad;
  if (std::isfinite(yaw_near_rad)) {
    yaw_deg += 360.0 * std::round((yaw_near_rad * kDegPerRad - yaw_deg) / 360.0);
  }
  columns.yaw_deg.push_back(yaw_deg);
}

void appendEmpty(FigureColumns& columns, double t_s) {
  columns.t_s.push_back(t_s);
  for (std::vector<double>* v : {&columns.x_m, &columns.y_m, &columns.z_m, &columns.roll_deg,
                                 &columns.pitch_deg, &columns.yaw_deg}) {
    v->push_back(kNaN);
  }
}

SourceSeries sourceSeries(const core::Trajectory& truth,
                          const std::vector<logs::SourceEstimate>& estimates,
                          double truth_max_gap_s) {
  SourceSeries series;
  series.estimates = estimates;
  bool in_stretch = false;
  for (const logs::SourceEstimate& e : estimates) {
    if (e.status != logs::SourceEstimate::kTracking) {
      series.position_error_m.push_back(kNaN);
      series.truth_yaw_rad.push_back(kNaN);
      in_stretch = false;
      continue;
    }
    if (!in_stretch) series.tracked.emplace_back();
    in_stretch = true;
    series.tracked.back().push_back(e);
    const std::optional<core::StampedPose> reference =
        core::interpolate(truth, e.t_s, truth_max_gap_s);
    series.position_error_m.push_back(reference ? (e.p_ned_m - reference->p_ned_m).norm() : kNaN);
    series.truth_yaw_rad.push_back(
        reference ? core::rpyFromQuaternion(reference->q_world_body).yaw_rad : kNaN);
  }
  return series;
}

std::vector<logs::SourceEstimate> trackingEstimates(const core::Trajectory& trajectory) {
  std::vector<logs::SourceEstimate> estimates;
  estimates.reserve(trajectory.size());
  for (const core::StampedPose& pose : trajectory) {
    estimates.push_back({pose, logs::SourceEstimate::kTracking});
  }
  return estimates;
}

// The TRACKING poses of a trajectory in stamp order, the first of equal stamps
// kept, the poses as they are (a recorded truth goes through unchanged).
core::Trajectory truthOf(std::vector<logs::SourceEstimate> estimates) {
  std::stable_sort(
      estimates.begin(), estimates.end(),
      [](const logs::SourceEstimate& a, const logs::SourceEstimate& b) { return a.t_s < b.t_s; });
  core::Trajectory truth;
  truth.reserve(estimates.size());
  for (const logs::SourceEstimate& e : estimates) {
    if (e.status != logs::SourceEstimate::kTracking) continue;
    if (!truth.empty() && e.t_s <= truth.back().t_s) continue;
    truth.push_back(e);
  }
  return truth;
}

std::vector<fs::path> tumFiles(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error)) {
    if (entry.path().extension() == kTumExtension && entry.is_regular_file(error)) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// The truth of a folder of TUM files without truth.tum: the first whose name says
// it is one (groundtruth, ground_truth, truth, gt), else the first by name.
std::string guessTruth(const std::vector<std::string>& names, std::string& note) {
  const auto says_truth = [](const std::string& name) {
    const std::string lower = lowercase(name);
    return lower.find("truth") != std::string::npos || lower == "gt" ||
           lower.rfind("gt_", 0) == 0 || (lower.size() > 3 && lower.ends_with("_gt"));
  };
  const auto found = std::find_if(names.begin(), names.end(), says_truth);
  const std::string chosen = found != names.end() ? *found : names.front();
  note = std::string("no ") + kTruthName + ": the truth is " + chosen + kTumExtension +
         (found != names.end() ? " (its name says so)" : " (the first by name)");
  return chosen;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

std::vector<std::string> namesOf(const RunTrajectories& read) {
  std::vector<std::string> names = {read.recorded_truth};
  for (const auto& [name, estimates] : read.by_name) {
    if (name != read.recorded_truth) names.push_back(name);
  }
  return names;
}

// The run's metrics against truth, its truth's poses as truthOf gives them.
void setMetrics(RunData& run, const core::Trajectory& truth) {
  const RunTrajectories& read = *run.trajectories;
  run.metrics = {};
  run.metrics_from.clear();
  if (run.truth_name == kRecordedTruthName && read.recorded_metrics) {
    run.metrics = *read.recorded_metrics;
    run.metrics_from = read.metrics_file;
    return;
  }
  std::map<std::string, std::vector<logs::SourceEstimate>> others;
  for (const auto& [name, estimates] : read.by_name) {
    if (name != run.truth_name) others.emplace(name, estimates);
  }
  try {
    run.metrics = eval::evaluate(truth, others, read.options, read.filters);
  } catch (const eval::EvalError& e) {
    throw RunDataError(run.poses_from + ": cannot evaluate against " + run.truth_name + ": " +
                       e.what());
  }
}

// Builds the series and metrics of a run against one of its trajectories.
RunData buildRun(const std::string& dir, std::shared_ptr<const RunTrajectories> read,
                 std::string poses_from, std::string damage, const std::string& truth_name,
                 bool compute_metrics) {
  const auto chosen = read->by_name.find(truth_name);
  if (chosen == read->by_name.end()) {
    throw RunDataError(dir + ": no trajectory " + truth_name + " (it has " +
                       joined(namesOf(*read)) + ")");
  }
  const core::Trajectory truth = truthOf(chosen->second);
  if (truth.empty()) throw RunDataError(dir + ": " + truth_name + " has no tracked pose");
  RunData run;
  run.dir = dir;
  run.poses_from = std::move(poses_from);
  run.damage = std::move(damage);
  run.truth_name = truth_name;
  if (truth_name == read->recorded_truth) run.truth_note = read->recorded_truth_note;
  run.options = read->options;
  run.t0_s = truth.front().t_s;
  run.truth = truth;
  for (const auto& [name, estimates] : read->by_name) {
    if (name == truth_name) continue;
    SourceSeries& series = run.sources[name];
    series = sourceSeries(truth, estimates, read->options.truth_max_gap_s);
    if (const auto filter = read->filters.find(name); filter != read->filters.end()) {
      for (const logs::FilterState& state : filter->second) {
        series.sigma3_t_s.push_back(state.t_s);
        series.sigma3_m.push_back(3.0 * std::sqrt(state.position_covariance_m2.trace()));
      }
    }
  }
  run.trajectories = std::move(read);
  if (compute_metrics) setMetrics(run, truth);
  return run;
}

std::shared_ptr<RunTrajectories> trajectoriesOf(const logs::LogTrajectories& recorded,
                                                const eval::EvalOptions& options) {
  auto read = std::make_shared<RunTrajectories>();
  read->by_name = recorded.sources;
  read->filters = recorded.filters;
  read->by_name[kRecordedTruthName] = trackingEstimates(recorded.truth);
  read->recorded_truth = kRecordedTruthName;
  read->options = options;
  return read;
}

void appendNumber(std::string& out, double value) {
  if (!std::isfinite(value)) return;
  char text[32];
  const std::to_chars_result result = std::to_chars(text, text + sizeof text, value);
  out.append(text, result.ptr);
}

}  // namespace

FigureColumns figureColumns(const core::Trajectory& trajectory) {
  FigureColumns columns;
  for (const core::StampedPose& pose : trajectory) appendPose(columns, pose, kNaN);
  return columns;
}

FigureColumns figureColumns(const SourceSeries& source) {
  FigureColumns columns;
  for (std::size_t i = 0; i < source.estimates.size(); ++i) {
    const logs::SourceEstimate& e = source.estimates[i];
    if (e.status == logs::SourceEstimate::kTracking) {
      appendPose(columns, e, source.truth_yaw_rad[i]);
    } else {
      appendEmpty(columns, e.t_s);
    }
  }
  return columns;
}

std::vector<std::string> trajectoryNames(const RunData& run) {
  return run.trajectories ? namesOf(*run.trajectories) : std::vector<std::string>{};
}

RunData compareWithTruth(const RunData& run, const std::string& truth_name, bool compute_metrics) {
  if (!run.trajectories) throw RunDataError(run.dir + ": the run holds no trajectories");
  return buildRun(run.dir, run.trajectories, run.poses_from, run.damage, truth_name,
                  compute_metrics);
}

void computeMetrics(RunData& run) {
  if (!run.trajectories) throw RunDataError(run.dir + ": the run holds no trajectories");
  setMetrics(run, truthOf(run.trajectories->by_name.at(run.truth_name)));
}

bool isRunDir(const std::string& dir) {
  const fs::path path(dir);
  return isFile(path / kLogName) || isFile(path / kMetricsName) || !tumFiles(path).empty();
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

RunData loadRun(const std::string& path, const std::string& truth_name) {
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
    std::optional<eval::RunMetrics> metrics;
    const fs::path metrics_path = root / kMetricsName;
    if (own_metrics && isFile(metrics_path)) {
      metrics = eval::readMetricsJson(metrics_path.string(), &options);
    }

    std::shared_ptr<RunTrajectories> read;
    std::string poses_from;
    std::string damage;
    const fs::path log_path = is_log_file ? given : root / kLogName;
    const std::vector<fs::path> tum_files = is_log_file ? std::vector<fs::path>{} : tumFiles(root);
    if (isFile(log_path)) {
      const logs::LogTrajectories recorded = logs::readRunLog(log_path.string());
      read = trajectoriesOf(recorded, options);
      poses_from = log_path.string();
      damage = recorded.damage;
    } else if (!tum_files.empty()) {
      read = std::make_shared<RunTrajectories>();
      read->options = options;
      std::vector<std::string> names;
      fs::path truth_file;
      for (const fs::path& file : tum_files) {
        names.push_back(file.stem().string());
        read->by_name[names.back()] = trackingEstimates(core::readTum(file.string()));
      }
      read->recorded_truth = isFile(root / kTruthName)
                                 ? std::string(kRecordedTruthName)
                                 : guessTruth(names, read->recorded_truth_note);
      poses_from = (root / (read->recorded_truth + kTumExtension)).string();
    } else {
      throw RunDataError(path + ": neither " + kLogName +
                         " nor a TUM file (*.tum): no poses to plot");
    }
    // metrics.json holds against the truth nadir recorded, never a guessed one.
    if (metrics && read->recorded_truth == kRecordedTruthName) {
      read->recorded_metrics = std::move(metrics);
      read->metrics_file = metrics_path.string();
    }
    const std::string truth = truth_name.empty() ? read->recorded_truth : truth_name;
    return buildRun(path, std::move(read), std::move(poses_from), std::move(damage), truth, true);
  } catch (const eval::EvalError& e) {
    throw RunDataError(e.what());
  } catch (const core::TrajectoryError& e) {
    throw RunDataError(e.what());
  } catch (const logs::RunLogError& e) {
    throw RunDataError(e.what());
  } catch (const fs::filesystem_error& e) {
    throw RunDataError(path + ": " + e.what());
  }
}

RunData runFromPoses(const std::string& name, const logs::LogTrajectories& recorded,
                     const eval::EvalOptions& options) {
  if (recorded.truth.empty()) throw RunDataError(name + ": no truth pose");
  return buildRun(name, trajectoriesOf(recorded, options), {}, recorded.damage, kRecordedTruthName,
                  false);
}

std::string resultsCsv(const eval::RunMetrics& metrics) {
  std::string out = "source,position_rmse_m,rotation_rmse_deg,tracked_pct,ape_rmse_m,rpe_rmse_m\n";
  for (const auto& [name, m] : metrics.sources) {
    out += core::csvField(name);
    for (const double value : {m.position_rmse_m, m.rotation_rmse_deg, m.tracked_pct,
                               m.ape_translation_m.rmse, m.rpe_translation_m.rmse}) {
      out += ',';
      appendNumber(out, value);
    }
    out += '\n';
  }
  return out;
}

std::string figureDataCsv(const RunData& run, const std::string& figure,
                          const std::set<std::string>& hidden) {
  using Field = const std::vector<double> FigureColumns::*;
  std::vector<Field> fields;
  std::string header;
  if (figure == "position") {
    fields = {&FigureColumns::x_m, &FigureColumns::y_m, &FigureColumns::z_m};
    header = "north_m,east_m,down_m";
  } else if (figure == "attitude") {
    fields = {&FigureColumns::roll_deg, &FigureColumns::pitch_deg, &FigureColumns::yaw_deg};
    header = "roll_deg,pitch_deg,yaw_deg";
  } else if (figure == "top_view") {
    fields = {&FigureColumns::x_m, &FigureColumns::y_m};
    header = "north_m,east_m";
  } else if (figure != "error") {
    throw RunDataError("no figure " + figure + " (position, attitude, error, top_view)");
  } else {
    header = "position_error_m";
  }
  std::string out = "trajectory,time_s," + header + "\n";
  const auto rows = [&](const std::string& name, const FigureColumns& pose,
                        const std::vector<double>* error) {
    if (hidden.contains(name)) return;
    for (std::size_t i = 0; i < pose.size(); ++i) {
      if (error != nullptr ? !std::isfinite((*error)[i]) : !std::isfinite(pose.x_m[i])) continue;
      out += core::csvField(name);
      out += ',';
      appendNumber(out, pose.t_s[i] - run.t0_s);
      if (error != nullptr) {
        out += ',';
        appendNumber(out, (*error)[i]);
      }
      for (const Field field : fields) {
        out += ',';
        appendNumber(out, (pose.*field)[i]);
      }
      out += '\n';
    }
  };
  if (figure != "error") rows(run.truth_name, figureColumns(run.truth), nullptr);
  for (const auto& [name, source] : run.sources) {
    rows(name, figureColumns(source), figure == "error" ? &source.position_error_m : nullptr);
  }
  return out;
}

}  // namespace nadir::gui
