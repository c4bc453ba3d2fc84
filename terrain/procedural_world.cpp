#include "terrain/procedural_world.h"

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "terrain/procedural/generator.h"

// The procedural world is drawn by the parts in terrain/procedural/, each a
// pure function of the seed and the position:
//  - relief.cpp: domain-warped ridged/smooth fBm hills that fall into valleys
//    along the rivers, a regional tilt down the flow direction and a carved
//    channel;
//  - water.cpp: the rivers (the zero set of a flow-aligned noise, its signed
//    distance from the noise's analytic gradient), their banks and water;
//  - blocks.cpp, fields.cpp, hedges_roads.cpp: a road network on the edges of
//    a warped Voronoi diagram of "blocks"; inside each block strip-like
//    Voronoi fields in the block's own orientation, each with a crop, a colour
//    and rows in its own direction; hedgerows and farm tracks;
//  - forests.cpp: a forest mask (clumpy noise) with individual tree crowns;
//    riverside, hedgerow and lone trees;
//  - buildings.cpp: farmsteads along the roads;
//  - shading.cpp: Lambertian hillshade from the same sun that casts the
//    shadows of trees and buildings.
// A square is rendered in blocks of at most kBlockPx pixels (in parallel with
// cv::parallel_for_) by render_block.cpp.

namespace nadir::terrain {
namespace procedural {

Generator::Generator(const ProceduralWorldParams& params)
    : p(params), table(mix64(static_cast<u64>(params.seed) ^ 0x7AB1E5EEDULL)) {
  seed = mix64(static_cast<u64>(p.seed) ^ 0x6E61646972ULL);
  // One independent hash seed per layer (stream numbers are fixed: changing
  // one layer leaves the others as they were).
  const auto stream = [this](u64 k) { return mix64(seed + 0x9E3779B97F4A7C15ULL * k); };
  s_warp_x = stream(1);
  s_warp_y = stream(2);
  s_hills = stream(3);
  s_base = stream(4);
  s_river = stream(5);
  s_meander1 = stream(6);
  s_meander2 = stream(7);
  s_width = stream(8);
  s_valley = stream(9);
  s_bwarp_x = stream(12);
  s_bwarp_y = stream(13);
  s_block = stream(14);
  s_field = stream(15);
  s_region = stream(16);
  s_tint = stream(18);
  s_soil = stream(19);
  s_conifer = stream(20);
  s_trees = stream(22);
  s_bld = stream(24);
  s_settle = stream(25);
  s_roof = stream(26);

  const double flow_angle = 2.0 * kPi * uniform(seed, 100);
  flow_x = std::cos(flow_angle);
  flow_y = std::sin(flow_angle);
  setSun();
  tilt_per_m = 0.2 * p.relief_m / p.size_m;
  // Last: the calibrations draw fields and forest with all of the above.
  calibrateFields();
  calibrateForests();
}

}  // namespace procedural

namespace {

constexpr int kBlockPx = 256;

}  // namespace

struct ProceduralWorld::Impl {
  explicit Impl(const ProceduralWorldParams& params) : gen(params) {}
  procedural::Generator gen;
};

ProceduralWorld::ProceduralWorld(const ProceduralWorldParams& params) {
  ProceduralWorldParams checked = params;
  core::validateParams([&checked](core::ParamVisitor& v) { checked.visit(v); }, "procedural world");
  impl_ = std::make_unique<const Impl>(checked);
}

ProceduralWorld::~ProceduralWorld() = default;

double ProceduralWorld::groundUp_m(double north_m, double east_m) const {
  const double half = 0.5 * impl_->gen.p.size_m;
  const double n = std::clamp(north_m, -half, half);
  const double e = std::clamp(east_m, -half, half);
  return impl_->gen.terrain(e, n, 0.0).up;
}

void ProceduralWorld::imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const {
  drawImagery(square, size_px, true, rgb);
}

void ProceduralWorld::imageryBeneathObjects(const GroundSquare& square, int size_px,
                                            cv::Mat& rgb) const {
  drawImagery(square, size_px, false, rgb);
}

void ProceduralWorld::drawImagery(const GroundSquare& square, int size_px, bool tops,
                                  cv::Mat& rgb) const {
  if (size_px <= 0 || !(square.size_m > 0.0) || !std::isfinite(square.size_m) ||
      !std::isfinite(square.north_min_m) || !std::isfinite(square.east_min_m)) {
    throw std::invalid_argument("ProceduralWorld::imagery: needs size_px > 0 and a finite square");
  }
  rgb.create(size_px, size_px, CV_8UC3);
  const int nb = (size_px + kBlockPx - 1) / kBlockPx;
  const procedural::Generator& gen = impl_->gen;
  cv::parallel_for_(cv::Range(0, nb * nb), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      const int br = b / nb, bc = b % nb;
      procedural::PixelFrame pf;
      pf.east_min = square.east_min_m;
      pf.north_min = square.north_min_m;
      pf.px = square.size_m / size_px;
      pf.tops = tops;
      pf.size_px = size_px;
      pf.r0 = br * kBlockPx;
      pf.c0 = bc * kBlockPx;
      pf.rows = std::min(size_px, pf.r0 + kBlockPx) - pf.r0;
      pf.cols = std::min(size_px, pf.c0 + kBlockPx) - pf.c0;
      gen.renderBlock(pf, rgb);
    }
  });
}

