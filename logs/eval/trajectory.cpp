#include "logs/eval/trajectory.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string_view>

namespace nadir::eval {
namespace {

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t at = 0;
  while (at < line.size()) {
    while (at < line.size() &&
           (line[at] == ' ' || line[at] == '\t' || line[at] == ',' || line[at] == '\r')) {
      ++at;
    }
    const std::size_t start = at;
    while (at < line.size() && line[at] != ' ' && line[at] != '\t' && line[at] != ',' &&
           line[at] != '\r') {
      ++at;
    }
    if (at > start) fields.push_back(line.substr(start, at - start));
  }
  return fields;
}

std::optional<double> parseDouble(std::string_view text) {
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

void appendDouble(std::string& out, double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), result.ptr);
}

std::vector<double> stamps(const PoseTrajectory& trajectory) {
  std::vector<double> t;
  t.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory) t.push_back(pose.t_s);
  return t;
}

// Index of the stamp nearest to t in sorted stamps (the earlier one on a tie,
// as numpy's argmin); stamps must not be empty.
std::size_t nearestIndex(const std::vector<double>& sorted, double t) {
  const auto upper = std::lower_bound(sorted.begin(), sorted.end(), t);
  if (upper == sorted.begin()) return 0;
  if (upper == sorted.end()) return sorted.size() - 1;
  const auto lower = upper - 1;
  return static_cast<std::size_t>((t - *lower <= *upper - t ? lower : upper) - sorted.begin());
}

}  // namespace

PoseTrajectory readTum(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw EvalError(path + ": cannot open the file for reading");
  PoseTrajectory trajectory;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::vector<std::string_view> fields = splitFields(line);
    if (fields.empty() || fields.front().starts_with('#')) continue;
    const std::string where = path + ":" + std::to_string(line_number) + ": ";
    if (fields.size() != 8) {
      throw EvalError(where + "expected 8 numbers (t tx ty tz qx qy qz qw), got " +
                      std::to_string(fields.size()) + " fields");
    }
    std::array<double, 8> v{};
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const std::optional<double> value = parseDouble(fields[i]);
      if (!value) {
        throw EvalError(where + "field " + std::to_string(i + 1) + " '" + std::string(fields[i]) +
                        "' is not a finite number");
      }
      v[i] = *value;
    }
    StampedPose pose;
    pose.t_s = v[0];
    pose.p_m = Eigen::Vector3d(v[1], v[2], v[3]);
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (q.norm() < 1e-9) throw EvalError(where + "the quaternion (qx qy qz qw) is zero");
    pose.q = q.normalized();
    if (!trajectory.empty() && pose.t_s <= trajectory.back().t_s) {
      throw EvalError(where + "timestamp " + std::string(fields[0]) +
                      " does not increase (timestamps must increase strictly)");
    }
    trajectory.push_back(pose);
  }
  if (in.bad()) throw EvalError(path + ": read error");
  if (trajectory.empty()) throw EvalError(path + ": no poses in the file");
  return trajectory;
}

void writeTum(const std::string& path, const PoseTrajectory& trajectory) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw EvalError(path + ": cannot open the file for writing");
  std::string text;
  for (const StampedPose& pose : trajectory) {
    const std::array<double, 8> v{pose.t_s,   pose.p_m.x(), pose.p_m.y(), pose.p_m.z(),
                                  pose.q.x(), pose.q.y(),   pose.q.z(),   pose.q.w()};
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (i > 0) text += ' ';
      appendDouble(text, v[i]);
    }
    text += '\n';
  }
  out << text;
  out.flush();
  if (!out) throw EvalError(path + ": write error");
}

std::optional<StampedPose> interpolate(const PoseTrajectory& trajectory, double t_s,
                                       double max_gap_s) {
  if (trajectory.empty() || t_s < trajectory.front().t_s || t_s > trajectory.back().t_s) {
    return std::nullopt;
  }
  const auto after =
      std::lower_bound(trajectory.begin(), trajectory.end(), t_s,
                       [](const StampedPose& pose, double t) { return pose.t_s < t; });
  if (after->t_s == t_s) return StampedPose{t_s, after->p_m, after->q};
  const StampedPose& b = *after;
  const StampedPose& a = *(after - 1);
  if (b.t_s - a.t_s > max_gap_s) return std::nullopt;
  const double u = (t_s - a.t_s) / (b.t_s - a.t_s);
  StampedPose pose;
  pose.t_s = t_s;
  pose.p_m = a.p_m + u * (b.p_m - a.p_m);
  pose.q = a.q.slerp(u, b.q).normalized();
  return pose;
}

std::vector<std::pair<std::size_t, std::size_t>> associate(const PoseTrajectory& ref,
                                                           const PoseTrajectory& est,
                                                           double t_max_diff_s) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  if (ref.empty() || est.empty()) return pairs;
  const std::vector<double> ref_t = stamps(ref);
  const std::vector<double> est_t = stamps(est);
  for (std::size_t i = 0; i < est_t.size(); ++i) {
    const std::size_t j = nearestIndex(ref_t, est_t[i]);
    if (std::abs(ref_t[j] - est_t[i]) > t_max_diff_s) continue;
    if (nearestIndex(est_t, ref_t[j]) != i) continue;
    pairs.emplace_back(j, i);
  }
  return pairs;
}

double trackLength(const PoseTrajectory& trajectory) {
  double length = 0;
  for (std::size_t i = 1; i < trajectory.size(); ++i) {
    length += (trajectory[i].p_m - trajectory[i - 1].p_m).norm();
  }
  return length;
}

}  // namespace nadir::eval
