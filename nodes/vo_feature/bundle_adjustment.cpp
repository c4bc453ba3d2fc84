#include "nodes/vo_feature/bundle_adjustment.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
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
  v.field("num_threads", &num_threads,
          {.doc = "threads evaluating the residuals and their Jacobians (the result does not "
                  "depend on them)",
           .min = 1,
           .max = 256});
}

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat26 = Eigen::Matrix<double, 2, 6>;
using Mat23 = Eigen::Matrix<double, 2, 3>;
using Mat63 = Eigen::Matrix<double, 6, 3>;

struct CameraState {
  Eigen::Quaterniond q_world_cam = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_world_cam_m = Eigen::Vector3d::Zero();
};

// The cameras and points one call refines, written back at the end.
struct State {
  std::vector<CameraState> cameras;
  std::vector<Eigen::Vector3d> points;
};

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

Eigen::Quaterniond expMap(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle < 1e-12) {
    return Eigen::Quaterniond(1.0, 0.5 * rotation_vector.x(), 0.5 * rotation_vector.y(),
                              0.5 * rotation_vector.z())
        .normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation_vector / angle));
}

Eigen::Vector3d logMap(Eigen::Quaterniond q) {
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double n = q.vec().norm();
  if (n < 1e-12) return 2.0 * q.vec();
  return 2.0 * std::atan2(n, q.w()) * q.vec() / n;
}

