#include "core/trajectory.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string_view>

#include "core/frames.h"
#include "core/geodesy.h"

namespace nadir::core {
namespace {

bool isSeparator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t at = 0;
  while (at < line.size()) {
    while (at < line.size() && isSeparator(line[at])) ++at;
    const std::size_t start = at;
    while (at < line.size() && !isSeparator(line[at])) ++at;
    if (at > start) fields.push_back(line.substr(start, at - start));
  }
  return fields;
}

// CSV fields keep empty ones (a missing value is an error, not a shift).
std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::string field = line.substr(start, comma == std::string::npos ? comma : comma - start);
    field.erase(0, field.find_first_not_of(" \t\r"));
    field.erase(field.find_last_not_of(" \t\r") + 1);
    fields.push_back(field);
    if (comma == std::string::npos) break;
    start = comma + 1;
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

}  // namespace

std::optional<Bracket> bracket(const Trajectory& trajectory, double t_s, double max_gap_s) {
  if (trajectory.empty() || t_s < trajectory.front().t_s || t_s > trajectory.back().t_s) {
    return std::nullopt;
  }
  const auto after =
      std::lower_bound(trajectory.begin(), trajectory.end(), t_s,
                       [](const StampedPose& pose, double t) { return pose.t_s < t; });
  const auto i1 = static_cast<std::size_t>(after - trajectory.begin());
  if (after->t_s == t_s) return Bracket{i1, i1, 0.0};
  const StampedPose& b = *after;
  const StampedPose& a = *(after - 1);
  if (b.t_s - a.t_s > max_gap_s) return std::nullopt;
  return Bracket{i1 - 1, i1, (t_s - a.t_s) / (b.t_s - a.t_s)};
}

std::optional<StampedPose> interpolate(const Trajectory& trajectory, double t_s, double max_gap_s) {
  const std::optional<Bracket> at = bracket(trajectory, t_s, max_gap_s);
  if (!at) return std::nullopt;
  const StampedPose& a = trajectory[at->i0];
  if (at->i0 == at->i1) return StampedPose{t_s, a.p_ned_m, a.q_world_body};
  const StampedPose& b = trajectory[at->i1];
  const double u = at->fraction;
  StampedPose pose;
  pose.t_s = t_s;
  pose.p_ned_m = a.p_ned_m + u * (b.p_ned_m - a.p_ned_m);
  pose.q_world_body = a.q_world_body.slerp(u, b.q_world_body).normalized();
  return pose;
}

double trackLength(const Trajectory& trajectory) {
  double length = 0;
  for (std::size_t i = 1; i < trajectory.size(); ++i) {
    length += (trajectory[i].p_ned_m - trajectory[i - 1].p_ned_m).norm();
  }
  return length;
}

void requireIncreasing(const Trajectory& trajectory, const std::string& source,
                       std::size_t min_poses) {
  if (trajectory.size() < min_poses) {
    throw TrajectoryError(source + ": a trajectory needs at least " +
                          (min_poses == 2 ? std::string("two") : std::to_string(min_poses)) +
                          " poses, got " + std::to_string(trajectory.size()));
  }
  for (std::size_t i = 1; i < trajectory.size(); ++i) {
    if (trajectory[i].t_s <= trajectory[i - 1].t_s) {
      throw TrajectoryError(source + ": pose " + std::to_string(i + 1) +
                            " is not later than the one before");
    }
  }
}

namespace {

// A TUM file's "# frame: world=W body=B" line, as writeTum writes it.
void readFrameLine(const std::string& line, const std::string& where, Axes& axes, BodyAxes& body) {
  std::istringstream words(line.substr(line.find("frame:") + 6));
  std::string world_word, body_word;
  words >> world_word >> body_word;
  if (!world_word.starts_with("world=") || !body_word.starts_with("body=")) {
    throw TrajectoryError(where + "a frame line is '# frame: world=ned|enu body=frd|flu|camera'");
  }
  try {
    axes = parseAxes(world_word.substr(6));
  } catch (const std::invalid_argument& error) {
    throw TrajectoryError(where + error.what());
  }
  const std::string body_name = body_word.substr(5);
  if (body_name == "camera") {
    body = BodyAxes::kCamera;
  } else if (body_name == (axes == Axes::kEnu ? "flu" : "frd")) {
    body = BodyAxes::kVehicle;
  } else {
    throw TrajectoryError(where + "body '" + body_name + "' does not go with world " +
                          axesName(axes) + " (" + (axes == Axes::kEnu ? "flu" : "frd") +
                          " or camera)");
  }
}

}  // namespace

