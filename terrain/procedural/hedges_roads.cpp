// Hedges and roads: the road network on the edges of the blocks (asphalt
// with shoulders, gravel with a grassy middle), hedgerows and farm tracks
// along field edges, and the lone trees of meadows.

#include <cmath>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {
namespace {

constexpr Rgb kAsphalt{112, 111, 106};
constexpr Rgb kShoulder{152, 145, 128};
constexpr Rgb kGravel{164, 153, 130};
constexpr Rgb kTrackGrass{110, 118, 76};

struct Road {
  bool kept;
  double hw;
  bool gravel;
};

Road roadOf(u64 key, double road_density) {
  Road r;
  r.kept = uniform(key, 0) < road_density;
  const double cls = uniform(key, 1);
  r.gravel = cls > 0.72;
  r.hw = cls < 0.3 ? 3.0 + 1.0 * uniform(key, 2)
                   : (r.gravel ? 2.0 + 0.4 * uniform(key, 2) : 2.1 + 0.7 * uniform(key, 2));
  return r;
}

// Is the point of the bisector with site m nearest to q on the block's real
// edge, or past the edge's ends by no more than slack?
bool onEdge(const BlockHit& hit, int m, double qx, double qy, double slack) {
  const Site& a = hit.sites[hit.nearest];
  const Site& b = hit.sites[m];
  const double d = hit.edge_dist[m];
  const double nx = b.x - a.x, ny = b.y - a.y;
  const double len = std::sqrt(nx * nx + ny * ny);
  const double fx = qx + nx / len * d, fy = qy + ny / len * d;
  for (int o = 0; o < 9; ++o) {
    if (o == hit.nearest || o == m) continue;
    const Site& s = hit.sites[o];
    const double ox = s.x - a.x, oy = s.y - a.y;
    const double olen = std::sqrt(ox * ox + oy * oy);
    const double beyond = ((fx - 0.5 * (a.x + s.x)) * ox + (fy - 0.5 * (a.y + s.y)) * oy) / olen;
    if (beyond > slack) return false;
  }
  return true;
}

}  // namespace

// Is the boundary between the fields of fh lined with a hedgerow?
bool Generator::hedged(const FieldHit& fh) const {
  return uniform(pairKey(fh.id, fh.neighbour), 7) < p.hedge_fraction;
}

// A hedgerow tree or a lone tree in a meadow at t (block hit bh at warped q)?
// If so, size is its crown's scale.
bool Generator::fieldEdgeTree(const TreeSite& t, const BlockHit& bh, double qx, double qy,
                              TreeLookup& look, double& size) const {
  const Site& a = bh.sites[bh.nearest];
  if (!look.have_frame || look.frame.id != a.id) {
    look.frame = blockFrame(a);
    look.have_frame = true;
  }
  const FieldHit fh = fieldAt(look.frame, qx, qy, look.fcell);
  if (fh.edge < 2.2 && fh.edge < bh.edge && t.u < 0.9 && hedged(fh) &&
      table.noise(t.x / 40.0 + 0.5, t.y / 40.0) > -0.45) {
    size = 0.9;
    return true;
  }
  if (t.u < 0.0015) {
    const Crop crop = fieldInfoAt(fh.id, look.frame).crop;
    if (crop == Crop::kMeadow || crop == Crop::kPasture) {
      size = 1.3;
      return true;
    }
  }
  return false;
}

// Hedgerows seen from afar and farm tracks over the field colour of pixel g.
Rgb Generator::hedgesAndTracks(Rgb field, const GroundPixel& g, const PixelScale& sc,
                               const GroundHit& hit) const {
  const double px = sc.px, fe = hit.fe, be = hit.be;
  const FieldHit& fh = hit.fh;
  // Hedgerows seen from afar: their trees' mean share of the pixel.
  if (sc.coarse > 0.0 && fe < 2.2 + px && fe <= be && hedged(fh)) {
    const double hc = bandCoverage(fe, 2.2, px) * 0.7 * sc.coarse;
    field = mix(field, forest_mean_broadleaf, hc);
  }
  // Farm tracks along a few field edges: bare ruts and a grassy middle.
  if (fe < 2.0 + px && fe <= be && uniform(pairKey(fh.id, fh.neighbour), 8) < 0.07) {
    const double track = bandCoverage(fe, 1.6, px);
    if (track > 0.0) {
      const double grass = bandCoverage(fe, 0.35, px);
      const Rgb dirt = kDirt * (1.0 + 0.1 * g.detail);
      field = mix(field, (dirt * (track - grass) + kTrackGrass * grass) * (1.0 / track), track);
    }
  }
  return field;
}

// Road coverage of a pixel and its colour; the block hit is at warped q.
double Generator::roadAt(const BlockHit& hit, double qx, double qy, double px, Rgb& colour,
                         double detail) const {
  const Site& a = hit.sites[hit.nearest];
  double best = 0.0;
  for (int m = 0; m < 9; ++m) {
    const double d = hit.edge_dist[m];
    if (d > 4.0 + px) continue;
    const Site& b = hit.sites[m];
    const u64 key = pairKey(a.id, b.id);
    const Road road = roadOf(key, p.road_density);
    if (!road.kept) continue;
    const double cov = bandCoverage(d, road.hw, px);
    if (cov <= best) continue;
    const bool real = onEdge(hit, m, qx, qy, road.hw);
    if (!real) continue;
    best = cov;
    if (road.gravel) {
      const double grass = bandCoverage(d, 0.35, px);
      const double tracks = bandCoverage(d - 0.9, 0.3, px);
      const Rgb g = kGravel * (1.0 + 0.06 * detail);
      colour = (g * (cov - grass - tracks) + kTrackGrass * grass + g * 0.82 * tracks) * (1.0 / cov);
    } else {
      const double inner = bandCoverage(d, road.hw - 0.5, px);
      const double k = 0.94 + 0.12 * uniform(key, 3);
      colour = (kAsphalt * (k * (1.0 + 0.04 * detail)) * inner + kShoulder * (cov - inner)) *
               (1.0 / cov);
    }
  }
  return best;
}

// Distance from q to the nearest kept road of q's block (1e300 if none),
// that road's half width and the site across it.
double Generator::roadDistance(const BlockHit& hit, double qx, double qy, double& hw,
                               int& site) const {
  const Site& a = hit.sites[hit.nearest];
  double best = 1e300;
  for (int m = 0; m < 9; ++m) {
    if (m == hit.nearest || hit.edge_dist[m] >= best) continue;
    const Road road = roadOf(pairKey(a.id, hit.sites[m].id), p.road_density);
    if (!road.kept || !onEdge(hit, m, qx, qy, road.hw)) continue;
    best = hit.edge_dist[m];
    hw = road.hw;
    site = m;
  }
  return best;
}

// The roads found with the blocks (lookUpRow) over the row's colours.
void Generator::paintRoads(const GroundRow& row, std::span<Rgb> col) {
  for (std::size_t c = 0; c < col.size(); ++c) {
    const GroundHit& hit = row.hits[c];
    if (hit.road_cov > 0.0) col[c] = mix(col[c], hit.road, hit.road_cov);
  }
}

}  // namespace nadir::terrain::procedural
