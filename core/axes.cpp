#include "core/axes.h"

#include <cmath>
#include <stdexcept>

namespace nadir::core {
namespace {

// R_enu_ned: a half turn about (north + east) / sqrt 2 swaps north and east
// and turns down into up.
const Eigen::Quaterniond kQ_enu_ned(0.0, M_SQRT1_2, M_SQRT1_2, 0.0);
// R_frd_flu: a half turn about x turns left into right and up into down.
const Eigen::Quaterniond kQ_frd_flu(0.0, 1.0, 0.0, 0.0);

}  // namespace

Axes parseAxes(const std::string& name) {
  if (name == "ned") return Axes::kNed;
  if (name == "enu") return Axes::kEnu;
  throw std::invalid_argument("axes '" + name +
                              "' are neither ned (nadir's: world NED, body FRD) nor enu "
                              "(REP-103's: world ENU, body FLU)");
}

std::string axesName(Axes axes) { return axes == Axes::kEnu ? "enu" : "ned"; }

Eigen::Vector3d worldVectorIn(Axes axes, const Eigen::Vector3d& v_ned) {
  if (axes == Axes::kNed) return v_ned;
  return {v_ned.y(), v_ned.x(), -v_ned.z()};
}

Eigen::Vector3d worldVectorToNed(Axes axes, const Eigen::Vector3d& v) {
  return worldVectorIn(axes, v);  // the swap is its own inverse
}

Eigen::Vector3d bodyVectorIn(Axes axes, const Eigen::Vector3d& v_frd) {
  if (axes == Axes::kNed) return v_frd;
  return {v_frd.x(), -v_frd.y(), -v_frd.z()};
}

Eigen::Quaterniond attitudeIn(Axes axes, const Eigen::Quaterniond& q_ned_body, BodyAxes body) {
  if (axes == Axes::kNed) return q_ned_body;
  Eigen::Quaterniond q = kQ_enu_ned * q_ned_body;
  if (body == BodyAxes::kVehicle) q = q * kQ_frd_flu;
  // w >= 0: the same rotation, as most writers of REP-103 files give it.
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return q.normalized();
}

Eigen::Quaterniond attitudeToNed(Axes axes, const Eigen::Quaterniond& q_world_body, BodyAxes body) {
  if (axes == Axes::kNed) return q_world_body;
  Eigen::Quaterniond q = kQ_enu_ned.conjugate() * q_world_body;
  if (body == BodyAxes::kVehicle) q = q * kQ_frd_flu.conjugate();
  return q.normalized();
}

Eigen::Isometry3d bodyToSensorIn(Axes axes, const Eigen::Isometry3d& T_frd_sensor) {
  if (axes == Axes::kNed) return T_frd_sensor;
  Eigen::Isometry3d T_flu_frd = Eigen::Isometry3d::Identity();
  T_flu_frd.linear() = kQ_frd_flu.conjugate().toRotationMatrix();
  return T_flu_frd * T_frd_sensor;
}

std::string frameTag(Axes axes, BodyAxes body) {
  const std::string body_name =
      body == BodyAxes::kCamera ? "camera" : (axes == Axes::kEnu ? "flu" : "frd");
  return "world=" + axesName(axes) + " body=" + body_name;
}

std::string frameWords(Axes axes, BodyAxes body) {
  std::string words = axes == Axes::kEnu ? "world local ENU (x east, y north, z up: REP-103)"
                                         : "world local NED (x north, y east, z down)";
  if (body == BodyAxes::kCamera) {
    words += ", body the camera (OpenCV optical: x right, y down, z along the optical axis)";
  } else {
    words += axes == Axes::kEnu ? ", body FLU (x forward, y left, z up)"
                                : ", body FRD (x forward, y right, z down)";
  }
  return words;
}

}  // namespace nadir::core
