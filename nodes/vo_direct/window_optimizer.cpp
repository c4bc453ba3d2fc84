#include "nodes/vo_direct/window_optimizer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "nodes/vo_direct/lie.h"

namespace nadir::vo {

void WindowOptimizerParams::visit(core::ParamVisitor& v) {
  v.field("iterations", &iterations,
          {.doc = "Levenberg-Marquardt iterations per key-frame", .min = 0, .max = 100});
  v.field("huber_threshold", &huber_threshold,
          {.doc = "Huber threshold on a photometric residual, intensity", .min = 0.1, .max = 255});
  v.field("gradient_weight_c", &gradient_weight_c,
          {.doc = "weight c^2/(c^2+|grad|^2) of a pixel on an edge", .min = 1, .max = 1e6});
  v.field("photometric_sigma", &photometric_sigma,
          {.doc = "photometric noise the priors are weighed against, intensity",
           .min = 0.01,
           .max = 255});
  v.field("outlier_rms", &outlier_rms,
          {.doc = "a point's block in a key-frame with a larger RMS residual is an outlier",
           .min = 0.1,
           .max = 255});
  v.field("affine_prior_sigma_a", &affine_prior_sigma_a,
          {.doc = "prior on a key-frame's log gain around its tracking estimate",
           .min = 1e-6,
           .max = 100});
  v.field("affine_prior_sigma_b", &affine_prior_sigma_b,
          {.doc = "prior on a key-frame's offset around its tracking estimate",
           .min = 1e-6,
           .max = 1e4});
  v.field("idepth_prior_sigma", &idepth_prior_sigma,
          {.doc = "weak prior on a point's inverse depth, relative", .min = 1e-3, .max = 1e6});
  v.field("range_prior_sigma", &range_prior_sigma,
          {.doc = "the rangefinder's prior on the log depth of points near its ray",
           .min = 1e-4,
           .max = 100});
}

void preparePoint(WindowPoint& point, const ImagePyramid& host, const cv::Matx33d& K,
                  const WindowOptimizerParams& params) {
  if (!host.hasGradients(0))
    throw std::invalid_argument("preparePoint: the host has no level-0 gradients");
  const float c2 = static_cast<float>(params.gradient_weight_c * params.gradient_weight_c);
  point.ray = PinholeLevel::at(K, 0).ray(point.x, point.y);
  for (int k = 0; k < kPatternSize; ++k) {
    const float x = point.x + static_cast<float>(kPattern[k][0]);
    const float y = point.y + static_cast<float>(kPattern[k][1]);
    const IntensitySample s = ImagePyramid::sample(host.samples(0), x, y);
    point.intensities[k] = s.intensity;
    point.weights[k] = gradientWeight(s.dx, s.dy, c2);
  }
}

namespace {

constexpr int kMaxFrames = 32;
constexpr int kJoinMarginPx = 8;
using Vector8d = Eigen::Matrix<double, 8, 1>;
using Matrix6f = Eigen::Matrix<float, 6, 6>;
using Vector6f = Eigen::Matrix<float, 6, 1>;

using Matrix10d = Eigen::Matrix<double, 10, 10>;
using Vector10d = Eigen::Matrix<double, 10, 1>;

struct PointSystem {
  double Hpp = 0.0;
  double bp = 0.0;
  std::uint32_t frames = 0;  // bit f: the point's block with frame f holds something
};

// The blocks of one (host, target) pair, in the pair's relative coordinates:
// the relative pose (6), the target's (a, b), the host's (a, b). Summed over
// the pair's points, then mapped to the two key-frames' own coordinates once.
struct PairSystem {
  Matrix10d H = Matrix10d::Zero();
  Vector10d g = Vector10d::Zero();
  bool used = false;
};

struct System {
  double energy = 0.0;
  double photometric_cost = 0.0;
  int residuals = 0;
  int blocks = 0;
  Eigen::MatrixXd H;  // frames x frames, before eliminating the points
  Eigen::VectorXd g;
  std::vector<PointSystem> points;
  // Point p's coupling with frame f: hfp[(p * frames + f) * 8 ...], 8 values.
  std::vector<double> hfp;
  int frames = 0;

