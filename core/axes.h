#pragma once
// The axes a file is written in. nadir's own: world local NED, a vehicle's body
// FRD. REP-103's, as ROS and evo take them: world local ENU (x east, y north,
// z up), a vehicle's body FLU (x forward, y left, z up). A camera keeps its
// OpenCV optical frame (x right, y down, z along the optical axis) in both.
// Every conversion is a swap and sign flips of axes: positions and vectors
// convert exactly; a quaternion to within a rounding.

#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nadir::core {

enum class Axes { kNed, kEnu };
// "ned" or "enu"; throws std::invalid_argument naming both otherwise.
Axes parseAxes(const std::string& name);
std::string axesName(Axes axes);

// What the body of a pose is: a vehicle (FRD; FLU in ENU) or a camera.
enum class BodyAxes { kVehicle, kCamera };

// A world-frame position or vector, from NED into axes, and back.
Eigen::Vector3d worldVectorIn(Axes axes, const Eigen::Vector3d& v_ned);
Eigen::Vector3d worldVectorToNed(Axes axes, const Eigen::Vector3d& v);
// A vehicle-body vector (an IMU's rate or force), from FRD into axes.
Eigen::Vector3d bodyVectorIn(Axes axes, const Eigen::Vector3d& v_frd);
// q_world_body, from nadir's axes into axes, and back.
Eigen::Quaterniond attitudeIn(Axes axes, const Eigen::Quaterniond& q_ned_body, BodyAxes body);
Eigen::Quaterniond attitudeToNed(Axes axes, const Eigen::Quaterniond& q_world_body, BodyAxes body);
// T_body_sensor with the vehicle body in axes (the sensor's frame unchanged).
Eigen::Isometry3d bodyToSensorIn(Axes axes, const Eigen::Isometry3d& T_frd_sensor);

// What a file's frame line says: "world=enu body=flu", "world=ned body=camera".
std::string frameTag(Axes axes, BodyAxes body);
// The same in words, for a file's header.
std::string frameWords(Axes axes, BodyAxes body);

}  // namespace nadir::core
