#pragma once
// The procedural world's generator, shared by its parts in terrain/procedural/
// (one file per thing drawn: relief, water, fields, forests, hedges and
// roads, buildings, shading; blocks.cpp finds the block and field under a
// point and render_block.cpp puts a block of imagery together). Internal to
// terrain/: ProceduralWorld (terrain/procedural_world.h) is the interface.
//
// Internally x is east and y is north (metres, world frame), so that angles
// and rotations read as in the plane; only groundUp_m and imagery() speak
// (north, east).

#include <opencv2/core/mat.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "terrain/procedural/noise.h"
#include "terrain/procedural_world.h"

namespace nadir::terrain::procedural {

inline constexpr double kMaxShadow = 40.0;  // longest tree shadow drawn, m

// ----------------------------------------------------------------- colour --

struct Rgb {
  double r = 0.0, g = 0.0, b = 0.0;
};
inline Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
inline Rgb operator-(Rgb a, Rgb b) { return {a.r - b.r, a.g - b.g, a.b - b.b}; }
inline Rgb operator*(Rgb a, double k) { return {a.r * k, a.g * k, a.b * k}; }
inline Rgb mix(Rgb a, Rgb b, double t) { return a + (b - a) * t; }

// Bare earth of farm tracks and driveways.
inline constexpr Rgb kDirt{150, 136, 110};

// ------------------------------------------------------------------ types --

enum class Crop { kCereal, kRipe, kMaize, kRape, kMeadow, kPasture, kSoil, kStubble };

struct FieldInfo {
  u64 id = 0;
  Crop crop = Crop::kCereal;
  Rgb plant, dry;     // plant colour and its dry/yellow variant
  double soil_k = 1;  // soil brightness factor
  double cover = 0.8;
  double bright = 1.0;
  double row_nx = 1, row_ny = 0;  // unit normal to the rows
  double row_lambda = 0;          // 0: no rows
  double row_phase = 0;
  double row_amp1 = 0, row_amp2 = 0;  // the rows' harmonics filtered to the pixel
  double row_cover = 0;               // coverage modulation by the rows
  double row_bright = 0;              // brightness modulation by the rows
  double tram_lambda = 0;
  double tram_phase = 0;
  double band_lambda = 0;  // mowing / swath bands along the rows
  double band_phase = 0;
  double band_hw = 0;
  double band_bright = 0;
  double var_cover = 0;
  double var_bright = 0;
  double detail = 0.05;  // mid-scale (24..6 m) texture amplitude
  double fine = 0.08;    // fine (3..0.75 m) texture amplitude
  double headland = 0;
  double margin_hw = 0.6;
};

// A block of the road network: its Voronoi site, id and field layout frame.
struct Site {
  double x = 0, y = 0;
  u64 id = 0;
};

// The 3 x 3 block sites around a cell, with the bisectors of the nearest.
struct BlockCell {
  bool valid = false;
  i64 ci = 0, cj = 0;
  std::array<Site, 9> sites;
  int nearest = -1;
  std::array<double, 9> nx{}, ny{}, off{};  // distance to bisector m: off - q . n
};

struct BlockHit {
  const Site* sites = nullptr;  // the 9 sites, owned by a BlockCell
  int nearest = 0;
  std::array<double, 9> edge_dist{};  // distance to the bisector with each site
  double edge = 1e300;                // distance to the block's boundary
  int edge_site = -1;
};

struct BlockFrame {
  u64 id = 0;
  double c = 1, s = 0;  // field axis (cos, sin)
  double lu = 1, lv = 1;
};

struct FieldCell {
  bool valid = false;
  u64 block = 0;
  i64 cj = 0;
  std::array<i64, 3> ci{};
  std::array<double, 9> su{}, sv{};
  std::array<u64, 9> ids{};
  int nearest = -1;
  std::array<double, 9> nu{}, nv{}, off{};  // distance in metres: off - (u, v) . n
};

struct FieldHit {
  u64 id = 0;
  double edge = 1e300;  // distance to the field's boundary, m
  u64 neighbour = 0;
};

struct Tree {
  double x, y, r;
  double height;        // the crown's top above the ground, m
  double shadow_short;  // shadow length on surrounding canopy, m
  double crown_off;     // crown shadow's centre along the shadow direction, m
  double crown_half;    // half the elongation of the crown's shadow, m
  bool interior;        // deep in a forest: only the short shadow can show
  double alpha;
  double wob_c, wob_s;  // crown outline: r (1 + wob_c cos 3t + wob_s sin 3t + ...)
  Rgb colour;
  bool conifer;
  u64 h;
};

struct Building {
  double x, y, ux, uy, hl, hw, height;
  Rgb roof;
  bool gable;
  u64 h;
};

struct Yard {
  double x, y, ux, uy, hl, hw;
  Rgb colour;
  u64 h;
};

// A rectangle of the world, x (east) in [x0, x1] and y (north) in [y0, y1], m.
struct WorldBox {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  WorldBox grown(double m) const { return {x0 - m, y0 - m, x1 + m, y1 + m}; }
};

// Which trees collectTrees returns: forest trees get alpha_forest, the others
// alpha_other (a class with alpha 0 is skipped). calibrate_share >= 0: closed
// forest everywhere with that share of conifers (for the calibration of the
// mean colour).
struct TreeDraw {
  double alpha_forest = 1.0;
  double alpha_other = 1.0;
  double calibrate_share = -1.0;
};

// A candidate tree: its cell's hash, its position (m) and the uniform number
// that decides whether it stands.
struct TreeSite {
  u64 h = 0;
  double x = 0, y = 0, u = 0;
};

// The block and field lookups reused while trees are placed.
struct TreeLookup {
  BlockCell bcell;
  FieldCell fcell;
  BlockFrame frame;
  bool have_frame = false;
};

// The smooth fields at a pixel, interpolated from the block's grid.
struct Pix {
  double shade, sd, hw, mask, wx, wy, var, tint, soil, conifer, mask_grad;
};

// Smooth fields on a world-anchored grid of spacing s (a power of two, 4 to
// 8 pixels), evaluated at the grid's footprint; per pixel row the grid is
// interpolated to the row's y (line), per pixel along x.
struct SmoothGrid {
  static constexpr int kCh = 11;  // channels of Pix, in order
  double s = 1;
  i64 kx0 = 0, ky0 = 0;
  int nx = 0, ny = 0;
  std::vector<double> nodes, up, line;

