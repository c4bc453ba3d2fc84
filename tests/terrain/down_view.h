#pragma once
// A tile-selection view for the tile tests: straight down from a height.

#include <cmath>
#include <cstddef>

#include <Eigen/Core>

#include "terrain/tiles.h"

namespace nadir::terrain {

// A view straight down from height h over (north, east), 1000 px focal length, 90 deg field.
inline LodView downView(double north, double east, double h) {
  LodView view;
  view.camera_ned = Eigen::Vector3d(north, east, -h);
  view.focal_px = 1000.0;
  // Four side planes at 45 deg from the vertical, near and far.
  const double s = std::sqrt(0.5);
  const Eigen::Vector3d normals[4] = {{s, 0, s}, {-s, 0, s}, {0, s, s}, {0, -s, s}};
  for (int i = 0; i < 4; ++i) {
    view.frustum_planes[static_cast<std::size_t>(i)] << normals[i],
        -normals[i].dot(view.camera_ned);
  }
  view.frustum_planes[4] << 0, 0, 1, h - 0.1;    // down from the camera, past 0.1 m
  view.frustum_planes[5] << 0, 0, -1, -h + 1e5;  // up to 100 km
  return view;
}

}  // namespace nadir::terrain