Trajectory readTum(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError(path + ": cannot open the file for reading");
  Trajectory trajectory;
  Axes axes = Axes::kNed;
  BodyAxes body = BodyAxes::kVehicle;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::vector<std::string_view> fields = splitFields(line);
    const std::string where = path + ":" + std::to_string(line_number) + ": ";
    if (!fields.empty() && fields.front().starts_with('#')) {
      if (line.starts_with("# frame:")) readFrameLine(line, where, axes, body);
      continue;
    }
    if (fields.empty()) continue;
    if (fields.size() != 8) {
      throw TrajectoryError(where + "expected 8 numbers (t tx ty tz qx qy qz qw), got " +
                            std::to_string(fields.size()) + " fields");
    }
    std::array<double, 8> v{};
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const std::optional<double> value = parseDouble(fields[i]);
      if (!value) {
        throw TrajectoryError(where + "field " + std::to_string(i + 1) + " '" +
                              std::string(fields[i]) + "' is not a finite number");
      }
      v[i] = *value;
    }
    StampedPose pose;
    pose.t_s = v[0];
    pose.p_ned_m = Eigen::Vector3d(v[1], v[2], v[3]);
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    // Eigen's stable norm: a plain one of components near 1e308 overflows (found by fuzzing).
    if (q.coeffs().stableNorm() < 1e-9) {
      throw TrajectoryError(where + "the quaternion (qx qy qz qw) is zero");
    }
    pose.q_world_body = Eigen::Quaterniond(q.coeffs().stableNormalized());
    if (!trajectory.empty() && pose.t_s <= trajectory.back().t_s) {
      throw TrajectoryError(where + "timestamp " + std::string(fields[0]) +
                            " does not increase (timestamps must increase strictly)");
    }
    trajectory.push_back(pose);
  }
  if (in.bad()) throw TrajectoryError(path + ": read error");
  if (trajectory.empty()) throw TrajectoryError(path + ": no poses in the file");
  if (axes != Axes::kNed) {
    for (StampedPose& pose : trajectory) {
      pose.p_ned_m = worldVectorToNed(axes, pose.p_ned_m);
      pose.q_world_body = attitudeToNed(axes, pose.q_world_body, body);
    }
  }
  return trajectory;
}

void writeTum(const std::string& path, const Trajectory& trajectory, Axes axes, BodyAxes body) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw TrajectoryError(path + ": cannot open the file for writing");
  std::string text =
      "# t tx ty tz qx qy qz qw: time (s), position (m), orientation (Hamilton), T_world_body\n"
      "# " +
      frameWords(axes, body) + "\n# frame: " + frameTag(axes, body) + "\n";
  for (const StampedPose& pose : trajectory) {
    const Eigen::Vector3d p = worldVectorIn(axes, pose.p_ned_m);
    const Eigen::Quaterniond q = attitudeIn(axes, pose.q_world_body, body);
    const std::array<double, 8> v{pose.t_s, p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()};
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (i > 0) text += ' ';
      appendDouble(text, v[i]);
    }
    text += '\n';
  }
  out << text;
  out.flush();
  if (!out) throw TrajectoryError(path + ": write error");
}

Trajectory readFlightCsv(const std::string& path, const LocalNedFrame& frame) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError("cannot open flight CSV " + path);
  std::string line;
  if (!std::getline(in, line)) throw TrajectoryError(path + ": empty file, expected a header");
  const std::vector<std::string> header = splitCsv(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (!column.emplace(header[i], i).second && !header[i].empty()) {
      throw TrajectoryError(path + ": the header names column '" + header[i] + "' twice");
    }
  }
  for (const char* name :
       {"time_s", "lat_deg", "lon_deg", "alt_m", "roll_deg", "pitch_deg", "yaw_deg"}) {
    if (column.count(name) == 0) {
      throw TrajectoryError(
          path + ": the header has no column '" + name +
          "' (needs time_s, lat_deg, lon_deg, alt_m, roll_deg, pitch_deg, yaw_deg)");
    }
  }
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  Trajectory trajectory;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> fields = splitCsv(line);
    const std::string where = path + ":" + std::to_string(line_number);
    if (fields.size() < header.size()) {
      throw TrajectoryError(where + ": " + std::to_string(fields.size()) +
                            " fields, the header has " + std::to_string(header.size()));
    }
    const auto value = [&](const char* name) {
      const std::string& text = fields[column.at(name)];
      std::size_t used = 0;
      double number = 0.0;
      try {
        number = std::stod(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != text.size() || text.empty() || !std::isfinite(number)) {
        throw TrajectoryError(where + ": '" + text + "' is not a number");
      }
      return number;
    };
    const double lat_deg = value("lat_deg");
    if (std::abs(lat_deg) > 90.0) {
      throw TrajectoryError(where + ": lat_deg " + fields[column.at("lat_deg")] +
                            " is outside [-90, 90]");
    }
    const Eigen::Vector3d p_ned_m =
        frame.nedFromGeodetic(geodeticFromDegrees(lat_deg, value("lon_deg"), value("alt_m")));
    if (!p_ned_m.allFinite()) {
      throw TrajectoryError(where + ": the position is too far from the frame's origin to hold");
    }
    trajectory.push_back(
        {value("time_s"), p_ned_m,
         quaternionFromRpy({value("roll_deg") * kRadPerDeg, value("pitch_deg") * kRadPerDeg,
                            value("yaw_deg") * kRadPerDeg})});
  }
  return trajectory;
}

}  // namespace nadir::core
