#include "nodes/control/course_results.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "core/frames.h"

namespace nadir::control {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// A board's line crossed further than this from its centre is not a passage of it, m.
constexpr double kPassageReach_m = 2.0;
// Moving: faster than this, m/s.
constexpr double kMoving_mps = 0.05;
// A turn board is approached when the body, still in front of it, comes this
// close heading within kApproach_deg of its axis; the turn it asks for must
// come within kTurnTravel_m of travel after that and reach kTurnShare of its
// angle; it ends when the yaw rate falls under kTurnEnd_rps.
constexpr double kApproach_m = 1.5;
constexpr double kApproach_deg = 45.0;
constexpr double kTurnTravel_m = 3.0;
constexpr double kTurnShare = 0.7;
constexpr double kTurnEnd_rps = 0.3;
// Liu et al. (2021) table 2, us: capture and threshold, flooding, de-noising,
// the disks' coordinates, their transfer, the PID.
constexpr std::array<double, 6> kPaperUs = {52.0, 63.0, 4.0, 328.0, 24.0, 1.0};

double yawOf(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d forward = q * Eigen::Vector3d::UnitX();
  return std::atan2(forward.y(), forward.x());
}

FloorRectangle bodyAt(const core::StampedPose& pose, const Footprint& footprint) {
  const double yaw = yawOf(pose.q_world_body);
  const double ahead = 0.5 * footprint.length_m - footprint.rear_overhang_m;
  return {pose.p_ned_m.x() + ahead * std::cos(yaw), pose.p_ned_m.y() + ahead * std::sin(yaw), yaw,
          0.5 * footprint.length_m, 0.5 * footprint.width_m};
}

std::array<Eigen::Vector2d, 4> corners(const FloorRectangle& r) {
  const Eigen::Vector2d f(std::cos(r.heading_rad), std::sin(r.heading_rad));
  const Eigen::Vector2d s(-f.y(), f.x());
  const Eigen::Vector2d c(r.north_m, r.east_m);
  return {
      c + r.half_length_m * f + r.half_width_m * s, c + r.half_length_m * f - r.half_width_m * s,
      c - r.half_length_m * f - r.half_width_m * s, c - r.half_length_m * f + r.half_width_m * s};
}

std::string number(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

}  // namespace

bool overlap(const FloorRectangle& a, const FloorRectangle& b) {
  const auto ca = corners(a), cb = corners(b);
  for (const FloorRectangle* r : {&a, &b}) {
    for (const double angle : {r->heading_rad, r->heading_rad + 0.5 * std::numbers::pi}) {
      const Eigen::Vector2d axis(std::cos(angle), std::sin(angle));
      double a_min = 1e300, a_max = -1e300, b_min = 1e300, b_max = -1e300;
      for (const Eigen::Vector2d& p : ca) {
        a_min = std::min(a_min, p.dot(axis));
        a_max = std::max(a_max, p.dot(axis));
      }
      for (const Eigen::Vector2d& p : cb) {
        b_min = std::min(b_min, p.dot(axis));
        b_max = std::max(b_max, p.dot(axis));
      }
      if (a_max < b_min || b_max < a_min) return false;  // a separating axis
    }
  }
  return true;
}

namespace {

// A turn board's first approach: from there, the heading's change over the
// next kTurnTravel_m of travel. Turned (crossed) once it changes by
// kTurnShare of the angle either way, at the time it first changes by half;
// passed when that is to the board's side. heading_error_deg: the change at
// the turn's end less the angle asked (signed to the board's side);
// offset_m: not a crossing (NaN).
void scoreTurn(const core::Trajectory& truth, const std::vector<FloorRectangle>& body,
               const terrain::CourseBoard& board, logs::BoardPassage& passage) {
  const double h = board.heading_deg * kDeg;
  const Eigen::Vector2d centre(board.north_m, board.east_m);
  const Eigen::Vector2d forward(std::cos(h), std::sin(h));
  const double side = board.kind == "slalom_right" ? 1.0 : -1.0;
  std::size_t start = body.size();
  for (std::size_t i = 0; i < body.size(); ++i) {
    const Eigen::Vector2d p(body[i].north_m, body[i].east_m);
    if ((p - centre).norm() <= kApproach_m && (p - centre).dot(forward) < 0.0 &&
        std::abs(core::wrapAngle_rad(body[i].heading_rad - h)) <= kApproach_deg * kDeg) {
      start = i;
      break;
    }
  }
  if (start == body.size()) return;
  const double asked = board.turn_deg * kDeg;
  double change = 0.0, travel = 0.0;
  for (std::size_t i = start + 1; i < body.size() && travel <= kTurnTravel_m; ++i) {
    const double step = core::wrapAngle_rad(body[i].heading_rad - body[i - 1].heading_rad);
    const double dt = truth[i].t_s - truth[i - 1].t_s;
    change += step;
    travel += (truth[i].p_ned_m - truth[i - 1].p_ned_m).head<2>().norm();
    if (std::isnan(passage.time_s) && std::abs(change) >= 0.5 * asked) {
      passage.time_s = truth[i].t_s - truth.front().t_s;
    }
    if (!passage.crossed && std::abs(change) >= kTurnShare * asked) {
      passage.crossed = true;
      passage.passed = side * change > 0.0;
    }
    if (passage.crossed && dt > 0.0 && std::abs(step) / dt < kTurnEnd_rps) break;
  }
  if (passage.crossed) passage.heading_error_deg = (side * change - asked) / kDeg;
}

}  // namespace

logs::CourseMetrics courseResults(const CourseRunInput& input) {
  const core::Trajectory& truth = input.truth;
  if (truth.size() < 2) {
    throw std::invalid_argument("the course's truth has " + std::to_string(truth.size()) +
                                " poses; need at least 2");
  }
  logs::CourseMetrics m;
  const double t0 = truth.front().t_s;
  std::vector<FloorRectangle> body;
  body.reserve(truth.size());
  for (const core::StampedPose& pose : truth) body.push_back(bodyAt(pose, input.footprint));

  double last_crossing_s = -1.0;
  for (const terrain::CourseBoard& board : input.boards) {
    const bool gate = board.kind == "gate";
    const bool slalom = board.kind == "slalom_left" || board.kind == "slalom_right";
    // Any of its posts touched at any time.
    bool hit = false;
    for (const terrain::Post& post : terrain::boardPosts(board)) {
      const FloorRectangle square{post.north_m, post.east_m, post.heading_deg * kDeg,
                                  0.5 * post.size_m, 0.5 * post.size_m};
      for (const FloorRectangle& b : body) {
        if (overlap(b, square)) {
          hit = true;
          break;
        }
      }
      if (hit) break;
    }
    if (!gate && !slalom) {
      if (hit) ++m.decoys_hit;
      continue;
    }
    logs::BoardPassage passage;
    passage.kind = board.kind;
    passage.hit = hit;
    const double h = board.heading_deg * kDeg;
    const bool turn = slalom && board.turn_deg > 0.0;
    if (turn) {
      passage.kind = board.kind == "slalom_right" ? "turn_right" : "turn_left";
      scoreTurn(truth, body, board, passage);
      if (passage.crossed) last_crossing_s = std::max(last_crossing_s, passage.time_s);
    }
    const Eigen::Vector2d forward(std::cos(h), std::sin(h)), right(-std::sin(h), std::cos(h));
    const Eigen::Vector2d centre(board.north_m, board.east_m);
    for (std::size_t i = 1; !turn && i < body.size() && !passage.crossed; ++i) {
      const Eigen::Vector2d a(body[i - 1].north_m, body[i - 1].east_m);
      const Eigen::Vector2d b(body[i].north_m, body[i].east_m);
      const double da = (a - centre).dot(forward), db = (b - centre).dot(forward);
      if (!(da < 0.0 && db >= 0.0)) continue;
      const double share = da / (da - db);
      const Eigen::Vector2d at = a + share * (b - a);
      const double lateral = (at - centre).dot(right);
      if (std::abs(lateral) > kPassageReach_m) continue;
      passage.crossed = true;
      passage.time_s = truth[i - 1].t_s + share * (truth[i].t_s - truth[i - 1].t_s) - t0;
      passage.offset_m = lateral;
      passage.heading_error_deg = core::wrapAngle_rad(body[i].heading_rad - h) / kDeg;
      last_crossing_s = std::max(last_crossing_s, passage.time_s);
      if (gate) {
        passage.passed = std::abs(lateral) <= 0.5 * board.opening_m;
      } else {
        passage.passed = board.kind == "slalom_right" ? lateral > 0.0 : lateral < 0.0;
      }
    }
    if (gate) {
      ++m.gates;
      m.gates_passed += passage.passed ? 1 : 0;
      m.gates_missed += passage.passed ? 0 : 1;
      m.gates_hit += hit ? 1 : 0;
    } else {
      ++m.slalom_boards;
      m.slalom_passed += passage.passed ? 1 : 0;
      m.slalom_wrong_side += passage.crossed && !passage.passed ? 1 : 0;
      m.slalom_missed += passage.crossed ? 0 : 1;
      m.slalom_hit += hit ? 1 : 0;
    }
    m.passages.push_back(passage);
  }

  // Speeds: from the first motion to the last crossing (or the last motion).
  std::size_t first = truth.size(), last = 0;
  double peak = 0.0;
  for (std::size_t i = 1; i < truth.size(); ++i) {
    const double dt = truth[i].t_s - truth[i - 1].t_s;
    if (!(dt > 0.0)) continue;
    const double speed = (truth[i].p_ned_m - truth[i - 1].p_ned_m).head<2>().norm() / dt;
    peak = std::max(peak, speed);
    if (speed > kMoving_mps) {
      first = std::min(first, i - 1);
      last = i;
    }
  }
  m.peak_speed_mps = peak;
  if (first < last) {
    const double end_s = last_crossing_s >= 0.0 ? last_crossing_s + t0 : truth[last].t_s;
    double distance = 0.0;
    for (std::size_t i = first + 1; i < truth.size() && truth[i].t_s <= end_s; ++i) {
      distance += (truth[i].p_ned_m - truth[i - 1].p_ned_m).head<2>().norm();
    }
    m.distance_m = distance;
    m.duration_s = end_s - truth[first].t_s;
    if (m.duration_s > 0.0) m.average_speed_mps = distance / m.duration_s;
  }

  // The pipeline per frame.
  m.frames = static_cast<int>(input.frames.size());
  const char* names[6] = {
      "capture and threshold",  "flooding (intact and broken squares)", "de-noising",
      "the disks' coordinates", "transfer to the controller",           "PID"};
  double sums[4] = {0, 0, 0, 0}, chip_s = 0.0;
  for (const PatternFrame& frame : input.frames) {
    sums[0] += static_cast<double>(frame.threshold);
    sums[1] += static_cast<double>(frame.flood);
    sums[2] += static_cast<double>(frame.denoise);
    sums[3] += static_cast<double>(frame.coordinates);
    chip_s += frame.chip_time_s;
  }
  for (int k = 0; k < 6; ++k) {
    logs::PipelineStage stage;
    stage.name = names[k];
    stage.paper_us = kPaperUs[static_cast<std::size_t>(k)];
    if (k < 4 && m.frames > 0) {
      stage.instructions = sums[k] / m.frames;
      stage.chip_us = 1e6 * stage.instructions / input.chip_instruction_rate_hz;
    } else if (k == 4) {
      stage.chip_us = 1e6 * input.transfer_s;
    } else if (k == 5) {
      stage.chip_us = 1e6 * input.compute_s;
    }
    m.stages.push_back(stage);
  }
  if (m.frames > 0) {
    m.chip_time_us = 1e6 * chip_s / m.frames;
    if (m.chip_time_us > 0.0) m.emulated_fps = 1e6 / m.chip_time_us;
  }
  if (!input.commands.empty()) {
    double sum = 0.0, worst = 0.0;
    for (const CommandTiming& c : input.commands) {
      const double us = static_cast<double>(c.utime - c.frame_utime);
      sum += us;
      worst = std::max(worst, us);
    }
    m.latency_mean_us = sum / static_cast<double>(input.commands.size());
    m.latency_max_us = worst;
  }
  return m;
}

std::string formatCourse(const logs::CourseMetrics& m) {
  std::string out;
  if (m.gates > 0) {
    out += "course: " + std::to_string(m.gates_passed) + " of " + std::to_string(m.gates) +
           " gates passed, " + std::to_string(m.gates_missed) + " missed, " +
           std::to_string(m.gates_hit) + " hit";
    if (m.decoys_hit > 0) out += ", " + std::to_string(m.decoys_hit) + " decoys hit";
    out += "\n";
  }
  if (m.slalom_boards > 0) {
    out += "slalom: " + std::to_string(m.slalom_passed) + " of " + std::to_string(m.slalom_boards) +
           " boards passed on their side or turned at their way, " +
           std::to_string(m.slalom_wrong_side) + " the wrong way, " +
           std::to_string(m.slalom_missed) + " missed, " + std::to_string(m.slalom_hit) + " hit\n";
  }
  out += "speed: average " + number(m.average_speed_mps, 2) + " m/s over " +
         number(m.distance_m, 1) + " m in " + number(m.duration_s, 1) + " s, peak " +
         number(m.peak_speed_mps, 2) + " m/s\n";
  for (std::size_t i = 0; i < m.passages.size(); ++i) {
    const logs::BoardPassage& p = m.passages[i];
    if (p.kind == "turn_left" || p.kind == "turn_right") {
      out += "  " + std::to_string(i + 1) + " " + p.kind + ": " +
             (p.passed    ? "turned its way"
              : p.crossed ? "turned the wrong way"
                          : "missed") +
             (p.hit ? ", post hit" : "") +
             (p.crossed ? " at " + number(p.time_s, 2) + " s, " + number(p.heading_error_deg, 1) +
                              " deg beyond the turn asked"
                        : "") +
             "\n";
      continue;
    }
    out +=
        "  " + std::to_string(i + 1) + " " + p.kind + ": " +
        (p.passed    ? "passed"
         : p.crossed ? "crossed outside"
                     : "missed") +
        (p.hit ? ", post hit" : "") +
        (p.crossed ? " at " + number(p.time_s, 2) + " s, " + number(100.0 * p.offset_m, 1) +
                         " cm off centre, " + number(p.heading_error_deg, 1) + " deg off its axis"
                   : "") +
        "\n";
  }
  if (m.frames > 0) {
    out += "pipeline per frame (" + std::to_string(m.frames) +
           " frames)          instructions   chip us   paper us\n";
    double chip_total = 0.0, paper_total = 0.0;
    for (const logs::PipelineStage& s : m.stages) {
      char line[160];
      std::snprintf(line, sizeof line, "  %-40s %10s %9s %10s\n", s.name.c_str(),
                    number(s.instructions, 0).c_str(), number(s.chip_us, 1).c_str(),
                    number(s.paper_us, 0).c_str());
      out += line;
      if (std::isfinite(s.chip_us)) chip_total += s.chip_us;
      paper_total += s.paper_us;
    }
    char line[160];
    std::snprintf(line, sizeof line, "  %-40s %10s %9s %10s\n", "total", "",
                  number(chip_total, 1).c_str(), number(paper_total, 0).c_str());
    out += line;
    out += "emulated chip: " + number(m.emulated_fps, 0) + " frames/s; camera-to-command latency " +
           number(m.latency_mean_us, 0) + " us mean, " + number(m.latency_max_us, 0) +
           " us at most\n";
  }
  return out;
}

}  // namespace nadir::control
