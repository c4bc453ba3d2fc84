#pragma once
// The map's range along the rangefinder's ray: what the range the rangefinder
// measures is compared with to keep the map metric (docs/vo_feature.md, "Scale").

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace nadir::vo {

// Fewest points a plane is fitted to.
inline constexpr std::size_t kMinPlanePoints = 10;

// The distance from the origin along the ray to the plane fitted to the points
// (all in one frame, the camera's): least squares, then again without the
// points farther from it than 3 robust sigmas. Nothing with fewer than
// kMinPlanePoints points, a plane seen nearly edge-on (|normal . ray| < 0.2) or
// one behind. Unlike the points' median range along the ray, it is not biased
// when the points lie on one side of the ray, as in a bank that turns the view
// onto ground the map has not reached yet.
std::optional<double> rangeToPlaneAlongRay(const std::vector<Eigen::Vector3d>& points,
                                           const Eigen::Vector3d& ray);

// The factor the map is scaled by when its range is `ratio` times the measured
// one: 1 within `tolerance` of 1, else gain (1 / ratio - 1) of the way to
// metric, but within max_step of 1. A plane fitted to a few points on new
// ground in a bank was once 71 % short (ratio 0.29): taken at gain 0.5 it
// would scale the map by 2.2, which the next key-frames undo by halves, the
// estimate running 18 m ahead meanwhile; a scale that drifts needs only a
// percent a key-frame.
double scaleCorrection(double ratio, double tolerance, double gain, double max_step);

}  // namespace nadir::vo
