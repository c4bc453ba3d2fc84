#include "terrain/geo_world.h"

#include <GeographicLib/Constants.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

namespace nadir::terrain {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// Knot indices 0, step, 2 step, ..., always ending at n - 1.
std::vector<int> knotIndices(int n, int step) {
  std::vector<int> knots;
  for (int i = 0; i < n - 1; i += step) knots.push_back(i);
  knots.push_back(n - 1);
  return knots;
}

// Lagrange interpolation through up to 4 consecutive knots around an index:
// cubic, so it follows the mapping's curvature terms exactly.
struct KnotWeights {
  std::size_t first = 0;  // index of the first knot used
  std::size_t count = 0;
  std::array<double, 4> weight{};
};

std::vector<KnotWeights> knotWeights(const std::vector<int>& knots, int n) {
  const std::size_t m = knots.size();
  const std::size_t count = std::min<std::size_t>(m, 4);
  std::vector<KnotWeights> out(static_cast<std::size_t>(n));
  std::size_t k = 0;  // knots[k] <= i < knots[k + 1]
  for (int i = 0; i < n; ++i) {
    while (k + 2 < m && i >= knots[k + 1]) ++k;
    KnotWeights& w = out[static_cast<std::size_t>(i)];
    w.count = count;
    w.first = std::min(k > 0 ? k - 1 : 0, m - count);
    for (std::size_t a = 0; a < count; ++a) {
      double weight = 1.0;
      const double xa = knots[w.first + a];
      for (std::size_t b = 0; b < count; ++b) {
        if (b != a) weight *= (i - knots[w.first + b]) / (xa - knots[w.first + b]);
      }
      w.weight[a] = weight;
    }
  }
  return out;
}

// NED of a latitude/longitude at the height that puts it on the tangent plane
// (down = 0), i.e. where a query groundUp_m(north, east) would land.
Eigen::Vector3d nedOnPlane(const core::LocalNedFrame& frame, double lat_rad, double lon_rad) {
  double alt_m = 0.0;
  Eigen::Vector3d ned = Eigen::Vector3d::Zero();
  for (int iteration = 0; iteration < 3; ++iteration) {
    ned = frame.nedFromGeodetic({lat_rad, lon_rad, alt_m});
    alt_m += ned.z();
  }
  return ned;
}

// The largest north/east box inside a raster's footprint, from points along
// its outer edges.
WorldExtent footprintBox(const core::LocalNedFrame& frame, const RasterGeoref& georef, int width,
                         int height, const std::string& source) {
  constexpr int kSamplesPerEdge = 64;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  WorldExtent box{-kInf, kInf, -kInf, kInf};
  const double west = -0.5;
  const double east = width - 0.5;
  const double north = -0.5;
  const double south = height - 0.5;
  for (int i = 0; i <= kSamplesPerEdge; ++i) {
    const double t = static_cast<double>(i) / kSamplesPerEdge;
    const auto ned_of = [&](double col, double row) {
      const core::Geodetic g = georef.geodeticFromPixel({col, row});
      if (!std::isfinite(g.lat_rad) || !std::isfinite(g.lon_rad) ||
          std::abs(g.lat_rad) > std::numbers::pi / 2) {
        throw TerrainError(source + ": its footprint is not a valid position in " +
                           georef.crs.name());
      }
      return nedOnPlane(frame, g.lat_rad, g.lon_rad);
    };
    box.north_max_m = std::min(box.north_max_m, ned_of(west + t * (east - west), north).x());
    box.north_min_m = std::max(box.north_min_m, ned_of(west + t * (east - west), south).x());
    box.east_min_m = std::max(box.east_min_m, ned_of(west, north + t * (south - north)).y());
    box.east_max_m = std::min(box.east_max_m, ned_of(east, north + t * (south - north)).y());
  }
  return box;
}

double finestGroundSpacing_m(const RasterGeoref& georef, int width, int height) {
  const PixelGroundSize size = georef.groundPixelSize(width, height);
  return std::min(size.col_m, size.row_m);
}

std::array<double, 3> tint(double t) {
  struct Stop {
    double at;
    std::array<double, 3> rgb;
  };
  static constexpr std::array<Stop, 5> kStops{{{0.0, {70, 120, 60}},
                                               {0.3, {140, 160, 90}},
                                               {0.6, {175, 145, 105}},
                                               {0.85, {140, 110, 90}},
                                               {1.0, {240, 240, 240}}}};
  t = std::clamp(t, 0.0, 1.0);
  std::size_t k = 0;
  while (k + 2 < kStops.size() && t > kStops[k + 1].at) ++k;
  const double u = (t - kStops[k].at) / (kStops[k + 1].at - kStops[k].at);
  std::array<double, 3> out{};
  for (std::size_t c = 0; c < 3; ++c) {
    out[c] = kStops[k].rgb[c] + u * (kStops[k + 1].rgb[c] - kStops[k].rgb[c]);
  }
  return out;
}

// Maps the pixel centres of a size_px x size_px grid over a tangent-plane
// square to a raster's pixels, one output row at a time (see
// rasterPixelsOfSquare).
class SquareMapper {
 public:
  SquareMapper(const core::LocalNedFrame& frame, const RasterGeoref& georef,
               const GroundSquare& square, int size_px)
      : n_(size_px) {
    const double pixel_m = square.size_m / n_;
    const int step =
        std::clamp(static_cast<int>(kKnotSpacing_m / std::max(pixel_m, 1e-9)), 1, kMaxKnotStep_px);
    const std::vector<int> knots = knotIndices(n_, step);
    m_ = knots.size();
    at_knot_.resize(m_ * m_);
    for (std::size_t ki = 0; ki < m_; ++ki) {
      const double north_m = square.north_min_m + square.size_m * (1.0 - (knots[ki] + 0.5) / n_);
      for (std::size_t kj = 0; kj < m_; ++kj) {
        const double east_m = square.east_min_m + square.size_m * (knots[kj] + 0.5) / n_;
        at_knot_[ki * m_ + kj] =
            georef.pixelFromGeodetic(frame.geodeticFromNed({north_m, east_m, 0.0}));
      }
    }
    // Rows and columns share the knots, so one set of weights serves both.
    weights_ = knotWeights(knots, n_);
    knot_row_.resize(m_);
  }

