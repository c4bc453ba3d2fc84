#include "terrain/checkerboard_world.h"

#include <cmath>

#include <opencv2/core.hpp>

namespace nadir::terrain {

void CheckerboardParams::visit(core::ParamVisitor& v) {
  v.field("inner_cols", &inner_cols,
          {.doc = "inner corners along the board's rows (east)", .min = 2, .max = 200});
  v.field("inner_rows", &inner_rows,
          {.doc = "inner corners along the board's columns (north)", .min = 2, .max = 200});
  v.field("square_m", &square_m, {.doc = "side of one square, m", .min = 1e-4, .max = 100});
}

CheckerboardWorld::CheckerboardWorld(const CheckerboardParams& params, double ground_up_m)
    : params_(params), ground_up_m_(ground_up_m) {
  CheckerboardParams copy = params;
  core::validateParams([&copy](core::ParamVisitor& v) { copy.visit(v); }, "checkerboard");
}

double CheckerboardWorld::groundUp_m(double, double) const { return ground_up_m_; }

double CheckerboardWorld::imageryResolution_m() const { return params_.square_m / 200.0; }

double CheckerboardWorld::elevationResolution_m() const { return 100.0 * params_.square_m; }

WorldExtent CheckerboardWorld::extent() const {
  const double half_m = 200.0 * params_.square_m;
  return {-half_m, half_m, -half_m, half_m};
}

double CheckerboardWorld::cornerNorth_m(int row) const {
  return (row + 1 - 0.5 * (params_.inner_rows + 1)) * params_.square_m;
}

double CheckerboardWorld::cornerEast_m(int col) const {
  return (col + 1 - 0.5 * (params_.inner_cols + 1)) * params_.square_m;
}

void CheckerboardWorld::imagery(const GroundSquare& sq, int size_px, cv::Mat& rgb) const {
  rgb.create(size_px, size_px, CV_8UC3);
  const double cell_m = sq.size_m / size_px;
  constexpr int kSamples = 4;
  for (int row = 0; row < size_px; ++row) {
    auto* out = rgb.ptr<cv::Vec3b>(row);
    for (int col = 0; col < size_px; ++col) {
      double sum = 0.0;
      for (int i = 0; i < kSamples; ++i) {
        for (int j = 0; j < kSamples; ++j) {
          const double north = sq.north_min_m + sq.size_m - (row + (i + 0.5) / kSamples) * cell_m;
          const double east = sq.east_min_m + (col + (j + 0.5) / kSamples) * cell_m;
          sum += value(north, east);
        }
      }
      const auto v = static_cast<unsigned char>(std::lround(sum / (kSamples * kSamples)));
      out[col] = cv::Vec3b(v, v, v);
    }
  }
}

double CheckerboardWorld::value(double north_m, double east_m) const {
  const int squares_north = params_.inner_rows + 1;
  const int squares_east = params_.inner_cols + 1;
  const double half_n = 0.5 * squares_north * params_.square_m;
  const double half_e = 0.5 * squares_east * params_.square_m;
  if (std::abs(north_m) < half_n && std::abs(east_m) < half_e) {
    const int i = static_cast<int>(std::floor((north_m + half_n) / params_.square_m));
    const int j = static_cast<int>(std::floor((east_m + half_e) / params_.square_m));
    return (i + j) % 2 == 0 ? kDark : kLight;
  }
  const bool margin =
      std::abs(north_m) < half_n + params_.square_m && std::abs(east_m) < half_e + params_.square_m;
  return margin ? kLight : kGround;
}

}  // namespace nadir::terrain
