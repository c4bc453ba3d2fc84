#include "nodes/vo_feature/feature_vo.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <set>
#include <unordered_map>

#include "nodes/common/rolling_shutter.h"
#include "nodes/vo_feature/map_range.h"

namespace nadir::vo {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<long>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

Eigen::Vector2d project(const cv::Matx33d& K, const Eigen::Vector3d& p_cam) {
  return {K(0, 0) * p_cam.x() / p_cam.z() + K(0, 2), K(1, 1) * p_cam.y() / p_cam.z() + K(1, 2)};
}

BaIntrinsics baIntrinsics(const cv::Matx33d& K) { return {K(0, 0), K(1, 1), K(0, 2), K(1, 2)}; }

double rotationAngleDeg(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  return Eigen::AngleAxisd(R_a.transpose() * R_b).angle() / kRadPerDeg;
}

// The per-frame share of a motion spread over n frames (rotation angle and
// translation divided by n; exact for a constant twist up to the coupling).
Eigen::Isometry3d perFrame(const Eigen::Isometry3d& T, int n) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  const Eigen::AngleAxisd aa(T.linear());
  out.linear() = Eigen::AngleAxisd(aa.angle() / n, aa.axis()).matrix();
  out.translation() = T.translation() / n;
  return out;
}

}  // namespace

void FeatureVoParams::visit(core::ParamVisitor& v) {
  core::visitGroup(v, "features", "ORB extraction", features);
  core::visitGroup(v, "two_view", "two-view initialisation", two_view);
  core::visitGroup(v, "ba", "local bundle adjustment", ba);
  core::visitGroup(v, "photometric", "the lens's vignetting and response, as calibrated",
                   photometric);
  v.field("min_init_matches", &min_init_matches,
          {.doc = "initialise only from at least this many matches", .min = 8, .max = 100000});
  v.field("min_tracked_points", &min_tracked_points,
          {.doc = "fewer PnP inliers than this: the frame is lost", .min = 6, .max = 100000});
  v.field("keyframe_min_shared_ratio", &keyframe_min_shared_ratio,
          {.doc = "new key-frame when the tracked share of the last key-frame's points is below",
           .min = 0.0,
           .max = 1.0});
  v.field("keyframe_max_rotation_deg", &keyframe_max_rotation_deg,
          {.doc = "new key-frame when the rotation since the last one exceeds this, deg",
           .min = 0.1,
           .max = 180.0});
  v.field("local_window", &local_window,
          {.doc = "key-frames the local BA optimises: the new one and its most co-visible",
           .min = 2,
           .max = 100});
  v.field("map_keyframes", &map_keyframes,
          {.doc = "key-frames the map keeps (the oldest dropped beyond)", .min = 2, .max = 1000});
  v.field("min_covisible_points", &min_covisible_points,
          {.doc = "two key-frames are co-visible when they share at least this many points",
           .min = 1,
           .max = 100000});
  v.field("fuse_radius_px", &fuse_radius_px,
          {.doc = "fusion: a point takes a co-visible key-frame's feature within this of its "
                  "projection, px (0: no fusion)",
           .min = 0.0,
           .max = 100.0});
  v.field("point_min_found_ratio", &point_min_found_ratio,
          {.doc = "a new point is dropped when found in fewer than this share of the frames "
                  "it was in view of",
           .min = 0.0,
           .max = 1.0});
  v.field("point_min_keyframes", &point_min_keyframes,
          {.doc = "a new point is dropped when fewer key-frames see it two key-frames on",
           .min = 0,
           .max = 100});
  v.field("ba_every_keyframes", &ba_every_keyframes,
          {.doc = "local bundle adjustment every this many key-frames", .min = 1, .max = 1000});
  v.field("triangulation_keyframes", &triangulation_keyframes,
          {.doc = "co-visible key-frames (widest baseline first) a new key-frame triangulates "
                  "with",
           .min = 1,
           .max = 100});
  v.field("background_ba", &background_ba,
          {.doc = "local BA in a background thread (live); off: at its key-frame, byte-identical"});
  v.field("max_hamming", &max_hamming,
          {.doc = "largest Hamming distance of a match", .min = 1, .max = 256});
  v.field("match_ratio", &match_ratio,
          {.doc = "ratio test of the matching (>= 1 disables)", .min = 0.1, .max = 1.0});
  v.field("track_radius_px", &track_radius_px,
          {.doc = "tracking window around the predicted position, px", .min = 1.0, .max = 1e4});
  v.field("track_wide_radius_px", &track_wide_radius_px,
          {.doc = "the wider window of the retry, px", .min = 1.0, .max = 1e4});
  v.field("pnp_reprojection_px", &pnp_reprojection_px,
          {.doc = "PnP RANSAC inlier threshold, px", .min = 0.1, .max = 100.0});
  v.field("lost_frames_before_reset", &lost_frames_before_reset,
          {.doc = "consecutive lost frames before re-initialising", .min = 1, .max = 100000});
  v.field("attitude_prior_sigma_deg", &attitude_prior_sigma_deg,
          {.doc = "standard deviation of the attitude prior's tilt in tracking and local BA, deg",
           .min = 1e-3,
           .max = 180.0});
  v.field("attitude_prior_heading_sigma_deg", &attitude_prior_heading_sigma_deg,
          {.doc = "standard deviation of the attitude prior's heading, deg",
           .min = 1e-3,
           .max = 180.0});
  v.field("rolling_shutter", &rolling_shutter,
          {.doc = "rectify a rolling-shutter camera's frames with the motion model's velocity"});
  v.field("reinit_from_range", &reinit_from_range,
          {.doc = "after a loss, start the new map from the rangefinder's ground plane at once"});
  v.field("scale_tolerance", &scale_tolerance,
          {.doc = "correct the scale when |map range / measured - 1| exceeds this",
           .min = 0.0,
           .max = 1.0});
  v.field("scale_gain", &scale_gain,
          {.doc = "share of the scale error corrected per key-frame", .min = 0.0, .max = 1.0});
  v.field("scale_max_step", &scale_max_step,
          {.doc = "largest change of the map's scale at one key-frame (a wild map range moves it "
                  "no more)",
           .min = 0.0,
           .max = 1.0});
  v.field("range_window_px", &range_window_px,
          {.doc = "the map's range is taken from points within this of the rangefinder ray's "
                  "image, px",
           .min = 1.0,
           .max = 1e4});
}

