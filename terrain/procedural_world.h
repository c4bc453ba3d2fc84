#pragma once
// The procedural world: nadir's embedded default terrain. Rolling hills with
// ridges and river valleys, and over them an orthophoto-like patchwork of
// fields (each with crop rows in its own direction), forests of individual
// tree crowns, hedgerows, a road network, meandering rivers and farmsteads,
// shaded by one sun. Everything is a pure function of the seed and the
// position (integer hashing, no global state), so any square at any size is
// generated on demand, bit-identically on any thread and in any order, with no
// file and bounded memory.
//
// Imagery is filtered to the pixel's footprint: detail finer than a pixel fades
// to its mean (crop rows, tree crowns, buildings), lines and edges get their
// area coverage, so a coarse square looks like the area average of fine ones,
// and adjacent squares at the same pixel size meet without seams.
//
// Heights: hills about relief_m above broad valley floors, rivers 10-30 m
// wide carved into the valleys (so water lies in low ground), a gentle tilt
// along the rivers' direction; groundUp_m is analytic and stays within
// [-0.65, +0.7] * relief_m of the origin plane.

#include <cstdint>
#include <memory>

#include "core/params.h"
#include "terrain/world.h"

namespace nadir::terrain {

struct ProceduralWorldParams {
  std::int64_t seed = 1;
  double size_m = 20000.0;
  double relief_m = 100.0;
  double imagery_resolution_m = 0.3;
  double sun_azimuth_deg = 150.0;
  double sun_elevation_deg = 45.0;
  double field_size_m = 180.0;
  double block_size_m = 900.0;
  double road_density = 0.6;
  double river_spacing_m = 5000.0;
  double forest_fraction = 0.25;
  double bare_soil_fraction = 0.15;
  double hedge_fraction = 0.2;
  double buildings_per_km2 = 12.0;
  // Scales the texture inside the fields (crop rows, patchiness, fine detail):
  // 1 as drawn, 0 uniform fields with only their edges.
  double texture_strength = 1.0;

  void visit(core::ParamVisitor& v) {
    v.field("seed", &seed,
            {.doc = "world seed; the same seed gives the same world",
             .min = 0,
             .max = 9007199254740992.0});
    v.field(
        "size_m", &size_m,
        {.doc = "side of the square world, centred on the origin, m", .min = 100, .max = 200000});
    v.field("relief_m", &relief_m,
            {.doc = "height of the hills above the valley floors, m; heights stay within "
                    "+-relief_m of the origin plane",
             .min = 0,
             .max = 2000});
    v.field("imagery_resolution_m", &imagery_resolution_m,
            {.doc = "finest imagery ground sample distance, m/px", .min = 0.25, .max = 2});
    v.field("sun_azimuth_deg", &sun_azimuth_deg,
            {.doc = "direction of the sun, deg clockwise from north", .min = 0, .max = 360});
    v.field("sun_elevation_deg", &sun_elevation_deg,
            {.doc = "height of the sun above the horizon, deg (shadows and hillshade)",
             .min = 15,
             .max = 90});
    v.field("field_size_m", &field_size_m,
            {.doc = "typical side of an agricultural field, m", .min = 40, .max = 1000});
    v.field("block_size_m", &block_size_m,
            {.doc = "typical spacing of the road network's junctions, m", .min = 200, .max = 5000});
    v.field("road_density", &road_density,
            {.doc = "fraction of the road network's links that carry a road", .min = 0, .max = 1});
    v.field("river_spacing_m", &river_spacing_m,
            {.doc = "typical distance between neighbouring rivers, m", .min = 1000, .max = 50000});
    v.field("forest_fraction", &forest_fraction,
            {.doc = "fraction of the area covered by forest", .min = 0, .max = 0.9});
    v.field("bare_soil_fraction", &bare_soil_fraction,
            {.doc = "fraction of the fields that are bare (ploughed) soil", .min = 0, .max = 1});
    v.field("hedge_fraction", &hedge_fraction,
            {.doc = "fraction of field boundaries lined with hedgerow trees", .min = 0, .max = 1});
    v.field("buildings_per_km2", &buildings_per_km2,
            {.doc = "mean number of buildings per square kilometre", .min = 0, .max = 200});
    v.field("texture_strength", &texture_strength,
            {.doc = "texture inside the fields: 1 as drawn, 0 uniform fields", .min = 0, .max = 2});
  }
};

class ProceduralWorld final : public World {
 public:
  // Throws core::ParamError if a parameter is out of its range.
  explicit ProceduralWorld(const ProceduralWorldParams& params = {});
  ~ProceduralWorld() override;
  ProceduralWorld(const ProceduralWorld&) = delete;
  ProceduralWorld& operator=(const ProceduralWorld&) = delete;

  // Within [-relief_m, +relief_m] (see above); analytic, so continuous with
  // continuous slope; about 0.5 us a call.
  double groundUp_m(double north_m, double east_m) const override;
  // Any square at any size; outside extent() the landscape continues. Costs
  // roughly 10-20 ms per 256 x 256 pixels on one core; larger squares are
  // split into 256-pixel blocks rendered in parallel. Throws
  // std::invalid_argument for size_px < 1 or a non-finite or empty square.
  void imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const override;
  void imageryBeneathObjects(const GroundSquare& square, int size_px, cv::Mat& rgb) const override;
  // params().imagery_resolution_m: the finest detail is drawn for it.
  double imageryResolution_m() const override;
  // 4 m: the height field's finest octaves are about 12 m long.
  double elevationResolution_m() const override;
  WorldExtent extent() const override;
  // Every tree (forest, hedgerow, field-edge and riverside trees alike) and
  // building whose centre is in the square, as the imagery places them; about
  // 40 000 trees a square kilometre of forest.
  std::vector<GroundObject> objects(const GroundSquare& square) const override;
  std::array<double, 3> sunDirectionNed() const override;

  const ProceduralWorldParams& params() const;

 private:
  void drawImagery(const GroundSquare& square, int size_px, bool tops, cv::Mat& rgb) const;
  struct Impl;
  std::unique_ptr<const Impl> impl_;
};

}  // namespace nadir::terrain
