// Blocks and fields: the road network's blocks are the cells of a warped
// Voronoi diagram; inside each block strip-like Voronoi fields in the block's
// own orientation. Finds the block and field under a point, and keeps the
// lookups that neighbouring pixels reuse.

#include <algorithm>
#include <array>
#include <cmath>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {

Site Generator::blockSite(i64 i, i64 j) const {
  const u64 h = hash2(s_block, i, j);
  const double b = p.block_size_m;
  return {(static_cast<double>(i) + 0.5 + 0.6 * (bits(h, 0) - 0.5)) * b,
          (static_cast<double>(j) + 0.5 + 0.6 * (bits(h, 1) - 0.5)) * b, h};
}

// The block around warped position q. The 3 x 3 sites and the bisectors of
// the nearest one are kept in cell and reused while q stays in the same
// cell: they are pure functions of the cell, so results do not depend on
// what was asked before.
BlockHit Generator::blockAt(double qx, double qy, BlockCell& cell) const {
  const i64 ci = static_cast<i64>(std::floor(qx / p.block_size_m));
  const i64 cj = static_cast<i64>(std::floor(qy / p.block_size_m));
  if (!cell.valid || ci != cell.ci || cj != cell.cj) {
    int k = 0;
    for (i64 dj = -1; dj <= 1; ++dj) {
      for (i64 di = -1; di <= 1; ++di, ++k) cell.sites[k] = blockSite(ci + di, cj + dj);
    }
    cell.ci = ci;
    cell.cj = cj;
    cell.valid = true;
    cell.nearest = -1;
  }
  BlockHit hit;
  hit.sites = cell.sites.data();
  double best = 1e300;
  for (int k = 0; k < 9; ++k) {
    const double dx = cell.sites[k].x - qx, dy = cell.sites[k].y - qy;
    const double d2 = dx * dx + dy * dy;
    if (d2 < best) {
      best = d2;
      hit.nearest = k;
    }
  }
  if (hit.nearest != cell.nearest) {
    const Site& a = cell.sites[hit.nearest];
    for (int m = 0; m < 9; ++m) {
      if (m == hit.nearest) continue;
      const Site& b = cell.sites[m];
      const double nx = b.x - a.x, ny = b.y - a.y;
      const double inv = 1.0 / std::sqrt(nx * nx + ny * ny);
      cell.nx[m] = nx * inv;
      cell.ny[m] = ny * inv;
      cell.off[m] = (0.5 * (a.x + b.x) * nx + 0.5 * (a.y + b.y) * ny) * inv;
    }
    cell.nearest = hit.nearest;
  }
  for (int m = 0; m < 9; ++m) {
    if (m == hit.nearest) {
      hit.edge_dist[m] = 1e300;
      continue;
    }
    const double d = cell.off[m] - (qx * cell.nx[m] + qy * cell.ny[m]);
    hit.edge_dist[m] = d;
    if (d < hit.edge) {
      hit.edge = d;
      hit.edge_site = m;
    }
  }
  return hit;
}

BlockFrame Generator::blockFrame(const Site& a) const {
  BlockFrame f;
  f.id = a.id;
  const double region = kPi * fbm(a.x, a.y, s_region, 7000.0, 2, 0.5, 0.0);
  const double angle =
      region + 0.6 * (uniform(a.id, 3) - 0.5) + (uniform(a.id, 4) < 0.25 ? 0.5 * kPi : 0.0);
  f.c = std::cos(angle);
  f.s = std::sin(angle);
  const double fs = p.field_size_m;
  const double big = uniform(a.id, 7) < 0.25 ? 1.7 : 1.0;
  f.lu = big * fs * (1.0 + 1.0 * uniform(a.id, 5));
  f.lv = big * fs * (0.4 + 0.35 * uniform(a.id, 6));
  return f;
}

