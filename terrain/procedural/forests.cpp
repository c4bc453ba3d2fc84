// Forests: a forest mask (clumpy noise) with individual tree crowns and their
// shadows, drawn while the crowns span a few pixels; beyond that forests take
// their mean colour (calibrated at construction by drawing closed forest) with
// a crown-scale grain. Also the riverside, hedgerow and lone trees, which are
// drawn the same way.

#include <algorithm>
#include <cmath>
#include <vector>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {
namespace {

constexpr Rgb kForestFloor{60, 68, 46};
constexpr Rgb kBroadleaf{84, 104, 58};
constexpr Rgb kConifer{60, 78, 54};

}  // namespace

// Forest where positive: clumps of kilometres with ragged edges. Cheap
// enough (table noise) to evaluate exactly wherever an edge may be near.
double Generator::forestMask(double x, double y) const {
  return forest_large(table, x, y) + 0.22 * forest_edge(table, x, y) - forest_threshold;
}

Rgb Generator::forestMean(double conifer_share) const {
  const double t = std::clamp(conifer_share, 0.0, 1.0) * (forest_mean.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(t), forest_mean.size() - 2);
  return mix(forest_mean[i], forest_mean[i + 1], t - static_cast<double>(i));
}

// Forest stands: age and species patches, tens to hundreds of metres.
double Generator::stand(double x, double y) const { return stand_full(table, x, y); }

// The forest mask's gradient on the grid (channel 10, from channel 3), for
// the mask's area coverage of a pixel.
void Generator::forestMaskGradient(SmoothGrid& grid) {
  constexpr int kCh = SmoothGrid::kCh;
  const int nx = grid.nx, ny = grid.ny;
  const double s = grid.s;
  std::vector<double>& nodes = grid.nodes;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = grid.index(i, j);
      const int ia = std::max(i - 1, 0), ib = std::min(i + 1, nx - 1);
      const int ja = std::max(j - 1, 0), jb = std::min(j + 1, ny - 1);
      const auto idx = [&](int a, int b) { return grid.index(a, b); };
      const double mx =
          (nodes[idx(ib, j) * kCh + 3] - nodes[idx(ia, j) * kCh + 3]) / ((ib - ia) * s);
      const double my =
          (nodes[idx(i, jb) * kCh + 3] - nodes[idx(i, ja) * kCh + 3]) / ((jb - ja) * s);
      nodes[k * kCh + 10] = std::max(std::sqrt(mx * mx + my * my), 1e-6);
    }
  }
}

namespace {

// The forest's cover of pixel g, and the forest over colour. Seen coarsely,
// the canopy reaches a crown's radius beyond the floor. The grid's mask is
// exact enough except near an edge (its error grows as s^2): evaluate it
// there.
double forestOver(const Generator& gen, const GroundPixel& g, const PixelScale& sc, double grid_s,
                  Rgb& colour) {
  const ValueTable& table = gen.table;
  const Pix& f = g.f;
  const double px = sc.px, s = grid_s, x = g.x, y = g.y, coarse_forest = sc.coarse_forest;
  const double reach_mask = coarse_forest * (0.01 + 4.0 * f.mask_grad);
  const double mask =
      std::abs(f.mask + reach_mask) < 3e-4 * s * s + 0.6 * f.mask_grad * std::max(px, 0.5) + 0.01
          ? gen.forestMask(x, y)
          : f.mask;
  const double fc = clamp01(0.5 + (mask + reach_mask) / (f.mask_grad * std::max(px, 0.5)));
  if (fc > 0.0) {
    Rgb mean =
        gen.forestMean(f.conifer) * (1.0 + 0.25 * f.var + 0.18 * sc.stand_octaves(table, x, y));
    if (coarse_forest > 0.0) {
      // Crowns too small to draw still make a grain that averages out
      // slowly (random, so sampling it near the pixel scale cannot alias
      // into patterns).
      const double grain = table.noise(x * sc.grain_scale + 7.7, y * sc.grain_scale + 3.3);
      mean = mean *
             (1.0 + coarse_forest * (0.2 * sc.canopy_octaves(table, x, y) + sc.grain_amp * grain));
    }
    const Rgb floor = kForestFloor * (1.0 + 0.25 * g.detail);
    colour = mix(colour, mix(floor, mean, coarse_forest), fc);
  }
  return fc;
}

}  // namespace