FeatureVo::FeatureVo(const FeatureVoParams& params) : params_(params) {
  FeatureVoParams copy = params;
  core::validateParams([&copy](core::ParamVisitor& v) { copy.visit(v); }, "vo_feature feature_vo");
  setStartPose(Eigen::Isometry3d::Identity());
}

void FeatureVo::setStartPose(const Eigen::Isometry3d& T_world_body) {
  T_world_body_start_ = T_world_body;
  T_world_body_last_ = T_world_body;
  start_pending_ = true;
  seeded_unconfirmed_ = false;
  resetMap();
  status_ = VoStatus::kInitializing;
}

void FeatureVo::restart(const std::optional<Eigen::Isometry3d>& T_world_body) {
  setStartPose(T_world_body.value_or(T_world_body_last_));
  ++resets_;
}

FeatureVo::~FeatureVo() { collectBackgroundBa(true); }

void FeatureVo::resetMap() {
  ++map_generation_;
  reference_.reset();
  reference_range_m_.reset();
  points_.clear();
  keyframes_.clear();
  local_keyframe_ids_.clear();
  keyframes_since_ba_ = 0;
  keyframe_peak_shared_ = 0;
}

void FeatureVo::addAttitudePriors(BaProblem& problem,
                                  const std::vector<const Frame*>& frames) const {
  // An absolute attitude is a prior on the rotation from a fixed camera with
  // the world's axes (it has no observations, so it only anchors the priors).
  int world_axes = -1;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (!frames[k]->q_world_cam_prior) continue;
    if (world_axes < 0) {
      world_axes = static_cast<int>(problem.cameras.size());
      problem.cameras.push_back({Eigen::Isometry3d::Identity(), true});
    }
    problem.rotation_priors.push_back({world_axes, static_cast<int>(k),
                                       *frames[k]->q_world_cam_prior,
                                       params_.attitude_prior_sigma_deg * kRadPerDeg,
                                       params_.attitude_prior_heading_sigma_deg * kRadPerDeg});
  }
}

bool FeatureVo::seedMapFromRange(Frame& cur, const VoFrameInput& in) {
  if (!in.range_m || !(*in.range_m > 0.0)) return false;
  const Eigen::Matrix3d& R_world_cam = cur.T_world_cam.linear();
  const Eigen::Vector3d c = cur.T_world_cam.translation();
  const double ground_z = c.z() + *in.range_m * (R_world_cam * in.range_ray_cam.normalized()).z();
  if (!(ground_z > c.z())) return false;
  // Rays closer to the horizon than this meet the plane too far away to trust.
  const double max_range_m = 5.0 * *in.range_m;
  for (std::size_t i = 0; i < cur.features.keypoints.size(); ++i) {
    const cv::Point2f& px = cur.features.keypoints[i].pt;
    const Eigen::Vector3d ray_world =
        R_world_cam *
        Eigen::Vector3d((px.x - in.K(0, 2)) / in.K(0, 0), (px.y - in.K(1, 2)) / in.K(1, 1), 1.0);
    if (!(ray_world.z() > 0.0)) continue;
    const double s = (ground_z - c.z()) / ray_world.z();
    if (s * ray_world.norm() > max_range_m) continue;
    MapPoint mp;
    mp.p_world = c + s * ray_world;
    mp.descriptor = cur.features.descriptors.row(static_cast<int>(i)).clone();
    cur.point_of_feature[i] = static_cast<int>(points_.size());
    points_.push_back(std::move(mp));
  }
  if (numMapPoints() < params_.min_init_matches) {
    resetMap();
    std::fill(cur.point_of_feature.begin(), cur.point_of_feature.end(), -1);
    return false;
  }
  pushKeyframe(cur);
  return true;
}

void FeatureVo::compactMap() {
  // Points no key-frame of the window sees are never matched again; dropping
  // them keeps memory flat over a long flight. Not while a background BA holds
  // point indices, and only once most of the vector is dead (amortised O(1)).
  if (pending_ba_.valid()) return;
  std::vector<int> new_index(points_.size(), -1);
  int alive = 0;
  for (const Frame& kf : keyframes_)
    for (int id : kf.point_of_feature)
      if (id >= 0 && new_index[static_cast<std::size_t>(id)] < 0)
        new_index[static_cast<std::size_t>(id)] = 0;
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (new_index[i] == 0 && !points_[i].bad)
      new_index[i] = alive++;
    else
      new_index[i] = -1;
  if (static_cast<std::size_t>(alive) * 2 > points_.size()) return;
  const std::size_t last_bin = map_stats_.points_by_keyframes.size() - 1;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (new_index[i] >= 0) continue;
    ++map_stats_.points_dropped;
    ++map_stats_.points_by_keyframes[std::min(
        last_bin, static_cast<std::size_t>(std::max(points_[i].keyframes_seen, 0)))];
  }
  std::vector<MapPoint> kept;
  kept.reserve(static_cast<std::size_t>(alive));
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (new_index[i] >= 0) kept.push_back(std::move(points_[i]));
  points_ = std::move(kept);
  for (Frame& kf : keyframes_)
    for (int& id : kf.point_of_feature)
      if (id >= 0) id = new_index[static_cast<std::size_t>(id)];
}

void FeatureVo::pushKeyframe(Frame kf) {
  for (int id : kf.point_of_feature)
    if (id >= 0) ++points_[static_cast<std::size_t>(id)].keyframes_seen;
  keyframes_.push_back(std::move(kf));
}

void FeatureVo::markTracked(const Frame& frame) {
  for (std::size_t i = 0; i < frame.point_of_feature.size() && i < last_features_.size(); ++i)
    last_features_[i].tracked = frame.point_of_feature[i] >= 0;
}

int FeatureVo::numMapPoints() const {
  return static_cast<int>(
      std::count_if(points_.begin(), points_.end(), [](const MapPoint& p) { return !p.bad; }));
}

cv::Mat FeatureVo::globalShutterImage(const VoFrameInput& in, const cv::Mat& gray) const {
  if (!params_.rolling_shutter || !(in.readout_s > 0.0) || status_ != VoStatus::kTracking ||
      !(frame_period_s_ > 0.0) || !in.range_m || !(*in.range_m > 0.0))
    return gray;
  // T_world_cam(k) = T_world_cam(k-1) T_delta_.
  return rectifyRollingShutter(gray, in.K, in.readout_s, cameraTwist(T_delta_, frame_period_s_),
                               *in.range_m);
}

