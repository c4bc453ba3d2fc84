#pragma once
// The feature VO's tests' ground: the default TexturedPlane (0.2 m texels,
// +-400 m, fixed seed; tests/support/textured_plane.h), its texture made once.

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "tests/support/textured_plane.h"

namespace nadir::test {

inline const cv::Mat& groundTexture() {
  static const cv::Mat texture = TexturedPlane{}.texture();
  return texture;
}

// The frame a camera with intrinsics K at T_world_cam sees of that ground.
inline cv::Mat renderGround(const Eigen::Isometry3d& T_world_cam, const cv::Matx33d& K,
                            cv::Size size) {
  return TexturedPlane{}.render(groundTexture(), T_world_cam, K, size);
}

}  // namespace nadir::test