void Generator::paintForest(GroundRow& row, const PixelScale& sc, double grid_s, std::span<Rgb> col,
                            std::span<float> fcov) const {
  for (std::size_t c = 0; c < col.size(); ++c) {
    const double fc = forestOver(*this, row.pixels[c], sc, grid_s, col[c]);
    row.forest_cover[c] = fc;
    fcov[c] = static_cast<float>(fc);
  }
}

namespace {

constexpr double kTreeCell = 5.0;  // one candidate tree per cell, m

// Candidate tree cells [i0, i1] x [j0, j1].
struct CellRange {
  i64 i0, i1, j0, j1;
};

// Cells whose trees' crowns may touch box.
CellRange treeCells(const WorldBox& box) {
  constexpr double kCell = kTreeCell;
  return {static_cast<i64>(std::floor(box.x0 / kCell)) - 1,
          static_cast<i64>(std::floor(box.x1 / kCell)) + 1,
          static_cast<i64>(std::floor(box.y0 / kCell)) - 1,
          static_cast<i64>(std::floor(box.y1 / kCell)) + 1};
}

// Smooth fields for the decisions on a fixed, world-anchored grid, so every
// block and level that draws a tree decides it identically.
class TreeGrid {
 public:
  struct Node {
    double mask, sd, hw, wx, wy, var, conifer;
  };

  // Empty when forced (calibration: no decisions to take).
  TreeGrid(const Generator& gen, const CellRange& cells, bool force) {
    constexpr double kCell = kTreeCell;
    const i64 i0 = cells.i0, i1 = cells.i1, j0 = cells.j0, j1 = cells.j1;
    gx0_ = static_cast<i64>(std::floor(static_cast<double>(i0) * kCell / kGrid)) - 1;
    const i64 gx1 = static_cast<i64>(std::floor(static_cast<double>(i1 + 1) * kCell / kGrid)) + 2;
    gy0_ = static_cast<i64>(std::floor(static_cast<double>(j0) * kCell / kGrid)) - 1;
    const i64 gy1 = static_cast<i64>(std::floor(static_cast<double>(j1 + 1) * kCell / kGrid)) + 2;
    gnx_ = force ? 0 : static_cast<int>(gx1 - gx0_ + 1);
    gny_ = force ? 0 : static_cast<int>(gy1 - gy0_ + 1);
    grid_.resize(static_cast<std::size_t>(gnx_) * gny_);
    for (int j = 0; j < gny_; ++j) {
      for (int i = 0; i < gnx_; ++i) {
        const double x = static_cast<double>(gx0_ + i) * kGrid;
        const double y = static_cast<double>(gy0_ + j) * kGrid;
        TerrainSample t;
        gen.river(x, y, t);
        grid_[static_cast<std::size_t>(j) * gnx_ + i] = {0.0,
                                                         t.sd,
                                                         t.hw,
                                                         gen.blockWarpX(x, y),
                                                         gen.blockWarpY(x, y),
                                                         gen.varNoise(x, y),
                                                         gen.coniferShare(x, y)};
      }
    }
  }

  Node at(double x, double y) const {
    const int gnx = gnx_, gny = gny_;
    const double gx = x / kGrid - static_cast<double>(gx0_);
    const double gy = y / kGrid - static_cast<double>(gy0_);
    const int i = std::clamp(static_cast<int>(std::floor(gx)), 0, gnx - 2);
    const int j = std::clamp(static_cast<int>(std::floor(gy)), 0, gny - 2);
    const double tx = gx - i, ty = gy - j;
    const Node* a = &grid_[static_cast<std::size_t>(j) * gnx + i];
    const Node* c = a + gnx;
    const auto bl = [&](double Node::*f) {
      return (1 - ty) * ((1 - tx) * a->*f + tx * a[1].*f) + ty * ((1 - tx) * c->*f + tx * c[1].*f);
    };
    return Node{bl(&Node::mask), bl(&Node::sd),  bl(&Node::hw),     bl(&Node::wx),
                bl(&Node::wy),   bl(&Node::var), bl(&Node::conifer)};
  }

