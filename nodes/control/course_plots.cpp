#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nodes/control/course_results.h"

namespace nadir::control {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
const cv::Scalar kBlack(0, 0, 0), kGrey(150, 150, 150), kLight(225, 225, 225);

void text(cv::Mat& image, const std::string& what, cv::Point at, double size = 0.5,
          const cv::Scalar& colour = kBlack) {
  cv::putText(image, what, at, cv::FONT_HERSHEY_SIMPLEX, size, colour, 1, cv::LINE_AA);
}

// Blue (slow) to red (fast), BGR.
cv::Scalar speedColour(double share) {
  share = std::clamp(share, 0.0, 1.0);
  return {255.0 * (1.0 - share), 60.0, 255.0 * share};
}

// Where the body's centre was at each truth pose, and its speed.
struct PathPoint {
  double t_s;
  Eigen::Vector2d ne;
  double speed_mps;
};

std::vector<PathPoint> pathOf(const CourseRunInput& input) {
  std::vector<PathPoint> path;
  const Footprint& f = input.footprint;
  for (std::size_t i = 0; i < input.truth.size(); ++i) {
    const core::StampedPose& pose = input.truth[i];
    const Eigen::Vector3d forward = pose.q_world_body * Eigen::Vector3d::UnitX();
    const double ahead = 0.5 * f.length_m - f.rear_overhang_m;
    const Eigen::Vector2d ne = pose.p_ned_m.head<2>() + ahead * forward.head<2>().normalized();
    double speed = 0.0;
    if (i > 0 && pose.t_s > input.truth[i - 1].t_s) {
      speed = (pose.p_ned_m - input.truth[i - 1].p_ned_m).head<2>().norm() /
              (pose.t_s - input.truth[i - 1].t_s);
    }
    path.push_back({pose.t_s, ne, speed});
  }
  return path;
}

void writePng(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error("cannot write " + path);
}

}  // namespace

