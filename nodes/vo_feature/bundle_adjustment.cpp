#include "nodes/vo_feature/bundle_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

namespace nadir::vo {

void BundleAdjustmentParams::visit(core::ParamVisitor& v) {
  v.field("max_iterations", &max_iterations,
          {.doc = "Levenberg-Marquardt iterations per solve", .min = 1, .max = 1000});
  v.field("huber_px", &huber_px,
          {.doc = "Huber threshold on the reprojection error / sigma_px (0: none)",
           .min = 0.0,
           .max = 1000.0});
  v.field("outlier_chi2", &outlier_chi2,
          {.doc = "after solving, (error / sigma_px)^2 above this flags an outlier (5.991: 95 %)",
           .min = 0.01,
           .max = 1e6});
  v.field("outlier_rounds", &outlier_rounds,
          {.doc = "re-solves without the flagged outliers, repeated while the flags change",
           .min = 0,
           .max = 10});
  v.field(
      "num_threads", &num_threads,
      {.doc = "solver threads (1 gives bit-identical results between runs)", .min = 1, .max = 256});
}

namespace {

// A camera's parameter blocks: R_world_cam as an Eigen quaternion (x, y, z, w)
// and the camera centre in the world frame, m.
struct CameraBlocks {
  std::array<double, 4> q_world_cam{};
  std::array<double, 3> p_world_cam_m{};
};

// The whitened reprojection error of one observation.
class ReprojectionCost {
 public:
  ReprojectionCost(const BaIntrinsics& K, const Eigen::Vector2d& px, double sigma_px)
      : K_(K), px_(px), inv_sigma_(1.0 / sigma_px) {}

  template <typename T>
  bool operator()(const T* q_world_cam, const T* p_world_cam_m, const T* p_world_m,
                  T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_world_cam);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> centre(p_world_cam_m);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> point(p_world_m);
    const Eigen::Matrix<T, 3, 1> p_cam = q.conjugate() * (point - centre);
    if (!(p_cam.z() > T(0))) {
      return false;  // behind the camera: Ceres rejects the step
    }
    residual[0] = (T(K_.fx) * p_cam.x() / p_cam.z() + T(K_.cx) - T(px_.x())) * T(inv_sigma_);
    residual[1] = (T(K_.fy) * p_cam.y() / p_cam.z() + T(K_.cy) - T(px_.y())) * T(inv_sigma_);
    return true;
  }

 private:
  BaIntrinsics K_;
  Eigen::Vector2d px_;
  double inv_sigma_;
};

// The rotation vector of R_ab_prior^T R_world_cam_a^T R_world_cam_b, over
// sigma.
class RotationPriorCost {
 public:
  RotationPriorCost(const Eigen::Quaterniond& R_ab, double sigma_rad, double sigma_about_a_z_rad)
      : R_ab_prior_(R_ab.normalized()),
        R_ba_prior_(R_ab.normalized().conjugate()),
        inv_sigma_(1.0 / sigma_rad),
        inv_sigma_z_(1.0 / (sigma_about_a_z_rad > 0.0 ? sigma_about_a_z_rad : sigma_rad)) {}

  template <typename T>
  bool operator()(const T* q_world_cam_a, const T* q_world_cam_b, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_a(q_world_cam_a);
    const Eigen::Map<const Eigen::Quaternion<T>> q_b(q_world_cam_b);
    const Eigen::Quaternion<T> q_err = R_ba_prior_.cast<T>() * (q_a.conjugate() * q_b);
    const T wxyz[4] = {q_err.w(), q_err.x(), q_err.y(), q_err.z()};
    Eigen::Matrix<T, 3, 1> error_b;
    ceres::QuaternionToAngleAxis(wxyz, error_b.data());
    // In a's axes, where the heading is the part about z.
    const Eigen::Matrix<T, 3, 1> error_a = R_ab_prior_.cast<T>() * error_b;
    residual[0] = error_a.x() * T(inv_sigma_);
    residual[1] = error_a.y() * T(inv_sigma_);
    residual[2] = error_a.z() * T(inv_sigma_z_);
    return true;
  }