Eigen::Isometry3d FeatureVo::predict(int steps) const {
  Eigen::Isometry3d T = T_world_cam_last_;
  for (int i = 0; i < steps; ++i) T = T * T_delta_;
  return T;
}

VoFrameOutput FeatureVo::output(VoStatus status, const Eigen::Isometry3d& T_world_cam,
                                const Eigen::Isometry3d& T_body_cam, int tracked,
                                bool keyframe) const {
  VoFrameOutput out;
  out.status = status;
  out.T_world_body = T_world_cam * T_body_cam.inverse();
  out.tracked_points = tracked;
  out.new_keyframe = keyframe;
  out.resets = resets_;
  return out;
}

VoFrameOutput FeatureVo::process(const VoFrameInput& in) {
  const VoFrameOutput out = processFrame(in);
  T_world_body_last_ = out.T_world_body;
  return out;
}

VoFrameOutput FeatureVo::processFrame(const VoFrameInput& in) {
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  T_body_cam.linear() = in.R_body_cam;
  if (start_pending_) {
    T_world_cam_last_ = T_world_body_start_ * T_body_cam;
    T_delta_ = Eigen::Isometry3d::Identity();
    frames_since_good_ = 0;
    lost_count_ = 0;
    start_pending_ = false;
  }
  ++frame_index_;
  ++frames_since_good_;

  ++timing_.frames;
  collectBackgroundBa(false);
  auto stage_start = Clock::now();
  if (last_utime_ != 0 && in.utime > last_utime_)
    frame_period_s_ = static_cast<double>(in.utime - last_utime_) * 1e-6;
  last_utime_ = in.utime;
  Frame cur;
  cur.id = frame_index_;
  cur.features =
      extractOrb(globalShutterImage(in, vignetting_.apply(in.gray, in.K, params_.photometric)),
                 params_.features);
  cur.point_of_feature.assign(cur.features.keypoints.size(), -1);
  timing_.extract_s += secondsSince(stage_start);
  last_features_.clear();
  for (const cv::KeyPoint& kp : cur.features.keypoints)
    last_features_.push_back({kp.pt, kp.octave, false});
  stage_start = Clock::now();

  Eigen::Isometry3d T_pred = predict(frames_since_good_);
  if (in.q_world_body_prior) {
    T_pred.linear() = in.q_world_body_prior->matrix() * in.R_body_cam;
    cur.q_world_cam_prior = Eigen::Quaterniond(T_pred.linear());
  }

  if (status_ == VoStatus::kInitializing) {
    VoFrameOutput out = initialise(cur, in, T_body_cam, T_pred);
    timing_.track_s += secondsSince(stage_start);
    if (out.status == VoStatus::kTracking) markTracked(keyframes_.back());
    return out;
  }

  const bool tracked_ok = track(cur, in, T_pred);
  timing_.track_s += secondsSince(stage_start);
  if (!tracked_ok) {
    ++lost_count_;
    // A map seeded from the range that the next frame cannot track was seeded
    // from a bad frame: seed again at once (the same re-initialisation).
    if (seeded_unconfirmed_ || lost_count_ >= params_.lost_frames_before_reset) {
      // Start again from this frame, anchored where the motion model puts it.
      resetMap();
      if (!seeded_unconfirmed_) ++resets_;
      seeded_unconfirmed_ = false;
      status_ = VoStatus::kInitializing;
      cur.T_world_cam = T_pred;
      if (params_.reinit_from_range && seedMapFromRange(cur, in)) {
        // The new map's first key-frame is this frame, at the extrapolated pose.
        T_world_cam_last_ = T_pred;
        frames_since_good_ = 0;
        lost_count_ = 0;
        seeded_unconfirmed_ = true;
        status_ = VoStatus::kTracking;
        return output(VoStatus::kInitializing, T_pred, T_body_cam, 0, true);
      }
      reference_ = std::move(cur);
      reference_range_m_ = in.range_m;
      reference_frame_index_ = frame_index_;
      return output(VoStatus::kInitializing, T_pred, T_body_cam, 0, false);
    }
    return output(VoStatus::kLost, T_pred, T_body_cam, 0, false);
  }

  markTracked(cur);
  seeded_unconfirmed_ = false;
  int tracked = 0;
  for (int id : cur.point_of_feature)
    if (id >= 0) {
      ++points_[static_cast<std::size_t>(id)].found;
      ++tracked;
    }
  if (frames_since_good_ == 1) T_delta_ = T_world_cam_last_.inverse() * cur.T_world_cam;
  lost_count_ = 0;
  status_ = VoStatus::kTracking;

  // Key-frame decision: the share of the last key-frame's points still tracked, the rotation.
  const Frame& last_kf = keyframes_.back();
  std::vector<int> kf_ids;
  for (int id : last_kf.point_of_feature)
    if (id >= 0 && !points_[static_cast<std::size_t>(id)].bad) kf_ids.push_back(id);
  std::sort(kf_ids.begin(), kf_ids.end());
  int shared = 0;
  for (int id : cur.point_of_feature)
    if (id >= 0 && std::binary_search(kf_ids.begin(), kf_ids.end(), id)) ++shared;
  // The share is of the most of them any frame since the key-frame tracked:
  // some of a key-frame's new points are never found again, and counting them
  // would call for a key-frame at every frame.
  keyframe_peak_shared_ = std::max(keyframe_peak_shared_, shared);
  const double share = keyframe_peak_shared_ == 0 ? 0.0
                                                  : static_cast<double>(shared) /
                                                        static_cast<double>(keyframe_peak_shared_);
  const bool new_kf = share < params_.keyframe_min_shared_ratio ||
                      rotationAngleDeg(last_kf.T_world_cam.linear(), cur.T_world_cam.linear()) >
                          params_.keyframe_max_rotation_deg;
  if (new_kf) {
    keyframe_peak_shared_ = 0;
    stage_start = Clock::now();
    addKeyframe(cur, in);
    cur.T_world_cam = keyframes_.back().T_world_cam;
    timing_.mapping_s += secondsSince(stage_start);
    ++timing_.keyframes;
  }
  T_world_cam_last_ = cur.T_world_cam;
  frames_since_good_ = 0;
  return output(VoStatus::kTracking, cur.T_world_cam, T_body_cam, tracked, new_kf);
}