 private:
  static constexpr double kGrid = 8.0;
  i64 gx0_ = 0, gy0_ = 0;
  int gnx_ = 0, gny_ = 0;
  std::vector<Node> grid_;
};

// Whether a candidate tree stands, and what kind.
struct TreeChoice {
  bool exists = false;
  bool interior = false;  // deep in a forest
  bool conifer = false;
  double size = 1.0;  // crown scale
  double var = 0.0;   // within-forest variation
  double alpha = 0.0;
};

// Closed forest everywhere (calibration). Conifers stand in every cell;
// broadleaf crowns are larger and sparser.
TreeChoice forcedTree(const TreeSite& s, const TreeDraw& draw) {
  TreeChoice ch;
  ch.interior = true;
  ch.alpha = draw.alpha_forest;
  ch.conifer = uniform(s.h, 3) < draw.calibrate_share;
  ch.exists = s.u < (ch.conifer ? 0.97 : 0.65);
  return ch;
}

// Forest trees, scattered trees along the forest's edge, riverside,
// hedgerow and meadow trees; roads and water are kept open. t holds the
// smooth fields at the candidate.
TreeChoice chooseTree(const Generator& gen, const TreeSite& s, const TreeGrid::Node& t,
                      const TreeDraw& draw, TreeLookup& look) {
  const double x = s.x, y = s.y, u = s.u;
  const u64 h = s.h;
  TreeChoice ch;
  ch.alpha = draw.alpha_forest;
  ch.var = t.var;
  const double mask = gen.forestMask(x, y);
  const bool forest = mask > -0.01;
  if (forest ? draw.alpha_forest <= 0.0 : draw.alpha_other <= 0.0) return TreeChoice{};
  // Conifers stand in every cell; broadleaf crowns are larger and sparser.
  if (forest) {
    ch.conifer = uniform(h, 3) < t.conifer;
    ch.exists = u < (ch.conifer ? 0.97 : 0.65);
    ch.interior = mask > 0.3;  // the mask changes by < 0.01 per metre
  } else {
    ch.alpha = draw.alpha_other;
  }
  if (!forest && mask > -0.08 && u < 0.1 * (1.0 + mask * 12.0)) {
    ch.exists = true;  // scattered trees along the forest's edge
  }
  const double bank = std::abs(t.sd) - t.hw;
  if (!ch.exists && bank > 3.0 && bank < 11.0 &&
      u < 0.75 * smooth01(0.5 + 2.0 * gen.table.noise(x / 150.0, y / 150.0))) {
    ch.exists = true;  // riverside trees
    ch.size = 0.9;
  }
  const double qx = x + t.wx, qy = y + t.wy;
  const BlockHit bh = gen.blockAt(qx, qy, look.bcell);
  if (!ch.exists) {  // hedgerows and a few trees in meadows
    ch.exists = gen.fieldEdgeTree(s, bh, qx, qy, look, ch.size);
  }
  if (ch.exists) {  // keep roads and water open
    double hw = 0;
    int site = -1;
    if (gen.roadDistance(bh, qx, qy, hw, site) < hw + 1.5) ch.exists = false;
    if (std::abs(t.sd) < t.hw + 1.5) ch.exists = false;
  }
  return ch;
}

// The tree that stands at s: colour, crown and shadows.
Tree makeTree(const Generator& gen, const TreeSite& s, const TreeChoice& ch, bool force) {
  const double x = s.x, y = s.y, size = ch.size, var = ch.var;
  const double sun_z = gen.sun_z, inv_tan_sun = gen.inv_tan_sun;
  const bool conifer = ch.conifer;
  const u64 h = s.h;
  Tree t;
  t.x = x;
  t.y = y;
  t.h = h;
  t.conifer = conifer;
  t.interior = ch.interior;
  t.alpha = ch.alpha;
  const double k = 0.8 + 0.4 * uniform(h, 4);
  const double hue = uniform(h, 5);
  t.colour = (conifer ? kConifer : kBroadleaf) * k;
  t.colour = hue < 0.5 ? mix(t.colour, Rgb{112, 116, 62}, 0.5 * (0.5 - hue))
                       : mix(t.colour, Rgb{58, 80, 70}, 0.4 * (hue - 0.5));
  if (!force) t.colour = t.colour * (1.0 + 0.25 * var + 0.18 * gen.stand(x, y));
  t.r = size * (conifer ? 1.8 + 1.1 * uniform(h, 6) : 3.2 + 2.0 * uniform(h, 6));
  const double height = (conifer ? 14.0 : 10.0) + 8.0 * uniform(h, 7);
  t.height = height;
  // The crown, a ball of radius r at height - r, casts an ellipse; the
  // trunk a thin line up to it. Inside a forest only the top few metres
  // stand out of the canopy.
  t.crown_half = std::max(0.0, t.r / std::max(sun_z, 0.2) - t.r);
  t.crown_off = std::min(kMaxShadow - t.crown_half - t.r, (height - t.r) * inv_tan_sun);
  t.shadow_short = std::min(kMaxShadow, (1.0 + 2.0 * uniform(h, 8)) * inv_tan_sun);
  const double w = 2.0 * kPi * uniform(h, 9);
  t.wob_c = 0.11 * std::cos(w);
  t.wob_s = 0.11 * std::sin(w);
  return t;
}

}  // namespace

