#pragma once
// The direct (photometric) monocular VO: frames and the rangefinder's range in,
// metric T_world_body out, plain structs, no LCM. Each frame is aligned to the
// newest key-frame (frame_tracker.h); key-frames are made on change of view
// (optical flow, rotation, brightness) and a window of them is optimised on
// the photometric error (window_optimizer.h). The map starts at once from the
// ground plane the rangefinder sees; after a loss it starts again there from
// the extrapolated pose, so the estimate does not jump. docs/vo_direct.md says
// how each piece works.

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/params.h"
#include "nodes/common/photometric.h"
#include "nodes/common/vo_frame.h"
#include "nodes/vo_direct/frame_tracker.h"
#include "nodes/vo_direct/image_pyramid.h"
#include "nodes/vo_direct/pixel_selection.h"
#include "nodes/vo_direct/window_optimizer.h"

namespace nadir::vo {

struct DirectVoParams {
  // Pyramid levels (the coarsest is tracked first).
  int pyramid_levels = 5;
  PixelSelectionParams selection;
  TrackerParams tracker;
  WindowOptimizerParams window;
  // Key-frames in the optimised window; the oldest is dropped beyond it.
  int window_keyframes = 7;
  // Points the window holds at most (a new key-frame adds points where the
  // view has none, up to this).
  int max_points = 1000;
  // A new key-frame when, since the newest one, flow_t / (flow_translation *
  // (w + h)) + flow_rt / (flow_rotation_translation * (w + h)) + |scale
  // change| / scale_change + |log gain change| / brightness exceeds 1:
  // flow_t is the RMS optical flow of the points from the translation alone,
  // flow_rt with the rotation, the scale change the mean ratio of the points'
  // depths in the frame and the key-frame, less one (climbs and descents,
  // which the flow hardly shows at the image's centre).
  double keyframe_flow_translation = 0.01;
  double keyframe_flow_rotation_translation = 0.045;
  double keyframe_scale_change = 0.02;
  double keyframe_brightness = 0.5;
  // ... or when fewer than this share of its points stay in the image.
  double keyframe_min_in_image = 0.6;
  // A frame is lost when its RMS residual exceeds lost_rms_ratio times the
  // map's typical one (a running mean over the frames tracked) and
  // lost_rms_floor, when its brightness changes by more than lost_log_gain
  // from the key-frame's (a blinded or noisy image is matched by a gain near
  // zero), or when fewer than lost_min_in_image of the points stay in the
  // image; after lost_frames_before_reset of those the map is made again.
  // A frame is also reported lost, but its pose and the map kept, when the
  // image fixes the pose too loosely: its least-determined direction moves
  // its rays by more than lost_pose_sigma_mrad at 1 sigma
  // (TrackResult::pose_sigma_rad; 0.286 mrad is 0.2 px at a 700 px focal length). Over low-texture
  // ground the estimate drifts away with every frame otherwise "tracked" (docs/vo_direct.md).
  double lost_rms_ratio = 3.0;
  double lost_rms_floor = 10.0;
  double lost_log_gain = 0.7;
  double lost_min_in_image = 0.2;
  double lost_pose_sigma_mrad = 0.286;
  // A frame whose pose puts the camera further from the last good one than
  // this speed allows is lost: no vehicle nadir flies is faster, and a pose
  // fitted to faint texture can leap by kilometres.
  double lost_speed_mps = 150.0;
  // Rectify the frames of a rolling-shutter camera (VoFrameInput::readout_s)
  // to a global shutter at their stamp, with the motion model's velocity
  // (rolling_shutter.h), before they are tracked.
  bool rolling_shutter = true;
  // The lens's vignetting and the response, as calibrated: frames are
  // divided by the vignetting before they are tracked (photometric.h).
  PhotometricCalibration photometric;
  // Lost frames in a row before the map is dropped and made again.
  int lost_frames_before_reset = 3;
  // Points of a key-frame within this of the rangefinder ray's image carry
  // its range (level-0 px).
  double range_window_px = 120.0;
  // Each key-frame with a range hosts this many points there (the window's scale).
  int range_points = 60;
  // A map starts only on a frame with at least this many selected pixels.
  int min_start_points = 200;

  void visit(core::ParamVisitor& v);
};

// Wall-clock seconds in each stage, summed over the frames (diagnostics only).
struct DirectVoTiming {
  double pyramid_s = 0;   // the frame's pyramid and gradients
  double track_s = 0;     // coarse-to-fine alignment
  double keyframe_s = 0;  // selection, new points, tracking reference
  double window_s = 0;    // the windowed optimisation
  std::int64_t frames = 0;
  std::int64_t keyframes = 0;
  std::int64_t track_iterations = 0;  // Levenberg-Marquardt steps tried, all levels and guesses
};

struct DirectVoOutput {
  VoStatus status = VoStatus::kInitializing;
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  int points = 0;  // points aligned in this frame
  bool new_keyframe = false;
  int resets = 0;
  AffineBrightness affine;  // the frame's brightness
  double rms = 0.0;         // the alignment's RMS residual
  // How loosely the image fixes the pose (TrackResult::pose_sigma_rad).
  double pose_sigma_rad = 0.0;
};

class DirectVo {
 public:
  // Throws std::invalid_argument on bad params.
  explicit DirectVo(const DirectVoParams& params);

