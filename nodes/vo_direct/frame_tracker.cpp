#include "nodes/vo_direct/frame_tracker.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "nodes/vo_direct/lie.h"

namespace nadir::vo {

void TrackerParams::visit(core::ParamVisitor& v) {
  v.field("finest_level", &finest_level,
          {.doc = "finest pyramid level aligned (0: full resolution)", .min = 0, .max = 4});
  v.field("max_iterations", &max_iterations,
          {.doc = "Levenberg-Marquardt iterations per level, at most", .min = 1, .max = 100});
  v.field("huber_threshold", &huber_threshold,
          {.doc = "Huber threshold on a photometric residual, intensity", .min = 0.1, .max = 255});
  v.field("gradient_weight_c", &gradient_weight_c,
          {.doc = "weight c^2/(c^2+|grad|^2) of a pixel on an edge", .min = 1, .max = 1e6});
  v.field(
      "affine_prior_sigma_a", &affine_prior_sigma_a,
      {.doc = "prior on a frame's log gain change from its key-frame", .min = 1e-6, .max = 100});
  v.field("affine_prior_sigma_b", &affine_prior_sigma_b,
          {.doc = "prior on a frame's offset change from its key-frame, intensity",
           .min = 1e-6,
           .max = 1e4});
  v.field("photometric_sigma", &photometric_sigma,
          {.doc = "photometric noise the priors are weighed against, intensity",
           .min = 0.01,
           .max = 255});
  v.field("convergence_px", &convergence_px,
          {.doc = "a level stops when a step moves the image by less than this, level px",
           .min = 0,
           .max = 10});
}

TrackingReference makeTrackingReference(const ImagePyramid& keyframe, const cv::Matx33d& K,
                                        const std::vector<DepthPixel>& points,
                                        const AffineBrightness& affine, int finest_level,
                                        int coarsest_level, double gradient_weight_c) {
  if (finest_level < 0 || coarsest_level < finest_level || coarsest_level >= keyframe.levels())
    throw std::invalid_argument("makeTrackingReference: levels " + std::to_string(finest_level) +
                                "-" + std::to_string(coarsest_level) + " outside the pyramid's " +
                                std::to_string(keyframe.levels()));
  TrackingReference ref;
  ref.affine = affine;
  ref.levels.resize(coarsest_level + 1);
  ref.cameras.resize(coarsest_level + 1);
  double idepth_sum = 0;
  for (const DepthPixel& p : points) idepth_sum += p.idepth;
  ref.mean_idepth = points.empty() ? 0.f : static_cast<float>(idepth_sum / points.size());
  for (int l = finest_level; l <= coarsest_level; ++l) {
    const PinholeLevel cam = PinholeLevel::at(K, l);
    ref.cameras[l] = cam;
    const int w = keyframe.width(l), h = keyframe.height(l);
    cv::Mat sum = cv::Mat::zeros(h, w, CV_32F);
    cv::Mat count = cv::Mat::zeros(h, w, CV_32F);
    const float s = 1.f / static_cast<float>(1 << l);
    for (const DepthPixel& p : points) {
      const int x = static_cast<int>(std::lround(p.x * s));
      const int y = static_cast<int>(std::lround(p.y * s));
      if (x < kPatternRadius || y < kPatternRadius || x >= w - kPatternRadius ||
          y >= h - kPatternRadius)
        continue;
      sum.at<float>(y, x) += p.idepth;
      count.at<float>(y, x) += 1.f;
    }
    if (!keyframe.hasGradients(l))
      throw std::invalid_argument(
          "makeTrackingReference: the key-frame has no gradients at level " + std::to_string(l));
    const cv::Mat& samples = keyframe.samples(l);
    const float c2 = static_cast<float>(gradient_weight_c * gradient_weight_c);
    std::vector<TrackingPoint>& level = ref.levels[l];
    for (int y = 0; y < h; ++y) {
      const float* c = count.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        if (c[x] == 0.f) continue;
        TrackingPoint tp;
        tp.idepth = sum.at<float>(y, x) / c[x];
        tp.x = static_cast<float>(x);
        tp.y = static_cast<float>(y);
        tp.ray = cam.ray(tp.x, tp.y);
        for (int k = 0; k < kPatternSize; ++k) {
          const int px = x + kPattern[k][0], py = y + kPattern[k][1];
          const float* sample = samples.ptr<float>(py) + 3 * px;
          tp.intensities[k] = sample[0];
          tp.weights[k] = gradientWeight(sample[1], sample[2], c2);
        }
        level.push_back(tp);
      }
    }
  }
  return ref;
}