  Eigen::Map<Vector8d> Hfp(std::size_t p, int f) {
    return Eigen::Map<Vector8d>(hfp.data() + (p * frames + f) * 8);
  }
  Eigen::Map<const Vector8d> Hfp(std::size_t p, int f) const {
    return Eigen::Map<const Vector8d>(hfp.data() + (p * frames + f) * 8);
  }
};

struct State {
  std::vector<Eigen::Isometry3d> T_cam_world;
  std::vector<AffineBrightness> affine;
  std::vector<float> idepth;
};

class Optimizer {
 public:
  Optimizer(std::vector<WindowFrame>& frames, std::vector<WindowPoint>& points,
            const cv::Matx33d& K, const WindowOptimizerParams& params)
      : frames_(frames), points_(points), camera_(PinholeLevel::at(K, 0)), params_(params) {
    const int n = static_cast<int>(frames.size());
    if (n > kMaxFrames)
      throw std::invalid_argument("optimizeWindow: at most " + std::to_string(kMaxFrames) +
                                  " key-frames");
    for (const WindowFrame& f : frames) {
      if (f.pyramid == nullptr || !f.pyramid->hasGradients(0))
        throw std::invalid_argument("optimizeWindow: a key-frame without level-0 gradients");
    }
    block_of_.assign(n, -1);
    for (int f = 0; f < n; ++f)
      if (!frames[f].fixed) block_of_[f] = 8 * free_frames_++;
    active_.assign(points.size(), 0u);
    outlier_.assign(points.size(), 0u);
    sigma2_ = params.photometric_sigma * params.photometric_sigma;
  }

  WindowStats run() {
    WindowStats stats;
    State state = current();
    System sys = linearize(state, true);
    stats.rms_start = rms(sys);
    stats.blocks = sys.blocks;
    for (std::size_t p = 0; p < points_.size(); ++p)
      stats.outlier_blocks += __builtin_popcount(outlier_[p]);
    double lambda = 1e-4;
    if (free_frames_ > 0 || !points_.empty()) {
      for (int it = 0; it < params_.iterations; ++it) {
        const State trial_state = step(state, sys, lambda);
        System trial = linearize(trial_state, false);
        if (trial.energy < sys.energy) {
          const double decrease = (sys.energy - trial.energy) / std::max(sys.energy, 1e-12);
          state = trial_state;
          sys = std::move(trial);
          ++stats.iterations;
          lambda = std::max(lambda * 0.5, 1e-7);
          if (decrease < 1e-9) break;
        } else {
          lambda *= 10.0;
          if (lambda > 1e4) break;
        }
      }
    }
    stats.rms_end = rms(sys);
    store(state);
    for (std::size_t p = 0; p < points_.size(); ++p) {
      const int outliers = __builtin_popcount(outlier_[p]);
      const int inliers = __builtin_popcount(active_[p]);
      if ((outliers >= 2 && outliers > inliers) || !(points_[p].idepth > 0.f) ||
          !std::isfinite(points_[p].idepth)) {
        points_[p].bad = true;
        ++stats.bad_points;
      }
    }
    return stats;
  }

 private:
  static double rms(const System& sys) {
    return sys.residuals > 0 ? std::sqrt(sys.photometric_cost / sys.residuals) : 0.0;
  }

  State current() const {
    State s;
    for (const WindowFrame& f : frames_) {
      s.T_cam_world.push_back(f.T_cam_world);
      s.affine.push_back(f.affine);
    }
    for (const WindowPoint& p : points_) s.idepth.push_back(p.idepth);
    return s;
  }

