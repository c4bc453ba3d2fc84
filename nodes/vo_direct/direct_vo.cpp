#include "nodes/vo_direct/direct_vo.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>

#include "nodes/common/rolling_shutter.h"
#include "nodes/vo_direct/camera_model.h"
#include "nodes/vo_direct/lie.h"

namespace nadir::vo {

void DirectVoParams::visit(core::ParamVisitor& v) {
  v.field("pyramid_levels", &pyramid_levels,
          {.doc = "pyramid levels; the coarsest is aligned first", .min = 3, .max = 8});
  core::visitGroup(v, "selection", "which pixels a key-frame hosts", selection);
  core::visitGroup(v, "tracker", "aligning each frame to the newest key-frame", tracker);
  core::visitGroup(v, "window", "the windowed photometric bundle adjustment", window);
  core::visitGroup(v, "photometric", "the lens's vignetting and response, as calibrated",
                   photometric);
  v.field("window_keyframes", &window_keyframes,
          {.doc = "key-frames in the optimised window", .min = 2, .max = 16});
  v.field("max_points", &max_points,
          {.doc = "points the window holds at most", .min = 100, .max = 100000});
  v.field("keyframe_flow_translation", &keyframe_flow_translation,
          {.doc = "key-frame when the flow from translation reaches this share of w+h",
           .min = 1e-4,
           .max = 10});
  v.field("keyframe_flow_rotation_translation", &keyframe_flow_rotation_translation,
          {.doc = "key-frame when the flow from rotation and translation reaches this share of w+h",
           .min = 1e-4,
           .max = 10});
  v.field("keyframe_scale_change", &keyframe_scale_change,
          {.doc = "key-frame when the ground's distance changes by this share (climb, descent)",
           .min = 1e-4,
           .max = 10});
  v.field("keyframe_brightness", &keyframe_brightness,
          {.doc = "key-frame when the log gain changes by this", .min = 1e-3, .max = 100});
  v.field("keyframe_min_in_image", &keyframe_min_in_image,
          {.doc = "key-frame when fewer of its points stay in the image", .min = 0, .max = 1});
  v.field("lost_rms_ratio", &lost_rms_ratio,
          {.doc = "lost when the RMS residual exceeds this times the map's typical one",
           .min = 1,
           .max = 1000});
  v.field("lost_rms_floor", &lost_rms_floor,
          {.doc = "... and exceeds this, intensity", .min = 0, .max = 255});
  v.field("lost_log_gain", &lost_log_gain,
          {.doc = "lost when the log gain changes by more than this from the key-frame",
           .min = 0.01,
           .max = 100});
  v.field("lost_min_in_image", &lost_min_in_image,
          {.doc = "a frame keeping fewer of the points in the image is lost", .min = 0, .max = 1});
  v.field("lost_pose_sigma_mrad", &lost_pose_sigma_mrad,
          {.doc = "lost when the image fixes the pose to worse than this, 1-sigma ray angle, mrad",
           .min = 1e-3,
           .max = 1e6});
  v.field("lost_speed_mps", &lost_speed_mps,
          {.doc = "lost when the camera moved faster than this since the last good frame, m/s",
           .min = 0.1,
           .max = 1e6});
  v.field("rolling_shutter", &rolling_shutter,
          {.doc = "rectify a rolling-shutter camera's frames with the motion model's velocity"});
  v.field("lost_frames_before_reset", &lost_frames_before_reset,
          {.doc = "lost frames in a row before the map is made again", .min = 1, .max = 1000});
  v.field("range_window_px", &range_window_px,
          {.doc = "points this close to the rangefinder ray's image carry its range, px",
           .min = 1,
           .max = 10000});
  v.field("range_points", &range_points,
          {.doc = "points each key-frame hosts near the rangefinder ray's image",
           .min = 0,
           .max = 10000});
  v.field("min_start_points", &min_start_points,
          {.doc = "a map starts only on a frame with this many selected pixels",
           .min = 10,
           .max = 100000});
}

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

Eigen::Isometry3d power(const Eigen::Isometry3d& T, int n) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  for (int i = 0; i < n; ++i) out = orthonormalized(T * out);
  return out;
}