void writeCoursePlots(const CourseRunInput& input, const logs::CourseMetrics& metrics,
                      const std::string& path_png, const std::string& steering_png) {
  const std::vector<PathPoint> path = pathOf(input);
  // ---------------------------------------------------------------- the path
  double min_n = 1e300, max_n = -1e300, min_e = 1e300, max_e = -1e300, top_speed = 0.1;
  const auto extend = [&](double n, double e) {
    min_n = std::min(min_n, n);
    max_n = std::max(max_n, n);
    min_e = std::min(min_e, e);
    max_e = std::max(max_e, e);
  };
  for (const PathPoint& p : path) {
    extend(p.ne.x(), p.ne.y());
    top_speed = std::max(top_speed, p.speed_mps);
  }
  for (const terrain::CourseBoard& b : input.boards) extend(b.north_m, b.east_m);
  min_n -= 0.5;
  max_n += 0.5;
  min_e -= 0.5;
  max_e += 0.5;
  constexpr int kWidth = 1400, kMargin = 50, kTop = 70;
  const double scale = (kWidth - 2 * kMargin) / std::max(max_n - min_n, 1.0);
  const int height = kTop + kMargin + static_cast<int>(std::ceil((max_e - min_e) * scale));
  cv::Mat image(height, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  // North to the right, east down.
  const auto pixel = [&](double n, double e) {
    return cv::Point2d(kMargin + (n - min_n) * scale, kTop + (e - min_e) * scale);
  };
  const auto toPoint = [](const cv::Point2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
  };
  for (const terrain::CourseBoard& board : input.boards) {
    const bool decoy = board.kind == "decoy";
    const cv::Scalar colour = decoy ? kGrey : kBlack;
    for (const terrain::Post& post : terrain::boardPosts(board)) {
      const double h = post.heading_deg * kDeg, s = 0.5 * post.size_m;
      const Eigen::Vector2d f(std::cos(h), std::sin(h)), r(-std::sin(h), std::cos(h));
      std::vector<cv::Point> square;
      for (const auto& [a, b] : {std::pair{-1, -1}, {-1, 1}, {1, 1}, {1, -1}}) {
        const Eigen::Vector2d c =
            Eigen::Vector2d(post.north_m, post.east_m) + a * s * f + b * s * r;
        square.push_back(toPoint(pixel(c.x(), c.y())));
      }
      cv::fillConvexPoly(image, square, colour, cv::LINE_AA);
    }
    // The board's face as a line, its pattern's side marked for slalom boards.
    const terrain::BoardFrame frame = terrain::boardFrame(board, 0.0);
    const Eigen::Vector3d a = frame.centre_ned - 0.5 * board.board_m * frame.right_ned;
    const Eigen::Vector3d b = frame.centre_ned + 0.5 * board.board_m * frame.right_ned;
    cv::line(image, toPoint(pixel(a.x(), a.y())), toPoint(pixel(b.x(), b.y())),
             decoy ? kLight : kGrey, 3, cv::LINE_AA);
    if (board.kind == "slalom_left" || board.kind == "slalom_right") {
      const double side = board.kind == "slalom_right" ? 1.0 : -1.0;
      const Eigen::Vector3d tip = frame.centre_ned + side * 0.6 * frame.right_ned;
      cv::arrowedLine(image, toPoint(pixel(frame.centre_ned.x(), frame.centre_ned.y())),
                      toPoint(pixel(tip.x(), tip.y())), kBlack, 1, cv::LINE_AA, 0, 0.3);
    }
  }
  for (std::size_t i = 1; i < path.size(); ++i) {
    cv::line(image, toPoint(pixel(path[i - 1].ne.x(), path[i - 1].ne.y())),
             toPoint(pixel(path[i].ne.x(), path[i].ne.y())),
             speedColour(path[i].speed_mps / top_speed), 2, cv::LINE_AA);
  }
  char title[256];
  std::snprintf(title, sizeof title,
                "the rover's path (body centre), coloured by speed: blue 0, red %.2f m/s;  "
                "%s %d/%d passed, %d hit; average %.2f m/s",
                top_speed, metrics.gates > 0 ? "gates" : "boards",
                metrics.gates_passed + metrics.slalom_passed, metrics.gates + metrics.slalom_boards,
                metrics.gates_hit + metrics.slalom_hit, metrics.average_speed_mps);
  text(image, title, {kMargin, 30}, 0.55);
  text(image, "north to the right, east down; posts and boards to scale, decoys grey",
       {kMargin, 52}, 0.45, kGrey);
  // 1 m scale bar.
  cv::line(image, {kMargin, height - 20}, {kMargin + static_cast<int>(scale), height - 20}, kBlack,
           2);
  text(image, "1 m", {kMargin, height - 28}, 0.45);
  writePng(path_png, image);

  // ------------------------------------------------------------ the steering
  constexpr int kW = 900, kH = 520, kLeft = 70, kRight = 20, kPlotTop = 50, kBottom = 50;
  constexpr double kMaxDistance_m = 3.0;
  double lock_deg = 5.0;
  for (const CommandTiming& c : input.commands)
    lock_deg = std::max(lock_deg, std::abs(c.steer_rad) / kDeg);
  lock_deg = std::ceil(lock_deg / 5.0) * 5.0;
  cv::Mat plot(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto at = [&](double distance_m, double steer_deg) {
    return cv::Point(
        static_cast<int>(std::lround(kLeft + (kMaxDistance_m - distance_m) / kMaxDistance_m *
                                                 (kW - kLeft - kRight))),
        static_cast<int>(std::lround(kPlotTop + (lock_deg - steer_deg) / (2.0 * lock_deg) *
                                                    (kH - kPlotTop - kBottom))));
  };
  cv::rectangle(plot, at(kMaxDistance_m, lock_deg), at(0.0, -lock_deg), kBlack, 1);
  cv::line(plot, at(kMaxDistance_m, 0.0), at(0.0, 0.0), kLight, 1);
  for (double d = 0.0; d <= kMaxDistance_m + 1e-9; d += 0.5) {
    char label[16];
    std::snprintf(label, sizeof label, "%.1f", d);
    text(plot, label, at(d, -lock_deg) + cv::Point(-12, 20), 0.45);
  }
  for (double s = -lock_deg; s <= lock_deg + 1e-9; s += 5.0) {
    char label[16];
    std::snprintf(label, sizeof label, "%+.0f", s);
    text(plot, label, at(kMaxDistance_m, s) + cv::Point(-45, 5), 0.45);
  }
  text(plot, "distance to the gate ahead, m (body centre to the board's line)",
       {kLeft + 150, kH - 12}, 0.5);
  text(plot, "steering angle while approaching each gate, deg (+ right)", {kLeft, 30}, 0.6);
  // Each command at the body's distance ahead of the next gate not yet crossed.
  std::vector<std::pair<const terrain::CourseBoard*, double>> targets;  // board, crossing time
  for (std::size_t i = 0, k = 0; i < input.boards.size(); ++i) {
    const terrain::CourseBoard& b = input.boards[i];
    if (b.kind == "decoy") continue;
    const double crossed = k < metrics.passages.size() && metrics.passages[k].crossed
                               ? metrics.passages[k].time_s
                               : 1e300;
    targets.emplace_back(&b, crossed);
    ++k;
  }
  const double t0 = input.truth.empty() ? 0.0 : input.truth.front().t_s;
  std::size_t next = 0, index = 0;
  std::vector<cv::Point> curve;
  const auto flush = [&] {
    if (curve.size() >= 2) {
      cv::polylines(plot, curve, false, speedColour(static_cast<double>(index % 8) / 7.0), 1,
                    cv::LINE_AA);
    }
    curve.clear();
  };
  for (const CommandTiming& c : input.commands) {
    const double t = c.utime * 1e-6 - t0;
    while (next < targets.size() && t > targets[next].second) {
      flush();
      ++next;
      ++index;
    }
    if (next >= targets.size()) break;
    const auto found = std::lower_bound(path.begin(), path.end(), c.utime * 1e-6,
                                        [](const PathPoint& p, double v) { return p.t_s < v; });
    if (found == path.end()) break;
    const terrain::CourseBoard& board = *targets[next].first;
    const double h = board.heading_deg * kDeg;
    const double distance = -(found->ne - Eigen::Vector2d(board.north_m, board.east_m))
                                 .dot(Eigen::Vector2d(std::cos(h), std::sin(h)));
    if (distance < 0.0 || distance > kMaxDistance_m) continue;
    curve.push_back(at(distance, c.steer_rad / kDeg));
  }
  flush();
  writePng(steering_png, plot);
}

}  // namespace nadir::control