  // Output row i (0 = north) into out[0 .. size_px - 1]. Not thread-safe:
  // one mapper per call.
  void row(int i, PixelPoint* out) const {
    const KnotWeights& wi = weights_[static_cast<std::size_t>(i)];
    for (std::size_t kj = 0; kj < m_; ++kj) {
      PixelPoint sum;
      for (std::size_t a = 0; a < wi.count; ++a) {
        const PixelPoint& p = at_knot_[(wi.first + a) * m_ + kj];
        sum.col += wi.weight[a] * p.col;
        sum.row += wi.weight[a] * p.row;
      }
      knot_row_[kj] = sum;
    }
    for (int j = 0; j < n_; ++j) {
      const KnotWeights& wj = weights_[static_cast<std::size_t>(j)];
      PixelPoint sum;
      for (std::size_t b = 0; b < wj.count; ++b) {
        const PixelPoint& p = knot_row_[wj.first + b];
        sum.col += wj.weight[b] * p.col;
        sum.row += wj.weight[b] * p.row;
      }
      out[j] = sum;
    }
  }

 private:
  int n_ = 0;
  std::size_t m_ = 0;
  std::vector<PixelPoint> at_knot_;
  std::vector<KnotWeights> weights_;
  mutable std::vector<PixelPoint> knot_row_;
};

}  // namespace

void rasterPixelsOfSquare(const core::LocalNedFrame& frame, const RasterGeoref& georef,
                          const GroundSquare& square, int size_px,
                          std::vector<PixelPoint>& pixels) {
  pixels.resize(static_cast<std::size_t>(std::max(size_px, 0)) *
                static_cast<std::size_t>(std::max(size_px, 0)));
  if (size_px <= 0) return;
  const SquareMapper mapper(frame, georef, square, size_px);
  for (int i = 0; i < size_px; ++i) {
    mapper.row(i, &pixels[static_cast<std::size_t>(i) * static_cast<std::size_t>(size_px)]);
  }
}