// The level ground through the point the rangefinder sees, in a camera: its
// normal (world down, in the camera) and the inverse depth along a ray with
// z = 1: rho = n.f / n.H (H: the rangefinder's ground point in the camera).
struct GroundPlane {
  Eigen::Vector3f normal_cam;
  float n_dot_h = 0;
  float idepth(const Eigen::Vector3f& ray) const { return normal_cam.dot(ray) / n_dot_h; }
};
std::optional<GroundPlane> groundPlane(const Eigen::Isometry3d& T_cam_world,
                                       const VoFrameInput& in) {
  if (!in.range_m || !(*in.range_m > 0.0)) return std::nullopt;
  GroundPlane plane;
  plane.normal_cam = (T_cam_world.linear() * Eigen::Vector3d::UnitZ()).cast<float>();
  const Eigen::Vector3f hit = (*in.range_m * in.range_ray_cam.normalized()).cast<float>();
  plane.n_dot_h = plane.normal_cam.dot(hit);
  if (plane.n_dot_h <= 1e-3f) return std::nullopt;  // the ray does not look down
  return plane;
}

// The rangefinder ray's image point, level-0 px.
std::optional<Eigen::Vector2f> rangeImagePoint(const VoFrameInput& in) {
  if (in.range_ray_cam.z() <= 1e-6) return std::nullopt;
  const Eigen::Vector3d r = in.range_ray_cam / in.range_ray_cam.z();
  return Eigen::Vector2f(static_cast<float>(in.K(0, 0) * r.x() + in.K(0, 2)),
                         static_cast<float>(in.K(1, 1) * r.y() + in.K(1, 2)));
}

}  // namespace

DirectVo::DirectVo(const DirectVoParams& params) : params_(params) {
  if (params.tracker.finest_level >= params.pyramid_levels)
    throw std::invalid_argument(
        "DirectVo: tracker.finest_level " + std::to_string(params.tracker.finest_level) +
        " is not below pyramid_levels " + std::to_string(params.pyramid_levels));
  if (params.pyramid_levels < 3)
    throw std::invalid_argument("DirectVo: pyramid_levels must be at least 3");
  if (params.window_keyframes < 2 || params.window_keyframes > 16)
    throw std::invalid_argument("DirectVo: window_keyframes must be 2-16");
}

void DirectVo::setStartPose(const Eigen::Isometry3d& T_world_body) {
  dropMap();
  pending_start_ = T_world_body;
  pending_in_place_ = false;
  pending_is_reset_ = false;
  started_ = false;
  delta_ = Eigen::Isometry3d::Identity();
}

void DirectVo::requestReset(const std::optional<Eigen::Isometry3d>& T_world_body) {
  if (!T_world_body && !started_) return;  // nothing estimated yet: the start pose stands
  pending_start_ = T_world_body;
  pending_in_place_ = !T_world_body;
  pending_is_reset_ = true;
}

void DirectVo::dropMap() {
  keyframes_.clear();
  points_.clear();
  reference_ = {};
  keyframe_points_.clear();
}

cv::Mat DirectVo::globalShutterImage(const VoFrameInput& in, const cv::Mat& gray) const {
  if (!params_.rolling_shutter || !(in.readout_s > 0.0) || keyframes_.empty() ||
      !(delta_period_s_ > 0.0) || !in.range_m || !(*in.range_m > 0.0))
    return gray;
  // delta_ maps the last frame's camera coordinates to the frame's: its
  // inverse is the frame's pose in the last frame's axes.
  return rectifyRollingShutter(gray, in.K, in.readout_s,
                               cameraTwist(delta_.inverse(), delta_period_s_), *in.range_m);
}

Eigen::Isometry3d DirectVo::predictCamWorld(int steps) const {
  return power(delta_, steps) * T_cam_world_last_;
}

DirectVoOutput DirectVo::output(VoStatus status, const Eigen::Isometry3d& T_cam_world, int points,
                                bool keyframe) const {
  DirectVoOutput out;
  out.status = status;
  out.T_world_body = T_cam_world.inverse() * T_body_cam_.inverse();
  out.points = points;
  out.new_keyframe = keyframe;
  out.resets = resets_;
  out.affine = affine_last_;
  return out;
}

