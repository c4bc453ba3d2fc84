// Buildings: farmsteads along the roads (a house and up to three barns
// around a yard, with a driveway) and a few alone in the fields, drawn
// supersampled with their shadows and pitched or flat roofs.

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {
namespace {

// Does the segment from (px, py) along (dx, dy) (t in [0, 1]) meet the box |u| <= hl, |v| <= hw?
bool segmentHitsBox(double pu, double pv, double du, double dv, double hl, double hw) {
  double t0 = 0.0, t1 = 1.0;
  const auto slab = [&](double p0, double d, double h) {
    if (std::abs(d) < 1e-12) return std::abs(p0) <= h;
    double ta = (-h - p0) / d, tb = (h - p0) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    return t0 <= t1;
  };
  return slab(pu, du, hl) && slab(pv, dv, hw);
}

constexpr std::array<Rgb, 7> kRoofs = {{{150, 78, 60},
                                        {164, 96, 72},
                                        {124, 88, 70},
                                        {76, 76, 80},
                                        {136, 138, 138},
                                        {110, 66, 54},
                                        {170, 166, 158}}};

// Where and how a farmstead stands: its origin (m), u along the road (or the
// field axis) and n away from the road.
struct Farmstead {
  double x = 0, y = 0;
  double ux = 0, uy = 0, nx = 0, ny = 0;
  bool by_road = false;
  double setback = 0.0;  // of the origin from the road's centre line, m
  double rhw = 0.0;      // the road's half width, m
};

// The extent of a farmstead's buildings in its frame (u, v), m.
struct FarmBounds {
  double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
};

// The farmstead of candidate h at (x, y): set back from a nearby road, else
// (rarely) alone along the field axis. False where none stands: no road near
// and not alone, in or near a forest or a river, or too near a road (or too
// far from it once set back).
bool placeFarmstead(const Generator& gen, u64 h, double x, double y, BlockCell& bcell,
                    Farmstead& fs) {
  const double wx = gen.blockWarpX(x, y), wy = gen.blockWarpY(x, y);
  const BlockHit bh = gen.blockAt(x + wx, y + wy, bcell);
  double rhw = 0;
  int site = -1;
  const double dr = gen.roadDistance(bh, x + wx, y + wy, rhw, site);
  double ux, uy, nx, ny;
  const bool by_road = dr < 90.0 && site >= 0;
  double setback = 0.0;
  if (by_road) {
    const Site& a = bh.sites[bh.nearest];
    const Site& b = bh.sites[site];
    const double len = std::hypot(a.x - b.x, a.y - b.y);
    nx = (a.x - b.x) / len;
    ny = (a.y - b.y) / len;
    setback = rhw + 10.0 + 12.0 * uniform(h, 3);
    x += nx * (setback - dr);
    y += ny * (setback - dr);
    ux = -ny;
    uy = nx;
  } else if (uniform(h, 4) < 0.12) {
    const BlockFrame f = gen.blockFrame(bh.sites[bh.nearest]);
    ux = f.c;
    uy = f.s;
    nx = -uy;
    ny = ux;
  } else {
    return false;
  }
  if (gen.forestMask(x, y) > -0.08) return false;
  TerrainSample t;
  gen.river(x, y, t);
  if (std::abs(t.sd) < t.hw + 30.0) return false;
  {
    BlockCell cell2;
    const double qx2 = x + gen.blockWarpX(x, y), qy2 = y + gen.blockWarpY(x, y);
    const BlockHit bh2 = gen.blockAt(qx2, qy2, cell2);
    double hw2 = 0;
    int s2 = -1;
    const double d2 = gen.roadDistance(bh2, qx2, qy2, hw2, s2);
    if (d2 < hw2 + 8.0 || (by_road && d2 > hw2 + 40.0)) return false;
  }
  fs = Farmstead{x, y, ux, uy, nx, ny, by_road, setback, rhw};
  return true;
}

// A house and up to three barns around the farmstead's origin.
void layOutBuildings(u64 h, const Farmstead& fs, std::vector<Building>& out, FarmBounds& bounds) {
  const double x = fs.x, y = fs.y, ux = fs.ux, uy = fs.uy, nx = fs.nx, ny = fs.ny;
  const int count = 1 + static_cast<int>(uniform(h, 5) * 3.3);
  double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
  double along = 0.0;
  for (int k = 0; k < count; ++k) {
    const u64 hk = mix64(h + 77 * (k + 1));
    Building b;
    b.h = hk;
    double bu, bv;  // centre in the farmstead frame (u along the road, v away)
    bool rotated;
    if (k == 0) {
      b.hl = 5.0 + 2.5 * uniform(hk, 0);
      b.hw = 4.0 + 1.5 * uniform(hk, 1);
      b.height = 7.0 + 2.0 * uniform(hk, 2);
      b.gable = true;
      b.roof = kRoofs[static_cast<std::size_t>(uniform(hk, 3) * 4.0)];
      rotated = uniform(hk, 4) < 0.3;
      bu = 0.0;
      bv = 0.0;
      along = rotated ? b.hw : b.hl;
    } else {
      b.hl = 8.0 + 10.0 * uniform(hk, 0);
      b.hw = 5.0 + 3.5 * uniform(hk, 1);
      b.height = 6.0 + 3.0 * uniform(hk, 2);
      b.gable = uniform(hk, 5) < 0.6;
      b.roof = kRoofs[3 + static_cast<std::size_t>(uniform(hk, 3) * 4.0)];
      rotated = uniform(hk, 4) < 0.45;
      const double half_u = rotated ? b.hw : b.hl;
      const double half_v = rotated ? b.hl : b.hw;
      if (k % 2 == 1) {  // beside, along the road
        bu = along + 5.0 + 4.0 * uniform(hk, 6) + half_u;
        bv = (half_v - 5.0) + 3.0 * uniform(hk, 7);
        along = bu + half_u;
      } else {  // behind
        bu = (uniform(hk, 6) - 0.3) * 12.0;
        bv = 6.0 + 8.0 + 4.0 * uniform(hk, 7) + half_v;
      }
    }
    const double half_u = rotated ? b.hw : b.hl;
    const double half_v = rotated ? b.hl : b.hw;
    umin = std::min(umin, bu - half_u);
    umax = std::max(umax, bu + half_u);
    vmin = std::min(vmin, bv - half_v);
    vmax = std::max(vmax, bv + half_v);
    b.x = x + ux * bu + nx * bv;
    b.y = y + uy * bu + ny * bv;
    b.ux = rotated ? nx : ux;
    b.uy = rotated ? ny : uy;
    out.push_back(b);
  }
  bounds = FarmBounds{umin, umax, vmin, vmax};
}

// The yard around the buildings and, by a road, a gravel driveway to it.
void addYards(u64 h, const Farmstead& fs, const FarmBounds& bounds, std::vector<Yard>& yards) {
  const double x = fs.x, y = fs.y, ux = fs.ux, uy = fs.uy, nx = fs.nx, ny = fs.ny;
  const double umin = bounds.umin, umax = bounds.umax, vmin = bounds.vmin, vmax = bounds.vmax;
  const double setback = fs.setback, rhw = fs.rhw;
  const bool by_road = fs.by_road;
  Yard yard;
  const double cu = 0.5 * (umin + umax), cv = 0.5 * (vmin + vmax);
  yard.x = x + ux * cu + nx * cv;
  yard.y = y + uy * cu + ny * cv;
  yard.ux = ux;
  yard.uy = uy;
  yard.hl = 0.5 * (umax - umin) + 4.0 + 3.0 * uniform(h, 8);
  yard.hw = 0.5 * (vmax - vmin) + 4.0 + 3.0 * uniform(h, 9);
  yard.colour = mix(Rgb{146, 140, 126}, Rgb{120, 116, 104}, uniform(h, 10));
  yard.h = h;
  yards.push_back(yard);
  if (by_road) {  // a gravel driveway from the road to the yard
    Yard drive;
    const double v0 = -(setback - rhw), v1 = cv - yard.hw + 1.0;
    const double du = (uniform(h, 11) - 0.5) * 10.0;
    drive.x = x + ux * du + nx * 0.5 * (v0 + v1);
    drive.y = y + uy * du + ny * 0.5 * (v0 + v1);
    drive.ux = nx;
    drive.uy = ny;
    drive.hl = std::max(0.0, 0.5 * (v1 - v0));
    drive.hw = 1.8;
    drive.colour = kDirt;
    drive.h = mix64(h + 5);
    if (drive.hl > 0.0) yards.push_back(drive);
  }
}

// Subsamples per pixel side for buildings.
int supersamples(double px) {
  return px < 0.5 ? 2 : std::min(6, static_cast<int>(std::ceil(px / 0.5)));
}

}  // namespace

void Generator::collectBuildings(const WorldBox& box, std::vector<Building>& out,
                                 std::vector<Yard>& yards) const {
  const double x0 = box.x0, y0 = box.y0, x1 = box.x1, y1 = box.y1;
  constexpr double kCell = 150.0;
  const i64 i0 = static_cast<i64>(std::floor(x0 / kCell));
  const i64 i1 = static_cast<i64>(std::floor(x1 / kCell));
  const i64 j0 = static_cast<i64>(std::floor(y0 / kCell));
  const i64 j1 = static_cast<i64>(std::floor(y1 / kCell));
  const double per_cell = p.buildings_per_km2 * kCell * kCell / 1e6 / 2.5;
  BlockCell bcell;
  for (i64 j = j1; j >= j0; --j) {
    for (i64 i = i0; i <= i1; ++i) {
      const u64 h = hash2(s_bld, i, j);
      const double x = (static_cast<double>(i) + 0.15 + 0.7 * uniform(h, 1)) * kCell;
      const double y = (static_cast<double>(j) + 0.15 + 0.7 * uniform(h, 2)) * kCell;
      if (uniform(h, 0) >= per_cell * settlement(x, y)) continue;
      Farmstead fs;
      if (!placeFarmstead(*this, h, x, y, bcell, fs)) continue;
      // A farmstead: a house and up to three barns around a yard.
      FarmBounds bounds;
      layOutBuildings(h, fs, out, bounds);
      addYards(h, fs, bounds, yards);
    }
  }
}

void Generator::drawYards(const std::vector<Yard>& yards, const PixelFrame& pf, double alpha_bld,
                          Scratch& scratch) {
  const double px = pf.px;
  const int cols = pf.cols;
  std::vector<Rgb>& col = scratch.col;
  const std::vector<float>& detail_px = scratch.detail;
  const int k = supersamples(px);
  for (const Yard& yd : yards) {
    const double ext = std::abs(yd.ux) * yd.hl + std::abs(yd.uy) * yd.hw + px;
    const double eyt = std::abs(yd.uy) * yd.hl + std::abs(yd.ux) * yd.hw + px;
    int ca, cb, ra, rb;
    pf.colRange(yd.x - ext, yd.x + ext, ca, cb);
    pf.rowRange(yd.y - eyt, yd.y + eyt, ra, rb);
    for (int r = ra; r <= rb; ++r) {
      for (int c = ca; c <= cb; ++c) {
        int inside = 0;
        for (int sj = 0; sj < k; ++sj) {
          for (int si = 0; si < k; ++si) {
            const double x = pf.x(c) + ((si + 0.5) / k - 0.5) * px - yd.x;
            const double y = pf.y(r) + ((sj + 0.5) / k - 0.5) * px - yd.y;
            const double u = x * yd.ux + y * yd.uy, v = -x * yd.uy + y * yd.ux;
            if (std::abs(u) <= yd.hl && std::abs(v) <= yd.hw) ++inside;
          }
        }
        if (inside == 0) continue;
        const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
        col[idx] = mix(col[idx], yd.colour * (1.0 + 0.1 * detail_px[idx]),
                       alpha_bld * inside / static_cast<double>(k * k));
      }
    }
  }
}

void Generator::drawBuildingShadows(const std::vector<Building>& buildings, const PixelFrame& pf,
                                    double alpha_bld, std::vector<float>& shadow) const {
  const double px = pf.px;
  const int cols = pf.cols;
  const int k = supersamples(px);
  const double cos_el = std::sqrt(sun_x * sun_x + sun_y * sun_y);
  const double sdx = cos_el > 1e-9 ? sun_x / cos_el : 0.0,
               sdy = cos_el > 1e-9 ? sun_y / cos_el : 0.0;
  for (const Building& b : buildings) {  // shadows
    const double len = b.height * inv_tan_sun;
    const double ex = std::abs(b.ux) * b.hl + std::abs(b.uy) * b.hw + px;
    const double ey = std::abs(b.uy) * b.hl + std::abs(b.ux) * b.hw + px;
    const double sx = -sdx * len, sy = -sdy * len;
    int ca, cb, ra, rb;
    pf.colRange(b.x + std::min(0.0, sx) - ex, b.x + std::max(0.0, sx) + ex, ca, cb);
    pf.rowRange(b.y + std::min(0.0, sy) - ey, b.y + std::max(0.0, sy) + ey, ra, rb);
    const double du = (sdx * b.ux + sdy * b.uy) * len, dv = (-sdx * b.uy + sdy * b.ux) * len;
    for (int r = ra; r <= rb; ++r) {
      for (int c = ca; c <= cb; ++c) {
        int inside = 0;
        for (int sj = 0; sj < k; ++sj) {
          for (int si = 0; si < k; ++si) {
            const double x = pf.x(c) + ((si + 0.5) / k - 0.5) * px - b.x;
            const double y = pf.y(r) + ((sj + 0.5) / k - 0.5) * px - b.y;
            const double u = x * b.ux + y * b.uy, v = -x * b.uy + y * b.ux;
            if (segmentHitsBox(u, v, du, dv, b.hl, b.hw)) ++inside;
          }
        }
        if (inside == 0) continue;
        const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
        const float cov = static_cast<float>(0.6 * alpha_bld * inside / (k * k));
        if (cov > shadow[idx]) shadow[idx] = cov;
      }
    }
  }
}

// Roofs, drawn last: over the trees and the shadows.
void Generator::drawRoofs(const std::vector<Building>& buildings, const PixelFrame& pf,
                          double alpha_bld, std::vector<Rgb>& col) const {
  const double px = pf.px;
  const int cols = pf.cols;
  const int k = supersamples(px);
  const double tile_w = detailWeight(2.5, px);
  for (const Building& b : buildings) {  // roofs
    const double ex = std::abs(b.ux) * b.hl + std::abs(b.uy) * b.hw + px;
    const double ey = std::abs(b.uy) * b.hl + std::abs(b.ux) * b.hw + px;
    int ca, cb, ra, rb;
    pf.colRange(b.x - ex, b.x + ex, ca, cb);
    pf.rowRange(b.y - ey, b.y + ey, ra, rb);
    // Gable roof halves face +v and -v, pitched 35 deg.
    const double vx = -b.uy, vy = b.ux;
    const double sp = std::sin(0.61), cp = std::cos(0.61);
    const double lam_pos = (sp * (vx * sun_x + vy * sun_y) + cp * sun_z);
    const double lam_neg = (-sp * (vx * sun_x + vy * sun_y) + cp * sun_z);
    const double k_pos = 0.5 + 0.6 * std::max(0.0, lam_pos) / sun_z * 0.85;
    const double k_neg = 0.5 + 0.6 * std::max(0.0, lam_neg) / sun_z * 0.85;
    const Rgb roof = b.roof * (0.92 + 0.16 * uniform(b.h, 20));
    for (int r = ra; r <= rb; ++r) {
      for (int c = ca; c <= cb; ++c) {
        Rgb sum;
        int inside = 0;
        for (int sj = 0; sj < k; ++sj) {
          for (int si = 0; si < k; ++si) {
            const double wxp = pf.x(c) + ((si + 0.5) / k - 0.5) * px;
            const double wyp = pf.y(r) + ((sj + 0.5) / k - 0.5) * px;
            const double x = wxp - b.x, y = wyp - b.y;
            const double u = x * b.ux + y * b.uy, v = -x * b.uy + y * b.ux;
            if (std::abs(u) > b.hl || std::abs(v) > b.hw) continue;
            ++inside;
            double kk;
            if (b.gable) {
              kk = v >= 0.0 ? k_pos : k_neg;
              if (std::abs(v) < 0.25) kk *= 0.85;
            } else {
              kk = 0.95;
              if (b.hl - std::abs(u) < 0.4 || b.hw - std::abs(v) < 0.4) kk = 1.08;
            }
            if (b.hl - std::abs(u) < 0.3 || b.hw - std::abs(v) < 0.3) kk *= 0.8;
            if (tile_w > 0.0)
              kk *= 1.0 + 0.07 * tile_w * gradNoise(wxp / 2.5, wyp / 2.5, s_roof + b.h);
            sum = sum + roof * kk;
          }
        }
        if (inside == 0) continue;
        const std::size_t idx = static_cast<std::size_t>(r) * cols + c;
        const double cov = alpha_bld * inside / static_cast<double>(k * k);
        col[idx] = mix(col[idx], sum * (1.0 / inside), cov);
      }
    }
  }
}

}  // namespace nadir::terrain::procedural
