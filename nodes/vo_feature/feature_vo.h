#pragma once
// The tracking core of the feature-based monocular VO (seed 002; ORB-SLAM2's
// tracking and local mapping, loop closing off): plain structs in and out, no
// LCM.
//
// Initialisation: the first frame after setStartPose (or after a reset) is the
// reference; later frames are matched to it by brute force (+ the rotation
// consistency check) until initialiseTwoView succeeds. The reference camera's
// world pose is T_world_body_start * T_body_cam: the VO assumes the vehicle is
// at the start pose when the reference frame is taken (nadir anchors every VO
// at the truth of its first frame). Metric scale: the reference camera's height
// above the (nearly planar) ground is the median depth of the triangulated
// points along the world-down direction; the map is scaled so it equals
// height_agl_m of the reference frame. Without a height the two-view
// translation keeps unit norm (the map is then up to an unknown scale). While
// initialising, the published pose is the reference's pose.
//
// Tracking: a constant-velocity model (or the attitude prior's rotation with
// the model's position) predicts the camera; the map points of the local
// key-frames are projected into the frame and matched within a window around
// their predictions (a wider window when too few match), the pose is found by
// cv::solvePnPRansac and refined by a motion-only bundle adjustment (points
// fixed, Huber loss, outliers dropped). Fewer than min_tracked_points inliers
// after the wide window: LOST for this frame, the published pose is the motion
// model's extrapolation, and the next frames try again from the extrapolation.
// After lost_frames_before_reset consecutive lost frames the map is dropped
// and the VO re-initialises with the reference anchored at the extrapolated
// pose (same world frame, scale from the height): the published pose continues
// from the extrapolation, it does not jump back.
//
// Key-frames: a frame becomes one when the share of the last key-frame's map
// points it tracks falls below keyframe_min_shared_ratio, or its rotation from
// the last key-frame exceeds keyframe_max_rotation_deg. Its unmatched features
// are matched to the previous key-frame's unmatched ones (window around the
// position predicted through the previous key-frame's median depth) and
// triangulated with the parallax and reprojection checks; then a local bundle
// adjustment (single thread: deterministic) refines the last local_window
// key-frames (the oldest one fixed: it holds the position and attitude gauge;
// the scale is left to the points and the height correction below, fixing two
// held the map's scale against it) and their points, every ba_every_keyframes
// key-frames.
//
// Scale upkeep: at each key-frame with a height, the map's height (median
// depth of the key-frame's points along the down direction) is compared with
// height_agl_m; their ratio is reported (lastScaleRatio). When it is off by
// more than scale_tolerance, the points the new key-frame sees are scaled
// about its camera centre by 1 + scale_gain * (ratio - 1), and so is the
// motion model's translation: the published pose does not move, the following
// motion comes out closer to metric, and the next local BA spreads it. A gain
// below 1 keeps a single noisy height from bending the map.

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/params.h"
#include "nodes/vo_feature/bundle_adjustment.h"
#include "nodes/vo_feature/features.h"
#include "nodes/vo_feature/two_view.h"

namespace nadir::vo {

struct FeatureVoParams {
  FeatureParams features;
  TwoViewParams two_view;
  BundleAdjustmentParams ba;
  // Initialise only from at least this many matches with the reference.
  int min_init_matches = 100;
  // Fewer PnP inliers than this: the frame is lost.
  int min_tracked_points = 30;
  // New key-frame when the tracked share of the last key-frame's points falls below this.
  double keyframe_min_shared_ratio = 0.6;
  // New key-frame when the rotation since the last key-frame exceeds this, deg.
  double keyframe_max_rotation_deg = 5.0;
  // Key-frames in the local bundle adjustment.
  int local_window = 8;
  // Local bundle adjustment every this many key-frames.
  int ba_every_keyframes = 1;
  // Matching: Hamming distance limit and ratio test.
  int max_hamming = 64;
  double match_ratio = 0.9;
  // Tracking windows around the predicted positions, px: first, then the wide retry.
  double track_radius_px = 15.0;
  double track_wide_radius_px = 60.0;
  // PnP RANSAC inlier threshold, px.
  double pnp_reprojection_px = 3.0;
  // Consecutive lost frames before the map is dropped and the VO re-initialises.
  int lost_frames_before_reset = 5;
  // Scale upkeep: correct when |height ratio - 1| exceeds this, by this share.
  double scale_tolerance = 0.01;
  double scale_gain = 0.5;

