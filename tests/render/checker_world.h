#pragma once
// A flat test world: ground at a fixed height, a checkerboard of known squares
// centred on the origin inside a white margin, mid-gray elsewhere. Imagery is
// area-averaged (4 x 4 samples per pixel) so edges land where they truly are.

#include <cmath>

#include <opencv2/core.hpp>

#include "terrain/world.h"

namespace nadir::test {

class CheckerWorld : public terrain::World {
 public:
  // squares_north x squares_east squares of square_m, centred on (0, 0).
  CheckerWorld(int squares_north, int squares_east, double square_m, double ground_up_m = 0.0)
      : squares_north_(squares_north),
        squares_east_(squares_east),
        square_m_(square_m),
        ground_up_m_(ground_up_m) {}

  double groundUp_m(double, double) const override { return ground_up_m_; }

  void imagery(const terrain::GroundSquare& sq, int size_px, cv::Mat& rgb) const override {
    rgb.create(size_px, size_px, CV_8UC3);
    const double cell_m = sq.size_m / size_px;
    constexpr int kSamples = 4;
    for (int row = 0; row < size_px; ++row) {
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
        rgb.at<cv::Vec3b>(row, col) = cv::Vec3b(v, v, v);
      }
    }
  }

  double imageryResolution_m() const override { return 0.005; }
  double elevationResolution_m() const override { return 100.0; }
  terrain::WorldExtent extent() const override { return {-200, 200, -200, 200}; }

  // Inner corner (i, j), i along north from the south, j along east from the west.
  double cornerNorth_m(int i) const { return (i + 1 - 0.5 * squares_north_) * square_m_; }
  double cornerEast_m(int j) const { return (j + 1 - 0.5 * squares_east_) * square_m_; }

 private:
  double value(double north, double east) const {
    const double half_n = 0.5 * squares_north_ * square_m_,
                 half_e = 0.5 * squares_east_ * square_m_;
    if (std::abs(north) < half_n && std::abs(east) < half_e) {
      const int i = static_cast<int>(std::floor((north + half_n) / square_m_));
      const int j = static_cast<int>(std::floor((east + half_e) / square_m_));
      return (i + j) % 2 == 0 ? 20.0 : 235.0;
    }
    if (std::abs(north) < half_n + square_m_ && std::abs(east) < half_e + square_m_) return 235.0;
    return 128.0;
  }

  int squares_north_;
  int squares_east_;
  double square_m_;
  double ground_up_m_;
};

}  // namespace nadir::test