void DirectVo::acceptPose(const Eigen::Isometry3d& T_cam_world, const AffineBrightness& affine) {
  delta_ = orthonormalized(T_cam_world * T_cam_world_last_.inverse());
  if (frame_time_s_ > last_good_time_s_)
    delta_period_s_ = (frame_time_s_ - last_good_time_s_) / std::max(frames_since_good_, 1);
  if (frames_since_good_ > 1) {
    // After lost frames the motion is spread over them.
    const Eigen::Isometry3d total = T_cam_world * T_cam_world_last_.inverse();
    const Eigen::AngleAxisd aa(total.linear());
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() =
        Eigen::AngleAxisd(aa.angle() / frames_since_good_, aa.axis()).toRotationMatrix();
    step.translation() = total.translation() / frames_since_good_;
    delta_ = step;
  }
  T_cam_world_last_ = T_cam_world;
  last_good_time_s_ = frame_time_s_;
  affine_last_ = affine;
  frames_since_good_ = 1;
  lost_count_ = 0;
}

DirectVoOutput DirectVo::process(const VoFrameInput& in) {
  if (in.gray.empty() || in.gray.type() != CV_8UC1)
    throw std::invalid_argument("DirectVo: a frame must be 8-bit gray");
  ++timing_.frames;
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  T_body_cam.linear() = in.R_body_cam;
  T_body_cam_ = T_body_cam;
  K_ = in.K;
  frame_time_s_ = static_cast<double>(in.utime) * 1e-6;

  auto t0 = Clock::now();
  const cv::Mat gray =
      globalShutterImage(in, vignetting_.apply(in.gray, in.K, params_.photometric));
  auto pyramid =
      std::make_unique<ImagePyramid>(gray, params_.pyramid_levels, params_.tracker.finest_level);
  timing_.pyramid_s += secondsSince(t0);

  if (pending_start_ || pending_in_place_) {
    // In place: where the motion model puts this frame, so the estimate does not jump.
    const Eigen::Isometry3d T_cam_world = pending_in_place_
                                              ? predictCamWorld(frames_since_good_)
                                              : (*pending_start_ * T_body_cam_).inverse();
    pending_in_place_ = false;
    dropMap();
    if (pending_is_reset_) ++resets_;
    pending_is_reset_ = false;
    started_ = true;
    T_cam_world_last_ = T_cam_world;
    last_good_time_s_ = frame_time_s_;
    frames_since_good_ = 1;
    lost_count_ = 0;
    unconfirmed_ = false;
    typical_rms_ = 0.0;
    pending_start_.reset();
    if (startMap(std::move(pyramid), in, T_cam_world, affine_last_))
      return output(VoStatus::kTracking, T_cam_world, static_cast<int>(points_.size()), true);
    // No range or no texture yet: the next frames try again from here.
    return output(VoStatus::kInitializing, T_cam_world, 0, false);
  }
  if (!started_) return output(VoStatus::kInitializing, Eigen::Isometry3d::Identity(), 0, false);

  if (keyframes_.empty()) {
    // Waiting to start (no range yet at the start pose) or to re-initialise
    // after a loss: from the motion model's pose, so the estimate does not jump.
    const Eigen::Isometry3d T_pred = predictCamWorld(frames_since_good_);
    if (lost_count_ == 0) {
      if (startMap(std::move(pyramid), in, T_pred, affine_last_)) {
        acceptPose(T_pred, affine_last_);
        return output(VoStatus::kTracking, T_pred, static_cast<int>(points_.size()), true);
      }
      ++frames_since_good_;
      return output(VoStatus::kInitializing, T_pred, 0, false);
    }
    return lostFrame(std::move(pyramid), in, 0);
  }

  t0 = Clock::now();
  const TrackResult result = track(*pyramid);
  timing_.track_s += secondsSince(t0);
  const Keyframe& kf = keyframes_.back();
  if (isLost(result)) return lostFrame(std::move(pyramid), in, result.points);
  unconfirmed_ = false;
  typical_rms_ = typical_rms_ > 0.0 ? 0.9 * typical_rms_ + 0.1 * result.rms : result.rms;
  const Eigen::Isometry3d T_cam_world = orthonormalized(result.T_frame_ref * kf.T_cam_world);
  // A frame the image fixes too loosely is reported lost but kept: making
  // the map again over the same faint ground would not fix the pose better.
  const VoStatus status = result.pose_sigma_rad * 1e3 > params_.lost_pose_sigma_mrad
                              ? VoStatus::kLost
                              : VoStatus::kTracking;
  if (needKeyframe(result)) {
    addKeyframe(std::move(pyramid), in, T_cam_world, result.affine);
    const Eigen::Isometry3d refined = keyframes_.back().T_cam_world;
    acceptPose(refined, keyframes_.back().affine);
    DirectVoOutput out = output(status, refined, result.points, true);
    out.rms = result.rms;
    out.pose_sigma_rad = result.pose_sigma_rad;
    return out;
  }
  acceptPose(T_cam_world, result.affine);
  DirectVoOutput out = output(status, T_cam_world, result.points, false);
  out.rms = result.rms;
  out.pose_sigma_rad = result.pose_sigma_rad;
  return out;
}