// The inverse of SO(3)'s right Jacobian at phi.
Eigen::Matrix3d rightJacobianInverse(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d s = skew(phi);
  if (angle < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * s;
  const double c =
      1.0 / (angle * angle) - (1.0 + std::cos(angle)) / (2.0 * angle * std::sin(angle));
  return Eigen::Matrix3d::Identity() + 0.5 * s + c * s * s;
}

// A rotation prior's whitened error, the rotation vector of
// R_ab_prior^T R_a^T R_b in a's axes over its sigmas, and its Jacobians with
// respect to rotations applied on each camera's side.
struct PriorTerm {
  Eigen::Vector3d error = Eigen::Vector3d::Zero();
  Eigen::Matrix3d d_a = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d d_b = Eigen::Matrix3d::Zero();
};

PriorTerm priorTerm(const BaRotationPrior& prior, const CameraState& a, const CameraState& b) {
  const Eigen::Quaterniond R_ab_prior = prior.R_ab.normalized();
  const Eigen::Matrix3d M = (a.q_world_cam.conjugate() * b.q_world_cam).toRotationMatrix();
  const Eigen::Vector3d phi =
      logMap(R_ab_prior.conjugate() * a.q_world_cam.conjugate() * b.q_world_cam);
  const double sigma_z =
      prior.sigma_about_a_z_rad > 0.0 ? prior.sigma_about_a_z_rad : prior.sigma_rad;
  const Eigen::Matrix3d A =
      Eigen::Vector3d(1.0 / prior.sigma_rad, 1.0 / prior.sigma_rad, 1.0 / sigma_z).asDiagonal() *
      R_ab_prior.toRotationMatrix();
  // E = R_prior^T R_a^T R_b: with R_b Exp(d), E Exp(d); with R_a Exp(d), E Exp(-M^T d).
  const Eigen::Matrix3d J = A * rightJacobianInverse(phi);
  return {A * phi, -J * M.transpose(), J};
}

// Ceres' convention: the cost of a residual r is rho(|r|^2) / 2 with Huber's
// rho(s) = s up to k^2 and 2 k sqrt(s) - k^2 beyond.
double huberRho(double s, double k) {
  return k <= 0.0 || s <= k * k ? s : 2.0 * k * std::sqrt(s) - k * k;
}

// rho'(s), the weight of the residual in the normal equations.
double huberWeight(double s, double k) { return k <= 0.0 || s <= k * k ? 1.0 : k / std::sqrt(s); }

// Runs fn(begin, end) over [0, n) in up to `threads` contiguous chunks, the
// first on this thread.
template <typename Fn>
void forChunks(std::size_t n, int threads, const Fn& fn) {
  const std::size_t chunks = std::min<std::size_t>(static_cast<std::size_t>(std::max(threads, 1)),
                                                   std::max<std::size_t>(n / 256, 1));
  if (chunks <= 1) {
    fn(std::size_t{0}, n);
    return;
  }
  std::vector<std::thread> workers;
  for (std::size_t c = 1; c < chunks; ++c)
    workers.emplace_back([&fn, n, c, chunks] { fn(n * c / chunks, n * (c + 1) / chunks); });
  fn(std::size_t{0}, n / chunks);
  for (std::thread& t : workers) t.join();
}

struct PassReport {
  bool converged = true;
  int iterations = 0;
  std::string summary = "nothing to adjust";
};

// One Levenberg-Marquardt solve over the active observations and the priors
// (the reduced camera system by the Schur complement of the points, dense),
// in place on state.
class LmPass {
 public:
  LmPass(const BaProblem& problem, const BundleAdjustmentParams& params,
         const std::vector<bool>& active, State& state)
      : problem_(problem), params_(params), state_(state) {
    const std::size_t num_cameras = problem.cameras.size();
    std::vector<bool> camera_used(num_cameras, false);
    std::vector<bool> point_used(problem.points.size(), false);
    for (std::size_t i = 0; i < problem.observations.size(); ++i) {
      if (!active[i]) continue;
      const BaObservation& obs = problem.observations[i];
      obs_.push_back(static_cast<int>(i));
      camera_used[obs.camera] = true;
      point_used[obs.point] = true;
    }
    for (std::size_t i = 0; i < problem.rotation_priors.size(); ++i) {
      const BaRotationPrior& prior = problem.rotation_priors[i];
      if (!problem.cameras[prior.camera_a].fixed || !problem.cameras[prior.camera_b].fixed) {
        priors_.push_back(static_cast<int>(i));
        camera_used[prior.camera_a] = camera_used[prior.camera_b] = true;
      }
    }
    camera_var_.assign(num_cameras, -1);
    for (std::size_t i = 0; i < num_cameras; ++i)
      if (camera_used[i] && !problem.cameras[i].fixed) camera_var_[i] = num_free_cameras_++;
    point_var_.assign(problem.points.size(), -1);
    for (std::size_t j = 0; j < point_used.size(); ++j)
      if (point_used[j] && !problem.points[j].fixed) point_var_[j] = num_free_points_++;
    // The observations of each free point, for the Schur complement.
    point_obs_begin_.assign(static_cast<std::size_t>(num_free_points_) + 1, 0);
    for (int o : obs_) {
      const int m = point_var_[problem.observations[o].point];
      if (m >= 0) ++point_obs_begin_[static_cast<std::size_t>(m) + 1];
    }
    for (std::size_t m = 0; m < static_cast<std::size_t>(num_free_points_); ++m)
      point_obs_begin_[m + 1] += point_obs_begin_[m];
    point_obs_.resize(point_obs_begin_.back());
    std::vector<int> fill(point_obs_begin_.begin(), point_obs_begin_.end() - 1);
    for (std::size_t k = 0; k < obs_.size(); ++k) {
      const int m = point_var_[problem.observations[obs_[k]].point];
      if (m >= 0)
        point_obs_[static_cast<std::size_t>(fill[static_cast<std::size_t>(m)]++)] =
            static_cast<int>(k);
    }
    residual_.resize(obs_.size());
    weight_.resize(obs_.size());
    d_camera_.resize(obs_.size());
    d_point_.resize(obs_.size());
    W_.resize(obs_.size());
  }

  PassReport run(std::vector<bool>& camera_moved, std::vector<bool>& point_moved) {
    for (std::size_t i = 0; i < camera_var_.size(); ++i)
      if (camera_var_[i] >= 0) camera_moved[i] = true;
    for (std::size_t j = 0; j < point_var_.size(); ++j)
      if (point_var_[j] >= 0) point_moved[j] = true;
    PassReport report;
    if ((obs_.empty() && priors_.empty()) || num_free_cameras_ + num_free_points_ == 0)
      return report;

    std::optional<double> cost = evaluate(state_);
    report.converged = false;
    if (!cost) {
      report.summary = "a point behind its camera at the start";
      return report;
    }
    const double initial_cost = *cost;
    const char* termination = "iterations ran out";
    int accepted = 0;
    double radius = 1e4;  // as Ceres' Levenberg-Marquardt: mu = 1 / radius
    double decrease_factor = 2.0;
    linearize();
    if (max_gradient_ <= 1e-10) {
      report.converged = true;
      termination = "gradient zero";
    }
    while (!report.converged && report.iterations < params_.max_iterations) {
      ++report.iterations;
      const std::optional<double> model_decrease = solveStep(1.0 / radius);
      std::optional<double> new_cost;
      State candidate;
      if (model_decrease) {
        if (step_norm_ <= 1e-8 * (parameterNorm() + 1e-8)) {
          report.converged = true;
          termination = "step tiny";
          break;
        }
        candidate = applyStep();
        new_cost = evaluate(candidate);
      }
      const double quality =
          new_cost && *model_decrease > 0.0 ? (*cost - *new_cost) / *model_decrease : -1.0;
      if (quality > 1e-3) {
        ++accepted;
        const double relative_decrease = (*cost - *new_cost) / std::max(*cost, 1e-300);
        state_ = std::move(candidate);
        cost = new_cost;
        radius /= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * quality - 1.0, 3));
        radius = std::min(radius, 1e16);
        decrease_factor = 2.0;
        linearize();
        if (relative_decrease <= 1e-6 || max_gradient_ <= 1e-10) {
          report.converged = true;
          termination = "converged";
        }
      } else {
        if (new_cost && std::abs(*cost - *new_cost) <= 1e-6 * *cost) {
          report.converged = true;
          termination = "converged";
          break;
        }
        radius /= decrease_factor;
        decrease_factor *= 2.0;
        if (radius < 1e-32) {
          termination = "no step decreases the cost";
          break;
        }
      }
    }
    char text[160];
    std::snprintf(text, sizeof text, "LM %d steps (%d taken), cost %.6g -> %.6g, %s",
                  report.iterations, accepted, initial_cost, *cost, termination);
    report.summary = text;
    return report;
  }

 private:
  // The total cost, or nothing when an observation's point is not in front.
  std::optional<double> evaluate(const State& s) const {
    std::vector<Eigen::Matrix3d> R(s.cameras.size());
    for (std::size_t i = 0; i < s.cameras.size(); ++i)
      R[i] = s.cameras[i].q_world_cam.toRotationMatrix();
    const double k = params_.huber_px;
    std::vector<double> part(obs_.size());
    std::vector<char> ok(obs_.size(), 1);
    forChunks(obs_.size(), params_.num_threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t n = begin; n < end; ++n) {
        const BaObservation& obs = problem_.observations[obs_[n]];
        Eigen::Vector2d r;
        ok[n] = reprojectionResidual(problem_.K, obs.px, 1.0 / obs.sigma_px, R[obs.camera],
                                     s.cameras[obs.camera].p_world_cam_m, s.points[obs.point], r,
                                     nullptr, nullptr);
        part[n] = ok[n] ? huberRho(r.squaredNorm(), k) : 0.0;
      }
    });
    double sum = 0.0;
    for (std::size_t n = 0; n < obs_.size(); ++n) {
      if (!ok[n]) return std::nullopt;
      sum += part[n];
    }
    for (int p : priors_) {
      const BaRotationPrior& prior = problem_.rotation_priors[p];
      sum += priorTerm(prior, s.cameras[prior.camera_a], s.cameras[prior.camera_b])
                 .error.squaredNorm();
    }
    return 0.5 * sum;
  }

  // The Gauss-Newton system at state_: H_cc (dense), the points' blocks, the
  // camera-point blocks W, the gradient.
  void linearize() {
    std::vector<Eigen::Matrix3d> R(state_.cameras.size());
    for (std::size_t i = 0; i < R.size(); ++i)
      R[i] = state_.cameras[i].q_world_cam.toRotationMatrix();
    const double k = params_.huber_px;
    forChunks(obs_.size(), params_.num_threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t n = begin; n < end; ++n) {
        const BaObservation& obs = problem_.observations[obs_[n]];
        reprojectionResidual(problem_.K, obs.px, 1.0 / obs.sigma_px, R[obs.camera],
                             state_.cameras[obs.camera].p_world_cam_m, state_.points[obs.point],
                             residual_[n], &d_camera_[n], &d_point_[n]);
        weight_[n] = huberWeight(residual_[n].squaredNorm(), k);
      }
    });
    const Eigen::Index nc = 6 * num_free_cameras_;
    H_cc_.setZero(nc, nc);
    g_c_.setZero(nc);
    V_.assign(static_cast<std::size_t>(num_free_points_), Eigen::Matrix3d::Zero());
    g_p_.assign(static_cast<std::size_t>(num_free_points_), Eigen::Vector3d::Zero());
    for (std::size_t n = 0; n < obs_.size(); ++n) {
      const BaObservation& obs = problem_.observations[obs_[n]];
      const int c = camera_var_[obs.camera];
      const int m = point_var_[obs.point];
      const double w = weight_[n];
      if (c >= 0) {
        const Eigen::Matrix<double, 6, 2> wJt = w * d_camera_[n].transpose();
        H_cc_.block<6, 6>(6 * c, 6 * c).noalias() += wJt * d_camera_[n];
        g_c_.segment<6>(6 * c).noalias() += wJt * residual_[n];
        if (m >= 0) W_[n].noalias() = wJt * d_point_[n];
      }
      if (m >= 0) {
        const Eigen::Matrix<double, 3, 2> wJt = w * d_point_[n].transpose();
        V_[static_cast<std::size_t>(m)].noalias() += wJt * d_point_[n];
        g_p_[static_cast<std::size_t>(m)].noalias() += wJt * residual_[n];
      }
    }
    for (int p : priors_) {
      const BaRotationPrior& prior = problem_.rotation_priors[p];
      const PriorTerm t =
          priorTerm(prior, state_.cameras[prior.camera_a], state_.cameras[prior.camera_b]);
      const int a = camera_var_[prior.camera_a];
      const int b = camera_var_[prior.camera_b];
      if (a >= 0) {
        H_cc_.block<3, 3>(6 * a, 6 * a) += t.d_a.transpose() * t.d_a;
        g_c_.segment<3>(6 * a) += t.d_a.transpose() * t.error;
      }
      if (b >= 0) {
        H_cc_.block<3, 3>(6 * b, 6 * b) += t.d_b.transpose() * t.d_b;
        g_c_.segment<3>(6 * b) += t.d_b.transpose() * t.error;
      }
      if (a >= 0 && b >= 0) {
        H_cc_.block<3, 3>(6 * a, 6 * b) += t.d_a.transpose() * t.d_b;
        H_cc_.block<3, 3>(6 * b, 6 * a) += t.d_b.transpose() * t.d_a;
      }
    }
    max_gradient_ = g_c_.size() > 0 ? g_c_.cwiseAbs().maxCoeff() : 0.0;
    for (const Eigen::Vector3d& g : g_p_)
      max_gradient_ = std::max(max_gradient_, g.cwiseAbs().maxCoeff());
  }

  // Solves (H + mu D) delta = -g, D = diag(H) within [1e-6, 1e32] (Ceres'
  // bounds), eliminating the points first. Returns the model's decrease
  // (nothing for a step that is not finite).
  std::optional<double> solveStep(double mu) {
    const auto damping = [mu](double d) { return mu * std::clamp(d, 1e-6, 1e32); };
    const Eigen::Index nc = 6 * num_free_cameras_;
    Eigen::MatrixXd S = H_cc_;
    Eigen::VectorXd b = g_c_;
    Eigen::VectorXd D_c(nc);
    for (Eigen::Index i = 0; i < nc; ++i) {
      D_c[i] = damping(H_cc_(i, i));
      S(i, i) += D_c[i];
    }
    V_inv_.resize(static_cast<std::size_t>(num_free_points_));
    D_p_.resize(static_cast<std::size_t>(num_free_points_));
    // S -= W V^-1 W^T point by point, into S's lower triangle (all the LDLT reads).
    std::vector<std::pair<int, Mat63>> seen;  // the point's free cameras and W V^-1
    for (std::size_t m = 0; m < static_cast<std::size_t>(num_free_points_); ++m) {
      Eigen::Matrix3d V = V_[m];
      for (int i = 0; i < 3; ++i) {
        D_p_[m][i] = damping(V_[m](i, i));
        V(i, i) += D_p_[m][i];
      }
      V_inv_[m] = V.inverse();
      seen.clear();
      for (int a = point_obs_begin_[m]; a < point_obs_begin_[m + 1]; ++a) {
        const std::size_t n = static_cast<std::size_t>(point_obs_[static_cast<std::size_t>(a)]);
        const int c = camera_var_[problem_.observations[obs_[n]].camera];
        if (c < 0) continue;
        const Mat63 Y = W_[n] * V_inv_[m];
        b.segment<6>(6 * c).noalias() -= Y * g_p_[m];
        S.block<6, 6>(6 * c, 6 * c).noalias() -= Y * W_[n].transpose();
        for (const auto& [c_before, Y_before] : seen) {
          // The pair's two blocks are each other's transpose: the lower one only.
          const Mat6 block = Y_before * W_[n].transpose();
          if (c_before > c) {
            S.block<6, 6>(6 * c_before, 6 * c) -= block;
          } else if (c_before < c) {
            S.block<6, 6>(6 * c, 6 * c_before) -= block.transpose();
          } else {
            S.block<6, 6>(6 * c, 6 * c) -= block + block.transpose();
          }
        }
        seen.emplace_back(c, Y);
      }
    }
    delta_c_ = nc > 0 ? Eigen::VectorXd(S.ldlt().solve(-b)) : Eigen::VectorXd();
    delta_p_.resize(static_cast<std::size_t>(num_free_points_));
    for (std::size_t m = 0; m < static_cast<std::size_t>(num_free_points_); ++m) {
      Eigen::Vector3d rhs = -g_p_[m];
      for (int a = point_obs_begin_[m]; a < point_obs_begin_[m + 1]; ++a) {
        const std::size_t n = static_cast<std::size_t>(point_obs_[static_cast<std::size_t>(a)]);
        const int c = camera_var_[problem_.observations[obs_[n]].camera];
        if (c >= 0) rhs.noalias() -= W_[n].transpose() * delta_c_.segment<6>(6 * c);
      }
      delta_p_[m] = V_inv_[m] * rhs;
    }
    // With (H + mu D) delta = -g: delta' H delta = -g' delta - delta' mu D delta.
    double g_dot = delta_c_.size() > 0 ? g_c_.dot(delta_c_) : 0.0;
    double d_dot = delta_c_.size() > 0 ? delta_c_.dot(D_c.cwiseProduct(delta_c_)) : 0.0;
    double norm_sq = delta_c_.squaredNorm();
    for (std::size_t m = 0; m < delta_p_.size(); ++m) {
      g_dot += g_p_[m].dot(delta_p_[m]);
      d_dot += delta_p_[m].dot(D_p_[m].cwiseProduct(delta_p_[m]));
      norm_sq += delta_p_[m].squaredNorm();
    }
    step_norm_ = std::sqrt(norm_sq);
    if (!std::isfinite(g_dot) || !std::isfinite(d_dot)) return std::nullopt;
    return 0.5 * (d_dot - g_dot);
  }

  State applyStep() const {
    State s = state_;
    for (std::size_t i = 0; i < camera_var_.size(); ++i) {
      const int c = camera_var_[i];
      if (c < 0) continue;
      CameraState& cam = s.cameras[i];
      cam.q_world_cam = (cam.q_world_cam * expMap(delta_c_.segment<3>(6 * c))).normalized();
      cam.p_world_cam_m += delta_c_.segment<3>(6 * c + 3);
    }
    for (std::size_t j = 0; j < point_var_.size(); ++j)
      if (point_var_[j] >= 0) s.points[j] += delta_p_[static_cast<std::size_t>(point_var_[j])];
    return s;
  }

  double parameterNorm() const {
    double sum = 0.0;
    for (std::size_t i = 0; i < camera_var_.size(); ++i)
      if (camera_var_[i] >= 0)
        sum += 1.0 + state_.cameras[i].p_world_cam_m.squaredNorm();  // a unit quaternion
    for (std::size_t j = 0; j < point_var_.size(); ++j)
      if (point_var_[j] >= 0) sum += state_.points[j].squaredNorm();
    return std::sqrt(sum);
  }

  const BaProblem& problem_;
  const BundleAdjustmentParams& params_;
  State& state_;
  std::vector<int> obs_;     // the active observations
  std::vector<int> priors_;  // the priors on a free camera
  std::vector<int> camera_var_;
  std::vector<int> point_var_;
  int num_free_cameras_ = 0;
  int num_free_points_ = 0;
  std::vector<int> point_obs_begin_;  // per free point, its entries of point_obs_
  std::vector<int> point_obs_;        // indices into obs_
  // Per active observation at state_.
  std::vector<Eigen::Vector2d> residual_;
  std::vector<double> weight_;
  std::vector<Mat26> d_camera_;
  std::vector<Mat23> d_point_;
  std::vector<Mat63> W_;
  Eigen::MatrixXd H_cc_;
  Eigen::VectorXd g_c_;
  std::vector<Eigen::Matrix3d> V_;
  std::vector<Eigen::Vector3d> g_p_;
  double max_gradient_ = 0.0;
  // The last step.
  std::vector<Eigen::Matrix3d> V_inv_;
  std::vector<Eigen::Vector3d> D_p_;
  Eigen::VectorXd delta_c_;
  std::vector<Eigen::Vector3d> delta_p_;
  double step_norm_ = 0.0;
};