 private:
  Eigen::Quaterniond R_ab_prior_;
  Eigen::Quaterniond R_ba_prior_;
  double inv_sigma_;
  double inv_sigma_z_;
};

// The reprojection error in px, or nothing when the point is not in front.
bool reprojectionError(const BaIntrinsics& K, const CameraBlocks& cam,
                       const std::array<double, 3>& p_world_m, const Eigen::Vector2d& px,
                       Eigen::Vector2d& error_px) {
  const Eigen::Map<const Eigen::Quaterniond> q(cam.q_world_cam.data());
  const Eigen::Map<const Eigen::Vector3d> centre(cam.p_world_cam_m.data());
  const Eigen::Map<const Eigen::Vector3d> point(p_world_m.data());
  const Eigen::Vector3d p_cam = q.conjugate() * (point - centre);
  if (!(p_cam.z() > 0.0)) {
    return false;
  }
  error_px =
      Eigen::Vector2d(K.fx * p_cam.x() / p_cam.z() + K.cx, K.fy * p_cam.y() / p_cam.z() + K.cy) -
      px;
  return true;
}

void checkCamera(int index, const BaProblem& problem, const char* what) {
  if (index < 0 || index >= static_cast<int>(problem.cameras.size())) {
    throw std::invalid_argument(std::string("bundleAdjust: ") + what + " " + std::to_string(index) +
                                " is not one of the " + std::to_string(problem.cameras.size()) +
                                " cameras");
  }
}

void validate(const BaProblem& problem) {
  if (!(problem.K.fx > 0.0) || !(problem.K.fy > 0.0)) {
    throw std::invalid_argument("bundleAdjust: the focal lengths must be positive");
  }
  for (const BaObservation& obs : problem.observations) {
    checkCamera(obs.camera, problem, "observation's camera");
    if (obs.point < 0 || obs.point >= static_cast<int>(problem.points.size())) {
      throw std::invalid_argument("bundleAdjust: observation's point " + std::to_string(obs.point) +
                                  " is not one of the " + std::to_string(problem.points.size()) +
                                  " points");
    }
    if (!(obs.sigma_px > 0.0) || !std::isfinite(obs.sigma_px)) {
      throw std::invalid_argument("bundleAdjust: an observation's sigma_px must be positive");
    }
  }
  for (const BaRotationPrior& prior : problem.rotation_priors) {
    checkCamera(prior.camera_a, problem, "rotation prior's camera_a");
    checkCamera(prior.camera_b, problem, "rotation prior's camera_b");
    if (prior.camera_a == prior.camera_b) {
      throw std::invalid_argument("bundleAdjust: a rotation prior needs two different cameras");
    }
    if (!(prior.sigma_rad > 0.0) || !std::isfinite(prior.sigma_rad)) {
      throw std::invalid_argument("bundleAdjust: a rotation prior's sigma_rad must be positive");
    }
    if (!(prior.sigma_about_a_z_rad >= 0.0) || !std::isfinite(prior.sigma_about_a_z_rad)) {
      throw std::invalid_argument(
          "bundleAdjust: a rotation prior's sigma_about_a_z_rad must be 0 or positive");
    }
  }
}

double rmse(double sum_squares, int count) {
  return count > 0 ? std::sqrt(sum_squares / (2.0 * count)) : 0.0;
}

// The parameter blocks of one call: copies of the cameras and points that
// Ceres refines, written back at the end.
struct State {
  std::vector<CameraBlocks> cameras;
  std::vector<std::array<double, 3>> points;
};

struct PassReport {
  bool converged = true;
  int iterations = 0;
  std::string summary = "nothing to adjust";
};

// One Levenberg-Marquardt solve over the active observations and the priors,
// in place on state; marks the free cameras and points that took part.
PassReport solvePass(const BaProblem& problem, const BundleAdjustmentParams& params,
                     const std::vector<bool>& active, State& state, std::vector<bool>& camera_moved,
                     std::vector<bool>& point_moved) {
  const std::size_t num_cameras = problem.cameras.size();
  std::vector<bool> rotation_used(num_cameras, false);
  std::vector<bool> position_used(num_cameras, false);
  std::vector<bool> point_used(problem.points.size(), false);
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    if (active[i]) {
      const BaObservation& obs = problem.observations[i];
      rotation_used[obs.camera] = position_used[obs.camera] = true;
      point_used[obs.point] = true;
    }
  }
  std::vector<bool> prior_used(problem.rotation_priors.size(), false);
  for (std::size_t i = 0; i < problem.rotation_priors.size(); ++i) {
    const BaRotationPrior& prior = problem.rotation_priors[i];
    if (!problem.cameras[prior.camera_a].fixed || !problem.cameras[prior.camera_b].fixed) {
      prior_used[i] = rotation_used[prior.camera_a] = rotation_used[prior.camera_b] = true;
    }
  }

