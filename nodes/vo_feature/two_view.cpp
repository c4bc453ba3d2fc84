#include "nodes/vo_feature/two_view.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <numbers>
#include <stdexcept>

namespace nadir::vo {

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
// Chi-square 95 % quantiles: 2 dof (a point to a point), 1 dof (a point to a line).
constexpr double kChi2TwoDof = 5.991;
constexpr double kChi2OneDof = 3.841;

Eigen::Matrix3d toEigen(const cv::Matx33d& m) {
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) e(r, c) = m(r, c);
  }
  return e;
}

Eigen::Matrix3d toEigen3x3(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) e(r, c) = d.at<double>(r, c);
  }
  return e;
}

Eigen::Vector3d toEigen3(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return {d.at<double>(0), d.at<double>(1), d.at<double>(2)};
}

Eigen::Vector3d homogeneous(const cv::Point2f& p) { return {p.x, p.y, 1.0}; }

std::string format(const char* fmt, double a, double b) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a, b);
  return buffer;
}

struct ModelScore {
  double score = 0.0;
  std::vector<char> inlier;  // per match
  int inliers = 0;
};

// ORB-SLAM's CheckHomography: the transfer error both ways, in pixels.
ModelScore scoreHomography(const Eigen::Matrix3d& H21, const std::vector<cv::Point2f>& px1,
                           const std::vector<cv::Point2f>& px2, double sigma_px) {
  ModelScore s;
  s.inlier.assign(px1.size(), 0);
  const Eigen::Matrix3d H12 = H21.inverse();
  const double inv_var = 1.0 / (sigma_px * sigma_px);
  for (std::size_t i = 0; i < px1.size(); ++i) {
    const Eigen::Vector3d p1 = homogeneous(px1[i]);
    const Eigen::Vector3d p2 = homogeneous(px2[i]);
    bool in = true;
    for (const auto& [from, to, H] : {std::tuple{&p1, &p2, &H21}, std::tuple{&p2, &p1, &H12}}) {
      const Eigen::Vector3d q = *H * *from;
      if (!(std::abs(q.z()) > 1e-12)) {
        in = false;
        continue;
      }
      const double chi2 = (q.hnormalized() - to->head<2>()).squaredNorm() * inv_var;
      if (!(chi2 <= kChi2TwoDof)) {
        in = false;
      } else {
        s.score += kChi2TwoDof - chi2;
      }
    }
    s.inlier[i] = in ? 1 : 0;
    s.inliers += in ? 1 : 0;
  }
  return s;
}

// ORB-SLAM's CheckFundamental: the distance to the epipolar line in both images, in
// pixels; a 1 dof test, scored with the 2 dof threshold so S_E compares with S_H.
ModelScore scoreFundamental(const Eigen::Matrix3d& F21, const std::vector<cv::Point2f>& px1,
                            const std::vector<cv::Point2f>& px2, double sigma_px) {
  ModelScore s;
  s.inlier.assign(px1.size(), 0);
  const double inv_var = 1.0 / (sigma_px * sigma_px);
  for (std::size_t i = 0; i < px1.size(); ++i) {
    const Eigen::Vector3d p1 = homogeneous(px1[i]);
    const Eigen::Vector3d p2 = homogeneous(px2[i]);
    bool in = true;
    for (const auto& [line, point] : {std::pair{Eigen::Vector3d(F21 * p1), &p2},
                                      std::pair{Eigen::Vector3d(F21.transpose() * p2), &p1}}) {
      const double norm2 = line.head<2>().squaredNorm();
      if (!(norm2 > 0.0)) {
        in = false;
        continue;
      }
      const double d = line.dot(*point);
      const double chi2 = d * d / norm2 * inv_var;
      if (!(chi2 <= kChi2OneDof)) {
        in = false;
      } else {
        s.score += kChi2TwoDof - chi2;
      }
    }
    s.inlier[i] = in ? 1 : 0;
    s.inliers += in ? 1 : 0;
  }
  return s;
}

struct Candidate {
  Eigen::Matrix3d R_21;
  Eigen::Vector3d t_21;  // unit
};

struct CandidateResult {
  int consistent = 0;
  std::vector<double> parallax_deg;  // of the consistent points
  std::vector<Eigen::Vector3d> points_1;
  std::vector<int> index;
};