namespace {

using Matrix8d = Eigen::Matrix<double, 8, 8>;
using Vector8d = Eigen::Matrix<double, 8, 1>;

struct LevelSystem {
  Matrix8d H = Matrix8d::Zero();
  Vector8d g = Vector8d::Zero();
  double energy = 0;      // Huber costs, out-of-image penalties, priors
  double data_cost = 0;   // the Huber costs of the points in the image
  double match_cost = 0;  // the same without the gradient weight (how well the frame matches)
  int residuals = 0;      // in the image
  int points_in = 0;
  int points_total = 0;
};

// Sums over a point's pattern of w z z^T and w r z for z = (gx, gy, d/da, d/db),
// the upper triangle of the symmetric 4x4 kept as ten scalars.
struct PatternSums {
  float gg00 = 0, gg01 = 0, gg11 = 0;            // gradient x gradient
  float ga00 = 0, ga01 = 0, ga10 = 0, ga11 = 0;  // gradient x brightness
  float aa00 = 0, aa01 = 0, aa11 = 0;            // brightness x brightness
  float rg0 = 0, rg1 = 0, ra0 = 0, ra1 = 0;

  void add(float w, float gx, float gy, float za, float zb, float r) {
    const float wgx = w * gx, wgy = w * gy, wza = w * za, wzb = w * zb;
    gg00 += wgx * gx;
    gg01 += wgx * gy;
    gg11 += wgy * gy;
    ga00 += wgx * za;
    ga01 += wgx * zb;
    ga10 += wgy * za;
    ga11 += wgy * zb;
    aa00 += wza * za;
    aa01 += wza * zb;
    aa11 += wzb * zb;
    rg0 += wgx * r;
    rg1 += wgy * r;
    ra0 += wza * r;
    ra1 += wzb * r;
  }
};

// The photometric system at one level for the frame's pose T (frame <- ref)
// and brightness; linearize = false computes the energy only.
// The points a level works with are chosen at its first evaluation (select):
// those inside the image by a margin. Only they count afterwards, so that the
// energies the steps are judged by compare the same points (a point crossing
// the border would otherwise stall the steps near it); one that leaves the
// image costs the Huber cost of a residual at the threshold per pixel.
constexpr float kSelectMarginPx = 3.f;

LevelSystem evaluate(const std::vector<TrackingPoint>& points, std::vector<char>& active,
                     bool select, const cv::Mat& samples, const PinholeLevel& cam,
                     const Eigen::Isometry3d& T, const AffineBrightness& frame,
                     const AffineBrightness& ref, const TrackerParams& params, bool linearize) {
  LevelSystem sys;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  const PatternOffsets offsets = rotatedPatternOffsets(cam, R);
  // Residuals symmetric in the two frames' brightness (see frame_tracker.h).
  const float half_gain = static_cast<float>(std::exp(0.5 * (frame.a - ref.a)));
  const float inv_half_gain = 1.f / half_gain;
  const float ref_b = static_cast<float>(ref.b);
  const float frame_b = static_cast<float>(frame.b);
  const float k = static_cast<float>(params.huber_threshold);
  const float margin = select ? kSelectMarginPx : 1.f;
  const float x_max = static_cast<float>(samples.cols - 1) - margin;
  const float y_max = static_cast<float>(samples.rows - 1) - margin;
  const float oob_penalty = kPatternSize * k * k;
  // The pose block in float, summed into double every point: J^T Zgg J,
  // J^T Zga, J^T zr; the brightness block does not depend on the point.
  Eigen::Matrix<double, 6, 6> H_pose = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 2> H_pose_affine = Eigen::Matrix<double, 6, 2>::Zero();
  Eigen::Matrix<double, 6, 1> g_pose = Eigen::Matrix<double, 6, 1>::Zero();
  double aa00 = 0, aa01 = 0, aa11 = 0, ra0 = 0, ra1 = 0;
  if (select) active.assign(points.size(), 0);
  for (std::size_t pi = 0; pi < points.size(); ++pi) {
    const TrackingPoint& p = points[pi];
    ++sys.points_total;
    if (!select && !active[pi]) continue;
    const Eigen::Vector3f qc = R * p.ray + p.idepth * t;
    std::array<float, kPatternSize> u, v;
    if (!projectPattern(qc, offsets, cam, margin, x_max, y_max, u, v)) {
      if (!select) sys.energy += oob_penalty;
      continue;
    }
    if (select) active[pi] = 1;
    ++sys.points_in;
    PatternSums z;
    for (int i = 0; i < kPatternSize; ++i) {
      const IntensitySample s = ImagePyramid::sample(samples, u[i], v[i]);
      const float seen = inv_half_gain * (s.intensity - frame_b);
      const float expected = half_gain * (p.intensities[i] - ref_b);
      const float r = seen - expected;
      const float wg = p.weights[i];
      const float cost = huberCost(r, k);
      sys.data_cost += wg * cost;
      sys.match_cost += cost;
      if (!linearize) continue;
      z.add(wg * huberWeight(r, k), inv_half_gain * s.dx, inv_half_gain * s.dy,
            -0.5f * (seen + expected), -inv_half_gain, r);
    }
    sys.residuals += kPatternSize;
    if (!linearize) continue;
    const ProjectionJacobian J = projectionJacobian(qc, p.idepth, t, cam.fx, cam.fy);
    Eigen::Matrix2f Zgg;
    Zgg << z.gg00, z.gg01, z.gg01, z.gg11;
    Eigen::Matrix2f Zga;
    Zga << z.ga00, z.ga01, z.ga10, z.ga11;
    const Eigen::Matrix<float, 2, 6> ZJ = Zgg * J.d_xi;
    H_pose.noalias() += J.d_xi.transpose().lazyProduct(ZJ).cast<double>();
    H_pose_affine.noalias() += J.d_xi.transpose().lazyProduct(Zga).cast<double>();
    g_pose.noalias() += (J.d_xi.transpose() * Eigen::Vector2f(z.rg0, z.rg1)).cast<double>();
    aa00 += z.aa00;
    aa01 += z.aa01;
    aa11 += z.aa11;
    ra0 += z.ra0;
    ra1 += z.ra1;
  }
  sys.energy += sys.data_cost;
  if (linearize) {
    sys.H.topLeftCorner<6, 6>() = H_pose;
    sys.H.topRightCorner<6, 2>() = H_pose_affine;
    sys.H.bottomLeftCorner<2, 6>() = H_pose_affine.transpose();
    sys.H(6, 6) = aa00;
    sys.H(6, 7) = sys.H(7, 6) = aa01;
    sys.H(7, 7) = aa11;
    sys.g.head<6>() = g_pose;
    sys.g(6) = ra0;
    sys.g(7) = ra1;
  }
  // Priors on the brightness change from the key-frame.
  const double sigma2 = params.photometric_sigma * params.photometric_sigma;
  const double wa = sigma2 / (params.affine_prior_sigma_a * params.affine_prior_sigma_a);
  const double wb = sigma2 / (params.affine_prior_sigma_b * params.affine_prior_sigma_b);
  const double da = frame.a - ref.a, db = frame.b - ref.b;
  sys.energy += wa * da * da + wb * db * db;
  if (linearize) {
    sys.H(6, 6) += wa;
    sys.g(6) += wa * da;
    sys.H(7, 7) += wb;
    sys.g(7) += wb * db;
  }
  return sys;
}

// See TrackResult::pose_sigma_rad. xi = (translation, rotation).
double poseSigma_rad(const Matrix8d& H, double rms, double mean_idepth) {
  const Eigen::LDLT<Matrix8d> ldlt(H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return 1e9;
  const Matrix8d covariance = ldlt.solve(Matrix8d::Identity()) * (rms * rms);
  if (!covariance.allFinite()) return 1e9;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> translation(covariance.topLeftCorner<3, 3>(),
                                                                   Eigen::EigenvaluesOnly);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rotation(covariance.block<3, 3>(3, 3),
                                                                Eigen::EigenvaluesOnly);
  const double sigma_t = std::sqrt(std::max(0.0, translation.eigenvalues().maxCoeff()));
  const double sigma_r = std::sqrt(std::max(0.0, rotation.eigenvalues().maxCoeff()));
  return sigma_r + sigma_t * mean_idepth;
}

}  // namespace

TrackResult trackFrame(const TrackingReference& reference, const ImagePyramid& frame,
                       const Eigen::Isometry3d& T_frame_ref_guess,
                       const AffineBrightness& affine_guess, const TrackerParams& params) {
  TrackResult result;
  result.T_frame_ref = T_frame_ref_guess;
  result.affine = affine_guess;
  if (reference.empty()) return result;
  const int coarsest = static_cast<int>(reference.levels.size()) - 1;
  const int finest = params.finest_level;
  if (coarsest >= frame.levels())
    throw std::invalid_argument(
        "trackFrame: the frame's pyramid has fewer levels than the reference");
  const double depth_scale = reference.mean_idepth > 0 ? 1.0 / reference.mean_idepth : 1.0;
  Eigen::Isometry3d T = T_frame_ref_guess;
  AffineBrightness affine = affine_guess;
  for (int l = coarsest; l >= finest; --l) {
    const std::vector<TrackingPoint>& points = reference.levels[l];
    if (points.empty()) continue;
    if (!frame.hasGradients(l))
      throw std::invalid_argument("trackFrame: the frame has no gradients at level " +
                                  std::to_string(l));
    const cv::Mat& samples = frame.samples(l);
    std::vector<char> active;
    LevelSystem sys = evaluate(points, active, true, samples, reference.cameras[l], T, affine,
                               reference.affine, params, true);
    double lambda = 1e-3;
    for (int it = 0; it < params.max_iterations; ++it) {
      ++result.iterations;
      Matrix8d H = sys.H;
      for (int i = 0; i < 8; ++i) H(i, i) *= 1.0 + lambda;
      const Vector8d step = -H.ldlt().solve(sys.g);
      if (!step.allFinite()) break;
      const Vector6d xi = step.head<6>();
      const double focal = reference.cameras[l].fx;
      const double moved_px = focal * (xi.tail<3>().norm() + xi.head<3>().norm() / depth_scale);
      const double gain = std::fabs(step(6)) + std::fabs(step(7)) / 255.0;
      const bool small = moved_px < params.convergence_px && gain < 0.01 * params.convergence_px;
      const Eigen::Isometry3d T_new = orthonormalized(se3Exp(xi) * T);
      const AffineBrightness affine_new{affine.a + step(6), affine.b + step(7)};
      LevelSystem trial = evaluate(points, active, false, samples, reference.cameras[l], T_new,
                                   affine_new, reference.affine, params, true);
      if (trial.energy < sys.energy) {
        T = T_new;
        affine = affine_new;
        sys = trial;
        lambda = std::max(lambda * 0.25, 1e-6);
        if (small) break;
      } else {
        // A small step that does not descend: the level is at its minimum
        // (more damping would only shrink the step further).
        if (small) break;
        lambda *= 10.0;
        if (lambda > 1e6) break;
      }
    }
    const double rms = sys.residuals > 0 ? std::sqrt(sys.match_cost / sys.residuals) : 1e9;
    if (l == coarsest) result.coarse_rms = rms;
    result.rms = rms;
    result.in_image_share =
        sys.points_total > 0 ? static_cast<double>(sys.points_in) / sys.points_total : 0.0;
    result.points = sys.points_in;
    if (l == finest) result.pose_sigma_rad = poseSigma_rad(sys.H, rms, reference.mean_idepth);
  }
  result.T_frame_ref = T;
  result.affine = affine;
  return result;
}

}  // namespace nadir::vo
