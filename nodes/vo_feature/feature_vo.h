#pragma once
// The tracking core of the feature-based monocular VO (Kim 2019; ORB-SLAM2's
// tracking and local mapping, loop closing off): frames and the rangefinder's
// range in, T_world_body out, plain structs, no LCM. Two-view initialisation,
// PnP tracking against the local map, key-frames on shared points or rotation,
// a local bundle adjustment, metric scale from the range, re-initialisation
// after a loss: docs/vo_feature.md says how each works.

#include <cstdint>
#include <deque>
#include <future>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/params.h"
#include "nodes/common/photometric.h"
#include "nodes/common/vo_frame.h"
#include "nodes/vo_feature/bundle_adjustment.h"
#include "nodes/vo_feature/debug_image.h"
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
  double keyframe_min_shared_ratio = 0.8;
  // New key-frame when the rotation since the last key-frame exceeds this, deg.
  double keyframe_max_rotation_deg = 5.0;
  // Key-frames the local bundle adjustment optimises: the new one and its most
  // co-visible ones (the others that see their points are held fixed).
  int local_window = 8;
  // Key-frames the map keeps (the oldest is dropped beyond this).
  int map_keyframes = 16;
  // Two key-frames are co-visible when they share at least this many points.
  int min_covisible_points = 15;
  // A new key-frame triangulates with this many co-visible key-frames, widest
  // baseline first.
  int triangulation_keyframes = 3;
  // Fusion: a point projected into a co-visible key-frame takes the feature
  // within this many pixels of its projection whose descriptor matches.
  double fuse_radius_px = 4.0;
  // A new point is dropped when tracking found it in fewer than this share of
  // the frames it was in view of, or when fewer than point_min_keyframes
  // key-frames see it two key-frames after it was made.
  double point_min_found_ratio = 0.25;
  int point_min_keyframes = 3;
  // Local bundle adjustment every this many key-frames.
  int ba_every_keyframes = 1;
  // Live: the local bundle adjustment runs in a background thread and its
  // result is taken in at the first frame after it finishes (a key-frame that
  // comes while one runs waits for the next). Off (nadir run): at its key-frame,
  // so that runs are byte-identical.
  bool background_ba = true;
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
  // Standard deviation of the attitude prior's tilt (the flight controller's
  // attitude) in tracking and in the local bundle adjustment, deg ...
  double attitude_prior_sigma_deg = 0.5;
  // ... of its heading, deg. A flight controller's heading comes from the
  // magnetometer with a bias of a degree or two that vision cannot see; held
  // to it, the estimate drifts off sideways (docs/vo_feature.md), so by
  // default only the tilt counts.
  double attitude_prior_heading_sigma_deg = 90.0;
  // After a loss, with a range: start the new map at once from the ground the
  // rangefinder sees (every feature's ray met with the level plane through the
  // range's ground point), not by two-view initialisation.
  bool reinit_from_range = true;
  // Rectify the frames of a rolling-shutter camera (VoFrameInput::readout_s)
  // to a global shutter at their stamp, with the motion model's velocity,
  // before features are found (nodes/common/rolling_shutter.h).
  bool rolling_shutter = true;
  // The lens's vignetting and the response, as calibrated: frames are
  // divided by the vignetting before features are found (photometric.h).
  PhotometricCalibration photometric;
  // Scale upkeep: correct when |range ratio - 1| exceeds this, by this share,
  // by at most scale_max_step at one key-frame.
  double scale_tolerance = 0.002;
  double scale_gain = 0.5;
  double scale_max_step = 0.02;
  // The map's range is taken from the points seen within this many pixels of
  // the rangefinder ray's image.
  double range_window_px = 120.0;

  void visit(core::ParamVisitor& v);
};

// Wall-clock seconds spent in each stage, summed over the frames processed
// (diagnostics only: nothing the VO computes depends on them).
struct FeatureVoTiming {
  double extract_s = 0;  // ORB extraction
  double track_s = 0;    // initialisation or tracking (matching, PnP, motion-only BA)
  double mapping_s = 0;  // key-frames: triangulation, local BA, scale upkeep
  std::int64_t frames = 0;
  std::int64_t keyframes = 0;
};