  std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * nx + i; }
  void prepareRow(double y) {
    const double gy = y / s - static_cast<double>(ky0);
    const int j = std::clamp(static_cast<int>(std::floor(gy)), 0, ny - 2);
    const double ty = gy - j;
    const double* a = &nodes[static_cast<std::size_t>(j) * nx * kCh];
    const double* b = a + static_cast<std::size_t>(nx) * kCh;
    for (std::size_t k = 0; k < line.size(); ++k) line[k] = a[k] + ty * (b[k] - a[k]);
  }
  Pix interp(double x) const {
    const double gx = x / s - static_cast<double>(kx0);
    const int i = std::clamp(static_cast<int>(std::floor(gx)), 0, nx - 2);
    const double tx = gx - i;
    const double* a = &line[static_cast<std::size_t>(i) * kCh];
    std::array<double, kCh> v;
    for (int k = 0; k < kCh; ++k) v[k] = a[k] + tx * (a[k + kCh] - a[k]);
    Pix q;
    q.shade = v[0];
    q.sd = v[1];
    q.hw = v[2];
    q.mask = v[3];
    q.wx = v[4];
    q.wy = v[5];
    q.var = v[6];
    q.tint = v[7];
    q.soil = v[8];
    q.conifer = v[9];
    q.mask_grad = v[10];
    return q;
  }
};