// The reprojection error in px, or nothing when the point is not in front.
bool reprojectionError(const BaIntrinsics& K, const CameraState& cam,
                       const Eigen::Vector3d& p_world_m, const Eigen::Vector2d& px,
                       Eigen::Vector2d& error_px) {
  return reprojectionResidual(K, px, 1.0, cam.q_world_cam.toRotationMatrix(), cam.p_world_cam_m,
                              p_world_m, error_px, nullptr, nullptr);
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

}  // namespace

BaResult bundleAdjust(BaProblem& problem, const BundleAdjustmentParams& params) {
  validate(problem);
  const std::size_t num_obs = problem.observations.size();

  State state;
  state.cameras.resize(problem.cameras.size());
  for (std::size_t i = 0; i < problem.cameras.size(); ++i) {
    const Eigen::Isometry3d& T = problem.cameras[i].T_world_cam;
    state.cameras[i].q_world_cam = Eigen::Quaterniond(T.rotation()).normalized();
    state.cameras[i].p_world_cam_m = T.translation();
  }
  state.points.resize(problem.points.size());
  for (std::size_t j = 0; j < problem.points.size(); ++j) {
    const Eigen::Vector3d& p = problem.points[j].p_world_m;
    state.points[j] = p;
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
  PassReport pass = LmPass(problem, params, in_front, state).run(camera_moved, point_moved);
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
    pass = LmPass(problem, params, active, state).run(camera_moved, point_moved);
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
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = state.cameras[i].q_world_cam.normalized().toRotationMatrix();
    T.translation() = state.cameras[i].p_world_cam_m;
    problem.cameras[i].T_world_cam = T;
  }
  for (std::size_t j = 0; j < problem.points.size(); ++j) {
    if (point_moved[j]) {
      problem.points[j].p_world_m = state.points[j];
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
