#include "logs/eval/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>

#include "core/frames.h"

namespace nadir::eval {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

void requireSameSize(const core::Trajectory& ref, const core::Trajectory& est, const char* what) {
  if (ref.size() != est.size()) {
    throw EvalError(std::string(what) + ": " + std::to_string(ref.size()) + " reference and " +
                    std::to_string(est.size()) +
                    " estimated poses (must be associated one to one)");
  }
}

Eigen::Isometry3d isometry(const core::StampedPose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = pose.q_world_body.toRotationMatrix();
  T.translation() = pose.p_ned_m;
  return T;
}

double wrapPi(double angle_rad) { return std::atan2(std::sin(angle_rad), std::cos(angle_rad)); }

std::string formatNumber(double value) {
  if (std::isnan(value)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.6f", value);
  return buffer;
}

std::string formatShort(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

void appendStatistics(std::string& out, const std::string& title, const Statistics& s) {
  out += title + "\n";
  const std::pair<const char*, double> rows[] = {{"max", s.max},       {"mean", s.mean},
                                                 {"median", s.median}, {"min", s.min},
                                                 {"rmse", s.rmse},     {"std", s.std}};
  char buffer[96];
  for (const auto& [name, value] : rows) {
    std::snprintf(buffer, sizeof buffer, "%10s  %s\n", name, formatNumber(value).c_str());
    out += buffer;
  }
  std::snprintf(buffer, sizeof buffer, "%10s  %zu\n\n", "count", s.count);
  out += buffer;
}

}  // namespace

Statistics computeStatistics(std::vector<double> values) {
  Statistics s;
  s.count = values.size();
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  double sum = 0;
  double sum_squares = 0;
  for (const double v : values) {
    sum += v;
    sum_squares += v * v;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_squares / n);
  double deviation = 0;
  for (const double v : values) deviation += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(deviation / n);
  std::sort(values.begin(), values.end());
  s.min = values.front();
  s.max = values.back();
  const std::size_t middle = values.size() / 2;
  s.median = values.size() % 2 == 1 ? values[middle] : 0.5 * (values[middle - 1] + values[middle]);
  return s;
}

void validateOptions(const EvalOptions& options) {
  parseAlignMode(options.align);
  const DeltaUnit unit = parseDeltaUnit(options.rpe_delta_unit);
  if (!(options.rpe_delta > 0) || !std::isfinite(options.rpe_delta)) {
    throw EvalError("RPE delta must be a positive number, got " + formatShort(options.rpe_delta));
  }
  if (unit == DeltaUnit::kFrames && options.rpe_delta != std::floor(options.rpe_delta)) {
    throw EvalError("RPE delta in frames must be a whole number, got " +
                    formatShort(options.rpe_delta));
  }
  if (!(options.t_max_diff_s >= 0)) {
    throw EvalError("t_max_diff must be >= 0 s, got " + formatShort(options.t_max_diff_s));
  }
  if (!(options.tracked_hold_periods > 0)) {
    throw EvalError("tracked_hold_periods must be > 0, got " +
                    formatShort(options.tracked_hold_periods));
  }
  if (!(options.track_length_interval_s >= 0)) {
    throw EvalError("track_length_interval_s must be >= 0 s, got " +
                    formatShort(options.track_length_interval_s));
  }
  if (!(options.truth_max_gap_s > 0)) {
    throw EvalError("truth_max_gap_s must be > 0 s, got " + formatShort(options.truth_max_gap_s));
  }
}

double rotationAngleDeg(const Eigen::Quaterniond& q) {
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w())) * kRadToDeg;
}

std::vector<double> apeTranslationErrors(const core::Trajectory& ref, const core::Trajectory& est) {
  requireSameSize(ref, est, "APE");
  std::vector<double> errors;
  errors.reserve(ref.size());
  for (std::size_t i = 0; i < ref.size(); ++i)
    errors.push_back((est[i].p_ned_m - ref[i].p_ned_m).norm());
  return errors;
}

std::vector<double> apeRotationErrorsDeg(const core::Trajectory& ref, const core::Trajectory& est) {
  requireSameSize(ref, est, "APE");
  std::vector<double> errors;
  errors.reserve(ref.size());
  for (std::size_t i = 0; i < ref.size(); ++i) {
    errors.push_back(rotationAngleDeg(est[i].q_world_body.conjugate() * ref[i].q_world_body));
  }
  return errors;
}

DeltaUnit parseDeltaUnit(const std::string& name) {
  if (name == "frames") return DeltaUnit::kFrames;
  if (name == "meters") return DeltaUnit::kMeters;
  throw EvalError("unknown RPE delta unit '" + name + "' (expected frames or meters)");
}

IndexPairs rpePairs(const core::Trajectory& poses, double delta, DeltaUnit unit) {
  IndexPairs pairs;
  std::vector<std::size_t> ids;
  if (unit == DeltaUnit::kFrames) {
    const auto step = static_cast<std::size_t>(std::llround(delta));
    if (step == 0) return pairs;
    for (std::size_t i = 0; i < poses.size(); i += step) ids.push_back(i);
  } else {
    double path = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (i > 0) path += (poses[i].p_ned_m - poses[i - 1].p_ned_m).norm();
      if (path >= delta) {
        ids.push_back(i);
        path = 0;
      }
    }
  }
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

RelativeErrors rpeErrors(const core::Trajectory& ref, const core::Trajectory& est,
                         const IndexPairs& pairs) {
  requireSameSize(ref, est, "RPE");
  RelativeErrors errors;
  errors.translation_m.reserve(pairs.size());
  errors.rotation_deg.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    const Eigen::Isometry3d ref_rel = isometry(ref[i]).inverse() * isometry(ref[j]);
    const Eigen::Isometry3d est_rel = isometry(est[i]).inverse() * isometry(est[j]);
    const Eigen::Isometry3d E = ref_rel.inverse() * est_rel;
    errors.translation_m.push_back(E.translation().norm());
    errors.rotation_deg.push_back(rotationAngleDeg(Eigen::Quaterniond(E.rotation())));
  }
  return errors;
}

