// Fields: each field of a block has a crop, a colour and rows in its own
// direction, tramlines and mowing bands, a headland and a grassy margin;
// fields narrower than a pixel blend into their analytic mean colour.

#include <algorithm>
#include <array>
#include <cmath>

#include "terrain/procedural/generator.h"

namespace nadir::terrain::procedural {
namespace {

constexpr Rgb kSoilDark{98, 84, 68};
constexpr Rgb kSoilLight{158, 140, 112};
constexpr Rgb kMarginGrass{104, 114, 72};

// Fifteen uniform numbers from five hashes.
class FieldUniforms {
 public:
  explicit FieldUniforms(u64 id)
      : hs_{mix64(id + 0x1111), mix64(id + 0x2222), mix64(id + 0x3333), mix64(id + 0x4444),
            mix64(id + 0x5555)} {}
  double operator()(int k) const { return bits(hs_[static_cast<std::size_t>(k / 3)], k % 3); }

 private:
  std::array<u64, 5> hs_;
};

Crop chooseCrop(double u0, double bare_soil_fraction) {
  if (u0 < bare_soil_fraction) return Crop::kSoil;
  const double u = (u0 - bare_soil_fraction) / std::max(1e-9, 1.0 - bare_soil_fraction);
  static constexpr std::array<double, 7> kCum = {0.30, 0.40, 0.52, 0.58, 0.82, 0.94, 1.0};
  static constexpr std::array<Crop, 7> kCrops = {Crop::kCereal, Crop::kRipe,   Crop::kMaize,
                                                 Crop::kRape,   Crop::kMeadow, Crop::kPasture,
                                                 Crop::kStubble};
  for (std::size_t i = 0; i < kCum.size(); ++i) {
    if (u < kCum[i]) return kCrops[i];
  }
  return Crop::kStubble;
}

// Brightness, soil, the rows' direction and the phases of rows, tramlines and
// bands, common to all crops.
void setLayout(FieldInfo& fi, const BlockFrame& f, const FieldUniforms& u) {
  const double j1 = u(1), j2 = u(2), j3 = u(3), j4 = u(4), j5 = u(5), j6 = u(6);
  fi.bright = 0.9 + 0.2 * j1;
  fi.soil_k = 0.92 + 0.16 * j2;
  // Rows along the field's long axis mostly, else across it or skewed.
  double nx = -f.s, ny = f.c;
  if (j3 > 0.75) {
    nx = f.c;
    ny = f.s;
  }
  if (j3 > 0.92) {
    const double rx = 0.939372713 * nx - 0.342897807 * ny;
    ny = 0.342897807 * nx + 0.939372713 * ny;
    nx = rx;
  }
  const double jitter = 0.04 * (j4 - 0.5);
  const double norm = 1.0 / std::sqrt(1.0 + jitter * jitter);
  fi.row_nx = (nx - jitter * ny) * norm;
  fi.row_ny = (ny + jitter * nx) * norm;
  fi.row_phase = j5 * 100.0;
  fi.tram_phase = j6 * 100.0;
  fi.band_phase = u(7) * 100.0;
  fi.margin_hw = 0.4 + 0.9 * u(8);
  fi.headland = 8.0 + 8.0 * u(9);
}

// The crop's colours and texture.
void setCropLook(FieldInfo& fi, const FieldUniforms& u) {
  const double hue = u(10);
  switch (fi.crop) {
    case Crop::kCereal:
      fi.plant = mix(Rgb{92, 112, 60}, Rgb{108, 120, 66}, hue);
      fi.dry = Rgb{150, 146, 92};
      fi.cover = 0.88;
      fi.row_lambda = 1.4 + 1.2 * u(11);
      fi.row_cover = 0.05;
      fi.row_bright = 0.05;
      fi.tram_lambda = 18.0 + 6.0 * std::floor(u(12) * 2.0);
      fi.var_cover = 0.05;
      fi.var_bright = 0.04;
      fi.detail = 0.05;
      fi.fine = 0.07;
      break;
    case Crop::kRipe:
      fi.plant = mix(Rgb{178, 160, 106}, Rgb{196, 176, 124}, hue);
      fi.dry = Rgb{200, 184, 138};
      fi.cover = 0.92;
      fi.row_lambda = 1.2 + 1.0 * u(11);
      fi.row_cover = 0.03;
      fi.row_bright = 0.04;
      fi.tram_lambda = 18.0 + 6.0 * std::floor(u(12) * 2.0);
      fi.var_cover = 0.04;
      fi.var_bright = 0.03;
      fi.detail = 0.045;
      fi.fine = 0.06;
      break;
    case Crop::kMaize:
      fi.plant = mix(Rgb{66, 90, 46}, Rgb{80, 100, 52}, hue);
      fi.dry = Rgb{110, 118, 70};
      fi.cover = 0.72;
      fi.row_lambda = 0.75;
      fi.row_cover = 0.25;
      fi.row_bright = 0.06;
      fi.var_cover = 0.05;
      fi.var_bright = 0.035;
      fi.detail = 0.07;
      fi.headland = 6.0;
      fi.fine = 0.1;
      break;
    case Crop::kRape:
      fi.plant = mix(Rgb{100, 114, 64}, Rgb{120, 126, 72}, hue);
      fi.dry = Rgb{146, 140, 88};
      fi.cover = 0.9;
      fi.row_lambda = 1.5 + 0.8 * u(11);
      fi.row_cover = 0.04;
      fi.row_bright = 0.04;
      fi.tram_lambda = 24.0;
      fi.var_cover = 0.06;
      fi.var_bright = 0.04;
      fi.detail = 0.06;
      fi.fine = 0.08;
      break;
    case Crop::kMeadow:
      fi.plant = mix(Rgb{96, 118, 66}, Rgb{116, 130, 78}, hue);
      fi.dry = Rgb{150, 148, 100};
      fi.cover = 0.95;
      if (u(13) < 0.5) {
        fi.band_lambda = 3.0 + 3.0 * u(14);
        fi.band_hw = 0.25 * fi.band_lambda;
        fi.band_bright = 0.07;
      }
      fi.var_cover = 0.025;
      fi.var_bright = 0.04;
      fi.detail = 0.06;
      fi.headland = 0.0;
      fi.fine = 0.13;
      break;
    case Crop::kPasture:
      fi.plant = mix(Rgb{116, 128, 80}, Rgb{132, 138, 90}, hue);
      fi.dry = Rgb{160, 152, 108};
      fi.cover = 0.85;
      fi.var_cover = 0.06;
      fi.var_bright = 0.04;
      fi.detail = 0.07;
      fi.headland = 0.0;
      fi.fine = 0.15;
      break;
    case Crop::kSoil:
      fi.plant = Rgb{104, 112, 70};
      fi.dry = Rgb{120, 118, 80};
      fi.cover = 0.04 * u(11);
      fi.row_lambda = 0.9 + 2.2 * u(12);
      fi.row_cover = 0.0;
      fi.row_bright = 0.06 + 0.05 * u(13);
      fi.var_cover = 0.025;
      fi.var_bright = 0.08;
      fi.detail = 0.07;
      fi.headland = 10.0;
      fi.fine = 0.14;
      break;
    case Crop::kStubble:
      fi.plant = mix(Rgb{184, 168, 128}, Rgb{196, 180, 140}, hue);
      fi.dry = Rgb{200, 186, 146};
      fi.cover = 0.8;
      fi.row_lambda = 1.5 + 1.0 * u(11);
      fi.row_cover = 0.04;
      fi.row_bright = 0.03;
      fi.band_lambda = 5.0 + 3.0 * u(14);
      fi.band_hw = 0.6;
      fi.band_bright = 0.1;
      fi.tram_lambda = 18.0 + 6.0 * std::floor(u(12) * 2.0);
      fi.var_cover = 0.05;
      fi.var_bright = 0.035;
      fi.detail = 0.06;
      fi.fine = 0.09;
      break;
  }
}

}  // namespace

FieldInfo Generator::fieldInfo(u64 id, const BlockFrame& f, double px) const {
  FieldInfo fi = fieldInfoAt(id, f);
  if (fi.row_lambda > 0.0) {
    fi.row_amp1 = sineAmplitude(fi.row_lambda, px);
    fi.row_amp2 = sineAmplitude(0.5 * fi.row_lambda, px);
  }
  return fi;
}

FieldInfo Generator::fieldInfoAt(u64 id, const BlockFrame& f) const {
  FieldInfo fi;
  fi.id = id;
  const FieldUniforms u(id);
  fi.crop = chooseCrop(u(0), p.bare_soil_fraction);
  setLayout(fi, f, u);
  setCropLook(fi, u);
  const double k = p.texture_strength;
  fi.row_cover *= k;
  fi.row_bright *= k;
  fi.band_bright *= k;
  fi.var_cover *= k;
  fi.var_bright *= k;
  fi.detail *= k;
  fi.fine *= k;
  return fi;
}

Rgb Generator::soilColour(const Pix& c) const {
  return mix(kSoilDark, kSoilLight, smooth01(0.5 + 1.2 * c.soil));
}

double Generator::dryness(const Pix& c) const { return clamp01(0.3 + 0.9 * c.tint); }

Rgb Generator::meanFieldColour(const Pix& c) const {
  return soilColour(c) * field_soil + field_plant + field_dry * dryness(c);
}

// Colour of field fi at pixel g (at its warped position, with its smooth
// fields), e from the field's edge.
Rgb Generator::fieldColour(const FieldInfo& fi, const GroundPixel& g, double e, double px) const {
  const double qx = g.qx, qy = g.qy, mid = g.mid, fine = g.fine;
  const Pix& c = g.f;
  const double detail = 0.6 * mid + 0.8 * fine;
  double across = qx * fi.row_nx + qy * fi.row_ny;
  const bool headland = e < fi.headland;
  if (headland) across = e + fi.row_phase;
  double cover = fi.cover + fi.var_cover * c.var * 2.0;
  double bright =
      fi.bright * (1.0 + fi.var_bright * c.var * 2.0) * (1.0 + fi.detail * mid + fi.fine * fine);
  if (fi.row_lambda > 0.0) {
    const double turns = (across + fi.row_phase) / fi.row_lambda;
    const double sn = sine(turns), cs = sine(turns + 0.25);
    const double s = fi.row_amp1 * sn + 0.7 * fi.row_amp2 * sn * cs;
    cover += fi.row_cover * s;
    bright *= 1.0 + fi.row_bright * s;
  }
  if (fi.tram_lambda > 0.0 && !headland) {
    const double t = periodicBand(across, fi.tram_lambda, fi.tram_phase - 0.9, 0.25, px) +
                     periodicBand(across, fi.tram_lambda, fi.tram_phase + 0.9, 0.25, px);
    cover = lerp(cover, 0.1, 0.75 * t);
  }
  if (fi.band_lambda > 0.0 && !headland) {
    const double b = periodicBand(across, fi.band_lambda, fi.band_phase, fi.band_hw, px) -
                     2.0 * fi.band_hw / fi.band_lambda;
    bright *= 1.0 + fi.band_bright * b;
  }
  const Rgb soil = soilColour(c) * fi.soil_k;
  const Rgb plant = mix(fi.plant, fi.dry, dryness(c));
  Rgb col = mix(soil, plant, clamp01(cover)) * bright;
  const double m = bandCoverage(e, fi.margin_hw, px);
  if (m > 0.0) col = mix(col, kMarginGrass * (1.0 + 0.12 * detail), m);
  return col;
}

namespace {

// The description of field id, from the cache or made and kept there.
const FieldInfo& cachedFieldInfo(const Generator& gen, u64 id, const BlockFrame& f, double px,
                                 FieldCache& cache) {
  const std::size_t k = static_cast<std::size_t>(mix64(id) & 7u);
  if (!cache.ok[k] || cache.info[k].id != id) {
    cache.info[k] = gen.fieldInfo(id, f, px);
    cache.ok[k] = true;
  }
  return cache.info[k];
}

// The colour of the field across the pixel's nearer edge: the neighbour in
// the same block, or the field of the block beyond the block's edge.
Rgb neighbourColour(const Generator& gen, const GroundPixel& g, const GroundHit& hit, double px,
                    FieldCache& cache) {
  const double e = hit.e;
  if (hit.fe <= hit.be) {
    return gen.fieldColour(cachedFieldInfo(gen, hit.fh.neighbour, hit.frame, px, cache), g, e, px);
  }
  const Site& nb = hit.across;
  if (!cache.have_frame_nb || cache.frame_nb.id != nb.id) {
    cache.frame_nb = gen.blockFrame(nb);
    cache.have_frame_nb = true;
  }
  const FieldHit nh = gen.fieldAt(cache.frame_nb, g.qx, g.qy, cache.fcell_nb);
  return gen.fieldColour(cachedFieldInfo(gen, nh.id, cache.frame_nb, px, cache), g, e, px);
}

// The fields under pixel g: its field with the neighbour's share of the
// pixel across an edge, hedges and tracks along the edge.
Rgb fieldsColour(const Generator& gen, const GroundPixel& g, const GroundHit& hit,
                 const PixelScale& sc, FieldCache& cache) {
  const double px = sc.px, e = hit.e;
  // Once pixels span several fields, their colours average out.
  const double to_mean = smoothstep(0.25, 0.8, px / hit.frame.lv);
  Rgb colour = gen.meanFieldColour(g.f) * (1.0 + 0.08 * g.mid);
  if (to_mean < 1.0) {
    const FieldInfo& fi = cachedFieldInfo(gen, hit.fh.id, hit.frame, px, cache);
    Rgb field = gen.fieldColour(fi, g, e, px);
    if (e < 0.5 * px && px >= 4.0) {
      // Coarse: the pixel's share beyond the edge gets the fields' mean.
      field = mix(field, colour, clamp01(0.5 - e / px));
    } else if (e < 0.5 * px) {  // the neighbouring field's share of the pixel
      const Rgb other = neighbourColour(gen, g, hit, px, cache);
      field = mix(field, other, clamp01(0.5 - e / px));
    }
    field = gen.hedgesAndTracks(field, g, sc, hit);
    colour = mix(field, colour, to_mean);
  }
  return colour;
}

}  // namespace

void Generator::paintFields(const GroundRow& row, const PixelScale& sc, FieldCache& cache,
                            std::span<Rgb> col) const {
  for (std::size_t c = 0; c < col.size(); ++c) {
    col[c] = fieldsColour(*this, row.pixels[c], row.hits[c], sc, cache);
  }
}

// The analytic mean colour of the fields, from a fixed sample of them.
void Generator::calibrateFields() {
  BlockFrame frame;
  const int n = 8192;
  for (int i = 0; i < n; ++i) {
    const FieldInfo fi = fieldInfoAt(mix64(seed + 0xF1E1DULL * (i + 1)), frame);
    const double cover = clamp01(fi.cover);
    field_soil += fi.bright * (1.0 - cover) * fi.soil_k;
    field_plant = field_plant + fi.plant * (fi.bright * cover);
    field_dry = field_dry + (fi.dry - fi.plant) * (fi.bright * cover);
  }
  field_soil /= n;
  field_plant = field_plant * (1.0 / n);
  field_dry = field_dry * (1.0 / n);
}

}  // namespace nadir::terrain::procedural