DirectVoOutput DirectVo::lostFrame(std::unique_ptr<ImagePyramid> pyramid, const VoFrameInput& in,
                                   int points) {
  ++lost_count_;
  const Eigen::Isometry3d T_pred = predictCamWorld(frames_since_good_);
  ++frames_since_good_;
  const bool remake = unconfirmed_ || keyframes_.empty();
  if (!remake && lost_count_ < params_.lost_frames_before_reset)
    return output(VoStatus::kLost, T_pred, points, false);
  // Make a new map here, at the motion model's pose: a new loss counts as a
  // reset; a map made after the loss that the next frame could not track is
  // the same loss.
  if (!remake) ++resets_;
  dropMap();
  typical_rms_ = 0.0;
  if (startMap(std::move(pyramid), in, T_pred, affine_last_)) {
    unconfirmed_ = true;
    // The motion model flies on from here.
    const Eigen::Isometry3d delta = delta_;
    T_cam_world_last_ = T_pred;
    last_good_time_s_ = frame_time_s_;
    frames_since_good_ = 1;
    delta_ = delta;
  }
  return output(VoStatus::kLost, T_pred, points, false);
}

TrackResult DirectVo::track(const ImagePyramid& pyramid) {
  const Keyframe& kf = keyframes_.back();
  const Eigen::Isometry3d T_kf_inv = kf.T_cam_world.inverse();
  // The constant-velocity guess first; if it fails, no motion and twice the motion.
  const int steps = frames_since_good_;
  const Eigen::Isometry3d guesses[] = {predictCamWorld(steps), T_cam_world_last_,
                                       predictCamWorld(2 * steps)};
  TrackResult best;
  bool have = false;
  for (const Eigen::Isometry3d& guess : guesses) {
    TrackResult r =
        trackFrame(reference_, pyramid, guess * T_kf_inv, affine_last_, params_.tracker);
    timing_.track_iterations += r.iterations;
    if (!isLost(r)) return r;
    if (!have || r.rms < best.rms) {
      best = r;
      have = true;
    }
  }
  return best;
}

bool DirectVo::isLost(const TrackResult& r) const {
  const double rms_limit = std::max(params_.lost_rms_floor, params_.lost_rms_ratio * typical_rms_);
  const Eigen::Isometry3d T_cam_world = r.T_frame_ref * keyframes_.back().T_cam_world;
  const double moved_m =
      (T_cam_world.inverse().translation() - T_cam_world_last_.inverse().translation()).norm();
  // At least 1 ms: frames with the same stamp still compare.
  const double elapsed_s = std::max(frame_time_s_ - last_good_time_s_, 1e-3);
  return r.points < 20 || r.rms > rms_limit || r.in_image_share < params_.lost_min_in_image ||
         moved_m > params_.lost_speed_mps * elapsed_s ||
         std::fabs(r.affine.a - keyframes_.back().affine.a) > params_.lost_log_gain ||
         !r.T_frame_ref.matrix().allFinite();
}