// Trees whose crowns may touch box, in a fixed, global order.
void Generator::collectTrees(const WorldBox& box, const TreeDraw& draw,
                             std::vector<Tree>& out) const {
  constexpr double kCell = kTreeCell;
  const bool force = draw.calibrate_share >= 0.0;
  const CellRange cells = treeCells(box);
  const TreeGrid grid(*this, cells, force);
  TreeLookup look;
  for (i64 j = cells.j1; j >= cells.j0; --j) {  // north to south: a fixed, global order
    for (i64 i = cells.i0; i <= cells.i1; ++i) {
      const u64 h = hash2(s_trees, i, j);
      const double x = (static_cast<double>(i) + 0.5 + 0.8 * (bits(h, 0) - 0.5)) * kCell;
      const double y = (static_cast<double>(j) + 0.5 + 0.8 * (bits(h, 1) - 0.5)) * kCell;
      const TreeSite site{h, x, y, bits(h, 2)};
      const TreeChoice ch =
          force ? forcedTree(site, draw) : chooseTree(*this, site, grid.at(x, y), draw, look);
      if (!ch.exists) continue;
      out.push_back(makeTree(*this, site, ch, force));
    }
  }
}

namespace {

// Tree shadows into the shadow buffer: on open ground the crown's ellipse and
// the trunk's line, on canopy only the short shadow of the crown's top.
void drawTreeShadows(const Generator& gen, const std::vector<Tree>& trees, const PixelFrame& pf,
                     const std::vector<float>& fcov, std::vector<float>& shadow) {
  const double px = pf.px;
  const int cols = pf.cols;
  const double shadow_x = gen.shadow_x, shadow_y = gen.shadow_y;
  const double sl = std::sqrt(shadow_x * shadow_x + shadow_y * shadow_y);
  const double sdx = sl > 0 ? shadow_x / sl : 0.0, sdy = sl > 0 ? shadow_y / sl : 0.0;
  for (const Tree& t : trees) {
    const double far =
        t.interior ? t.shadow_short : std::max(t.shadow_short, t.crown_off + t.crown_half);
    const double ex = t.x + sdx * far, ey = t.y + sdy * far;
    int ca, cb, ra, rb;
    pf.colRange(std::min(t.x, ex) - t.r - px, std::max(t.x, ex) + t.r + px, ca, cb);
    pf.rowRange(std::min(t.y, ey) - t.r - px, std::max(t.y, ey) + t.r + px, ra, rb);
    const double crown_a = std::max(0.0, t.crown_off - t.crown_half);
    const double crown_b = t.crown_off + t.crown_half;
    for (int r = ra; r <= rb; ++r) {
      const double y = pf.y(r);
      for (int c = ca; c <= cb; ++c) {
        const double x = pf.x(c);
        const double dx = x - t.x, dy = y - t.y;
        if (dx * dx + dy * dy < t.r * t.r) continue;  // own crown
        const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
        const double along = dx * sdx + dy * sdy;
        const double perp = std::abs(-dx * sdy + dy * sdx);
        if (perp > t.r + px || along < -t.r - px) continue;
        const auto capsule = [&](double a0, double a1) {
          const double ca0 = std::clamp(along, a0, a1) - along;
          return std::sqrt(ca0 * ca0 + perp * perp);
        };
        double cov;
        if (t.interior || fcov[idx] > 0.5f) {
          cov = clamp01(0.5 + (t.r * 0.9 - capsule(0.0, t.shadow_short)) / px);
        } else {
          cov = std::max(clamp01(0.5 + (t.r * 0.95 - capsule(crown_a, crown_b)) / px),
                         bandCoverage(capsule(0.0, crown_a), 0.2, px) * 0.8);
        }
        cov *= 0.5 * t.alpha;
        if (cov > shadow[idx]) shadow[idx] = static_cast<float>(cov);
      }
    }
  }
}

// Crowns in order, lit by the sun, with a lumpy outline and foliage clumps
// while they span enough pixels.
void drawCrowns(const Generator& gen, const std::vector<Tree>& trees, const PixelFrame& pf,
                std::vector<Rgb>& col) {
  const double px = pf.px;
  const int cols = pf.cols;
  const double sun_x = gen.sun_x, sun_y = gen.sun_y, sun_z = gen.sun_z;
  const ValueTable& table = gen.table;
  const double leaf_w = detailWeight(0.9, px), clump_w = detailWeight(1.7, px);
  const double twig_w = detailWeight(0.4, px);
  const bool lumpy = px < 0.7;
  for (const Tree& t : trees) {
    const double reach = t.r * (lumpy ? 1.15 : 1.0) + px;
    int ra, rb;
    pf.rowRange(t.y - reach, t.y + reach, ra, rb);
    for (int r = ra; r <= rb; ++r) {
      const double y = pf.y(r);
      const double dy = y - t.y;
      const double half = std::sqrt(std::max(0.0, reach * reach - dy * dy));
      int ca, cb;
      pf.colRange(t.x - half, t.x + half, ca, cb);
      for (int c = ca; c <= cb; ++c) {
        const double x = pf.x(c);
        const double dx = x - t.x;
        const double d = std::sqrt(dx * dx + dy * dy);
        double rr = t.r;
        if (lumpy && d > 0.5 * t.r) {  // a lumpy outline: 3rd and 5th harmonics of the angle
          const double cx = dx / d, cy = dy / d;
          const double c3 = cx * (4.0 * cx * cx - 3.0), s3 = cy * (3.0 - 4.0 * cy * cy);
          const double c5 = c3 * (2.0 * cx * cx - 1.0) - s3 * (2.0 * cx * cy);
          rr *= 1.0 + t.wob_c * c3 + t.wob_s * s3 + 0.8 * t.wob_s * c5 + 0.5 * t.wob_c * s3 * c3;
        }
        const double cov = clamp01(0.5 + (rr - d) / px) * t.alpha;
        if (cov <= 0.0) continue;
        double lam;
        if (t.conifer) {
          const double inv = d > 1e-6 ? 1.0 / d : 0.0;
          lam = 0.75 * (dx * inv * sun_x + dy * inv * sun_y) + 0.66 * sun_z;
        } else {
          const double ux = dx / t.r, uy = dy / t.r;
          const double nz = std::sqrt(std::max(0.0, 1.0 - ux * ux - uy * uy));
          // A flattened dome: softer than a ball.
          const double nn = std::sqrt(0.5 * (ux * ux + uy * uy) + nz * nz) + 1e-9;
          lam = (0.7 * (ux * sun_x + uy * sun_y) + nz * sun_z) / nn;
        }
        double bright = 0.62 + 0.5 * std::max(0.0, lam);
        if (clump_w > 0.0) {  // clumps of foliage, lit from the sun's side
          const double ox = t.wob_c * 300.0, oy = t.wob_s * 300.0;
          const double cx = x / 1.7 + ox, cy = y / 1.7 + oy;
          const double n0 = table.noise(cx, cy);
          const double gx = table.noise(cx + 0.25, cy) - n0, gy = table.noise(cx, cy + 0.25) - n0;
          bright *= 1.0 + clump_w * (0.1 * n0 - 1.6 * (gx * sun_x + gy * sun_y)) +
                    0.25 * leaf_w * table.noise(x / 0.9 + oy, y / 0.9 + ox);
          if (twig_w > 0.0) bright *= 1.0 + 0.3 * twig_w * table.noise(x / 0.4 + ox, y / 0.4);
        }
        const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
        col[idx] = mix(col[idx], t.colour * bright, cov);
      }
    }
  }
}

}  // namespace

