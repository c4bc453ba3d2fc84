// A block of imagery put together: the smooth fields on a world-anchored
// grid, then every pixel coloured (fields, forest, water, roads), then the
// sprites (yards, trees, shadows, roofs) in a global order, then shading.
//
// Filtering to the pixel's footprint: noise octaves fade out before they would
// alias; lines, bands and edges (roads, rivers, margins, tracks, field edges)
// take their area coverage; buildings are supersampled; trees are drawn while
// their crowns span a few pixels and beyond that forests take their mean
// colour; fields narrower than a pixel blend into their analytic mean colour.
//
// Pixel positions come from global pixel indices and every decision from world
// positions, so the result depends neither on how the square is cut into
// blocks, nor on the number of threads, nor on earlier calls; adjacent squares
// at the same pixel size meet without seams. Memory per block is bounded (a
// few MB of per-thread scratch).

#include <opencv2/core.hpp>

#include <algorithm>
#include <array>
#include <cmath>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {

PixelScale::PixelScale(double px_m)
    : px(px_m),
      alpha_forest(smooth01((2.0 - px_m) / 1.0)),
      alpha_trees(smooth01((2.5 - px_m) / 1.25)),
      coarse_forest(1.0 - alpha_forest),
      coarse(1.0 - alpha_trees),
      mid_octaves(24.0, 3, 0.75, px_m, 1.0 / 1.2, 0.0),
      fine_octaves(3.0, 4, 0.85, px_m, 1.0 / 1.3, 101.0),
      stand_octaves(350.0, 2, 0.6, px_m, 1.0, 333.0),
      ripple_octaves(2.4, 3, 0.7, px_m, 1.0, 777.0),
      var_octaves(96.0, 3, 0.6, px_m, 0.8, 555.0),
      canopy_octaves(9.0, 2, 0.7, px_m, 1.0, 999.0),
      grain_scale(1.0 / std::max(5.0, 1.3 * px_m)),
      grain_amp(0.3 * std::min(1.0, 6.0 / px_m)),
      far_field(std::max(17.0, 3.2 + 1.5 * px_m)),
      far_block(std::max(far_field, 5.0 + 1.5 * px_m)) {}

// The smooth fields at the grid's nodes around box (the block's pixel
// centres); the spacing is a power of two, 4 to 8 pixels, and the fields are
// evaluated at the grid's footprint.
void Generator::sampleGrid(const WorldBox& box, double px, SmoothGrid& grid) const {
  constexpr int kCh = SmoothGrid::kCh;
  const double xmin = box.x0, ymin = box.y0, xmax = box.x1, ymax = box.y1;
  const double s = std::max(2.0, std::exp2(std::floor(std::log2(8.0 * px))));
  const i64 kx0 = static_cast<i64>(std::floor(xmin / s)) - 1;
  const i64 kx1 = static_cast<i64>(std::floor(xmax / s)) + 2;
  const i64 ky0 = static_cast<i64>(std::floor(ymin / s)) - 1;
  const i64 ky1 = static_cast<i64>(std::floor(ymax / s)) + 2;
  const int nx = static_cast<int>(kx1 - kx0 + 1), ny = static_cast<int>(ky1 - ky0 + 1);
  grid.s = s;
  grid.kx0 = kx0;
  grid.ky0 = ky0;
  grid.nx = nx;
  grid.ny = ny;
  std::vector<double>& nodes = grid.nodes;
  std::vector<double>& up = grid.up;
  nodes.resize(static_cast<std::size_t>(nx) * ny * kCh);
  up.resize(static_cast<std::size_t>(nx) * ny);
  grid.line.resize(static_cast<std::size_t>(nx) * kCh);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = static_cast<double>(kx0 + i) * s;
      const double y = static_cast<double>(ky0 + j) * s;
      const TerrainSample t = terrain(x, y, s);
      const std::size_t k = static_cast<std::size_t>(j) * nx + i;
      up[k] = t.up;
      double* n = &nodes[k * kCh];
      n[1] = t.sd;
      n[2] = t.hw;
      n[3] = forestMask(x, y);
      n[4] = blockWarpX(x, y);
      n[5] = blockWarpY(x, y);
      n[6] = 0.0;  // per pixel, in paintGround
      n[7] = tintNoise(x, y);
      n[8] = soilNoise(x, y);
      n[9] = coniferShare(x, y);
      n[10] = 0.0;
    }
  }
}