bool DirectVo::needKeyframe(const TrackResult& r) const {
  if (r.in_image_share < params_.keyframe_min_in_image) return true;
  const int level = params_.tracker.finest_level;
  const std::vector<TrackingPoint>& points = reference_.levels[level];
  const PinholeLevel& cam = reference_.cameras[level];
  const Eigen::Matrix3f R = r.T_frame_ref.linear().cast<float>();
  const Eigen::Vector3f t = r.T_frame_ref.translation().cast<float>();
  double sum_t = 0, sum_rt = 0, sum_scale = 0;
  int n = 0;
  const std::size_t stride = std::max<std::size_t>(1, points.size() / 500);
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const TrackingPoint& p = points[i];
    const Eigen::Vector3f& ray = p.ray;
    const Eigen::Vector3f q_t = ray + p.idepth * t;
    const Eigen::Vector3f q_rt = R * ray + p.idepth * t;
    if (q_t.z() <= 1e-6f || q_rt.z() <= 1e-6f) continue;
    const float ut = cam.fx * q_t.x() / q_t.z() + cam.cx - p.x;
    const float vt = cam.fy * q_t.y() / q_t.z() + cam.cy - p.y;
    const float urt = cam.fx * q_rt.x() / q_rt.z() + cam.cx - p.x;
    const float vrt = cam.fy * q_rt.y() / q_rt.z() + cam.cy - p.y;
    sum_t += ut * ut + vt * vt;
    sum_rt += urt * urt + vrt * vrt;
    sum_scale += q_rt.z();  // the point's depth in the frame over its depth in the key-frame
    ++n;
  }
  if (n == 0) return true;
  const double scale = static_cast<double>(1 << level);  // to level-0 pixels
  const double flow_t = scale * std::sqrt(sum_t / n);
  const double flow_rt = scale * std::sqrt(sum_rt / n);
  const Keyframe& kf = keyframes_.back();
  const double wh = keyframes_.back().pyramid->width(0) + kf.pyramid->height(0);
  const double scale_change = std::fabs(sum_scale / n - 1.0);
  const double score = flow_t / (params_.keyframe_flow_translation * wh) +
                       flow_rt / (params_.keyframe_flow_rotation_translation * wh) +
                       scale_change / params_.keyframe_scale_change +
                       std::fabs(r.affine.a - kf.affine.a) / params_.keyframe_brightness;
  return score > 1.0;
}

bool DirectVo::startMap(std::unique_ptr<ImagePyramid> pyramid, const VoFrameInput& in,
                        const Eigen::Isometry3d& T_cam_world, const AffineBrightness& affine) {
  const std::optional<GroundPlane> plane = groundPlane(T_cam_world, in);
  if (!plane) return false;
  const auto t0 = Clock::now();
  for (int l = 0; l < 3; ++l) pyramid->computeGradients(l);
  const std::vector<SelectedPixel> candidates =
      selectPixels(*pyramid, params_.selection, &selection_cell_px_);
  timing_.keyframe_s += secondsSince(t0);
  if (static_cast<int>(candidates.size()) < params_.min_start_points) return false;
  dropMap();
  pushKeyframe(std::move(pyramid), T_cam_world, affine);
  addPoints(0, candidates, {}, in);
  makeTrackingReference();
  return !points_.empty();
}

void DirectVo::pushKeyframe(std::unique_ptr<ImagePyramid> pyramid,
                            const Eigen::Isometry3d& T_cam_world, const AffineBrightness& affine) {
  Keyframe kf;
  kf.pyramid = std::move(pyramid);
  kf.T_cam_world = T_cam_world;
  kf.affine = affine;
  kf.affine_prior = affine;
  keyframes_.push_back(std::move(kf));
  ++timing_.keyframes;
}

void DirectVo::addKeyframe(std::unique_ptr<ImagePyramid> pyramid, const VoFrameInput& in,
                           const Eigen::Isometry3d& T_cam_world, const AffineBrightness& affine) {
  auto t0 = Clock::now();
  for (int l = 0; l < 3; ++l) pyramid->computeGradients(l);
  pushKeyframe(std::move(pyramid), T_cam_world, affine);
  // The oldest key-frame and the points it hosts leave the window.
  while (static_cast<int>(keyframes_.size()) > params_.window_keyframes) {
    keyframes_.pop_front();
    std::erase_if(points_, [](const WindowPoint& p) { return p.host == 0; });
    for (WindowPoint& p : points_) --p.host;
  }
  const int host = static_cast<int>(keyframes_.size()) - 1;
  // The window's points seen from the new key-frame: they say where the new
  // points lie and which parts of the view already have points. Points it
  // does not see are dropped: behind the camera they no longer help tracking,
  // and their share of max_points goes to the ground ahead.
  std::vector<DepthPixel> projected;
  const PinholeLevel cam = PinholeLevel::at(K_, 0);
  const float w = static_cast<float>(keyframes_.back().pyramid->width(0));
  const float h = static_cast<float>(keyframes_.back().pyramid->height(0));
  std::erase_if(points_, [&](const WindowPoint& p) {
    const Eigen::Isometry3d T =
        keyframes_[host].T_cam_world * keyframes_[p.host].T_cam_world.inverse();
    const Eigen::Vector3f q =
        T.linear().cast<float>() * p.ray + p.idepth * T.translation().cast<float>();
    if (q.z() <= 1e-6f) return true;
    const float x = cam.fx * q.x() / q.z() + cam.cx;
    const float y = cam.fy * q.y() / q.z() + cam.cy;
    if (x < 0 || y < 0 || x > w - 1 || y > h - 1) return true;
    projected.push_back({x, y, p.idepth / q.z()});
    return false;
  });
  const std::vector<SelectedPixel> candidates =
      selectPixels(*keyframes_.back().pyramid, params_.selection, &selection_cell_px_);
  addPoints(host, candidates, projected, in);
  timing_.keyframe_s += secondsSince(t0);

  t0 = Clock::now();
  optimiseWindow();
  timing_.window_s += secondsSince(t0);
  t0 = Clock::now();
  makeTrackingReference();
  timing_.keyframe_s += secondsSince(t0);
}