// How long the map's points lived: of the points dropped from the map (no
// key-frame of the window sees them any more), how many saw each number of
// key-frames (diagnostics: docs/vo_feature.md, "Where the tilt comes from").
struct FeatureVoMapStats {
  // points_by_keyframes[k]: points seen by k key-frames (the last bin: that many or more).
  std::vector<std::int64_t> points_by_keyframes = std::vector<std::int64_t>(33, 0);
  std::int64_t points_dropped = 0;
  // Observations fusion added, points it merged into another, new points culled.
  std::int64_t observations_fused = 0;
  std::int64_t points_merged = 0;
  std::int64_t points_culled = 0;
  // The last local BA: the key-frames it optimised and held fixed, its points
  // by the observations they entered it with (the last bin: that many or more),
  // and its points that some key-frame of the map saw without that
  // observation in the BA (none: each point is optimised against all that saw it).
  int ba_free_keyframes = 0;
  int ba_fixed_keyframes = 0;
  std::vector<std::int64_t> ba_points_by_observations = std::vector<std::int64_t>(33, 0);
  std::int64_t ba_points_missing_observations = 0;
};

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
  ~FeatureVo();  // waits for a background bundle adjustment

  // The pose of the body when the VO starts: the world frame the estimates are
  // published in. Drops any map and starts initialising from the next frame.
  void setStartPose(const Eigen::Isometry3d& T_world_body);
  // A restart asked for from outside (a reset command): drops the map as
  // setStartPose does and counts in the resets; from T_world_body, or without
  // one from the last estimate, so that the estimate does not jump.
  void restart(const std::optional<Eigen::Isometry3d>& T_world_body);

  VoFrameOutput process(const VoFrameInput& frame);

  // Diagnostics: map range / measured range at the last key-frame with a
  // range (1 before), key-frames in the map and map points alive.
  double lastScaleRatio() const { return last_scale_ratio_; }
  int numKeyframes() const { return static_cast<int>(keyframes_.size()); }
  int numMapPoints() const;
  // Points held in memory, alive or not (for tests of the memory bound).
  std::size_t storedMapPoints() const { return points_.size(); }
  const FeatureVoTiming& timing() const { return timing_; }
  const FeatureVoMapStats& mapStats() const { return map_stats_; }
  // The last frame's features, each marked if it was matched to the map (the debug image).
  const std::vector<DebugFeature>& lastFrameFeatures() const { return last_features_; }

 private:
  struct MapPoint {
    Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
    cv::Mat descriptor;  // 1 x 32, CV_8U
    bool bad = false;
    int keyframes_seen = 0;  // key-frames that have observed it
    // Frames tracking expected it in view, and found it (culling).
    int visible = 1;
    int found = 1;
    // The key-frame count when it was made; -1: past the culling.
    std::int64_t made_at_keyframe = -1;
  };
  struct Frame {
    Features features;
    std::int64_t id = 0;                // the frame's index
    std::vector<int> point_of_feature;  // map point index per feature, -1: none
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
    // The flight controller's attitude of the camera, when given (attitude prior).
    std::optional<Eigen::Quaterniond> q_world_cam_prior;
  };

  VoFrameOutput processFrame(const VoFrameInput& in);
  void resetMap();
  void markTracked(const Frame& frame);
  void compactMap();
  // Appends a key-frame, counting it in its points' keyframes_seen.
  void pushKeyframe(Frame kf);
  void addAttitudePriors(BaProblem& problem, const std::vector<const Frame*>& frames) const;
  bool seedMapFromRange(Frame& cur, const VoFrameInput& in);
  VoFrameOutput initialise(Frame& cur, const VoFrameInput& in, const Eigen::Isometry3d& T_body_cam,
                           const Eigen::Isometry3d& T_pred);
  bool track(Frame& cur, const VoFrameInput& in, const Eigen::Isometry3d& T_pred);
  // Map points as a camera at T_world_cam sees them: those in front of it
  // whose projection is within margin_px of the image (in_image: inside it),
  // as features at their projections with the points' descriptors.
  struct ProjectedPoints {
    Features features;
    std::vector<cv::Point2f> px;
    std::vector<int> ids;
    std::vector<char> in_image;
  };
  ProjectedPoints projectPoints(const std::vector<int>& ids, const Eigen::Isometry3d& T_world_cam,
                                const cv::Matx33d& K, cv::Size image_size, double margin_px) const;
  // Matches the map points ids within radius_px of their predicted pixels;
  // count_visible: the first try of a frame counts the points in view (culling).
  int trackWithRadius(Frame& cur, const VoFrameInput& in, const Eigen::Isometry3d& T_pred,
                      const std::vector<int>& ids, double radius_px, bool count_visible);
  void addKeyframe(const Frame& cur, const VoFrameInput& in);
  // Indices into keyframes_ of the key-frames sharing at least
  // min_covisible_points points with keyframes_[k], most shared first.
  std::vector<std::size_t> covisibleKeyframes(std::size_t k) const;
  // The points of the local map: those of the newest key-frame's co-visible ones.
  std::vector<int> localMapPoints() const;
  // Fusion of the newest key-frame with its co-visible key-frames (both ways).
  void fuseNewKeyframe(const cv::Matx33d& K, cv::Size image_size);
  void fuseInto(Frame& target, const std::vector<int>& ids, const cv::Matx33d& K,
                cv::Size image_size, std::vector<std::pair<int, int>>& merges);
  void mergePoints(const std::vector<std::pair<int, int>>& merges);
  void cullNewPoints();
  // p -> c + factor (p - c) for every point and key-frame centre of the map.
  void scaleMap(const Eigen::Vector3d& c, double factor);
  VoFrameOutput output(VoStatus status, const Eigen::Isometry3d& T_world_cam,
                       const Eigen::Isometry3d& T_body_cam, int tracked, bool keyframe) const;
  // Returns the points added.
  int triangulateWithPrevious(Frame& kf_new, Frame& kf_prev, const cv::Matx33d& K);
  void triangulateNewPoints(Frame& kf_new, const cv::Matx33d& K);
  struct LocalBaJob;
  // Starts (or, not in the background, runs) a local BA over the newest
  // key-frame and the co-visible ones (covisibleKeyframes of it); false if none started.
  bool localBundleAdjust(const cv::Matx33d& K, const std::vector<std::size_t>& covisible);
  void applyLocalBa(const LocalBaJob& job);
  void recordLocalBaShape(const LocalBaJob& job, std::size_t free_keyframes,
                          std::size_t fixed_keyframes);
  void collectBackgroundBa(bool wait);
  // The map's range along the rangefinder's ray from a camera (see the top).
  std::optional<double> mapRange(const std::vector<Eigen::Vector3d>& p_cam,
                                 const VoFrameInput& in) const;
  std::optional<double> mapRange(const Frame& kf, const VoFrameInput& in) const;
  Eigen::Isometry3d predict(int steps) const;
  // The frame as a global shutter would see it (rolling_shutter).
  cv::Mat globalShutterImage(const VoFrameInput& in, const cv::Mat& gray) const;

  FeatureVoParams params_;
  Eigen::Isometry3d T_world_body_start_ = Eigen::Isometry3d::Identity();
  // The last estimate: the last frame's output, or the start pose before a frame.
  Eigen::Isometry3d T_world_body_last_ = Eigen::Isometry3d::Identity();
  VoStatus status_ = VoStatus::kInitializing;

  // Initialisation: the reference frame and its anchored camera pose.
  std::optional<Frame> reference_;
  std::optional<double> reference_range_m_;
  int reference_frame_index_ = 0;
  int frame_index_ = 0;
  bool start_pending_ = true;

  std::vector<MapPoint> points_;
  std::deque<Frame> keyframes_;
  std::int64_t keyframes_made_ = 0;
  // The newest key-frame and its co-visible ones (their ids): the local map tracking uses.
  std::vector<std::int64_t> local_keyframe_ids_;
  // The map's scaling since the background BA started, p -> a p + b.
  double scaled_since_ba_a_ = 1.0;
  Eigen::Vector3d scaled_since_ba_b_ = Eigen::Vector3d::Zero();
  int keyframes_since_ba_ = 0;
  // The most of the last key-frame's points a frame since it has tracked.
  int keyframe_peak_shared_ = 0;

  // Motion model: the last good camera pose, frames since it, and the velocity.
  Eigen::Isometry3d T_world_cam_last_ = Eigen::Isometry3d::Identity();
  // Per-frame motion: T_world_cam(k+1) = T_world_cam(k) * T_delta_.
  Eigen::Isometry3d T_delta_ = Eigen::Isometry3d::Identity();
  // The time between the last two frames, s (0: not known yet).
  double frame_period_s_ = 0.0;
  std::int64_t last_utime_ = 0;
  int frames_since_good_ = 1;
  int lost_count_ = 0;
  // The map was seeded from the range and no frame has tracked it yet.
  bool seeded_unconfirmed_ = false;
  int resets_ = 0;
  double last_scale_ratio_ = 1.0;
  FeatureVoTiming timing_;
  FeatureVoMapStats map_stats_;
  VignettingCorrection vignetting_;
  std::vector<DebugFeature> last_features_;
  // Counts map resets: a background BA of an earlier map is dropped.
  std::int64_t map_generation_ = 0;
  std::future<std::unique_ptr<LocalBaJob>> pending_ba_;
};

}  // namespace nadir::vo