ImageryRaster shadedRelief(const ElevationRaster& elevation) {
  const int width = elevation.width;
  const int height = elevation.height;
  const auto [min_it, max_it] =
      std::minmax_element(elevation.height_m.begin(), elevation.height_m.end());
  const double low_m = *min_it;
  const double range_m = std::max(static_cast<double>(*max_it) - low_m, 1.0);

  // Sun from the north-west (azimuth 315 deg), 45 deg up; east, north, up.
  const double sun_elevation_rad = 45.0 * kRadPerDeg;
  const double sun_azimuth_rad = 315.0 * kRadPerDeg;
  const Eigen::Vector3d sun(std::sin(sun_azimuth_rad) * std::cos(sun_elevation_rad),
                            std::cos(sun_azimuth_rad) * std::cos(sun_elevation_rad),
                            std::sin(sun_elevation_rad));

  const RasterGeoref& georef = elevation.georef;
  const double a = GeographicLib::Constants::WGS84_a();
  const double f = GeographicLib::Constants::WGS84_f();
  const double e2 = f * (2.0 - f);
  const PixelGroundSize centre_size = georef.groundPixelSize(width, height);

  ImageryRaster relief;
  relief.rgb.create(height, width, CV_8UC3);
  relief.georef = georef;
  relief.source = "shaded relief of " + elevation.source;
  for (int row = 0; row < height; ++row) {
    // A geographic raster's columns narrow towards the pole.
    double col_m = centre_size.col_m;
    double row_m = centre_size.row_m;
    if (georef.crs.kind == Crs::Kind::kGeographic) {
      const double lat_rad = georef.geodeticFromPixel({0.0, static_cast<double>(row)}).lat_rad;
      const double w = std::sqrt(1.0 - e2 * std::sin(lat_rad) * std::sin(lat_rad));
      col_m = std::max(std::abs(georef.pixel_dx) * kRadPerDeg * a / w * std::cos(lat_rad), 1e-3);
      row_m = std::abs(georef.pixel_dy) * kRadPerDeg * a * (1.0 - e2) / (w * w * w);
    }
    const int north_row = std::max(row - 1, 0);
    const int south_row = std::min(row + 1, height - 1);
    auto* out = relief.rgb.ptr<cv::Vec3b>(row);
    for (int col = 0; col < width; ++col) {
      const int west_col = std::max(col - 1, 0);
      const int east_col = std::min(col + 1, width - 1);
      const double dz_de = east_col > west_col
                               ? (elevation.at(east_col, row) - elevation.at(west_col, row)) /
                                     ((east_col - west_col) * col_m)
                               : 0.0;
      const double dz_dn = south_row > north_row
                               ? (elevation.at(col, north_row) - elevation.at(col, south_row)) /
                                     ((south_row - north_row) * row_m)
                               : 0.0;
      const Eigen::Vector3d normal = Eigen::Vector3d(-dz_de, -dz_dn, 1.0).normalized();
      const double shade = 0.25 + 0.75 * std::max(normal.dot(sun), 0.0);
      const std::array<double, 3> colour = tint((elevation.at(col, row) - low_m) / range_m);
      out[col] = cv::Vec3b(cv::saturate_cast<unsigned char>(colour[0] * shade),
                           cv::saturate_cast<unsigned char>(colour[1] * shade),
                           cv::saturate_cast<unsigned char>(colour[2] * shade));
    }
  }
  return relief;
}