  // The pose of the body when the VO starts: the world frame the estimates are
  // published in. Drops any map; the next frame with a range starts a new one.
  void setStartPose(const Eigen::Isometry3d& T_world_body);
  // A reset (counted in resets): drop the map and start again at the next
  // frame, from this pose, or without one from the pose estimated now.
  void requestReset(const std::optional<Eigen::Isometry3d>& T_world_body);

  // Throws std::invalid_argument on a frame that is not 8-bit gray.
  DirectVoOutput process(const VoFrameInput& frame);

  const DirectVoTiming& timing() const { return timing_; }
  int numKeyframes() const { return static_cast<int>(keyframes_.size()); }
  int numPoints() const { return static_cast<int>(points_.size()); }
  // The newest key-frame's image and the window's points in it (level-0 pixel,
  // inverse depth), for the debug image.
  const cv::Mat& keyframeImage() const { return keyframe_image_; }
  const std::vector<DepthPixel>& keyframePoints() const { return keyframe_points_; }
  // The window optimiser's last result.
  const WindowStats& lastWindowStats() const { return last_window_; }

 private:
  struct Keyframe {
    std::unique_ptr<ImagePyramid> pyramid;
    Eigen::Isometry3d T_cam_world = Eigen::Isometry3d::Identity();
    AffineBrightness affine;
    AffineBrightness affine_prior;
  };

  void dropMap();
  Eigen::Isometry3d predictCamWorld(int steps) const;
  bool startMap(std::unique_ptr<ImagePyramid> pyramid, const VoFrameInput& in,
                const Eigen::Isometry3d& T_cam_world, const AffineBrightness& affine);
  TrackResult track(const ImagePyramid& pyramid);
  bool isLost(const TrackResult& result) const;
  // The frame as a global shutter would see it (rolling_shutter).
  cv::Mat globalShutterImage(const VoFrameInput& in, const cv::Mat& gray) const;
  // The frame's pose when it is lost: the motion model's.
  DirectVoOutput lostFrame(std::unique_ptr<ImagePyramid> pyramid, const VoFrameInput& in,
                           int points);
  bool needKeyframe(const TrackResult& result) const;
  // Appends a key-frame (its pyramid with gradients at levels 0-2) to the window.
  void pushKeyframe(std::unique_ptr<ImagePyramid> pyramid, const Eigen::Isometry3d& T_cam_world,
                    const AffineBrightness& affine);
  void addKeyframe(std::unique_ptr<ImagePyramid> pyramid, const VoFrameInput& in,
                   const Eigen::Isometry3d& T_cam_world, const AffineBrightness& affine);
  void addPoints(int host, const std::vector<SelectedPixel>& candidates,
                 const std::vector<DepthPixel>& projected, const VoFrameInput& in);
  void optimiseWindow();
  void makeTrackingReference();
  void acceptPose(const Eigen::Isometry3d& T_cam_world, const AffineBrightness& affine);
  DirectVoOutput output(VoStatus status, const Eigen::Isometry3d& T_cam_world, int points,
                        bool keyframe) const;

  DirectVoParams params_;
  Eigen::Isometry3d T_body_cam_ = Eigen::Isometry3d::Identity();
  cv::Matx33d K_ = cv::Matx33d::eye();
  // A start or reset pose waiting for the next frame (T_world_body), and
  // whether it counts as a reset.
  std::optional<Eigen::Isometry3d> pending_start_;
  bool pending_in_place_ = false;  // a reset without a pose
  bool pending_is_reset_ = false;
  bool started_ = false;

  std::deque<Keyframe> keyframes_;
  std::vector<WindowPoint> points_;
  TrackingReference reference_;
  WindowStats last_window_;

  // Motion model: the last good camera pose (T_cam_world), the motion per
  // frame (T_cam_world(k+1) = delta * T_cam_world(k)) and the frames since.
  Eigen::Isometry3d T_cam_world_last_ = Eigen::Isometry3d::Identity();
  // Time of the last good frame and of the frame being processed, s.
  double last_good_time_s_ = 0.0;
  double delta_period_s_ = 0.0;  // the time delta_ spans
  double frame_time_s_ = 0.0;
  Eigen::Isometry3d delta_ = Eigen::Isometry3d::Identity();
  AffineBrightness affine_last_;
  int frames_since_good_ = 1;
  int lost_count_ = 0;
  // The map was made after a loss and no frame has tracked it yet: if the
  // next frame cannot, it is made again there (the same loss, no new reset).
  bool unconfirmed_ = false;
  double typical_rms_ = 0.0;  // 0: none yet for this map
  // The last key-frame's pixel-selection cell size: the next selection starts there.
  double selection_cell_px_ = 0.0;
  int resets_ = 0;

  DirectVoTiming timing_;
  VignettingCorrection vignetting_;
  cv::Mat keyframe_image_;
  std::vector<DepthPixel> keyframe_points_;
};

}  // namespace nadir::vo