VoFrameOutput FeatureVo::initialise(Frame& cur, const VoFrameInput& in,
                                    const Eigen::Isometry3d& T_body_cam,
                                    const Eigen::Isometry3d& T_pred) {
  const auto restart_here = [&]() {
    cur.T_world_cam = T_pred;
    reference_ = std::move(cur);
    reference_range_m_ = in.range_m;
    reference_frame_index_ = frame_index_;
    return output(VoStatus::kInitializing, T_pred, T_body_cam, 0, false);
  };
  if (!reference_) return restart_here();

  Frame& ref = *reference_;
  std::vector<cv::DMatch> matches = matchBruteForce(ref.features, cur.features, params_.max_hamming,
                                                    static_cast<float>(params_.match_ratio));
  matches = filterByOrientation(ref.features, cur.features, matches);
  // Too few matches: the reference is out of view; the VO starts again from
  // this frame (for the first start, still at the start pose).
  if (static_cast<int>(matches.size()) < params_.min_init_matches) return restart_here();

  std::vector<cv::Point2f> px1, px2;
  for (const cv::DMatch& m : matches) {
    px1.push_back(ref.features.keypoints[static_cast<std::size_t>(m.queryIdx)].pt);
    px2.push_back(cur.features.keypoints[static_cast<std::size_t>(m.trainIdx)].pt);
  }
  const TwoViewResult r = initialiseTwoView(px1, px2, in.K, params_.two_view);
  if (!r.ok) return output(VoStatus::kInitializing, T_pred, T_body_cam, 0, false);

  // Metric scale: the reference camera's range along the rangefinder's ray, from the map.
  double scale = 1.0;
  if (reference_range_m_) {
    const std::optional<double> map_range = mapRange(r.points_1, in);
    if (!map_range) return output(VoStatus::kInitializing, T_pred, T_body_cam, 0, false);
    scale = *reference_range_m_ / *map_range;
  }

  Eigen::Isometry3d T_cur_ref = Eigen::Isometry3d::Identity();
  T_cur_ref.linear() = r.R_21;
  T_cur_ref.translation() = scale * r.t_21;
  cur.T_world_cam = ref.T_world_cam * T_cur_ref.inverse();
  for (std::size_t j = 0; j < r.points_1.size(); ++j) {
    const cv::DMatch& m = matches[static_cast<std::size_t>(r.inlier_match_index[j])];
    MapPoint mp;
    mp.p_world = ref.T_world_cam * (scale * r.points_1[j]);
    mp.descriptor = cur.features.descriptors.row(m.trainIdx).clone();
    const int id = static_cast<int>(points_.size());
    points_.push_back(std::move(mp));
    ref.point_of_feature[static_cast<std::size_t>(m.queryIdx)] = id;
    cur.point_of_feature[static_cast<std::size_t>(m.trainIdx)] = id;
  }
  const int frames = std::max(1, frame_index_ - reference_frame_index_);
  T_delta_ = perFrame(T_cur_ref.inverse(), frames);
  T_world_cam_last_ = cur.T_world_cam;
  frames_since_good_ = 0;
  lost_count_ = 0;
  pushKeyframe(std::move(ref));
  pushKeyframe(cur);
  reference_.reset();
  status_ = VoStatus::kTracking;
  return output(VoStatus::kTracking, cur.T_world_cam, T_body_cam,
                static_cast<int>(r.points_1.size()), true);
}

bool FeatureVo::track(Frame& cur, const VoFrameInput& in, const Eigen::Isometry3d& T_pred) {
  const std::vector<int> ids = localMapPoints();
  if (trackWithRadius(cur, in, T_pred, ids, params_.track_radius_px, true) >=
      params_.min_tracked_points)
    return true;
  std::fill(cur.point_of_feature.begin(), cur.point_of_feature.end(), -1);
  if (trackWithRadius(cur, in, T_pred, ids, params_.track_wide_radius_px, false) >=
      params_.min_tracked_points)
    return true;
  std::fill(cur.point_of_feature.begin(), cur.point_of_feature.end(), -1);
  return false;
}

FeatureVo::ProjectedPoints FeatureVo::projectPoints(const std::vector<int>& ids,
                                                    const Eigen::Isometry3d& T_world_cam,
                                                    const cv::Matx33d& K, cv::Size image_size,
                                                    double margin_px) const {
  ProjectedPoints out;
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const double w = image_size.width;
  const double h = image_size.height;
  std::vector<cv::Mat> rows;
  for (int id : ids) {
    const MapPoint& mp = points_[static_cast<std::size_t>(id)];
    const Eigen::Vector3d p_cam = T_cam_world * mp.p_world;
    if (p_cam.z() <= 0.0) continue;
    const Eigen::Vector2d px = project(K, p_cam);
    if (px.x() < -margin_px || px.y() < -margin_px || px.x() > w + margin_px ||
        px.y() > h + margin_px)
      continue;
    out.in_image.push_back(px.x() >= 0.0 && px.y() >= 0.0 && px.x() < w && px.y() < h ? 1 : 0);
    out.px.emplace_back(static_cast<float>(px.x()), static_cast<float>(px.y()));
    out.features.keypoints.emplace_back(out.px.back(), 31.0f);
    rows.push_back(mp.descriptor);
    out.ids.push_back(id);
  }
  if (!rows.empty()) cv::vconcat(rows, out.features.descriptors);
  return out;
}