void DirectVo::addPoints(int host, const std::vector<SelectedPixel>& candidates,
                         const std::vector<DepthPixel>& projected, const VoFrameInput& in) {
  const Keyframe& kf = keyframes_[host];
  const int w = kf.pyramid->width(0), h = kf.pyramid->height(0);
  const PinholeLevel cam = PinholeLevel::at(K_, 0);
  // Occupancy: one point per cell of a grid that holds max_points cells.
  const double cell = std::sqrt(static_cast<double>(w) * h / params_.max_points);
  const int gw = static_cast<int>(std::ceil(w / cell)), gh = static_cast<int>(std::ceil(h / cell));
  std::vector<char> occupied(static_cast<std::size_t>(gw) * gh, 0);
  auto cellOf = [&](float x, float y) {
    const int cx = std::clamp(static_cast<int>(x / cell), 0, gw - 1);
    const int cy = std::clamp(static_cast<int>(y / cell), 0, gh - 1);
    return static_cast<std::size_t>(cy) * gw + cx;
  };
  // The depth prior for new points: the mean inverse depth of the projected
  // points in a coarse grid, else a plane fitted to them (inverse depth is
  // linear in the ray over a plane), else the rangefinder's ground.
  constexpr int kDepthCell = 64;
  const int dw = (w + kDepthCell - 1) / kDepthCell, dh = (h + kDepthCell - 1) / kDepthCell;
  std::vector<double> depth_sum(static_cast<std::size_t>(dw) * dh, 0.0);
  std::vector<int> depth_count(depth_sum.size(), 0);
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const DepthPixel& p : projected) {
    occupied[cellOf(p.x, p.y)] = 1;
    const std::size_t c =
        static_cast<std::size_t>(std::min(static_cast<int>(p.y) / kDepthCell, dh - 1)) * dw +
        std::min(static_cast<int>(p.x) / kDepthCell, dw - 1);
    depth_sum[c] += p.idepth;
    ++depth_count[c];
    const Eigen::Vector3d ray = cam.ray(p.x, p.y).cast<double>();
    A += ray * ray.transpose();
    b += ray * p.idepth;
  }
  std::optional<Eigen::Vector3d> plane_fit;
  if (projected.size() >= 30) {
    const Eigen::Vector3d coef = A.ldlt().solve(b);
    if (coef.allFinite()) plane_fit = coef;
  }
  const std::optional<GroundPlane> ground = groundPlane(kf.T_cam_world, in);
  const std::optional<Eigen::Vector2f> range_pixel = rangeImagePoint(in);

  // Candidates in a fixed pseudo-random order, so that the budget spreads over
  // the image rather than filling it from the top.
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 rng(12345u);
  std::shuffle(order.begin(), order.end(), rng);
  auto makePoint = [&](const SelectedPixel& s) -> std::optional<WindowPoint> {
    const Eigen::Vector3f ray = cam.ray(s.x, s.y);
    float idepth = 0.f;
    const std::size_t dc =
        static_cast<std::size_t>(std::min(static_cast<int>(s.y) / kDepthCell, dh - 1)) * dw +
        std::min(static_cast<int>(s.x) / kDepthCell, dw - 1);
    if (depth_count[dc] > 0) {
      idepth = static_cast<float>(depth_sum[dc] / depth_count[dc]);
    } else if (plane_fit) {
      idepth = static_cast<float>(plane_fit->dot(ray.cast<double>()));
    } else if (ground) {
      idepth = ground->idepth(ray);
    }
    if (!(idepth > 0.f) || !std::isfinite(idepth)) return std::nullopt;
    WindowPoint p;
    p.host = host;
    p.x = s.x;
    p.y = s.y;
    p.idepth = idepth;
    p.idepth_prior = idepth;
    if (ground && range_pixel &&
        (Eigen::Vector2f(s.x, s.y) - *range_pixel).norm() <= params_.range_window_px) {
      const float ground_idepth = ground->idepth(ray);
      if (ground_idepth > 0.f) p.idepth_range = ground_idepth;
    }
    preparePoint(p, *kf.pyramid, K_, params_.window);
    return p;
  };
  // Every key-frame with a range hosts points around the rangefinder ray's
  // image, whatever the map already has there: they carry its range into the
  // window's optimisation, which has the scale from them alone.
  std::vector<char> taken(candidates.size(), 0);
  if (ground && range_pixel) {
    int anchors = 0;
    for (std::size_t i : order) {
      if (anchors >= params_.range_points) break;
      const SelectedPixel& s = candidates[i];
      if ((Eigen::Vector2f(s.x, s.y) - *range_pixel).norm() > params_.range_window_px) continue;
      const std::optional<WindowPoint> p = makePoint(s);
      if (!p || p->idepth_range <= 0.f) continue;
      points_.push_back(*p);
      occupied[cellOf(s.x, s.y)] = 1;
      taken[i] = 1;
      ++anchors;
    }
  }
  int budget = params_.max_points - static_cast<int>(points_.size());
  for (std::size_t i : order) {
    if (budget <= 0) break;
    const SelectedPixel& s = candidates[i];
    const std::size_t c = cellOf(s.x, s.y);
    if (taken[i] || occupied[c]) continue;
    const std::optional<WindowPoint> p = makePoint(s);
    if (!p) continue;
    points_.push_back(*p);
    occupied[c] = 1;
    --budget;
  }
}