  void store(const State& s) {
    for (std::size_t f = 0; f < frames_.size(); ++f) {
      frames_[f].T_cam_world = s.T_cam_world[f];
      frames_[f].affine = s.affine[f];
    }
    for (std::size_t p = 0; p < points_.size(); ++p) points_[p].idepth = s.idepth[p];
  }

  System linearize(const State& s, bool first) {
    const int n = static_cast<int>(frames_.size());
    System sys;
    sys.H = Eigen::MatrixXd::Zero(8 * free_frames_, 8 * free_frames_);
    sys.g = Eigen::VectorXd::Zero(8 * free_frames_);
    sys.points.resize(points_.size());
    sys.frames = n;
    sys.hfp.assign(points_.size() * n * 8, 0.0);
    // Relative poses, their adjoints and the turned pattern, target <- host.
    std::vector<Eigen::Matrix3f> R(n * n);
    std::vector<Eigen::Vector3f> t(n * n);
    std::vector<Matrix6d> Ad(n * n);
    std::vector<Matrix6f> minus_Ad_T(n * n);
    std::vector<PatternOffsets> offsets(n * n);
    std::vector<PairSystem> pairs(n * n);
    for (int h = 0; h < n; ++h)
      for (int g = 0; g < n; ++g) {
        if (h == g) continue;
        const Eigen::Isometry3d T = s.T_cam_world[g] * s.T_cam_world[h].inverse();
        R[h * n + g] = T.linear().cast<float>();
        t[h * n + g] = T.translation().cast<float>();
        Ad[h * n + g] = adjoint(T);
        minus_Ad_T[h * n + g] = -Ad[h * n + g].transpose().cast<float>();
        offsets[h * n + g] = rotatedPatternOffsets(camera_, R[h * n + g]);
      }
    const float k = static_cast<float>(params_.huber_threshold);
    const float outlier2 = static_cast<float>(params_.outlier_rms * params_.outlier_rms);
    const float oob_penalty = kPatternSize * k * k;
    // Target by target: the lookups stay in one image at a time.
    for (int g = 0; g < n; ++g) {
      for (std::size_t pi = 0; pi < points_.size(); ++pi) {
        const WindowPoint& p = points_[pi];
        PointSystem& ps = sys.points[pi];
        const float rho = s.idepth[pi];
        const int h = p.host;
        if (g == h) continue;
        const std::uint32_t bit = 1u << g;
        if (!first && !(active_[pi] & bit)) continue;
        const int pair = h * n + g;
        const Eigen::Matrix3f& Rth = R[pair];
        const Eigen::Vector3f& tth = t[pair];
        const cv::Mat& samples = frames_[g].pyramid->samples(0);
        const cv::Mat& bytes = frames_[g].pyramid->level0Bytes();
        // A block joins only well inside the image, so that the small moves of
        // the optimisation rarely take it out (it then costs the Huber cost
        // of a residual at the threshold per pixel).
        const float margin = first ? static_cast<float>(kJoinMarginPx) : 1.f;
        const float x_max = static_cast<float>(samples.cols - 1) - margin;
        const float y_max = static_cast<float>(samples.rows - 1) - margin;
        const Eigen::Vector3f qc = Rth * p.ray + rho * tth;
        std::array<float, kPatternSize> u, v;
        if (!(rho > 0.f) ||
            !projectPattern(qc, offsets[pair], camera_, margin, x_max, y_max, u, v)) {
          if (!first) sys.energy += oob_penalty;  // it was in the image at the start
          continue;
        }
        // Symmetric in the two frames' brightness (frame_tracker.h).
        const float half_gain = static_cast<float>(std::exp(0.5 * (s.affine[g].a - s.affine[h].a)));
        const float inv_half_gain = 1.f / half_gain;
        const float b_t = static_cast<float>(s.affine[g].b);
        const float b_h = static_cast<float>(s.affine[h].b);
        std::array<IntensitySample, kPatternSize> smp;
        std::array<float, kPatternSize> r, mean;
        float raw2 = 0.f;
        for (int i = 0; i < kPatternSize; ++i) {
          smp[i] = ImagePyramid::sampleLevel0(bytes, samples, u[i], v[i]);
          const float seen = inv_half_gain * (smp[i].intensity - b_t);
          const float expected = half_gain * (p.intensities[i] - b_h);
          r[i] = seen - expected;
          mean[i] = 0.5f * (seen + expected);
          raw2 += r[i] * r[i];
        }
        if (first) {
          if (raw2 > outlier2 * kPatternSize) {
            outlier_[pi] |= bit;
            continue;
          }
          active_[pi] |= bit;
        }
        ++sys.blocks;
        // z = (gx, gy, d/da_t, d/db_t, d/da_h, d/db_h) = (gx, gy, -m, -1/g, m, g) with
        // m the pixel's mean brightness and g the half gain: Z = sum w z z^T and
        // zr = sum w r z follow from fourteen sums.
        float sw = 0, swm = 0, swmm = 0, sgx = 0, sgy = 0, sgxm = 0, sgym = 0;
        float sgxx = 0, sgxy = 0, sgyy = 0, srgx = 0, srgy = 0, srm = 0, sr = 0;
        for (int i = 0; i < kPatternSize; ++i) {
          const float wg = p.weights[i];
          const float cost = wg * huberCost(r[i], k);
          sys.photometric_cost += cost;
          sys.energy += cost;
          const float w = wg * huberWeight(r[i], k);
          const float gx = inv_half_gain * smp[i].dx, gy = inv_half_gain * smp[i].dy;
          const float wgx = w * gx, wgy = w * gy, wm = w * mean[i], wr = w * r[i];
          sw += w;
          swm += wm;
          swmm += wm * mean[i];
          sgx += wgx;
          sgy += wgy;
          sgxm += wgx * mean[i];
          sgym += wgy * mean[i];
          sgxx += wgx * gx;
          sgxy += wgx * gy;
          sgyy += wgy * gy;
          srgx += wr * gx;
          srgy += wr * gy;
          srm += wr * mean[i];
          sr += wr;
        }
        const float ct = inv_half_gain, ch = half_gain;
        Matrix6f Z;
        Z << sgxx, sgxy, -sgxm, -ct * sgx, sgxm, ch * sgx,                           //
            sgxy, sgyy, -sgym, -ct * sgy, sgym, ch * sgy,                            //
            -sgxm, -sgym, swmm, ct * swm, -swmm, -ch * swm,                          //
            -ct * sgx, -ct * sgy, ct * swm, ct * ct * sw, -ct * swm, -ct * ch * sw,  //
            sgxm, sgym, -swmm, -ct * swm, swmm, ch * swm,                            //
            ch * sgx, ch * sgy, -ch * swm, -ct * ch * sw, ch * swm, ch * ch * sw;
        Vector6f zr;
        zr << srgx, srgy, -srm, -ct * sr, srm, ch * sr;
        sys.residuals += kPatternSize;
        // The pair's system in relative coordinates: d(residual)/d(relative
        // pose) = grad * J, brightness directly.
        const ProjectionJacobian J = projectionJacobian(qc, rho, tth, camera_.fx, camera_.fy);
        PairSystem& ph = pairs[pair];
        ph.used = true;
        const Eigen::Matrix<float, 2, 6> ZJ = Z.topLeftCorner<2, 2>() * J.d_xi;
        ph.H.topLeftCorner<6, 6>().noalias() += J.d_xi.transpose().lazyProduct(ZJ).cast<double>();
        ph.H.topRightCorner<6, 4>().noalias() +=
            J.d_xi.transpose().lazyProduct(Z.topRightCorner<2, 4>()).cast<double>();
        ph.H.bottomRightCorner<4, 4>() += Z.bottomRightCorner<4, 4>().cast<double>();
        ph.g.head<6>().noalias() += (J.d_xi.transpose() * zr.head<2>()).cast<double>();
        ph.g.tail<4>() += zr.tail<4>().cast<double>();
        // The point's coupling: Z s_rho with s_rho = (d_rho, 0, 0, 0, 0).
        const Vector6f z_rho = Z.leftCols<2>() * J.d_rho;
        ps.Hpp += J.d_rho.dot(z_rho.head<2>());
        ps.bp += J.d_rho.dot(zr.head<2>());
        const Vector6f pose_rho = J.d_xi.transpose() * z_rho.head<2>();
        if (block_of_[g] >= 0) {
          auto Hfp = sys.Hfp(pi, g);
          Hfp.head<6>() += pose_rho.cast<double>();
          Hfp(6) += z_rho(2);
          Hfp(7) += z_rho(3);
          ps.frames |= 1u << g;
        }
        if (block_of_[h] >= 0) {
          auto Hfp = sys.Hfp(pi, h);
          Hfp.head<6>() += (minus_Ad_T[pair] * pose_rho).cast<double>();
          Hfp(6) += z_rho(4);
          Hfp(7) += z_rho(5);
          ps.frames |= 1u << h;
        }
      }
    }
    for (std::size_t pi = 0; pi < points_.size(); ++pi) {
      const WindowPoint& p = points_[pi];
      PointSystem& ps = sys.points[pi];
      const float rho = s.idepth[pi];
      // Priors on the inverse depth: weak around where it was made, and the
      // rangefinder's near its ray.
      const double prior0 = std::max(static_cast<double>(p.idepth_prior), 1e-9);
      const double w0 = sigma2_ / std::pow(params_.idepth_prior_sigma * prior0, 2);
      const double d0 = rho - p.idepth_prior;
      sys.energy += w0 * d0 * d0;
      ps.Hpp += w0;
      ps.bp += w0 * d0;
      if (p.idepth_range > 0.f && rho > 0.f) {
        const double wr = sigma2_ / (params_.range_prior_sigma * params_.range_prior_sigma);
        const double dr = std::log(rho / p.idepth_range);
        sys.energy += wr * dr * dr;
        ps.Hpp += wr / (rho * rho);
        ps.bp += wr * dr / rho;
      }
    }
    // Each pair's relative system into the key-frames' coordinates:
    // relative pose = xi_target - Ad(T_target_host) xi_host.
    for (int h = 0; h < n; ++h)
      for (int g = 0; g < n; ++g) {
        const int pair = h * n + g;
        if (h == g || !pairs[pair].used) continue;
        Matrix10d H_rel = pairs[pair].H;
        H_rel.bottomLeftCorner<4, 6>() = H_rel.topRightCorner<6, 4>().transpose();
        Eigen::Matrix<double, 10, 16> S = Eigen::Matrix<double, 10, 16>::Zero();
        S.block<6, 6>(0, 0).setIdentity();
        S.block<6, 6>(0, 8) = -Ad[pair];
        S(6, 6) = 1.0;
        S(7, 7) = 1.0;
        S(8, 14) = 1.0;
        S(9, 15) = 1.0;
        const Eigen::Matrix<double, 16, 16> Hb = S.transpose() * H_rel * S;
        const Eigen::Matrix<double, 16, 1> gb = S.transpose() * pairs[pair].g;
        const int fi[2] = {g, h};
        for (int a = 0; a < 2; ++a) {
          const int ba = block_of_[fi[a]];
          if (ba < 0) continue;
          sys.g.segment<8>(ba) += gb.segment<8>(8 * a);
          for (int b = 0; b < 2; ++b) {
            const int bb = block_of_[fi[b]];
            if (bb < 0) continue;
            sys.H.block<8, 8>(ba, bb) += Hb.block<8, 8>(8 * a, 8 * b);
          }
        }
      }
    // Each key-frame's brightness near its tracking estimate.
    const double wa = sigma2_ / std::pow(params_.affine_prior_sigma_a, 2);
    const double wb = sigma2_ / std::pow(params_.affine_prior_sigma_b, 2);
    for (int f = 0; f < n; ++f) {
      const double da = s.affine[f].a - frames_[f].affine_prior.a;
      const double db = s.affine[f].b - frames_[f].affine_prior.b;
      sys.energy += wa * da * da + wb * db * db;
      const int b = block_of_[f];
      if (b < 0) continue;
      sys.H(b + 6, b + 6) += wa;
      sys.g(b + 6) += wa * da;
      sys.H(b + 7, b + 7) += wb;
      sys.g(b + 7) += wb * db;
    }
    return sys;
  }