// Pixel centres of a block of an imagery square, from global pixel indices.
struct PixelFrame {
  double east_min = 0, north_min = 0, px = 1;
  // Draw the crowns and roofs (false: their shadows only, for 3D objects).
  bool tops = true;
  int size_px = 1, r0 = 0, c0 = 0, rows = 0, cols = 0;
  double x(int c) const { return east_min + (c0 + c + 0.5) * px; }
  double y(int r) const { return north_min + (size_px - (r0 + r) - 0.5) * px; }
  static int clampIndex(double v, int lo, int hi) {
    return static_cast<int>(std::clamp(v, static_cast<double>(lo), static_cast<double>(hi)));
  }
  // Local column range whose centres lie in [xa, xb] (empty when ca > cb).
  void colRange(double xa, double xb, int& ca, int& cb) const {
    ca = clampIndex(std::ceil((xa - east_min) / px - 0.5) - c0, 0, cols);
    cb = clampIndex(std::floor((xb - east_min) / px - 0.5) - c0, -1, cols - 1);
  }
  void rowRange(double ya, double yb, int& ra, int& rb) const {
    ra = clampIndex(std::ceil(size_px - 0.5 - (yb - north_min) / px) - r0, 0, rows);
    rb = clampIndex(std::floor(size_px - 0.5 - (ya - north_min) / px) - r0, -1, rows - 1);
  }
  // The box spanned by the block's pixel centres.
  WorldBox centres() const { return {x(0), y(rows - 1), x(cols - 1), y(0)}; }
};

// What the pixel size decides for a whole block: how trees are drawn, the
// texture octaves that survive the footprint, and how far a block or field
// lookup may be reused.
struct PixelScale {
  explicit PixelScale(double px_m);

  double px;
  // Trees are drawn one by one while their crowns span a few pixels; beyond,
  // forests take their calibrated mean colour with a canopy-scale texture,
  // and hedgerows and riverside trees their mean share of the pixel.
  double alpha_forest, alpha_trees, coarse_forest, coarse;
  Octaves mid_octaves, fine_octaves, stand_octaves, ripple_octaves, var_octaves, canopy_octaves;
  double grain_scale, grain_amp;
  // Beyond these distances from a field's or block's edge nothing depends on
  // the exact distance (headlands, margins, hedges, roads, edge blending), so
  // a lookup is reused while its edge is provably that far (the warp stretches
  // distances by less than 1.5).
  double far_field, far_block;
};

// One pixel of the ground being coloured.
struct GroundPixel {
  double x = 0, y = 0;    // pixel centre, m
  double qx = 0, qy = 0;  // the same, warped for the blocks and fields, m
  Pix f{};
  double mid = 0, fine = 0, detail = 0;  // texture
};

// The block and field under a pixel, and the road at the block's edge.
struct GroundHit {
  bool reuse = false;            // the lookup of a pixel further west was reused
  double fe = 0, be = 0, e = 0;  // distance to the field's, block's, nearer edge, m
  FieldHit fh;
  BlockFrame frame;
  Site across;            // the block beyond the block's nearest edge
  double road_cov = 0.0;  // the road's coverage of the pixel (0 when reused)
  Rgb road;
};

// One row of a block as the layers paint it, west to east: the pixels, the
// block and field under each, and the forest's cover (the river banks' grass
// stops at the forest).
struct GroundRow {
  std::vector<GroundPixel> pixels;
  std::vector<GroundHit> hits;
  std::vector<double> forest_cover;
};

// The block and field under the pixels of a row, reused from pixel to pixel
// while their edges are far.
struct GroundLookup {
  BlockCell bcell;
  FieldCell fcell;
  BlockFrame frame;
  bool have_frame = false;
  bool have_hit = false;  // bh and fh hold a lookup made in this row at ref_x
  double ref_x = 0.0;
  BlockHit bh;
  FieldHit fh;

