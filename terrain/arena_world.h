#pragma once
// An indoor robot arena: a flat floor with a mottled grey finish (a sealed
// concrete or vinyl floor), for the ground rover of Liu et al. (2021). The
// floor is light enough that the pixel processor's dark threshold never
// takes it for pattern ink, and textured enough that a rolling wheel's
// camera sees it move. Imagery is area-averaged, deterministic, thread-safe.

#include <cstdint>

#include "core/params.h"
#include "terrain/world.h"

namespace nadir::terrain {

struct ArenaParams {
  // Half the floor's side, m: the floor covers [-half_size_m, half_size_m] both ways.
  double half_size_m = 50.0;
  // Mean grey of the floor (8-bit counts) and the size of its mottling.
  double floor_grey = 165.0;
  double mottle_counts = 18.0;
  // Wavelength of the coarsest mottling, m (the finer octaves halve it).
  double mottle_m = 0.2;
  std::int64_t seed = 1;

  void visit(core::ParamVisitor& v);
};

class ArenaWorld : public World {
 public:
  // Throws core::ParamError on values outside ArenaParams' ranges.
  explicit ArenaWorld(const ArenaParams& params);

  double groundUp_m(double north_m, double east_m) const override;
  void imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const override;
  // 2 mm a pixel: a camera a decimetre above the floor sees its grain.
  double imageryResolution_m() const override { return 0.002; }
  double elevationResolution_m() const override { return 1.0; }
  WorldExtent extent() const override;

  // The floor's grey at a point, counts, averaged over a footprint of fp m.
  double floorGrey(double north_m, double east_m, double footprint_m) const;

 private:
  ArenaParams params_;
};

}  // namespace nadir::terrain
