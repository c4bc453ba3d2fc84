#include "calib/covariance.h"

#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace nadir::calib {

IntrinsicCovariance intrinsicCovariance(const std::vector<ViewJacobian>& views) {
  if (views.empty()) throw std::invalid_argument("intrinsicCovariance: no views");
  const Eigen::Index p = views.front().d_intrinsics.cols();
  IntrinsicCovariance result;
  Eigen::MatrixXd schur = Eigen::MatrixXd::Zero(p, p);
  double sum_r2 = 0.0;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const ViewJacobian& view = views[v];
    const Eigen::Index n = view.residuals_px.size();
    if (view.d_intrinsics.rows() != n || view.d_intrinsics.cols() != p || view.d_pose.rows() != n ||
        view.d_pose.cols() != 6)
      throw std::invalid_argument("intrinsicCovariance: view " + std::to_string(v) +
                                  "'s Jacobian does not match its residuals");
    // J^T J = [A B; B^T C] per view; the pose block C is eliminated.
    const Eigen::MatrixXd b = view.d_intrinsics.transpose() * view.d_pose;
    const Eigen::Matrix<double, 6, 6> c = view.d_pose.transpose() * view.d_pose;
    schur += view.d_intrinsics.transpose() * view.d_intrinsics - b * c.ldlt().solve(b.transpose());
    sum_r2 += view.residuals_px.squaredNorm();
    result.residuals += static_cast<int>(n);
  }
  result.parameters = static_cast<int>(p) + 6 * static_cast<int>(views.size());
  if (result.residuals <= result.parameters)
    throw std::invalid_argument("intrinsicCovariance: " + std::to_string(result.residuals) +
                                " residuals for " + std::to_string(result.parameters) +
                                " parameters");
  result.sigma2_px2 = sum_r2 / (result.residuals - result.parameters);
  // Scaled to a unit diagonal first: a focal length in px and a k3 differ in
  // scale by orders of magnitude.
  const Eigen::VectorXd scale = schur.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * schur * scale.asDiagonal();
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(scaled);
  result.ok = lu.isInvertible();
  if (result.ok)
    result.covariance =
        result.sigma2_px2 * (scale.asDiagonal() * lu.inverse() * scale.asDiagonal()).eval();
  return result;
}

}  // namespace nadir::calib
