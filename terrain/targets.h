#pragma once
// Ground targets: printed mats laid on the ground at known positions, drawn
// into the camera images at far finer resolution than the terrain imagery.
//  - concentric: nested black square rings on white (McConville et al.'s (2020) target, found
//    by flooding from the border and inverting N times);
//  - gate: four black disks inside two concentric black squares (Liu et al. 2021).

#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/geodesy.h"
#include "core/params.h"

namespace nadir::terrain {

struct GroundTarget {
  // "concentric" or "gate".
  std::string kind = "concentric";
  // Centre in the world frame (local NED), m; or, with geodetic, by latitude
  // and longitude (resolved to north/east by resolveGeodeticTargets).
  double north_m = 0.0;
  double east_m = 0.0;
  bool geodetic = false;
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  // Edge length of the square mat, m.
  double size_m = 1.0;
  // Rotation of the mat about the down axis, from north towards east, deg.
  double yaw_deg = 0.0;
  // Concentric: black rings, each two boundaries.
  int rings = 5;

  void visit(core::ParamVisitor& v);
};

// Sets north_m/east_m of the targets given by latitude and longitude.
void resolveGeodeticTargets(std::vector<GroundTarget>& targets, const core::LocalNedFrame& frame);

// The mat as an 8-bit RGB image (CV_8UC3), size_px square, row 0 at the mat's
// north edge when yaw is 0. Edges are area-averaged (anti-aliased).
cv::Mat targetTexture(const GroundTarget& target, int size_px);

}  // namespace nadir::terrain