  // The problem owns the costs; the one loss and manifold shared by all blocks
  // live here (declared first, they outlive the problem).
  ceres::EigenQuaternionManifold quaternion_manifold;
  std::unique_ptr<ceres::LossFunction> huber;
  if (params.huber_px > 0.0) {
    huber = std::make_unique<ceres::HuberLoss>(params.huber_px);
  }
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);

  // Parameter blocks; the free points go first in the elimination order.
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  int free_points = 0;
  int free_cameras = 0;
  for (std::size_t j = 0; j < point_used.size(); ++j) {
    if (!point_used[j]) {
      continue;
    }
    double* block = state.points[j].data();
    ceres_problem.AddParameterBlock(block, 3);
    if (problem.points[j].fixed) {
      ceres_problem.SetParameterBlockConstant(block);
    } else {
      ordering->AddElementToGroup(block, 0);
      point_moved[j] = true;
      ++free_points;
    }
  }
  for (std::size_t i = 0; i < num_cameras; ++i) {
    const bool fixed = problem.cameras[i].fixed;
    double* q = state.cameras[i].q_world_cam.data();
    double* p = state.cameras[i].p_world_cam_m.data();
    if (rotation_used[i]) {
      ceres_problem.AddParameterBlock(q, 4, &quaternion_manifold);
    }
    if (position_used[i]) {
      ceres_problem.AddParameterBlock(p, 3);
    }
    if (!rotation_used[i] && !position_used[i]) {
      continue;
    }
    if (fixed) {
      if (rotation_used[i]) ceres_problem.SetParameterBlockConstant(q);
      if (position_used[i]) ceres_problem.SetParameterBlockConstant(p);
      continue;
    }
    if (rotation_used[i]) ordering->AddElementToGroup(q, 1);
    if (position_used[i]) ordering->AddElementToGroup(p, 1);
    camera_moved[i] = true;
    ++free_cameras;
  }

  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    if (!active[i]) {
      continue;
    }
    const BaObservation& obs = problem.observations[i];
    auto* cost = new ceres::AutoDiffCostFunction<ReprojectionCost, 2, 4, 3, 3>(
        new ReprojectionCost(problem.K, obs.px, obs.sigma_px));
    ceres_problem.AddResidualBlock(cost, huber.get(), state.cameras[obs.camera].q_world_cam.data(),
                                   state.cameras[obs.camera].p_world_cam_m.data(),
                                   state.points[obs.point].data());
  }
  for (std::size_t i = 0; i < problem.rotation_priors.size(); ++i) {
    if (!prior_used[i]) {
      continue;
    }
    const BaRotationPrior& prior = problem.rotation_priors[i];
    auto* cost = new ceres::AutoDiffCostFunction<RotationPriorCost, 3, 4, 4>(
        new RotationPriorCost(prior.R_ab, prior.sigma_rad, prior.sigma_about_a_z_rad));
    ceres_problem.AddResidualBlock(cost, nullptr, state.cameras[prior.camera_a].q_world_cam.data(),
                                   state.cameras[prior.camera_b].q_world_cam.data());
  }

  PassReport report;
  if (ceres_problem.NumResidualBlocks() == 0 || free_points + free_cameras == 0) {
    return report;
  }
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = params.max_iterations;
  options.num_threads = params.num_threads;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  if (free_points > 0 && free_cameras > 0) {
    // A key-frame window's reduced camera system is small and dense.
    options.linear_solver_type = free_cameras <= 40 ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
    options.linear_solver_ordering = ordering;
  } else {
    options.linear_solver_type =
        free_points + free_cameras <= 40 ? ceres::DENSE_QR : ceres::SPARSE_NORMAL_CHOLESKY;
  }
  ceres::Solver::Summary summary;
  ceres::Solve(options, &ceres_problem, &summary);
  report.converged = summary.termination_type == ceres::CONVERGENCE;
  report.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  report.summary = summary.BriefReport();
  return report;
}

}  // namespace