void DirectVo::optimiseWindow() {
  if (keyframes_.size() < 2) return;
  std::vector<WindowFrame> frames;
  for (std::size_t i = 0; i < keyframes_.size(); ++i) {
    WindowFrame f;
    f.T_cam_world = keyframes_[i].T_cam_world;
    f.affine = keyframes_[i].affine;
    f.affine_prior = keyframes_[i].affine_prior;
    f.pyramid = keyframes_[i].pyramid.get();
    f.fixed = i == 0;
    frames.push_back(f);
  }
  last_window_ = optimizeWindow(frames, points_, K_, params_.window);
  for (std::size_t i = 0; i < keyframes_.size(); ++i) {
    keyframes_[i].T_cam_world = frames[i].T_cam_world;
    keyframes_[i].affine = frames[i].affine;
  }
  std::erase_if(points_, [](const WindowPoint& p) { return p.bad; });
}

void DirectVo::makeTrackingReference() {
  const int newest = static_cast<int>(keyframes_.size()) - 1;
  const Keyframe& kf = keyframes_[newest];
  const PinholeLevel cam = PinholeLevel::at(K_, 0);
  const float w = static_cast<float>(kf.pyramid->width(0));
  const float h = static_cast<float>(kf.pyramid->height(0));
  keyframe_points_.clear();
  for (const WindowPoint& p : points_) {
    if (p.host == newest) {
      keyframe_points_.push_back({p.x, p.y, p.idepth});
      continue;
    }
    const Eigen::Isometry3d T = kf.T_cam_world * keyframes_[p.host].T_cam_world.inverse();
    const Eigen::Vector3f q =
        T.linear().cast<float>() * p.ray + p.idepth * T.translation().cast<float>();
    if (q.z() <= 1e-6f) continue;
    const float x = cam.fx * q.x() / q.z() + cam.cx;
    const float y = cam.fy * q.y() / q.z() + cam.cy;
    if (x < 0 || y < 0 || x > w - 1 || y > h - 1) continue;
    keyframe_points_.push_back({x, y, p.idepth / q.z()});
  }
  reference_ = vo::makeTrackingReference(*kf.pyramid, K_, keyframe_points_, kf.affine,
                                         params_.tracker.finest_level, params_.pyramid_levels - 1,
                                         params_.tracker.gradient_weight_c);
  cv::Mat gray;
  kf.pyramid->intensity(0).convertTo(gray, CV_8U);
  keyframe_image_ = gray;
}

}  // namespace nadir::vo
