#include "nodes/vo_direct/frame_tracker.h"

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
  v.field("convergence_step", &convergence_step,
          {.doc = "a level stops when its step is below this (rad, relative)", .min = 0, .max = 1});
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
        for (int k = 0; k < kPatternSize; ++k) {
          const int px = x + kPattern[k][0], py = y + kPattern[k][1];
          tp.rays[k] = cam.ray(static_cast<float>(px), static_cast<float>(py));
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
  if (select) active.assign(points.size(), 0);
  for (std::size_t pi = 0; pi < points.size(); ++pi) {
    const TrackingPoint& p = points[pi];
    ++sys.points_total;
    if (!select && !active[pi]) continue;
    std::array<float, kPatternSize> u, v;
    bool inside = true;
    for (int i = 0; i < kPatternSize && inside; ++i) {
      const Eigen::Vector3f q = R * p.rays[i] + p.idepth * t;
      if (q.z() <= 1e-6f) {
        inside = false;
        break;
      }
      u[i] = cam.fx * q.x() / q.z() + cam.cx;
      v[i] = cam.fy * q.y() / q.z() + cam.cy;
      inside = u[i] >= margin && v[i] >= margin && u[i] < x_max && v[i] < y_max;
    }
    if (!inside) {
      if (!select) sys.energy += oob_penalty;
      continue;
    }
    if (select) active[pi] = 1;
    ++sys.points_in;
    // z = (gx, gy, d/da, d/db); Z = sum w z z^T, zr = sum w z r.
    Eigen::Matrix4f Z = Eigen::Matrix4f::Zero();
    Eigen::Vector4f zr = Eigen::Vector4f::Zero();
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
      const float w = wg * huberWeight(r, k);
      const Eigen::Vector4f z(inv_half_gain * s.dx, inv_half_gain * s.dy, -0.5f * (seen + expected),
                              -inv_half_gain);
      Z.noalias() += w * z * z.transpose();
      zr.noalias() += w * r * z;
    }
    sys.residuals += kPatternSize;
    if (!linearize) continue;
    const Eigen::Vector3f qc = R * p.rays[4] + p.idepth * t;  // the pattern's centre
    const ProjectionJacobian J = projectionJacobian(qc, p.idepth, t, cam.fx, cam.fy);
    Eigen::Matrix<float, 4, 8> S = Eigen::Matrix<float, 4, 8>::Zero();
    S.topLeftCorner<2, 6>() = J.d_xi;
    S(2, 6) = 1.f;
    S(3, 7) = 1.f;
    sys.H.noalias() += (S.transpose() * Z * S).cast<double>();
    sys.g.noalias() += (S.transpose() * zr).cast<double>();
  }
  sys.energy += sys.data_cost;
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
      Vector6d xi = step.head<6>();
      const Eigen::Isometry3d T_new = orthonormalized(se3Exp(xi) * T);
      const AffineBrightness affine_new{affine.a + step(6), affine.b + step(7)};
      LevelSystem trial = evaluate(points, active, false, samples, reference.cameras[l], T_new,
                                   affine_new, reference.affine, params, true);
      if (trial.energy < sys.energy) {
        T = T_new;
        affine = affine_new;
        sys = trial;
        lambda = std::max(lambda * 0.25, 1e-6);
      } else {
        lambda *= 10.0;
        if (lambda > 1e6) break;
        continue;
      }
      const double rot = xi.tail<3>().norm();
      const double trans = xi.head<3>().norm() / depth_scale;
      const double gain = std::fabs(step(6)) + std::fabs(step(7)) / 255.0;
      if (rot < params.convergence_step && trans < params.convergence_step &&
          gain < params.convergence_step)
        break;
    }
    const double rms = sys.residuals > 0 ? std::sqrt(sys.match_cost / sys.residuals) : 1e9;
    if (l == coarsest) result.coarse_rms = rms;
    result.rms = rms;
    result.in_image_share =
        sys.points_total > 0 ? static_cast<double>(sys.points_in) / sys.points_total : 0.0;
    result.points = sys.points_in;
  }
  result.T_frame_ref = T;
  result.affine = affine;
  return result;
}

}  // namespace nadir::vo