  void startRow() {
    have_hit = false;
    ref_x = 0.0;
    bh = BlockHit{};
    fh = FieldHit{};
  }
};

// The field descriptions met so far (a pixel's neighbours mostly lie in the
// same few fields) and the last field lookup in a neighbouring block.
struct FieldCache {
  std::array<FieldInfo, 8> info;
  std::array<bool, 8> ok{};
  FieldCell fcell_nb;
  BlockFrame frame_nb;
  bool have_frame_nb = false;
};

// Per-thread scratch buffers, reused from block to block (every element used
// is written first, so nothing carries over).
struct Scratch {
  SmoothGrid grid;
  GroundRow row;
  std::vector<Rgb> col;
  std::vector<float> fcov, shadow, shade, detail;
};

struct TerrainSample {
  double up = 0;
  double sd = 1e9;   // signed distance to the river's centre line (approx.), m
  double sdv = 1e9;  // the same without the small meanders, for the valley's shape
  double hw = 10;    // river half width, m
  double valley = 1;
};

// ---------------------------------------------------------------- generator --

// Every layer is a pure function of the seed and the position; the generator
// holds the seeds, the tables and what construction calibrated, and is
// immutable after it.
struct Generator {
  explicit Generator(const ProceduralWorldParams& params);

  ProceduralWorldParams p;
  ValueTable table;
  SineTable sine;
  Octaves stand_full{350.0, 2, 0.6, 0.0, 1.0, 333.0};
  Octaves var_full{96.0, 3, 0.6, 0.0, 0.8, 555.0};
  Octaves forest_large{2400.0, 4, 0.5, 0.0, 1.0, 1234.5};
  Octaves forest_edge{110.0, 2, 0.5, 0.0, 1.0, 2345.6};
  u64 seed = 0;
  u64 s_warp_x, s_warp_y, s_hills, s_base, s_river, s_meander1, s_meander2, s_width, s_valley,
      s_bwarp_x, s_bwarp_y, s_block, s_field, s_region, s_tint, s_soil, s_conifer, s_trees, s_bld,
      s_settle, s_roof;
  double flow_x = 1, flow_y = 0;  // unit vector rivers run along (downhill)
  double sun_x = 0, sun_y = 0, sun_z = 1;
  double shadow_x = 0, shadow_y = 0;  // ground shadow offset per metre of height
  double inv_tan_sun = 1;
  double tilt_per_m = 0;
  double forest_threshold = 0;
  // Mean colour of closed forest at conifer shares 0, 1/4, ..., 1.
  std::array<Rgb, 5> forest_mean;
  Rgb forest_mean_broadleaf;
  // The mean field colour is field_soil * soil + field_plant + dryness * field_dry.
  double field_soil = 0;
  Rgb field_plant, field_dry;

  // Smooth fields shared by the layers.
  double blockWarpX(double x, double y) const {
    return 22.0 * fbm(x, y, s_bwarp_x, 700.0, 2, 0.5, 0.0);
  }
  double blockWarpY(double x, double y) const {
    return 22.0 * fbm(x, y, s_bwarp_y, 700.0, 2, 0.5, 0.0);
  }
  // Within-field and within-forest variation, tens of metres.
  double varNoise(double x, double y) const { return var_full(table, x, y); }
  double tintNoise(double x, double y) const { return fbm(x, y, s_tint, 2600.0, 2, 0.5, 0.0); }
  double soilNoise(double x, double y) const { return fbm(x, y, s_soil, 1500.0, 2, 0.5, 0.0); }
  double coniferShare(double x, double y) const {
    return smooth01(0.5 + 1.6 * fbm(x, y, s_conifer, 2200.0, 2, 0.5, 0.0));
  }
  double settlement(double x, double y) const {
    return 0.25 + 1.75 * smooth01(0.5 + 1.3 * fbm(x, y, s_settle, 3000.0, 2, 0.5, 0.0));
  }

  // relief.cpp
  TerrainSample terrain(double x, double y, double fp) const;