CandidateResult evaluate(const Candidate& candidate, const std::vector<cv::Point2f>& px1,
                         const std::vector<cv::Point2f>& px2, const std::vector<char>& inlier,
                         const cv::Matx33d& K, const TwoViewParams& params) {
  const TriangulationChecks checks{.min_parallax_deg = params.min_point_parallax_deg,
                                   .max_reprojection_error_px = params.max_reprojection_error_px};
  CandidateResult result;
  for (std::size_t i = 0; i < px1.size(); ++i) {
    if (!inlier[i]) continue;
    const Triangulation tri =
        triangulate(px1[i], px2[i], candidate.R_21, candidate.t_21, K, checks);
    const bool in_front = tri.depth_1 > 0.0 && tri.depth_2 > 0.0;
    const bool low_parallax = tri.parallax_deg < params.min_point_parallax_deg;
    const bool consistent = tri.status != TriangulationStatus::kNotFinite &&
                            tri.reprojection_error_px <= params.max_reprojection_error_px &&
                            (in_front || low_parallax);
    if (!consistent) continue;
    ++result.consistent;
    result.parallax_deg.push_back(tri.parallax_deg);
    if (tri.status == TriangulationStatus::kOk) {
      result.points_1.push_back(tri.p_1);
      result.index.push_back(static_cast<int>(i));
    }
  }
  return result;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Sampson distances (normalised units) of the matches under E = [t]x R.
Eigen::VectorXd sampsonResiduals(const Candidate& c, const std::vector<Eigen::Vector3d>& x1,
                                 const std::vector<Eigen::Vector3d>& x2) {
  const Eigen::Matrix3d E = skew(c.t_21) * c.R_21;
  Eigen::VectorXd r(static_cast<Eigen::Index>(x1.size()));
  for (std::size_t i = 0; i < x1.size(); ++i) {
    const Eigen::Vector3d Ex1 = E * x1[i];
    const Eigen::Vector3d Etx2 = E.transpose() * x2[i];
    const double norm2 = Ex1.head<2>().squaredNorm() + Etx2.head<2>().squaredNorm();
    r(static_cast<Eigen::Index>(i)) = norm2 > 0.0 ? x2[i].dot(Ex1) / std::sqrt(norm2) : 0.0;
  }
  return r;
}

// The motion moved by d: rotation increment d[0..2] (rad, right-multiplied),
// translation moved by d[3..4] along the tangent basis and re-normalised.
Candidate perturbed(const Candidate& c, const Eigen::Matrix<double, 5, 1>& d,
                    const Eigen::Matrix<double, 3, 2>& tangent) {
  const Eigen::Vector3d w = d.head<3>();
  const double angle = w.norm();
  const Eigen::Matrix3d dR =
      angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).matrix() : Eigen::Matrix3d::Identity();
  return {c.R_21 * dR, (c.t_21 + tangent * d.tail<2>()).normalized()};
}

// Levenberg-Marquardt on the Sampson error over the 5 dof of a calibrated
// motion (rotation, direction of translation). The fitted H or the minimal
// 5-point E leave errors of a degree at a few degrees of parallax; this
// brings them to the noise level of all the points. Sampson holds for every
// point, on the plane or not, so it also removes the bias of relief in H.
Candidate refineMotion(const Candidate& start, const std::vector<Eigen::Vector3d>& x1,
                       const std::vector<Eigen::Vector3d>& x2) {
  Candidate current = start;
  Eigen::VectorXd r = sampsonResiduals(current, x1, x2);
  double cost = r.squaredNorm();
  double lambda = 1e-4;
  constexpr double kStep = 1e-6;
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Matrix<double, 3, 2> tangent;
    const Eigen::Vector3d any =
        std::abs(current.t_21.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    tangent.col(0) = current.t_21.cross(any).normalized();
    tangent.col(1) = current.t_21.cross(tangent.col(0));
    Eigen::MatrixXd J(r.size(), 5);
    for (int k = 0; k < 5; ++k) {
      Eigen::Matrix<double, 5, 1> d = Eigen::Matrix<double, 5, 1>::Zero();
      d(k) = kStep;
      const Eigen::VectorXd plus = sampsonResiduals(perturbed(current, d, tangent), x1, x2);
      d(k) = -kStep;
      const Eigen::VectorXd minus = sampsonResiduals(perturbed(current, d, tangent), x1, x2);
      J.col(k) = (plus - minus) / (2.0 * kStep);
    }
    const Eigen::Matrix<double, 5, 5> JtJ = J.transpose() * J;
    const Eigen::Matrix<double, 5, 1> Jtr = J.transpose() * r;
    bool improved = false;
    Eigen::Matrix<double, 5, 1> step = Eigen::Matrix<double, 5, 1>::Zero();
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::Matrix<double, 5, 5> A = JtJ;
      A.diagonal() += lambda * JtJ.diagonal();
      step = -A.ldlt().solve(Jtr);
      const Candidate next = perturbed(current, step, tangent);
      const Eigen::VectorXd next_r = sampsonResiduals(next, x1, x2);
      if (step.allFinite() && next_r.squaredNorm() < cost) {
        current = next;
        r = next_r;
        cost = next_r.squaredNorm();
        lambda = std::max(lambda * 0.1, 1e-9);
        improved = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved || step.norm() < 1e-10) break;
  }
  return current;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<long>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

void validate(const TwoViewParams& params) {
  TwoViewParams copy = params;
  core::validateParams([&copy](core::ParamVisitor& v) { copy.visit(v); }, "vo_feature two_view");
}

}  // namespace