double ProceduralWorld::imageryResolution_m() const { return impl_->gen.p.imagery_resolution_m; }

double ProceduralWorld::elevationResolution_m() const { return 4.0; }

WorldExtent ProceduralWorld::extent() const {
  const double half = 0.5 * impl_->gen.p.size_m;
  return {-half, half, -half, half};
}

std::vector<GroundObject> ProceduralWorld::objects(const GroundSquare& square) const {
  if (!(square.size_m > 0.0) || !std::isfinite(square.size_m) ||
      !std::isfinite(square.north_min_m) || !std::isfinite(square.east_min_m)) {
    throw std::invalid_argument("ProceduralWorld::objects: needs a finite, non-empty square");
  }
  const procedural::Generator& gen = impl_->gen;
  const double n0 = square.north_min_m, e0 = square.east_min_m, size = square.size_m;
  const auto inside = [&](double east, double north) {
    return north >= n0 && north < n0 + size && east >= e0 && east < e0 + size;
  };
  // Internally x is east and y north.
  const procedural::WorldBox box{e0, n0, e0 + size, n0 + size};
  // As the imagery writes its pixels (procedural/shading.cpp).
  const auto colour = [](const procedural::Rgb& c) {
    return std::array<std::uint8_t, 3>{cv::saturate_cast<uchar>(c.r), cv::saturate_cast<uchar>(c.g),
                                       cv::saturate_cast<uchar>(c.b)};
  };
  std::vector<GroundObject> out;
  std::vector<procedural::Tree> trees;
  gen.collectTrees(box, procedural::TreeDraw{}, trees);
  for (const procedural::Tree& t : trees) {
    if (!inside(t.x, t.y) || t.alpha <= 0.0) continue;
    GroundObject o;
    o.kind = t.conifer ? GroundObject::Kind::kConifer : GroundObject::Kind::kBroadleaf;
    o.north_m = t.y;
    o.east_m = t.x;
    o.base_up_m = groundUp_m(t.y, t.x);
    o.height_m = t.height;
    o.half_length_m = o.half_width_m = t.r;
    o.rgb = colour(t.colour);
    out.push_back(o);
  }
  // A farmstead's buildings lie within about 100 m of the cell that places it.
  std::vector<procedural::Building> buildings;
  std::vector<procedural::Yard> yards;
  gen.collectBuildings(box.grown(150.0), buildings, yards);
  for (const procedural::Building& b : buildings) {
    if (!inside(b.x, b.y)) continue;
    GroundObject o;
    o.kind = GroundObject::Kind::kBuilding;
    o.north_m = b.y;
    o.east_m = b.x;
    o.base_up_m = groundUp_m(b.y, b.x);
    o.height_m = b.height;
    o.half_length_m = b.hl;
    o.half_width_m = b.hw;
    o.heading_rad = std::atan2(b.ux, b.uy);
    o.gable = b.gable;
    o.rgb = colour(b.roof);
    out.push_back(o);
  }
  return out;
}

std::array<double, 3> ProceduralWorld::sunDirectionNed() const {
  return World::sunDirectionNed(impl_->gen.p.sun_azimuth_deg, impl_->gen.p.sun_elevation_deg);
}

const ProceduralWorldParams& ProceduralWorld::params() const { return impl_->gen.p; }

}  // namespace nadir::terrain