int FeatureVo::trackWithRadius(Frame& cur, const VoFrameInput& in, const Eigen::Isometry3d& T_pred,
                               const std::vector<int>& ids, double radius_px, bool count_visible) {
  const ProjectedPoints local = projectPoints(ids, T_pred, in.K, in.gray.size(), radius_px);
  if (count_visible)
    for (std::size_t j = 0; j < local.ids.size(); ++j)
      if (local.in_image[j] != 0) ++points_[static_cast<std::size_t>(local.ids[j])].visible;
  if (static_cast<int>(local.ids.size()) < params_.min_tracked_points) return 0;
  const std::vector<cv::DMatch> matches =
      matchByWindow(local.features, cur.features, local.px, static_cast<float>(radius_px),
                    params_.max_hamming, static_cast<float>(params_.match_ratio));
  if (static_cast<int>(matches.size()) < params_.min_tracked_points) return 0;

  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (const cv::DMatch& m : matches) {
    const Eigen::Vector3d& p =
        points_[static_cast<std::size_t>(local.ids[static_cast<std::size_t>(m.queryIdx)])].p_world;
    object.emplace_back(p.x(), p.y(), p.z());
    const cv::Point2f& px = cur.features.keypoints[static_cast<std::size_t>(m.trainIdx)].pt;
    image.emplace_back(px.x, px.y);
  }
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  const bool ok = cv::solvePnPRansac(object, image, cv::Mat(in.K), cv::noArray(), rvec, tvec, false,
                                     200, static_cast<float>(params_.pnp_reprojection_px), 0.999,
                                     inliers, cv::SOLVEPNP_AP3P);
  if (!ok || static_cast<int>(inliers.size()) < params_.min_tracked_points) return 0;
  cv::Mat R_cv;
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R_cam_world;
  cv::cv2eigen(R_cv, R_cam_world);
  Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
  T_cw.linear() = R_cam_world;
  T_cw.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  // OpenCV refits the RANSAC pose to all its inliers (EPnP after AP3P), and on
  // the near-planar ground that refit often leaves most of them outside the
  // threshold (once 480 m off, which lost the frame). The BA starts from
  // whichever of it and the prediction explains more of the inliers.
  const auto consistent = [&](const Eigen::Isometry3d& T_cam_world) {
    int count = 0;
    for (int i : inliers) {
      const cv::Point3d& o = object[static_cast<std::size_t>(i)];
      const Eigen::Vector3d p_cam = T_cam_world * Eigen::Vector3d(o.x, o.y, o.z);
      const cv::Point2d& px = image[static_cast<std::size_t>(i)];
      if (p_cam.z() > 0.0 && (project(in.K, p_cam) - Eigen::Vector2d(px.x, px.y)).norm() <=
                                 params_.pnp_reprojection_px)
        ++count;
    }
    return count;
  };
  if (consistent(T_pred.inverse()) > consistent(T_cw)) T_cw = T_pred.inverse();

  // Motion-only bundle adjustment on the RANSAC inliers: the points stay fixed.
  BaProblem problem;
  problem.K = baIntrinsics(in.K);
  problem.cameras.push_back({T_cw.inverse(), false});
  addAttitudePriors(problem, {&cur});
  for (int i : inliers) {
    const cv::DMatch& m = matches[static_cast<std::size_t>(i)];
    problem.points.push_back({Eigen::Vector3d(object[static_cast<std::size_t>(i)].x,
                                              object[static_cast<std::size_t>(i)].y,
                                              object[static_cast<std::size_t>(i)].z),
                              true});
    const cv::KeyPoint& kp = cur.features.keypoints[static_cast<std::size_t>(m.trainIdx)];
    problem.observations.push_back(
        {0, static_cast<int>(problem.points.size()) - 1, Eigen::Vector2d(kp.pt.x, kp.pt.y),
         std::pow(static_cast<double>(params_.features.scale_factor), kp.octave)});
  }
  const BaResult result = bundleAdjust(problem, params_.ba);
  int tracked = 0;
  for (std::size_t k = 0; k < inliers.size(); ++k) {
    if (result.outlier[k]) continue;
    const cv::DMatch& m = matches[static_cast<std::size_t>(inliers[k])];
    cur.point_of_feature[static_cast<std::size_t>(m.trainIdx)] =
        local.ids[static_cast<std::size_t>(m.queryIdx)];
    ++tracked;
  }
  cur.T_world_cam = problem.cameras[0].T_world_cam;
  return tracked;
}

std::optional<double> FeatureVo::mapRange(const std::vector<Eigen::Vector3d>& p_cam,
                                          const VoFrameInput& in) const {
  const Eigen::Vector3d ray = in.range_ray_cam.normalized();
  if (!(ray.z() > 1e-6)) return std::nullopt;
  const Eigen::Vector2d ray_px = project(in.K, ray);
  // The window grows until it holds enough points (a sparse patch under the ray).
  for (double window_px = params_.range_window_px; window_px <= 4.0 * params_.range_window_px;
       window_px *= 2.0) {
    std::vector<Eigen::Vector3d> near;
    for (const Eigen::Vector3d& p : p_cam)
      if (p.z() > 0.0 && (project(in.K, p) - ray_px).norm() <= window_px) near.push_back(p);
    if (near.size() < kMinPlanePoints) continue;
    if (const std::optional<double> range = rangeToPlaneAlongRay(near, ray)) return range;
  }
  return std::nullopt;
}

std::optional<double> FeatureVo::mapRange(const Frame& kf, const VoFrameInput& in) const {
  const Eigen::Isometry3d T_cam_world = kf.T_world_cam.inverse();
  std::vector<Eigen::Vector3d> p_cam;
  for (int id : kf.point_of_feature)
    if (id >= 0 && !points_[static_cast<std::size_t>(id)].bad)
      p_cam.push_back(T_cam_world * points_[static_cast<std::size_t>(id)].p_world);
  return mapRange(p_cam, in);
}

void FeatureVo::addKeyframe(const Frame& cur, const VoFrameInput& in) {
  ++keyframes_made_;
  pushKeyframe(cur);
  triangulateNewPoints(keyframes_.back(), in.K);
  fuseNewKeyframe(in.K, in.gray.size());
  cullNewPoints();
  while (static_cast<int>(keyframes_.size()) > params_.map_keyframes) keyframes_.pop_front();
  compactMap();
  const std::vector<std::size_t> covisible = covisibleKeyframes(keyframes_.size() - 1);
  local_keyframe_ids_ = {keyframes_.back().id};
  for (std::size_t k : covisible) local_keyframe_ids_.push_back(keyframes_[k].id);
  if (++keyframes_since_ba_ >= params_.ba_every_keyframes && localBundleAdjust(in.K, covisible))
    keyframes_since_ba_ = 0;
  if (!in.range_m) return;
  const Frame& newest = keyframes_.back();
  const std::optional<double> map_range = mapRange(newest, in);
  if (!map_range || !(*map_range > 0.0)) return;
  last_scale_ratio_ = *map_range / *in.range_m;
  const double factor = scaleCorrection(last_scale_ratio_, params_.scale_tolerance,
                                        params_.scale_gain, params_.scale_max_step);
  if (factor == 1.0) return;
  // Scale the whole map about the new key-frame's centre, a similarity that
  // keeps every attitude: its pose stays, the motion measured from here on
  // comes out closer to metric.
  scaleMap(newest.T_world_cam.translation(), factor);
}