// The field of block f at warped position q. Sites sit in staggered rows
// across the block's field axis (scaled by lu, lv): strips of fields with
// long near-parallel sides and offset ends.
FieldHit Generator::fieldAt(const BlockFrame& f, double qx, double qy, FieldCell& cell) const {
  const double u = (qx * f.c + qy * f.s) / f.lu;
  const double v = (-qx * f.s + qy * f.c) / f.lv;
  const i64 cj = static_cast<i64>(std::floor(v));
  std::array<i64, 3> ci;
  std::array<double, 3> offs;
  for (int r = 0; r < 3; ++r) {
    const double stagger = static_cast<double>(cj + r - 1) * 0.6180339887;
    offs[r] = stagger - std::floor(stagger);
    ci[r] = static_cast<i64>(std::floor(u - offs[r]));
  }
  if (!cell.valid || cell.block != f.id || cell.cj != cj || cell.ci[0] != ci[0] ||
      cell.ci[1] != ci[1] || cell.ci[2] != ci[2]) {
    const u64 fseed = s_field ^ f.id;
    int k = 0;
    for (int r = 0; r < 3; ++r) {
      const i64 row = cj + r - 1;
      for (i64 di = -1; di <= 1; ++di, ++k) {
        const u64 h = hash2(fseed, ci[r] + di, row);
        cell.ids[k] = h;
        cell.su[k] = static_cast<double>(ci[r] + di) + offs[r] + 0.5 + 0.7 * (bits(h, 0) - 0.5);
        cell.sv[k] = static_cast<double>(row) + 0.5 + 0.2 * (bits(h, 1) - 0.5);
      }
    }
    cell.block = f.id;
    cell.cj = cj;
    cell.ci = ci;
    cell.valid = true;
    cell.nearest = -1;
  }
  double best = 1e300;
  int nearest = 0;
  for (int k = 0; k < 9; ++k) {
    const double du = cell.su[k] - u, dv = cell.sv[k] - v;
    const double d2 = du * du + dv * dv;
    if (d2 < best) {
      best = d2;
      nearest = k;
    }
  }
  if (nearest != cell.nearest) {
    for (int m = 0; m < 9; ++m) {
      if (m == nearest) continue;
      const double nu = cell.su[m] - cell.su[nearest], nv = cell.sv[m] - cell.sv[nearest];
      const double gu = nu / f.lu, gv = nv / f.lv;
      const double inv_g = 1.0 / std::sqrt(gu * gu + gv * gv);
      cell.nu[m] = nu * inv_g;
      cell.nv[m] = nv * inv_g;
      cell.off[m] = (0.5 * (cell.su[m] + cell.su[nearest]) * nu +
                     0.5 * (cell.sv[m] + cell.sv[nearest]) * nv) *
                    inv_g;
    }
    cell.nearest = nearest;
  }
  FieldHit hit;
  hit.id = cell.ids[nearest];
  for (int m = 0; m < 9; ++m) {
    if (m == nearest) continue;
    const double d = cell.off[m] - (u * cell.nu[m] + v * cell.nv[m]);
    if (d < hit.edge) {
      hit.edge = d;
      hit.neighbour = cell.ids[m];
    }
  }
  return hit;
}

namespace {

// The block and field under pixel g, reusing the row's last lookup while the
// pixel stays provably far from their edges; fields are not looked up once
// pixels span several of them. The road at the block's edge comes with a
// fresh lookup.
void lookUp(const Generator& gen, const GroundPixel& g, const PixelScale& sc, GroundLookup& look,
            GroundHit& hit) {
  const double px = sc.px;
  const double moved = 1.5 * (g.x - look.ref_x);
  hit.reuse =
      look.have_hit && look.fh.edge - moved > sc.far_field && look.bh.edge - moved > sc.far_block;
  if (!hit.reuse) {
    look.bh = gen.blockAt(g.qx, g.qy, look.bcell);
    const Site& site = look.bh.sites[look.bh.nearest];
    if (!look.have_frame || look.frame.id != site.id) {
      look.frame = gen.blockFrame(site);
      look.have_frame = true;
    }
    if (smoothstep(0.25, 0.8, px / look.frame.lv) < 1.0) {
      look.fh = gen.fieldAt(look.frame, g.qx, g.qy, look.fcell);
      look.ref_x = g.x;
      look.have_hit = true;
    } else {
      look.fh = FieldHit{};
      look.have_hit = false;
    }
  }
  hit.fe = hit.reuse ? sc.far_field : look.fh.edge;
  hit.be = hit.reuse ? sc.far_block : look.bh.edge;
  hit.e = std::min(hit.fe, hit.be);
  hit.fh = look.fh;
  hit.frame = look.frame;
  hit.across = look.bh.edge_site >= 0 ? look.bh.sites[look.bh.edge_site] : Site{};
  hit.road_cov = hit.reuse ? 0.0 : gen.roadAt(look.bh, g.qx, g.qy, px, hit.road, g.detail);
}

}  // namespace

void Generator::lookUpRow(GroundRow& row, const PixelScale& sc, GroundLookup& look) const {
  for (std::size_t c = 0; c < row.pixels.size(); ++c) {
    lookUp(*this, row.pixels[c], sc, look, row.hits[c]);
  }
}

}  // namespace nadir::terrain::procedural
