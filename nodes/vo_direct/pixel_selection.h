#pragma once
// Which pixels a key-frame hosts: region-adaptive gradient thresholds (the
// median gradient of each block plus a margin, smoothed over the neighbouring
// blocks), and the strongest pixel of each cell of a grid, looked for at three
// scales so that weak-texture regions still give points at a coarser level.
// Spread over the whole image; docs/vo_direct.md says how.

#include <vector>

#include "core/params.h"
#include "nodes/vo_direct/image_pyramid.h"

namespace nadir::vo {

struct PixelSelectionParams {
  // How many pixels to aim for over the whole image.
  int target_points = 2000;
  // The blocks the gradient threshold adapts over, level-0 pixels.
  int block_px = 32;
  // A pixel qualifies when its gradient magnitude exceeds the block's median by this.
  double threshold_margin = 7.0;
  // At each coarser scale the threshold is multiplied by this.
  double coarse_threshold_factor = 0.75;
  // Pixels this close to the border are never selected (the pattern and the
  // coarse levels must fit), level-0 pixels.
  int border_px = 8;

  void visit(core::ParamVisitor& v);
};

struct SelectedPixel {
  float x = 0, y = 0;  // level-0 pixel
  int scale = 0;       // 0, 1 or 2: the scale of the cell it was found in
  float gradient = 0;  // gradient magnitude at that scale
};

// The pyramid needs gradients at levels 0-2. The cell size (level-0 px) that
// hits the target is found by trial; cell_px, when given, holds where to start
// (0: from the image's area) and receives the size used, so that a sequence of
// similar images mostly needs one trial.
std::vector<SelectedPixel> selectPixels(const ImagePyramid& pyramid,
                                        const PixelSelectionParams& params,
                                        double* cell_px = nullptr);

}  // namespace nadir::vo