void FeatureVo::scaleMap(const Eigen::Vector3d& c, double factor) {
  for (MapPoint& mp : points_) mp.p_world = c + factor * (mp.p_world - c);
  for (Frame& kf : keyframes_)
    kf.T_world_cam.translation() = c + factor * (kf.T_world_cam.translation() - c);
  T_delta_.translation() *= factor;
  scaled_since_ba_a_ *= factor;
  scaled_since_ba_b_ = factor * scaled_since_ba_b_ + (1.0 - factor) * c;
}

std::vector<std::size_t> FeatureVo::covisibleKeyframes(std::size_t k) const {
  std::vector<char> in_k(points_.size(), 0);
  for (int id : keyframes_[k].point_of_feature)
    if (id >= 0 && !points_[static_cast<std::size_t>(id)].bad)
      in_k[static_cast<std::size_t>(id)] = 1;
  std::vector<std::pair<int, std::size_t>> shared;
  for (std::size_t j = 0; j < keyframes_.size(); ++j) {
    if (j == k) continue;
    int n = 0;
    for (int id : keyframes_[j].point_of_feature)
      if (id >= 0 && in_k[static_cast<std::size_t>(id)] != 0) ++n;
    if (n >= params_.min_covisible_points) shared.emplace_back(-n, j);
  }
  std::sort(shared.begin(), shared.end());
  std::vector<std::size_t> out;
  for (const auto& [n, j] : shared) out.push_back(j);
  return out;
}