void TwoViewParams::visit(core::ParamVisitor& v) {
  v.field("sigma_px", &sigma_px,
          {.doc = "standard deviation of a keypoint position, px (scales the chi-square tests)",
           .min = 0.05,
           .max = 20.0});
  v.field(
      "homography_ratio", &homography_ratio,
      {.doc = "choose the homography when S_H / (S_H + S_E) exceeds this", .min = 0.0, .max = 1.0});
  v.field("ransac_confidence", &ransac_confidence,
          {.doc = "RANSAC confidence of the H and E fits", .min = 0.5, .max = 0.999999});
  v.field("ransac_max_iterations", &ransac_max_iterations,
          {.doc = "RANSAC iteration limit of the H and E fits", .min = 10, .max = 100000});
  v.field("max_reprojection_error_px", &max_reprojection_error_px,
          {.doc = "a triangulated point reprojects this close in both images, px",
           .min = 0.1,
           .max = 50.0});
  v.field("min_parallax_deg", &min_parallax_deg,
          {.doc = "refuse when the median parallax of the reconstruction is below, deg",
           .min = 0.0,
           .max = 45.0});
  v.field("min_point_parallax_deg", &min_point_parallax_deg,
          {.doc = "points with less parallax are not triangulated, deg", .min = 0.0, .max = 45.0});
  v.field("min_triangulated", &min_triangulated,
          {.doc = "refuse with fewer triangulated points", .min = 5, .max = 100000});
  v.field("min_good_fraction", &min_good_fraction,
          {.doc = "share of the model's inliers the chosen motion must explain",
           .min = 0.0,
           .max = 1.0});
  v.field("refine_motion", &refine_motion,
          {.doc = "refine the chosen motion on the Sampson error of its triangulated points"});
  v.field("ambiguity_ratio", &ambiguity_ratio,
          {.doc = "refuse when the second best motion explains this share of the best's points",
           .min = 0.0,
           .max = 1.0});
}

Triangulation triangulate(const cv::Point2f& px1, const cv::Point2f& px2,
                          const Eigen::Matrix3d& R_21, const Eigen::Vector3d& t_21,
                          const cv::Matx33d& K, const TriangulationChecks& checks) {
  Triangulation tri;
  const Eigen::Matrix3d Ke = toEigen(K);
  const Eigen::Matrix3d K_inv = Ke.inverse();
  const Eigen::Vector2d x1 = (K_inv * homogeneous(px1)).hnormalized();
  const Eigen::Vector2d x2 = (K_inv * homogeneous(px2)).hnormalized();

  // DLT: each view gives two rows x * P.row(2) - P.row(0|1) of A X = 0.
  Eigen::Matrix<double, 3, 4> P1 = Eigen::Matrix<double, 3, 4>::Zero();
  P1.leftCols<3>().setIdentity();
  Eigen::Matrix<double, 3, 4> P2;
  P2.leftCols<3>() = R_21;
  P2.col(3) = t_21;
  Eigen::Matrix4d A;
  A.row(0) = x1.x() * P1.row(2) - P1.row(0);
  A.row(1) = x1.y() * P1.row(2) - P1.row(1);
  A.row(2) = x2.x() * P2.row(2) - P2.row(0);
  A.row(3) = x2.y() * P2.row(2) - P2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  if (!X.allFinite() || !(std::abs(X(3)) > 1e-12 * X.head<3>().norm())) return tri;
  tri.p_1 = X.head<3>() / X(3);
  if (!tri.p_1.allFinite()) return tri;

  const Eigen::Vector3d p_2 = R_21 * tri.p_1 + t_21;
  tri.depth_1 = tri.p_1.z();
  tri.depth_2 = p_2.z();
  const Eigen::Vector3d centre_2_in_1 = -R_21.transpose() * t_21;
  const Eigen::Vector3d ray_1 = tri.p_1;
  const Eigen::Vector3d ray_2 = tri.p_1 - centre_2_in_1;
  const double cos_parallax = ray_1.dot(ray_2) / (ray_1.norm() * ray_2.norm());
  tri.parallax_deg = std::acos(std::clamp(cos_parallax, -1.0, 1.0)) * kDegPerRad;
  const double e1 = ((Ke * tri.p_1).hnormalized() - homogeneous(px1).head<2>()).norm();
  const double e2 = ((Ke * p_2).hnormalized() - homogeneous(px2).head<2>()).norm();
  tri.reprojection_error_px = std::max(e1, e2);
  if (!std::isfinite(tri.parallax_deg) || !std::isfinite(tri.reprojection_error_px)) return tri;

  if (tri.parallax_deg < checks.min_parallax_deg) {
    tri.status = TriangulationStatus::kLowParallax;
  } else if (!(tri.depth_1 > 0.0 && tri.depth_2 > 0.0)) {
    tri.status = TriangulationStatus::kBehindCamera;
  } else if (tri.reprojection_error_px > checks.max_reprojection_error_px) {
    tri.status = TriangulationStatus::kReprojectionError;
  } else {
    tri.status = TriangulationStatus::kOk;
  }
  return tri;
}

