#include "run/track_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace nadir::run {
namespace {

// Colour per source (BGR), in legend order after the truth's black.
const cv::Scalar kColours[] = {{40, 40, 220}, {200, 120, 20}, {30, 160, 30}, {170, 40, 170}};

// The largest "nice" length (1, 2 or 5 x 10^k) not above limit.
double niceLength(double limit) {
  const double decade = std::pow(10.0, std::floor(std::log10(limit)));
  for (const double step : {5.0, 2.0, 1.0}) {
    if (step * decade <= limit) return step * decade;
  }
  return decade;
}

}  // namespace

void writeTrackPlot(const std::string& png_path, const core::Trajectory& truth,
                    const std::map<std::string, core::Trajectory>& sources,
                    const std::string& title) {
  constexpr int kSize = 900, kMargin = 60;
  cv::Mat image(kSize, kSize, CV_8UC3, cv::Scalar(255, 255, 255));
  double min_n = 1e300, max_n = -1e300, min_e = 1e300, max_e = -1e300;
  const auto extend = [&](const core::Trajectory& track) {
    for (const core::StampedPose& pose : track) {
      min_n = std::min(min_n, pose.p_ned_m.x());
      max_n = std::max(max_n, pose.p_ned_m.x());
      min_e = std::min(min_e, pose.p_ned_m.y());
      max_e = std::max(max_e, pose.p_ned_m.y());
    }
  };
  extend(truth);
  for (const auto& entry : sources) extend(entry.second);
  if (min_n > max_n) {
    min_n = min_e = -1.0;
    max_n = max_e = 1.0;
  }
  const double span_m = std::max({max_n - min_n, max_e - min_e, 1.0});
  const double scale = (kSize - 2 * kMargin) / span_m;
  const double centre_n = 0.5 * (min_n + max_n), centre_e = 0.5 * (min_e + max_e);
  const auto pixel = [&](const Eigen::Vector3d& p) {
    return cv::Point(static_cast<int>(std::lround(kSize / 2 + (p.y() - centre_e) * scale)),
                     static_cast<int>(std::lround(kSize / 2 - (p.x() - centre_n) * scale)));
  };
  const auto draw = [&](const core::Trajectory& track, const cv::Scalar& colour, int width) {
    std::vector<cv::Point> points;
    for (const core::StampedPose& pose : track) points.push_back(pixel(pose.p_ned_m));
    if (points.size() >= 2) cv::polylines(image, points, false, colour, width, cv::LINE_AA);
    if (!points.empty()) cv::circle(image, points.front(), 5, colour, cv::FILLED, cv::LINE_AA);
  };
  draw(truth, cv::Scalar(0, 0, 0), 2);
  int legend_y = 55;
  cv::putText(image, title, {20, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.7, {0, 0, 0}, 2, cv::LINE_AA);
  cv::putText(image, "truth", {40, legend_y}, cv::FONT_HERSHEY_SIMPLEX, 0.55, {0, 0, 0}, 1,
              cv::LINE_AA);
  cv::line(image, {20, legend_y - 5}, {35, legend_y - 5}, {0, 0, 0}, 2);
  std::size_t index = 0;
  for (const auto& [name, track] : sources) {
    const cv::Scalar colour = kColours[index++ % std::size(kColours)];
    draw(track, colour, 2);
    legend_y += 22;
    cv::line(image, {20, legend_y - 5}, {35, legend_y - 5}, colour, 2);
    cv::putText(image, name, {40, legend_y}, cv::FONT_HERSHEY_SIMPLEX, 0.55, colour, 1,
                cv::LINE_AA);
  }
  // Scale bar, bottom left, and the north arrow's label.
  const double bar_m = niceLength(0.25 * span_m);
  const int bar_px = static_cast<int>(std::lround(bar_m * scale));
  cv::line(image, {20, kSize - 25}, {20 + bar_px, kSize - 25}, {0, 0, 0}, 2);
  char label[32];
  std::snprintf(label, sizeof(label), "%g m", bar_m);
  cv::putText(image, label, {20, kSize - 35}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1,
              cv::LINE_AA);
  cv::putText(image, "N up, E right", {kSize - 150, kSize - 25}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
              {0, 0, 0}, 1, cv::LINE_AA);
  if (!cv::imwrite(png_path, image)) throw std::runtime_error("cannot write " + png_path);
}

}  // namespace nadir::run