  void visit(core::ParamVisitor& v);
};

struct VoFrameInput {
  std::int64_t utime = 0;
  cv::Mat gray;  // 8-bit, undistorted
  cv::Matx33d K = cv::Matx33d::eye();
  Eigen::Matrix3d R_body_cam = Eigen::Matrix3d::Identity();
  std::optional<double> height_agl_m;  // from the rangefinder, for the metric scale
  std::optional<Eigen::Quaterniond> q_world_body_prior;  // optional attitude prior
};

enum class VoStatus { kInitializing, kTracking, kLost };

struct VoFrameOutput {
  VoStatus status = VoStatus::kInitializing;
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  int tracked_points = 0;
  bool new_keyframe = false;
  int resets = 0;
};

class FeatureVo {
 public:
  // Throws std::invalid_argument on bad params.
  explicit FeatureVo(const FeatureVoParams& params);

  // The pose of the body when the VO starts: the world frame the estimates are
  // published in. Drops any map and starts initialising from the next frame.
  void setStartPose(const Eigen::Isometry3d& T_world_body);

  VoFrameOutput process(const VoFrameInput& frame);

  // Diagnostics: map height / measured height at the last key-frame with a
  // height (1 before), key-frames and map points alive.
  double lastScaleRatio() const { return last_scale_ratio_; }
  int numKeyframes() const { return static_cast<int>(keyframes_.size()); }
  int numMapPoints() const;

 private:
  struct MapPoint {
    Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
    cv::Mat descriptor;  // 1 x 32, CV_8U
    bool bad = false;
  };
  struct Frame {
    Features features;
    std::vector<int> point_of_feature;  // map point index per feature, -1: none
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  };

  void resetMap();
  VoFrameOutput initialise(Frame& cur, const VoFrameInput& in, const Eigen::Isometry3d& T_body_cam,
                           const Eigen::Isometry3d& T_pred);
  bool track(Frame& cur, const VoFrameInput& in, const Eigen::Isometry3d& T_pred);
  int trackWithRadius(Frame& cur, const VoFrameInput& in, const Eigen::Isometry3d& T_pred,
                      double radius_px);
  void addKeyframe(const Frame& cur, const VoFrameInput& in);
  VoFrameOutput output(VoStatus status, const Eigen::Isometry3d& T_world_cam,
                       const Eigen::Isometry3d& T_body_cam, int tracked, bool keyframe) const;
  void triangulateWithPrevious(Frame& kf_new, Frame& kf_prev, const cv::Matx33d& K);
  void localBundleAdjust(const cv::Matx33d& K);
  double medianHeight(const Frame& kf) const;
  Eigen::Isometry3d predict(int steps) const;

  FeatureVoParams params_;
  Eigen::Isometry3d T_world_body_start_ = Eigen::Isometry3d::Identity();
  VoStatus status_ = VoStatus::kInitializing;

  // Initialisation: the reference frame and its anchored camera pose.
  std::optional<Frame> reference_;
  std::optional<double> reference_height_m_;
  int reference_frame_index_ = 0;
  int frame_index_ = 0;
  bool start_pending_ = true;

  std::vector<MapPoint> points_;
  std::deque<Frame> keyframes_;
  int keyframes_since_ba_ = 0;

  // Motion model: the last good camera pose, frames since it, and the velocity.
  Eigen::Isometry3d T_world_cam_last_ = Eigen::Isometry3d::Identity();
  // Per-frame motion: T_world_cam(k+1) = T_world_cam(k) * T_delta_.
  Eigen::Isometry3d T_delta_ = Eigen::Isometry3d::Identity();
  int frames_since_good_ = 1;
  int lost_count_ = 0;
  int resets_ = 0;
  double last_scale_ratio_ = 1.0;
};

}  // namespace nadir::vo