namespace {

// The pixels of row r: their positions and smooth fields, and the texture
// detail and hillshade kept for the sprites and shading.
void samplePixels(const Generator& gen, const PixelFrame& pf, const PixelScale& sc, int r,
                  Scratch& scratch) {
  const SmoothGrid& grid = scratch.grid;
  const ValueTable& table = gen.table;
  const double y = pf.y(r);
  for (int c = 0; c < pf.cols; ++c) {
    const double x = pf.x(c);
    const std::size_t idx = static_cast<std::size_t>(r) * pf.cols + c;
    GroundPixel& g = scratch.row.pixels[static_cast<std::size_t>(c)];
    g.x = x;
    g.y = y;
    g.f = grid.interp(x);
    g.f.var = sc.var_octaves(table, x, y);
    g.mid = sc.mid_octaves(table, x, y);
    g.fine = sc.fine_octaves(table, x, y);
    g.detail = 0.6 * g.mid + 0.8 * g.fine;
    scratch.detail[idx] = static_cast<float>(g.detail);
    scratch.shade[idx] = static_cast<float>(g.f.shade);
    g.qx = x + g.f.wx;
    g.qy = y + g.f.wy;
  }
}

}  // namespace

// Every pixel's ground colour, row by row, one layer over the other: fields,
// forest, water, roads. No layer reads what another pixel was painted, so a
// row painted layer by layer equals one painted pixel by pixel; a whole row
// per call keeps each layer's per-pixel step inlined in its loop.
void Generator::paintGround(const PixelFrame& pf, const PixelScale& sc, Scratch& scratch) const {
  const std::size_t cols = static_cast<std::size_t>(pf.cols);
  GroundRow& row = scratch.row;
  row.pixels.resize(cols);
  row.hits.resize(cols);
  row.forest_cover.resize(cols);
  GroundLookup look;
  FieldCache cache;
  for (int r = 0; r < pf.rows; ++r) {
    scratch.grid.prepareRow(pf.y(r));
    samplePixels(*this, pf, sc, r, scratch);
    look.startRow();
    lookUpRow(row, sc, look);
    const std::size_t first = static_cast<std::size_t>(r) * cols;
    const std::span<Rgb> col(scratch.col.data() + first, cols);
    paintFields(row, sc, cache, col);
    paintForest(row, sc, scratch.grid.s, col, std::span<float>(scratch.fcov.data() + first, cols));
    paintWater(row, sc, col);
    paintRoads(row, col);
  }
}

// The sprites in a global order: buildings' yards, trees, the shadows of
// trees and buildings, roofs.
void Generator::drawSprites(const PixelFrame& pf, const PixelScale& sc, Scratch& scratch) const {
  const double px = pf.px;
  const WorldBox box = pf.centres();
  const double alpha_bld = p.buildings_per_km2 > 0.0 ? smooth01((8.0 - px) / 4.0) : 0.0;
  std::vector<Building> buildings;
  std::vector<Yard> yards;
  if (alpha_bld > 0.0) {
    collectBuildings(box.grown(100.0), buildings, yards);
    drawYards(yards, pf, alpha_bld, scratch);
  }
  if (sc.alpha_trees > 0.0 || sc.alpha_forest > 0.0) {
    std::vector<Tree> trees;
    collectTrees(box.grown(kMaxShadow + 6.0), TreeDraw{sc.alpha_forest, sc.alpha_trees, -1.0},
                 trees);
    drawTrees(trees, pf, scratch.col, scratch.fcov, scratch.shadow);
  }
  if (alpha_bld > 0.0) drawBuildingShadows(buildings, pf, alpha_bld, scratch.shadow);
  applyShadows(scratch);
  if (alpha_bld > 0.0 && pf.tops) drawRoofs(buildings, pf, alpha_bld, scratch.col);
}

void Generator::renderBlock(const PixelFrame& pf, cv::Mat& out) const {
  // Per-thread scratch buffers, reused from block to block.
  thread_local Scratch scratch;
  const std::size_t n = static_cast<std::size_t>(pf.rows) * pf.cols;
  scratch.col.resize(n);
  scratch.fcov.assign(n, 0.0f);
  scratch.shadow.assign(n, 0.0f);
  scratch.shade.resize(n);
  scratch.detail.resize(n);
  sampleGrid(pf.centres(), pf.px, scratch.grid);
  hillshade(scratch.grid);
  forestMaskGradient(scratch.grid);
  const PixelScale sc(pf.px);
  paintGround(pf, sc, scratch);
  drawSprites(pf, sc, scratch);
  writePixels(pf, scratch, out);
}

}  // namespace nadir::terrain::procedural