BaResult bundleAdjust(BaProblem& problem, const BundleAdjustmentParams& params) {
  validate(problem);
  const std::size_t num_obs = problem.observations.size();

  State state;
  state.cameras.resize(problem.cameras.size());
  for (std::size_t i = 0; i < problem.cameras.size(); ++i) {
    const Eigen::Isometry3d& T = problem.cameras[i].T_world_cam;
    const Eigen::Quaterniond q(T.rotation());
    state.cameras[i].q_world_cam = {q.x(), q.y(), q.z(), q.w()};
    state.cameras[i].p_world_cam_m = {T.translation().x(), T.translation().y(),
                                      T.translation().z()};
  }
  state.points.resize(problem.points.size());
  for (std::size_t j = 0; j < problem.points.size(); ++j) {
    const Eigen::Vector3d& p = problem.points[j].p_world_m;
    state.points[j] = {p.x(), p.y(), p.z()};
  }

  // Observations of points in front of their camera at the start take part.
  std::vector<bool> in_front(num_obs, false);
  std::vector<double> initial_sq_px(num_obs, 0.0);
  for (std::size_t i = 0; i < num_obs; ++i) {
    const BaObservation& obs = problem.observations[i];
    Eigen::Vector2d error_px;
    in_front[i] = reprojectionError(problem.K, state.cameras[obs.camera], state.points[obs.point],
                                    obs.px, error_px);
    initial_sq_px[i] = in_front[i] ? error_px.squaredNorm() : 0.0;
  }

  // The chi-square test at the current state; returns the number of outliers.
  std::vector<bool> outlier(num_obs, false);
  std::vector<double> final_sq_px(num_obs, 0.0);
  const auto classify = [&] {
    int count = 0;
    for (std::size_t i = 0; i < num_obs; ++i) {
      const BaObservation& obs = problem.observations[i];
      Eigen::Vector2d error_px;
      outlier[i] = !in_front[i] ||
                   !reprojectionError(problem.K, state.cameras[obs.camera], state.points[obs.point],
                                      obs.px, error_px) ||
                   (error_px / obs.sigma_px).squaredNorm() > params.outlier_chi2;
      final_sq_px[i] = outlier[i] ? 0.0 : error_px.squaredNorm();
      count += outlier[i] ? 1 : 0;
    }
    return count;
  };

  std::vector<bool> camera_moved(problem.cameras.size(), false);
  std::vector<bool> point_moved(problem.points.size(), false);
  PassReport pass = solvePass(problem, params, in_front, state, camera_moved, point_moved);
  BaResult result;
  result.converged = pass.converged;
  result.iterations = pass.iterations;
  result.summary = pass.summary;
  int num_outliers = classify();
  const int num_behind = static_cast<int>(std::count(in_front.begin(), in_front.end(), false));
  // Solve again without the flagged observations while the flags change.
  for (int round = 0; round < params.outlier_rounds && num_outliers > num_behind; ++round) {
    std::vector<bool> active(num_obs);
    for (std::size_t i = 0; i < num_obs; ++i) {
      active[i] = !outlier[i];
    }
    pass = solvePass(problem, params, active, state, camera_moved, point_moved);
    result.converged = pass.converged;
    result.iterations += pass.iterations;
    result.summary += "; without " + std::to_string(num_outliers) + " outliers: " + pass.summary;
    const std::vector<bool> before = outlier;
    num_outliers = classify();
    if (outlier == before) {
      break;
    }
  }

  // Write back the free cameras and points that took part.
  for (std::size_t i = 0; i < problem.cameras.size(); ++i) {
    if (!camera_moved[i]) {
      continue;
    }
    const std::array<double, 4>& q = state.cameras[i].q_world_cam;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
    T.translation() = Eigen::Map<const Eigen::Vector3d>(state.cameras[i].p_world_cam_m.data());
    problem.cameras[i].T_world_cam = T;
  }
  for (std::size_t j = 0; j < problem.points.size(); ++j) {
    if (point_moved[j]) {
      problem.points[j].p_world_m = Eigen::Map<const Eigen::Vector3d>(state.points[j].data());
    }
  }

  // The RMSE before and after, over the observations that are not outliers.
  double initial_sum = 0.0;
  double final_sum = 0.0;
  for (std::size_t i = 0; i < num_obs; ++i) {
    if (!outlier[i]) {
      initial_sum += initial_sq_px[i];
      final_sum += final_sq_px[i];
    }
  }
  const int num_inliers = static_cast<int>(num_obs) - num_outliers;
  result.initial_rmse_px = rmse(initial_sum, num_inliers);
  result.final_rmse_px = rmse(final_sum, num_inliers);
  result.outlier = std::move(outlier);
  result.num_outliers = num_outliers;
  result.summary += "; " + std::to_string(num_outliers) + " of " + std::to_string(num_obs) +
                    " observations outliers";
  return result;
}

}  // namespace nadir::vo