TwoViewResult initialiseTwoView(const std::vector<cv::Point2f>& px1,
                                const std::vector<cv::Point2f>& px2, const cv::Matx33d& K,
                                const TwoViewParams& params) {
  validate(params);
  if (px1.size() != px2.size()) {
    throw std::invalid_argument("initialiseTwoView: px1 and px2 differ in size");
  }
  TwoViewResult result;
  const int n = static_cast<int>(px1.size());
  if (n < params.min_triangulated || n < 8) {
    result.why_not = "too few matches: " + std::to_string(n) + " < " +
                     std::to_string(std::max(params.min_triangulated, 8));
    return result;
  }

  // The fits run on normalised points (thresholds in focal lengths), the
  // scores in pixels.
  const Eigen::Matrix3d Ke = toEigen(K);
  const Eigen::Matrix3d K_inv = Ke.inverse();
  std::vector<cv::Point2d> n1(px1.size());
  std::vector<cv::Point2d> n2(px2.size());
  for (std::size_t i = 0; i < px1.size(); ++i) {
    const Eigen::Vector2d a = (K_inv * homogeneous(px1[i])).hnormalized();
    const Eigen::Vector2d b = (K_inv * homogeneous(px2[i])).hnormalized();
    n1[i] = {a.x(), a.y()};
    n2[i] = {b.x(), b.y()};
  }
  const double focal_px = 0.5 * (K(0, 0) + K(1, 1));
  const double h_threshold = std::sqrt(kChi2TwoDof) * params.sigma_px / focal_px;
  const double e_threshold = std::sqrt(kChi2OneDof) * params.sigma_px / focal_px;

  auto h_fit = std::async(std::launch::async, [&]() -> cv::Mat {
    try {
      return cv::findHomography(n1, n2, cv::RANSAC, h_threshold, cv::noArray(),
                                params.ransac_max_iterations, params.ransac_confidence);
    } catch (const cv::Exception&) {
      return {};
    }
  });
  cv::Mat E_cv;
  try {
    E_cv = cv::findEssentialMat(n1, n2, 1.0, cv::Point2d(0.0, 0.0), cv::RANSAC,
                                params.ransac_confidence, e_threshold, params.ransac_max_iterations,
                                cv::noArray());
  } catch (const cv::Exception&) {
    E_cv.release();
  }
  const cv::Mat H_cv = h_fit.get();

  ModelScore h_score;
  ModelScore e_score;
  Eigen::Matrix3d H_n = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d E_n = Eigen::Matrix3d::Zero();
  if (H_cv.rows == 3 && H_cv.cols == 3) {
    H_n = toEigen3x3(H_cv);
    h_score = scoreHomography(Ke * H_n * K_inv, px1, px2, params.sigma_px);
  }
  if (E_cv.rows >= 3 && E_cv.cols == 3) {
    E_n = toEigen3x3(E_cv.rowRange(0, 3));  // the 5-point solver may stack several
    e_score = scoreFundamental(K_inv.transpose() * E_n * K_inv, px1, px2, params.sigma_px);
  }
  if (h_score.score + e_score.score <= 0.0) {
    result.why_not = "neither a homography nor an essential matrix fits the matches";
    return result;
  }
  result.homography_score_ratio = h_score.score / (h_score.score + e_score.score);
  result.used_homography = result.homography_score_ratio > params.homography_ratio;
  const ModelScore& model = result.used_homography ? h_score : e_score;
  result.model_inliers = model.inliers;

  std::vector<Candidate> candidates;
  if (result.used_homography) {
    std::vector<cv::Mat> rotations;
    std::vector<cv::Mat> translations;
    std::vector<cv::Mat> normals;
    cv::decomposeHomographyMat(H_cv, cv::Mat::eye(3, 3, CV_64F), rotations, translations, normals);
    for (std::size_t k = 0; k < rotations.size(); ++k) {
      const Eigen::Vector3d t = toEigen3(translations[k]);
      // A rotation-only homography has no translation to normalise.
      if (t.norm() < 1e-9) continue;
      candidates.push_back({toEigen3x3(rotations[k]), t.normalized()});
    }
  } else {
    cv::Mat R1;
    cv::Mat R2;
    cv::Mat t;
    cv::decomposeEssentialMat(E_cv.rowRange(0, 3), R1, R2, t);
    const Eigen::Vector3d te = toEigen3(t).normalized();
    for (const cv::Mat& R : {R1, R2}) {
      candidates.push_back({toEigen3x3(R), te});
      candidates.push_back({toEigen3x3(R), -te});
    }
  }
  if (candidates.empty()) {
    result.why_not = "too little parallax: the homography is a pure rotation";
    return result;
  }

  std::vector<CandidateResult> evaluated;
  evaluated.reserve(candidates.size());
  for (const Candidate& candidate : candidates) {
    evaluated.push_back(evaluate(candidate, px1, px2, model.inlier, K, params));
  }
  // Ranked by triangulated points (see the top of two_view.h).
  auto triangulated = [&evaluated](std::size_t k) {
    return static_cast<int>(evaluated[k].points_1.size());
  };
  std::size_t best = 0;
  for (std::size_t k = 1; k < evaluated.size(); ++k) {
    if (triangulated(k) > triangulated(best) ||
        (triangulated(k) == triangulated(best) &&
         evaluated[k].consistent > evaluated[best].consistent)) {
      best = k;
    }
  }
  int second = 0;
  for (std::size_t k = 0; k < evaluated.size(); ++k) {
    if (k != best) second = std::max(second, triangulated(k));
  }
  const CandidateResult& chosen = evaluated[best];
  result.median_parallax_deg = median(chosen.parallax_deg);
  const std::string model_name = result.used_homography ? "homography" : "essential matrix";

  if (chosen.consistent == 0) {
    result.why_not = "no " + model_name + " motion candidate triangulates any inlier";
  } else if (result.median_parallax_deg < params.min_parallax_deg) {
    result.why_not = format("too little parallax: median %.3f deg < %.3f deg",
                            result.median_parallax_deg, params.min_parallax_deg);
  } else if (second >= params.ambiguity_ratio * triangulated(best)) {
    result.why_not = "ambiguous " + model_name +
                     " motion: the second best candidate triangulates " + std::to_string(second) +
                     " points, the best " + std::to_string(triangulated(best));
  } else if (chosen.consistent < params.min_good_fraction * model.inliers) {
    result.why_not = "the " + model_name + " motion explains only " +
                     std::to_string(chosen.consistent) + " of " + std::to_string(model.inliers) +
                     " inliers";
  } else if (static_cast<int>(chosen.points_1.size()) < params.min_triangulated) {
    result.why_not = "too few points triangulated: " + std::to_string(chosen.points_1.size()) +
                     " < " + std::to_string(params.min_triangulated);
  }
  if (!result.why_not.empty()) return result;

  Candidate motion = candidates[best];
  CandidateResult points = chosen;
  if (params.refine_motion) {
    std::vector<Eigen::Vector3d> x1;
    std::vector<Eigen::Vector3d> x2;
    for (int i : chosen.index) {
      x1.push_back(K_inv * homogeneous(px1[static_cast<std::size_t>(i)]));
      x2.push_back(K_inv * homogeneous(px2[static_cast<std::size_t>(i)]));
    }
    const Candidate refined = refineMotion(motion, x1, x2);
    CandidateResult refined_points = evaluate(refined, px1, px2, model.inlier, K, params);
    // The refinement only ever lowers the error; should it lose points it went astray.
    if (refined_points.points_1.size() >= chosen.points_1.size() * 9 / 10) {
      motion = refined;
      points = std::move(refined_points);
      result.median_parallax_deg = median(points.parallax_deg);
    }
  }
  result.ok = true;
  result.R_21 = motion.R_21;
  result.t_21 = motion.t_21;
  result.points_1 = std::move(points.points_1);
  result.inlier_match_index = std::move(points.index);
  return result;
}

}  // namespace nadir::vo