std::vector<int> FeatureVo::localMapPoints() const {
  std::vector<int> ids;
  for (const Frame& kf : keyframes_) {
    if (!local_keyframe_ids_.empty() &&
        std::find(local_keyframe_ids_.begin(), local_keyframe_ids_.end(), kf.id) ==
            local_keyframe_ids_.end())
      continue;
    for (int id : kf.point_of_feature)
      if (id >= 0 && !points_[static_cast<std::size_t>(id)].bad) ids.push_back(id);
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

void FeatureVo::fuseNewKeyframe(const cv::Matx33d& K, cv::Size image_size) {
  if (params_.fuse_radius_px <= 0.0) return;
  const std::size_t newest = keyframes_.size() - 1;
  const std::vector<std::size_t> neighbours = covisibleKeyframes(newest);
  std::vector<int> new_ids;
  for (int id : keyframes_[newest].point_of_feature)
    if (id >= 0) new_ids.push_back(id);
  std::vector<std::pair<int, int>> merges;
  std::vector<int> neighbour_ids;
  for (std::size_t k : neighbours) {
    fuseInto(keyframes_[k], new_ids, K, image_size, merges);
    for (int id : keyframes_[k].point_of_feature)
      if (id >= 0) neighbour_ids.push_back(id);
  }
  std::sort(neighbour_ids.begin(), neighbour_ids.end());
  neighbour_ids.erase(std::unique(neighbour_ids.begin(), neighbour_ids.end()), neighbour_ids.end());
  fuseInto(keyframes_[newest], neighbour_ids, K, image_size, merges);
  mergePoints(merges);
}

void FeatureVo::fuseInto(Frame& target, const std::vector<int>& ids, const cv::Matx33d& K,
                         cv::Size image_size, std::vector<std::pair<int, int>>& merges) {
  std::set<int> in_target;
  for (int id : target.point_of_feature)
    if (id >= 0) in_target.insert(id);
  std::vector<int> candidates;
  for (int id : ids)
    if (!points_[static_cast<std::size_t>(id)].bad && in_target.count(id) == 0)
      candidates.push_back(id);
  const ProjectedPoints projected =
      projectPoints(candidates, target.T_world_cam, K, image_size, 0.0);
  if (projected.ids.empty()) return;
  const std::vector<cv::DMatch> matches = matchByWindow(
      projected.features, target.features, projected.px, static_cast<float>(params_.fuse_radius_px),
      params_.max_hamming, static_cast<float>(params_.match_ratio));
  for (const cv::DMatch& m : matches) {
    const int id = projected.ids[static_cast<std::size_t>(m.queryIdx)];
    int& held = target.point_of_feature[static_cast<std::size_t>(m.trainIdx)];
    if (held >= 0 && !points_[static_cast<std::size_t>(held)].bad) {
      if (held != id) merges.emplace_back(held, id);
      continue;
    }
    held = id;
    ++points_[static_cast<std::size_t>(id)].keyframes_seen;
    ++map_stats_.observations_fused;
  }
}

void FeatureVo::mergePoints(const std::vector<std::pair<int, int>>& merges) {
  if (merges.empty()) return;
  // Each point merged into another names it; the one more key-frames see stays.
  std::unordered_map<int, int> merged_into;
  const auto root = [&merged_into](int id) {
    for (auto it = merged_into.find(id); it != merged_into.end(); it = merged_into.find(id))
      id = it->second;
    return id;
  };
  for (const auto& [a_in, b_in] : merges) {
    int a = root(a_in);
    int b = root(b_in);
    if (a == b) continue;
    if (points_[static_cast<std::size_t>(a)].keyframes_seen <
        points_[static_cast<std::size_t>(b)].keyframes_seen)
      std::swap(a, b);
    merged_into[b] = a;
    points_[static_cast<std::size_t>(b)].bad = true;
    ++map_stats_.points_merged;
  }
  for (Frame& kf : keyframes_) {
    std::set<int> held;
    for (int id : kf.point_of_feature)
      if (id >= 0 && !merged_into.contains(id)) held.insert(id);
    for (int& id : kf.point_of_feature) {
      if (id < 0 || !merged_into.contains(id)) continue;
      const int kept = root(id);
      id = held.insert(kept).second ? kept : -1;
      if (id >= 0) ++points_[static_cast<std::size_t>(id)].keyframes_seen;
    }
  }
}

void FeatureVo::cullNewPoints() {
  for (MapPoint& mp : points_) {
    if (mp.bad || mp.made_at_keyframe < 0) continue;
    const std::int64_t age = keyframes_made_ - mp.made_at_keyframe;
    if (static_cast<double>(mp.found) <
            params_.point_min_found_ratio * static_cast<double>(mp.visible) ||
        (age >= 2 && mp.keyframes_seen < params_.point_min_keyframes)) {
      mp.bad = true;
      ++map_stats_.points_culled;
    } else if (age >= 3) {
      mp.made_at_keyframe = -1;
    }
  }
}

int FeatureVo::triangulateWithPrevious(Frame& kf_new, Frame& kf_prev, const cv::Matx33d& K) {
  const auto subset = [](const Frame& f, std::vector<int>& index) {
    Features out;
    std::vector<cv::Mat> rows;
    for (std::size_t i = 0; i < f.point_of_feature.size(); ++i) {
      if (f.point_of_feature[i] >= 0) continue;
      index.push_back(static_cast<int>(i));
      out.keypoints.push_back(f.features.keypoints[i]);
      rows.push_back(f.features.descriptors.row(static_cast<int>(i)));
    }
    if (!rows.empty()) cv::vconcat(rows, out.descriptors);
    return out;
  };
  std::vector<int> index_prev, index_new;
  const Features a = subset(kf_prev, index_prev);
  const Features b = subset(kf_new, index_new);
  if (a.keypoints.empty() || b.keypoints.empty()) return 0;

  // Predict through the ground under the previous key-frame: the horizontal
  // plane at the median height of its points (the ground is nearly a plane;
  // a plane, unlike one depth, also holds for an oblique view in a banked turn).
  std::vector<double> ground_z;
  for (int id : kf_prev.point_of_feature)
    if (id >= 0 && !points_[static_cast<std::size_t>(id)].bad)
      ground_z.push_back(points_[static_cast<std::size_t>(id)].p_world.z());
  if (ground_z.empty()) return 0;
  const double plane_z = median(ground_z);
  const Eigen::Vector3d c_prev = kf_prev.T_world_cam.translation();
  if (!(plane_z > c_prev.z())) return 0;
  const Eigen::Isometry3d T_new_world = kf_new.T_world_cam.inverse();
  std::vector<cv::Point2f> predicted;
  for (const cv::KeyPoint& kp : a.keypoints) {
    const Eigen::Vector3d ray_world =
        kf_prev.T_world_cam.linear() *
        Eigen::Vector3d((kp.pt.x - K(0, 2)) / K(0, 0), (kp.pt.y - K(1, 2)) / K(1, 1), 1.0);
    const Eigen::Vector3d p_new =
        ray_world.z() > 1e-6
            ? Eigen::Vector3d(T_new_world *
                              (c_prev + (plane_z - c_prev.z()) / ray_world.z() * ray_world))
            : Eigen::Vector3d(0.0, 0.0, -1.0);
    if (p_new.z() <= 0.0) {
      predicted.emplace_back(-1e6f, -1e6f);
      continue;
    }
    const Eigen::Vector2d px = project(K, p_new);
    predicted.emplace_back(static_cast<float>(px.x()), static_cast<float>(px.y()));
  }
  std::vector<cv::DMatch> matches =
      matchByWindow(a, b, predicted, params_.track_wide_radius_px, params_.max_hamming,
                    static_cast<float>(params_.match_ratio));
  matches = filterByOrientation(a, b, matches);

  const Eigen::Isometry3d T_new_prev = T_new_world * kf_prev.T_world_cam;
  TriangulationChecks checks;
  checks.min_parallax_deg = std::max(1.0, params_.two_view.min_point_parallax_deg);
  checks.max_reprojection_error_px = params_.two_view.max_reprojection_error_px;
  int added = 0;
  for (const cv::DMatch& m : matches) {
    const Triangulation t = triangulate(a.keypoints[static_cast<std::size_t>(m.queryIdx)].pt,
                                        b.keypoints[static_cast<std::size_t>(m.trainIdx)].pt,
                                        T_new_prev.linear(), T_new_prev.translation(), K, checks);
    if (t.status != TriangulationStatus::kOk) continue;
    const int i_new = index_new[static_cast<std::size_t>(m.trainIdx)];
    MapPoint mp;
    mp.p_world = kf_prev.T_world_cam * t.p_1;
    mp.keyframes_seen = 2;
    mp.made_at_keyframe = keyframes_made_;
    mp.descriptor = kf_new.features.descriptors.row(i_new).clone();
    const int id = static_cast<int>(points_.size());
    points_.push_back(std::move(mp));
    kf_prev.point_of_feature[static_cast<std::size_t>(
        index_prev[static_cast<std::size_t>(m.queryIdx)])] = id;
    kf_new.point_of_feature[static_cast<std::size_t>(i_new)] = id;
    ++added;
  }
  return added;
}

void FeatureVo::triangulateNewPoints(Frame& kf_new, const cv::Matx33d& K) {
  // Pair the new key-frame (the newest of the map) with its most co-visible
  // ones, widest baseline first: in a turn, key-frames come every few degrees
  // of rotation with a baseline too short for the parallax the neighbour alone
  // would give.
  std::vector<std::size_t> covisible = covisibleKeyframes(keyframes_.size() - 1);
  if (covisible.size() > static_cast<std::size_t>(params_.local_window))
    covisible.resize(static_cast<std::size_t>(params_.local_window));
  std::vector<std::pair<double, std::size_t>> candidates;
  for (std::size_t k : covisible) {
    const double baseline_m =
        (keyframes_[k].T_world_cam.translation() - kf_new.T_world_cam.translation()).norm();
    candidates.emplace_back(-baseline_m, k);
  }
  std::sort(candidates.begin(), candidates.end());
  const std::size_t pairs =
      std::min(candidates.size(), static_cast<std::size_t>(params_.triangulation_keyframes));
  for (std::size_t c = 0; c < pairs; ++c)
    triangulateWithPrevious(kf_new, keyframes_[candidates[c].second], K);
}

struct FeatureVo::LocalBaJob {
  struct Ref {
    std::int64_t keyframe_id;
    std::size_t feature;
    int point_id;
  };
  std::int64_t map_generation = 0;
  BaProblem problem;
  BaResult result;
  std::vector<std::int64_t> keyframe_ids;  // of the problem's first cameras
  std::vector<int> point_ids;              // of the problem's points
  std::vector<Ref> refs;                   // of the problem's observations
};

bool FeatureVo::localBundleAdjust(const cv::Matx33d& K, const std::vector<std::size_t>& covisible) {
  const std::size_t n = keyframes_.size();
  if (n < 2) return false;
  if (params_.background_ba && pending_ba_.valid()) return false;
  auto job = std::make_unique<LocalBaJob>();
  job->map_generation = map_generation_;
  BaProblem& problem = job->problem;
  problem.K = baIntrinsics(K);
  // Optimised: the newest key-frame and its most co-visible ones. Held fixed:
  // every other key-frame that sees their points, so that the map's attitude
  // and scale come from all that saw it, not from the window alone.
  std::vector<std::size_t> free_kfs = covisible;
  if (free_kfs.size() + 1 > static_cast<std::size_t>(params_.local_window))
    free_kfs.resize(static_cast<std::size_t>(params_.local_window) - 1);
  free_kfs.insert(free_kfs.begin(), n - 1);
  std::vector<char> is_free(n, 0);
  for (std::size_t k : free_kfs) is_free[k] = 1;
  std::unordered_map<int, int> ba_index;
  for (std::size_t k : free_kfs)
    for (int id : keyframes_[k].point_of_feature)
      if (id >= 0 && !points_[static_cast<std::size_t>(id)].bad &&
          ba_index.emplace(id, static_cast<int>(job->point_ids.size())).second) {
        job->point_ids.push_back(id);
        problem.points.push_back({points_[static_cast<std::size_t>(id)].p_world, false});
      }
  std::vector<std::size_t> fixed_kfs;
  for (std::size_t k = 0; k < n; ++k) {
    if (is_free[k] != 0) continue;
    for (int id : keyframes_[k].point_of_feature)
      if (id >= 0 && ba_index.contains(id)) {
        fixed_kfs.push_back(k);
        break;
      }
  }
  // Without an outer key-frame (a young map) the oldest of the window holds the gauge.
  if (fixed_kfs.empty()) {
    const auto oldest = std::min_element(free_kfs.begin(), free_kfs.end());
    fixed_kfs.push_back(*oldest);
    free_kfs.erase(oldest);
  }
  std::vector<const Frame*> frames;
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t k : pass == 0 ? free_kfs : fixed_kfs) {
      const Frame& kf = keyframes_[k];
      const int camera = static_cast<int>(problem.cameras.size());
      problem.cameras.push_back({kf.T_world_cam, pass == 1});
      job->keyframe_ids.push_back(kf.id);
      if (pass == 0) frames.push_back(&kf);
      for (std::size_t i = 0; i < kf.point_of_feature.size(); ++i) {
        const int id = kf.point_of_feature[i];
        if (id < 0) continue;
        const auto it = ba_index.find(id);
        if (it == ba_index.end() || points_[static_cast<std::size_t>(id)].bad) continue;
        const cv::KeyPoint& kp = kf.features.keypoints[i];
        problem.observations.push_back(
            {camera, it->second, Eigen::Vector2d(kp.pt.x, kp.pt.y),
             std::pow(static_cast<double>(params_.features.scale_factor), kp.octave)});
        job->refs.push_back({kf.id, i, id});
      }
    }
  addAttitudePriors(problem, frames);
  recordLocalBaShape(*job, free_kfs.size(), fixed_kfs.size());
  BundleAdjustmentParams ba = params_.ba;
  ba.num_threads = 1;
  scaled_since_ba_a_ = 1.0;
  scaled_since_ba_b_.setZero();
  if (!params_.background_ba) {
    job->result = bundleAdjust(problem, ba);
    applyLocalBa(*job);
    return true;
  }
  pending_ba_ = std::async(std::launch::async, [ba, job = std::move(job)]() mutable {
    job->result = bundleAdjust(job->problem, ba);
    return std::move(job);
  });
  return true;
}

void FeatureVo::collectBackgroundBa(bool wait) {
  if (!pending_ba_.valid()) return;
  if (!wait && pending_ba_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  const std::unique_ptr<LocalBaJob> job = pending_ba_.get();
  applyLocalBa(*job);
}

void FeatureVo::recordLocalBaShape(const LocalBaJob& job, std::size_t free_keyframes,
                                   std::size_t fixed_keyframes) {
  map_stats_.ba_free_keyframes = static_cast<int>(free_keyframes);
  map_stats_.ba_fixed_keyframes = static_cast<int>(fixed_keyframes);
  std::vector<int> in_ba(job.point_ids.size(), 0);
  for (const BaObservation& o : job.problem.observations)
    ++in_ba[static_cast<std::size_t>(o.point)];
  std::unordered_map<int, int> in_map;
  for (int id : job.point_ids) in_map.emplace(id, 0);
  for (const Frame& kf : keyframes_)
    for (int id : kf.point_of_feature)
      if (const auto it = in_map.find(id); it != in_map.end()) ++it->second;
  auto& bins = map_stats_.ba_points_by_observations;
  std::fill(bins.begin(), bins.end(), 0);
  map_stats_.ba_points_missing_observations = 0;
  for (std::size_t j = 0; j < job.point_ids.size(); ++j) {
    ++bins[std::min(static_cast<std::size_t>(in_ba[j]), bins.size() - 1)];
    if (in_map.at(job.point_ids[j]) > in_ba[j]) ++map_stats_.ba_points_missing_observations;
  }
}

void FeatureVo::applyLocalBa(const LocalBaJob& job) {
  // A map dropped since the BA started is gone; key-frames that left the
  // window since keep their place (the deque holds them by age).
  if (job.map_generation != map_generation_) return;
  // The map may have been scaled since the BA started (in the background):
  // its result is scaled alike.
  const double a = scaled_since_ba_a_;
  const Eigen::Vector3d& b = scaled_since_ba_b_;
  std::unordered_map<std::int64_t, Frame*> by_id;
  for (Frame& kf : keyframes_) by_id.emplace(kf.id, &kf);
  for (std::size_t k = 0; k < job.keyframe_ids.size(); ++k) {
    const auto it = by_id.find(job.keyframe_ids[k]);
    if (it == by_id.end() || job.problem.cameras[k].fixed) continue;
    it->second->T_world_cam = job.problem.cameras[k].T_world_cam;
    it->second->T_world_cam.translation() = a * it->second->T_world_cam.translation() + b;
  }
  for (std::size_t j = 0; j < job.point_ids.size(); ++j)
    points_[static_cast<std::size_t>(job.point_ids[j])].p_world =
        a * job.problem.points[j].p_world_m + b;
  for (std::size_t o = 0; o < job.refs.size(); ++o) {
    if (!job.result.outlier[o]) continue;
    const auto it = by_id.find(job.refs[o].keyframe_id);
    if (it == by_id.end()) continue;
    int& point = it->second->point_of_feature[job.refs[o].feature];
    if (point != job.refs[o].point_id) continue;
    point = -1;
    --points_[static_cast<std::size_t>(job.refs[o].point_id)].keyframes_seen;
  }
}

}  // namespace nadir::vo
