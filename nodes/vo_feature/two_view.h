#pragma once
// Two-view initialisation of the monocular map, as ORB-SLAM2 does it (Kim 2019;
// Mur-Artal et al. 2015, section IV): homography and essential matrix fitted in
// parallel and scored, the motion chosen among their decompositions by the
// points it triangulates, refused when ambiguous or with too little parallax.
// docs/vo_feature.md ("Two-view initialisation") has the tests and thresholds.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "core/params.h"

namespace nadir::vo {

struct TwoViewParams {
  // Standard deviation of a keypoint's position, px: scales the chi-square tests.
  // About twice the real noise so a plane picks the homography (docs/vo_feature.md).
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