double thesisPositionRmse(const core::Trajectory& ref, const core::Trajectory& est) {
  requireSameSize(ref, est, "position RMSE");
  if (ref.empty()) return kNaN;
  double sum = 0;
  for (std::size_t i = 0; i < ref.size(); ++i)
    sum += (est[i].p_ned_m - ref[i].p_ned_m).squaredNorm();
  return std::sqrt(sum / static_cast<double>(ref.size()));
}

double thesisRotationRmseDeg(const core::Trajectory& ref, const core::Trajectory& est) {
  requireSameSize(ref, est, "rotation RMSE");
  if (ref.empty()) return kNaN;
  double sum = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const core::RollPitchYaw truth = core::rpyFromQuaternion(ref[i].q_world_body);
    const core::RollPitchYaw estimate = core::rpyFromQuaternion(est[i].q_world_body);
    const double d_roll = wrapPi(estimate.roll_rad - truth.roll_rad) * kRadToDeg;
    const double d_pitch = wrapPi(estimate.pitch_rad - truth.pitch_rad) * kRadToDeg;
    const double d_yaw = wrapPi(estimate.yaw_rad - truth.yaw_rad) * kRadToDeg;
    sum += d_roll * d_roll + d_pitch * d_pitch + d_yaw * d_yaw;
  }
  return std::sqrt(sum / static_cast<double>(ref.size()));
}

double meanAbsoluteError(const core::Trajectory& ref, const core::Trajectory& est) {
  const std::vector<double> errors = apeTranslationErrors(ref, est);
  if (errors.empty()) return kNaN;
  return std::accumulate(errors.begin(), errors.end(), 0.0) / static_cast<double>(errors.size());
}

TrajectoryEvaluation evaluateTrajectories(const core::Trajectory& ref, const core::Trajectory& est,
                                          const EvalOptions& options) {
  validateOptions(options);
  TrajectoryEvaluation result;
  result.ref_poses = ref.size();
  result.est_poses = est.size();
  const auto pairs = associate(ref, est, options.t_max_diff_s);
  result.matched_poses = pairs.size();
  if (pairs.size() < 2) {
    throw EvalError("too few associated poses: " + std::to_string(pairs.size()) + " of " +
                    std::to_string(est.size()) + " estimated poses are within t_max_diff " +
                    formatShort(options.t_max_diff_s) + " s of a reference pose (need 2)");
  }
  core::Trajectory ref_matched;
  core::Trajectory est_matched;
  for (const auto& [i_ref, i_est] : pairs) {
    ref_matched.push_back(ref[i_ref]);
    est_matched.push_back(est[i_est]);
  }
  result.align = parseAlignMode(options.align);
  result.alignment = alignTrajectories(ref_matched, est_matched, result.align);
  applyAlignment(result.alignment, est_matched);
  result.ape_translation_m = computeStatistics(apeTranslationErrors(ref_matched, est_matched));
  result.ape_rotation_deg = computeStatistics(apeRotationErrorsDeg(ref_matched, est_matched));
  const IndexPairs rpe_pairs =
      rpePairs(est_matched, options.rpe_delta, parseDeltaUnit(options.rpe_delta_unit));
  if (rpe_pairs.empty()) {
    throw EvalError("RPE delta " + formatShort(options.rpe_delta) + " " + options.rpe_delta_unit +
                    " gives no pose pair among " + std::to_string(pairs.size()) +
                    " associated poses; use a smaller delta");
  }
  const RelativeErrors relative = rpeErrors(ref_matched, est_matched, rpe_pairs);
  result.rpe_translation_m = computeStatistics(relative.translation_m);
  result.rpe_rotation_deg = computeStatistics(relative.rotation_deg);
  return result;
}

std::string formatTrajectoryReport(const TrajectoryEvaluation& evaluation,
                                   const EvalOptions& options) {
  std::string out;
  char buffer[256];
  std::snprintf(buffer, sizeof buffer,
                "associated %zu of %zu estimated poses with %zu reference poses "
                "(t_max_diff %s s)\n",
                evaluation.matched_poses, evaluation.est_poses, evaluation.ref_poses,
                formatShort(options.t_max_diff_s).c_str());
  out += buffer;
  if (evaluation.align == AlignMode::kNone) {
    out += "alignment: none\n\n";
  } else {
    std::snprintf(buffer, sizeof buffer, "alignment: %s Umeyama, scale %s\n\n",
                  evaluation.align == AlignMode::kSim3 ? "Sim(3)" : "SE(3)",
                  formatNumber(evaluation.alignment.scale).c_str());
    out += buffer;
  }
  appendStatistics(out, "APE w.r.t. translation part (m)", evaluation.ape_translation_m);
  appendStatistics(out, "APE w.r.t. rotation angle (deg)", evaluation.ape_rotation_deg);
  const std::string rpe_for = " for delta = " + formatShort(options.rpe_delta) + " (" +
                              options.rpe_delta_unit + ") using consecutive pairs";
  appendStatistics(out, "RPE w.r.t. translation part (m)" + rpe_for, evaluation.rpe_translation_m);
  appendStatistics(out, "RPE w.r.t. rotation angle (deg)" + rpe_for, evaluation.rpe_rotation_deg);
  out += formatNumber(evaluation.ape_translation_m.rmse) + "\n";
  return out;
}

}  // namespace nadir::eval