void Generator::drawTrees(const std::vector<Tree>& trees, const PixelFrame& pf,
                          std::vector<Rgb>& col, const std::vector<float>& fcov,
                          std::vector<float>& shadow) const {
  // Shadows first (into the shadow buffer), then crowns in order.
  drawTreeShadows(*this, trees, pf, fcov, shadow);
  if (pf.tops) drawCrowns(*this, trees, pf, col);
}

Rgb Generator::calibrateForest(double conifer_share) const {
  // The mean colour of closed forest drawn tree by tree at 0.4 m/px: what a
  // coarse pixel over forest shows once the crowns are finer than it.
  PixelFrame pf;
  pf.size_px = 300;
  pf.px = 0.4;
  pf.east_min = 1000.0;
  pf.north_min = 1000.0;
  pf.rows = pf.cols = pf.size_px;
  const std::size_t n = static_cast<std::size_t>(pf.rows) * pf.cols;
  std::vector<Rgb> col(n, kForestFloor);
  std::vector<float> fcov(n, 1.0f), shadow(n, 0.0f);
  std::vector<Tree> trees;
  const double m = kMaxShadow + 6.0;
  const WorldBox box{pf.east_min, pf.north_min, pf.east_min + 120.0, pf.north_min + 120.0};
  collectTrees(box.grown(m), TreeDraw{1.0, 1.0, conifer_share}, trees);
  drawTrees(trees, pf, col, fcov, shadow);
  Rgb sum;
  for (std::size_t i = 0; i < n; ++i) sum = sum + col[i] * (1.0 - shadow[i]);
  return sum * (1.0 / static_cast<double>(n));
}

// The forest threshold and the forest's mean colours. The threshold is the
// quantile of the mask that covers forest_fraction of a fixed sample of the
// world; it is found with forest_threshold still 0.
void Generator::calibrateForests() {
  std::vector<double> samples;
  const int n = 64;
  const double span = std::max(p.size_m, 8000.0);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double x = ((i + 0.5) / n - 0.5) * span;
      const double y = ((j + 0.5) / n - 0.5) * span;
      samples.push_back(forestMask(x, y));
    }
  }
  std::sort(samples.begin(), samples.end());
  const double q = std::clamp(1.0 - p.forest_fraction, 0.0, 1.0);
  if (p.forest_fraction <= 0.0) {
    forest_threshold = 1e9;
  } else {
    const std::size_t idx = std::min(
        samples.size() - 1, static_cast<std::size_t>(q * static_cast<double>(samples.size())));
    forest_threshold = samples[idx];
  }
  for (std::size_t m = 0; m < forest_mean.size(); ++m) {
    forest_mean[m] = calibrateForest(static_cast<double>(m) / (forest_mean.size() - 1));
  }
  forest_mean_broadleaf = forest_mean.front();
}

}  // namespace nadir::terrain::procedural
