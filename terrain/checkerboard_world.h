#pragma once
// A flat world holding one checkerboard: the calibration target of the virtual
// checkerboard (calib/virtual_board.h) and the renderer's geometric tests.
// The board lies on the ground centred on the origin, one square of white
// margin around it (the quiet zone a detector needs), mid-grey ground beyond.
// Imagery is area-averaged (4 x 4 samples per pixel), so an edge lands where
// it truly is at any resolution the renderer asks for.

#include "core/params.h"
#include "terrain/world.h"

namespace nadir::terrain {

struct CheckerboardParams {
  // Inner corners along east (the board's columns) and along north (its rows).
  int inner_cols = 9;
  int inner_rows = 6;
  double square_m = 0.025;

  void visit(core::ParamVisitor& v);
};

class CheckerboardWorld : public World {
 public:
  // Throws core::ParamError on values outside CheckerboardParams' ranges.
  explicit CheckerboardWorld(const CheckerboardParams& params, double ground_up_m = 0.0);

  double groundUp_m(double north_m, double east_m) const override;
  void imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const override;
  // 200 pixels a square; the ground 100 squares a sample (it is flat).
  double imageryResolution_m() const override;
  double elevationResolution_m() const override;
  // 200 squares either way of the origin.
  WorldExtent extent() const override;

  const CheckerboardParams& board() const { return params_; }
  // Inner corner (row, col): row along north from the south edge, col along
  // east from the west edge, world frame metres.
  double cornerNorth_m(int row) const;
  double cornerEast_m(int col) const;

  // Grey levels of the dark and light squares, and of the ground around.
  static constexpr double kDark = 20.0;
  static constexpr double kLight = 235.0;
  static constexpr double kGround = 128.0;

 private:
  double value(double north_m, double east_m) const;

  CheckerboardParams params_;
  double ground_up_m_;
};

}  // namespace nadir::terrain