GeoWorld::GeoWorld(ElevationRaster elevation, std::optional<ImageryRaster> imagery,
                   const core::LocalNedFrame& frame)
    : elevation_(std::move(elevation)), frame_(frame) {
  if (elevation_.width < 1 || elevation_.height < 1 ||
      elevation_.height_m.size() != static_cast<std::size_t>(elevation_.width) *
                                        static_cast<std::size_t>(elevation_.height)) {
    throw TerrainError(elevation_.source + ": empty or inconsistent elevation raster (" +
                       std::to_string(elevation_.width) + " x " +
                       std::to_string(elevation_.height) + ", " +
                       std::to_string(elevation_.height_m.size()) + " samples)");
  }
  extent_ = footprintBox(frame_, elevation_.georef, elevation_.width, elevation_.height,
                         elevation_.source);
  elevation_resolution_m_ =
      finestGroundSpacing_m(elevation_.georef, elevation_.width, elevation_.height);
  has_imagery_ = imagery.has_value();
  if (has_imagery_) {
    imagery_ = std::move(*imagery);
    if (imagery_.rgb.empty() || imagery_.rgb.type() != CV_8UC3) {
      throw TerrainError(imagery_.source + ": imagery must be a non-empty CV_8UC3 image");
    }
    const WorldExtent box =
        footprintBox(frame_, imagery_.georef, imagery_.width(), imagery_.height(), imagery_.source);
    extent_.north_min_m = std::max(extent_.north_min_m, box.north_min_m);
    extent_.north_max_m = std::min(extent_.north_max_m, box.north_max_m);
    extent_.east_min_m = std::max(extent_.east_min_m, box.east_min_m);
    extent_.east_max_m = std::min(extent_.east_max_m, box.east_max_m);
    imagery_resolution_m_ =
        finestGroundSpacing_m(imagery_.georef, imagery_.width(), imagery_.height());
  } else {
    imagery_ = shadedRelief(elevation_);
    imagery_resolution_m_ = elevation_resolution_m_;
  }
  if (!(extent_.north_min_m < extent_.north_max_m && extent_.east_min_m < extent_.east_max_m)) {
    throw TerrainError(elevation_.source + (has_imagery_
                                                ? " and " + imagery_.source + " do not overlap"
                                                : ": the DEM's footprint is empty"));
  }
}

double GeoWorld::groundUp_m(double north_m, double east_m) const {
  if (!std::isfinite(north_m) || !std::isfinite(east_m)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double north_in_m = std::clamp(north_m, extent_.north_min_m, extent_.north_max_m);
  const double east_in_m = std::clamp(east_m, extent_.east_min_m, extent_.east_max_m);
  const core::Geodetic on_plane = frame_.geodeticFromNed({north_in_m, east_in_m, 0.0});
  const double height_m =
      elevation_.heightAtPixelClamped(elevation_.georef.pixelFromGeodetic(on_plane));
  return -frame_.nedFromGeodetic({on_plane.lat_rad, on_plane.lon_rad, height_m}).z();
}

void GeoWorld::imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const {
  if (size_px <= 0) {
    rgb.release();
    return;
  }
  rgb.create(size_px, size_px, CV_8UC3);
  const SquareMapper mapper(frame_, imagery_.georef, square, size_px);
  std::vector<PixelPoint> pixels(static_cast<std::size_t>(size_px));

  // Bilinear in fixed point with 1/256 pixel steps: plenty for 8-bit colour
  // and about twice as fast as doubles.
  const cv::Mat& source = imagery_.rgb;
  const int max_col = source.cols - 1;
  const int max_row = source.rows - 1;
  const double max_col_d = max_col;
  const double max_row_d = max_row;
  const std::size_t row_step = source.step[0];
  const unsigned char* data = source.data;
  for (int i = 0; i < size_px; ++i) {
    auto* out = rgb.ptr<unsigned char>(i);
    mapper.row(i, pixels.data());
    for (int j = 0; j < size_px; ++j, out += 3) {
      const PixelPoint& p = pixels[static_cast<std::size_t>(j)];
      if (!std::isfinite(p.col) || !std::isfinite(p.row)) {
        out[0] = out[1] = out[2] = 0;
        continue;
      }
      const int col_fixed = static_cast<int>(std::clamp(p.col, 0.0, max_col_d) * 256.0 + 0.5);
      const int row_fixed = static_cast<int>(std::clamp(p.row, 0.0, max_row_d) * 256.0 + 0.5);
      const int c0 = std::min(col_fixed >> 8, max_col);
      const int r0 = std::min(row_fixed >> 8, max_row);
      const int fc = col_fixed - (c0 << 8);
      const int fr = row_fixed - (r0 << 8);
      const int dc = c0 < max_col ? 3 : 0;
      const std::size_t dr = r0 < max_row ? row_step : 0;
      const unsigned char* nw = data + static_cast<std::size_t>(r0) * row_step + 3 * c0;
      const unsigned char* sw = nw + dr;
      for (int k = 0; k < 3; ++k) {
        const int top = nw[k] * (256 - fc) + nw[k + dc] * fc;
        const int bottom = sw[k] * (256 - fc) + sw[k + dc] * fc;
        out[k] = static_cast<unsigned char>((top * (256 - fr) + bottom * fr + 32768) >> 16);
      }
    }
  }
}

}  // namespace nadir::terrain
