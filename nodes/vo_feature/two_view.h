#pragma once
// Two-view initialisation of the monocular map, as ORB-SLAM2 does it (seed 002,
// ORB-SLAM; Mur-Artal et al. 2015, section IV).
//
// A downward camera at altitude sees nearly planar ground: the essential matrix
// alone is badly conditioned there (a plane is a critical surface for the
// 5/8-point solvers, and many motions explain the matches almost equally), so
// both models are fitted in parallel on the matched normalised points:
//   H: cv::findHomography (RANSAC)       E: cv::findEssentialMat (RANSAC)
// and each is scored over all matches by the symmetric transfer error in
// pixels against a chi-square model (sigma = sigma_px):
//   S_M = sum over both images of (T_M - d^2 / sigma^2) where d^2 / sigma^2 < T_M,
//   T_H = 5.991 (2 dof, 95 %), T_E = 3.841 (1 dof, 95 %; scored with 5.991 like H).
// The homography wins when R_H = S_H / (S_H + S_E) > homography_ratio (0.45,
// the value of the ORB-SLAM paper; its code uses 0.40): a plane or a low
// parallax scene, where H explains as much as E with fewer parameters.
// The ratio of a plane depends on the keypoint noise: the transfer error
// carries the noise of both images in 2 dof against the epipolar distance's 1,
// so a plane scores R_H ~ 0.5 when the noise is well below sigma_px, and only
// ~0.41 when it equals sigma_px (then E wins on a plane, where E is ambiguous
// and the checks below mostly refuse it). Keep sigma_px at about twice the
// keypoints' noise (ORB-SLAM: sigma 1 px with level-0 keypoints).
//
// The motion candidates are the decompositions (H: cv::decomposeHomographyMat,
// 4; E: cv::decomposeEssentialMat, 4). Each candidate triangulates every inlier
// of its model. A point is consistent with the candidate when it reprojects
// within max_reprojection_error_px in both images and lies in front of both
// cameras (the side is not asked of points with less parallax than
// min_point_parallax_deg: their depth sign is noise); it is triangulated when
// it is consistent, in front and has at least min_point_parallax_deg. The
// candidate with the most triangulated points wins (a wrong one puts points
// behind a camera, or, the wrong solution of a plane, moves towards a "wall"
// and leaves no parallax near its focus of expansion), unless
//   - the median parallax of its consistent points is below min_parallax_deg
//     (pure rotation, a tiny baseline: depth is unknowable),
//   - the second best triangulates at least ambiguity_ratio times as many (the
//     twofold ambiguity of a plane, a degenerate configuration),
//   - its consistent points are fewer than min_good_fraction of the model's
//     inliers, or
//   - it triangulates fewer than min_triangulated points.
// The winner is refined on the Sampson error of its triangulated points
// (refine_motion: the fitted H or the minimal-sample E leave about a degree of
// error at a few degrees of parallax) and triangulates again.
// Refused initialisations say why; the tracker then waits for more motion.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "core/params.h"

namespace nadir::vo {

struct TwoViewParams {
  // Standard deviation of a keypoint's position, px: scales the chi-square tests.
  // About twice the real noise (see above) so a plane picks the homography.
  double sigma_px = 1.0;
  // Choose the homography when S_H / (S_H + S_E) exceeds this.
  double homography_ratio = 0.45;
  // RANSAC confidence and iteration limit of both fits.
  double ransac_confidence = 0.999;
  int ransac_max_iterations = 2000;
  // A triangulated point must reproject this close in both images, px.
  double max_reprojection_error_px = 2.0;
  // Median parallax of the reconstruction below this: too little motion, refused.
  double min_parallax_deg = 1.0;
  // A point with less parallax than this is not triangulated (its depth is noise).
  double min_point_parallax_deg = 0.5;
  // Refuse with fewer triangulated points than this.
  int min_triangulated = 50;
  // The chosen motion must explain at least this share of the model's inliers.
  double min_good_fraction = 0.9;
  // Refuse when the second best candidate explains this share of the best's points.
  double ambiguity_ratio = 0.75;
  // Refine the chosen motion (Levenberg-Marquardt on the Sampson error of its
  // triangulated points) and triangulate again.
  bool refine_motion = true;

  void visit(core::ParamVisitor& v);
};

struct TwoViewResult {
  bool ok = false;
  std::string why_not;  // empty when ok
  bool used_homography = false;
  // Motion of camera 2 relative to camera 1: x2 = R_21 x1 + t_21 (OpenCV optical frames).
  Eigen::Matrix3d R_21 = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_21 = Eigen::Vector3d::Zero();  // unit norm: camera 1 -> camera 2
  // Triangulated points in camera 1's frame, in the scale of t_21 (|t_21| = 1),
  // and the index of each one's match in px1/px2.
  std::vector<Eigen::Vector3d> points_1;
  std::vector<int> inlier_match_index;
  // Median parallax of the points consistent with the chosen motion, deg.
  double median_parallax_deg = 0.0;
  // Diagnostics: R_H = S_H / (S_H + S_E), and the inliers of the chosen model.
  double homography_score_ratio = 0.0;
  int model_inliers = 0;
};

// Initialises from matched pixels px1[i] <-> px2[i] (undistorted, same camera K).
TwoViewResult initialiseTwoView(const std::vector<cv::Point2f>& px1,
                                const std::vector<cv::Point2f>& px2, const cv::Matx33d& K,
                                const TwoViewParams& params);

struct TriangulationChecks {
  double min_parallax_deg = 0.5;
  double max_reprojection_error_px = 2.0;
};

enum class TriangulationStatus {
  kOk,
  kNotFinite,          // rays parallel, or the point at infinity
  kLowParallax,        // less than min_parallax_deg between the rays
  kBehindCamera,       // behind camera 1 or camera 2
  kReprojectionError,  // farther than max_reprojection_error_px in either image
};

struct Triangulation {
  TriangulationStatus status = TriangulationStatus::kNotFinite;
  Eigen::Vector3d p_1 = Eigen::Vector3d::Zero();  // in camera 1's frame, t_21's unit
  double depth_1 = 0.0;                           // z in camera 1
  double depth_2 = 0.0;                           // z in camera 2
  double parallax_deg = 0.0;                      // angle between the two rays at the point
  double reprojection_error_px = 0.0;             // the larger of the two images
};

// Linear (DLT) triangulation of one match seen by camera 1 at the origin and
// camera 2 with x2 = R_21 x1 + t_21, then the checks, in the order of
// TriangulationStatus. The values are filled in whenever the point is finite,
// so a caller may apply its own rules.
Triangulation triangulate(const cv::Point2f& px1, const cv::Point2f& px2,
                          const Eigen::Matrix3d& R_21, const Eigen::Vector3d& t_21,
                          const cv::Matx33d& K, const TriangulationChecks& checks);

}  // namespace nadir::vo