  // One damped Gauss-Newton step: the points eliminated (Schur complement),
  // the key-frames solved, the points back-substituted.
  State step(const State& s, const System& sys, double lambda) const {
    const int n = static_cast<int>(frames_.size());
    Eigen::MatrixXd H = sys.H;
    Eigen::VectorXd g = sys.g;
    for (int i = 0; i < H.rows(); ++i) H(i, i) *= 1.0 + lambda;
    for (std::size_t pi = 0; pi < sys.points.size(); ++pi) {
      const PointSystem& ps = sys.points[pi];
      if (ps.frames == 0 || ps.Hpp <= 0.0) continue;
      const double inv = 1.0 / (ps.Hpp * (1.0 + lambda));
      for (int a = 0; a < n; ++a) {
        if (!(ps.frames & (1u << a))) continue;
        const int ba = block_of_[a];
        g.segment<8>(ba) -= sys.Hfp(pi, a) * (ps.bp * inv);
        for (int b = 0; b < n; ++b) {
          if (!(ps.frames & (1u << b))) continue;
          H.block<8, 8>(ba, block_of_[b]).noalias() -=
              sys.Hfp(pi, a) * sys.Hfp(pi, b).transpose() * inv;
        }
      }
    }
    Eigen::VectorXd dx = Eigen::VectorXd::Zero(H.rows());
    if (H.rows() > 0) dx = -H.ldlt().solve(g);
    State out = s;
    for (int f = 0; f < n; ++f) {
      const int b = block_of_[f];
      if (b < 0) continue;
      const Vector6d xi = dx.segment<6>(b);
      out.T_cam_world[f] = orthonormalized(se3Exp(xi) * s.T_cam_world[f]);
      out.affine[f].a += dx(b + 6);
      out.affine[f].b += dx(b + 7);
    }
    for (std::size_t pi = 0; pi < sys.points.size(); ++pi) {
      const PointSystem& ps = sys.points[pi];
      if (ps.Hpp <= 0.0) continue;
      double rhs = ps.bp;
      for (int f = 0; f < n; ++f)
        if (ps.frames & (1u << f)) rhs += sys.Hfp(pi, f).dot(dx.segment<8>(block_of_[f]));
      const double d = -rhs / (ps.Hpp * (1.0 + lambda));
      const float old = s.idepth[pi];
      float next = old + static_cast<float>(d);
      if (!(next > 0.f) || !std::isfinite(next)) next = 0.5f * old;
      out.idepth[pi] = next;
    }
    return out;
  }

  std::vector<WindowFrame>& frames_;
  std::vector<WindowPoint>& points_;
  PinholeLevel camera_;
  const WindowOptimizerParams& params_;
  std::vector<int> block_of_;
  int free_frames_ = 0;
  std::vector<std::uint32_t> active_;
  std::vector<std::uint32_t> outlier_;
  double sigma2_ = 1.0;
};

}  // namespace

WindowStats optimizeWindow(std::vector<WindowFrame>& frames, std::vector<WindowPoint>& points,
                           const cv::Matx33d& K, const WindowOptimizerParams& params) {
  return Optimizer(frames, points, K, params).run();
}

}  // namespace nadir::vo
