#include "logs/eval/alignment.h"

#include <Eigen/SVD>

#include <limits>

namespace nadir::eval {

AlignMode parseAlignMode(const std::string& name) {
  if (name == "none") return AlignMode::kNone;
  if (name == "se3") return AlignMode::kSe3;
  if (name == "sim3") return AlignMode::kSim3;
  throw EvalError("unknown alignment '" + name + "' (expected none, se3 or sim3)");
}

std::string alignModeName(AlignMode mode) {
  switch (mode) {
    case AlignMode::kSe3:
      return "se3";
    case AlignMode::kSim3:
      return "sim3";
    case AlignMode::kNone:
      break;
  }
  return "none";
}

Alignment umeyamaAlignment(const std::vector<Eigen::Vector3d>& est,
                           const std::vector<Eigen::Vector3d>& ref, bool with_scale) {
  if (est.size() != ref.size()) {
    throw EvalError("alignment: " + std::to_string(est.size()) + " estimated and " +
                    std::to_string(ref.size()) + " reference positions (must be equal)");
  }
  if (est.empty()) throw EvalError("alignment: no positions to align");
  const double n = static_cast<double>(est.size());
  Eigen::Vector3d mean_est = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_ref = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < est.size(); ++i) {
    mean_est += est[i];
    mean_ref += ref[i];
  }
  mean_est /= n;
  mean_ref /= n;
  // Variance of the estimate and the ref-est cross-covariance (Umeyama eq. 36, 38).
  double variance_est = 0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < est.size(); ++i) {
    const Eigen::Vector3d e = est[i] - mean_est;
    variance_est += e.squaredNorm();
    covariance += (ref[i] - mean_ref) * e.transpose();
  }
  variance_est /= n;
  covariance /= n;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  // evo refuses fewer than m - 1 = 2 singular values above machine epsilon; a
  // relative threshold also catches collinear points that rounding lifts above it.
  const double threshold = std::max(std::numeric_limits<double>::epsilon(),
                                    1e-12 * std::max(d(0), std::numeric_limits<double>::min()));
  const int rank = (d.array() > threshold).count();
  if (rank < 2 || variance_est <= 0) {
    throw EvalError("alignment: degenerate positions (" + std::to_string(est.size()) +
                    " poses on a point or a line); Umeyama alignment is not possible");
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) S(2, 2) = -1;

  Alignment alignment;
  alignment.R = svd.matrixU() * S * svd.matrixV().transpose();
  alignment.scale = with_scale ? (d.asDiagonal() * S).trace() / variance_est : 1.0;
  alignment.t = mean_ref - alignment.scale * alignment.R * mean_est;
  return alignment;
}

Alignment alignTrajectories(const core::Trajectory& ref, const core::Trajectory& est,
                            AlignMode mode) {
  if (mode == AlignMode::kNone) return {};
  std::vector<Eigen::Vector3d> ref_p;
  std::vector<Eigen::Vector3d> est_p;
  ref_p.reserve(ref.size());
  est_p.reserve(est.size());
  for (const core::StampedPose& pose : ref) ref_p.push_back(pose.p_ned_m);
  for (const core::StampedPose& pose : est) est_p.push_back(pose.p_ned_m);
  return umeyamaAlignment(est_p, ref_p, mode == AlignMode::kSim3);
}

void applyAlignment(const Alignment& alignment, core::Trajectory& trajectory) {
  const Eigen::Quaterniond q_align(alignment.R);
  for (core::StampedPose& pose : trajectory) {
    pose.p_ned_m = alignment.scale * (alignment.R * pose.p_ned_m) + alignment.t;
    pose.q_world_body = (q_align * pose.q_world_body).normalized();
  }
}

}  // namespace nadir::eval