  // water.cpp
  void river(double x, double y, TerrainSample& t) const;
  void paintWater(const GroundRow& row, const PixelScale& sc, std::span<Rgb> col) const;

  // blocks.cpp
  Site blockSite(i64 i, i64 j) const;
  BlockHit blockAt(double qx, double qy, BlockCell& cell) const;
  BlockFrame blockFrame(const Site& a) const;
  FieldHit fieldAt(const BlockFrame& f, double qx, double qy, FieldCell& cell) const;
  void lookUpRow(GroundRow& row, const PixelScale& sc, GroundLookup& look) const;

  // fields.cpp
  FieldInfo fieldInfo(u64 id, const BlockFrame& f, double px) const;
  FieldInfo fieldInfoAt(u64 id, const BlockFrame& f) const;
  Rgb soilColour(const Pix& c) const;
  double dryness(const Pix& c) const;
  Rgb meanFieldColour(const Pix& c) const;
  Rgb fieldColour(const FieldInfo& fi, const GroundPixel& g, double e, double px) const;
  void paintFields(const GroundRow& row, const PixelScale& sc, FieldCache& cache,
                   std::span<Rgb> col) const;
  void calibrateFields();

  // forests.cpp
  double forestMask(double x, double y) const;
  Rgb forestMean(double conifer_share) const;
  double stand(double x, double y) const;
  void paintForest(GroundRow& row, const PixelScale& sc, double grid_s, std::span<Rgb> col,
                   std::span<float> fcov) const;
  static void forestMaskGradient(SmoothGrid& grid);
  void collectTrees(const WorldBox& box, const TreeDraw& draw, std::vector<Tree>& out) const;
  void drawTrees(const std::vector<Tree>& trees, const PixelFrame& pf, std::vector<Rgb>& col,
                 const std::vector<float>& fcov, std::vector<float>& shadow) const;
  Rgb calibrateForest(double conifer_share) const;
  void calibrateForests();

  // hedges_roads.cpp
  bool hedged(const FieldHit& fh) const;
  bool fieldEdgeTree(const TreeSite& t, const BlockHit& bh, double qx, double qy, TreeLookup& look,
                     double& size) const;
  Rgb hedgesAndTracks(Rgb field, const GroundPixel& g, const PixelScale& sc,
                      const GroundHit& hit) const;
  double roadAt(const BlockHit& hit, double qx, double qy, double px, Rgb& colour,
                double detail) const;
  double roadDistance(const BlockHit& hit, double qx, double qy, double& hw, int& site) const;
  static void paintRoads(const GroundRow& row, std::span<Rgb> col);

  // buildings.cpp
  void collectBuildings(const WorldBox& box, std::vector<Building>& out,
                        std::vector<Yard>& yards) const;
  static void drawYards(const std::vector<Yard>& yards, const PixelFrame& pf, double alpha_bld,
                        Scratch& scratch);
  void drawBuildingShadows(const std::vector<Building>& buildings, const PixelFrame& pf,
                           double alpha_bld, std::vector<float>& shadow) const;
  void drawRoofs(const std::vector<Building>& buildings, const PixelFrame& pf, double alpha_bld,
                 std::vector<Rgb>& col) const;

  // shading.cpp
  void setSun();
  void hillshade(SmoothGrid& grid) const;
  static void applyShadows(Scratch& scratch);
  static void writePixels(const PixelFrame& pf, const Scratch& scratch, cv::Mat& out);

  // render_block.cpp
  void renderBlock(const PixelFrame& pf, cv::Mat& out) const;
  void sampleGrid(const WorldBox& box, double px, SmoothGrid& grid) const;
  void paintGround(const PixelFrame& pf, const PixelScale& sc, Scratch& scratch) const;
  void drawSprites(const PixelFrame& pf, const PixelScale& sc, Scratch& scratch) const;
};

}  // namespace nadir::terrain::procedural
