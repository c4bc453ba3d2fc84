#pragma once
// ORB features for the feature-based monocular VO (Kim 2019, ORB-SLAM2), and
// the descriptor matching the tracker and the initialiser use.
//
// Extraction follows ORB-SLAM's ORBextractor: a scale pyramid (each level
// resized bilinearly from the one before) whose levels get a geometrically
// decreasing share of the wanted features; each level is cut into a grid of
// cells, and every cell keeps its strongest FAST-9 corners up to its share:
// the corners FAST finds at fast_threshold, or at min_fast_threshold where a
// cell has fewer than its share (weakly textured ground still gets features).
// What the poor cells leave unused goes to the strongest remaining corners of
// the level (those at fast_threshold, and the poor cells' at
// min_fast_threshold). FAST is nadir's own SIMD version with the same corners,
// scores (response) and non-maximum suppression as cv::FAST on the whole level;
// each cell lowers its threshold step by step from well above fast_threshold
// and stops once it has its share, so most pixels are never scored.
// Orientations are the intensity centroid angles. Descriptors are ORB's kind:
// 256 tests comparing two pixels of the level blurred with a 7 x 7, sigma 2
// Gaussian, at the points of a fixed pattern (learned as ORB's rBRIEF, see
// features.cpp) turned by the keypoint angle.
// Keypoints are in level-0 pixels, octave = pyramid level, size = the 31 px
// patch at that level, response = FAST score.

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <vector>

#include "core/params.h"

namespace nadir::vo {

struct FeatureParams {
  // Features wanted over all pyramid levels.
  int num_features = 2000;
  // Grid of cells each level is cut into, so features spread over the image.
  int grid_cols = 8;
  int grid_rows = 6;
  // Scale between pyramid levels, and the number of levels.
  float scale_factor = 1.2f;
  int num_levels = 8;
  // FAST threshold, grey levels; the fallback for cells with too few corners.
  int fast_threshold = 20;
  int min_fast_threshold = 7;

  void visit(core::ParamVisitor& v);
};

struct Features {
  std::vector<cv::KeyPoint> keypoints;  // level-0 pixels; octave = level; angle in deg
  cv::Mat descriptors;                  // one 32-byte descriptor (CV_8U row) per keypoint
};

// ORB features of an 8-bit grey image, spread over the grid on every pyramid
// level (see the top of this file). Deterministic: the same image gives the
// same features. Throws std::invalid_argument on a non-CV_8UC1 image or bad
// params.
Features extractOrb(const cv::Mat& gray, const FeatureParams& params);

// Hamming distance between two 32-byte ORB descriptors (rows of Features::descriptors).
int hammingDistance(const cv::Mat& descriptors_a, int row_a, const cv::Mat& descriptors_b,
                    int row_b);

// Matches each feature i of a to the feature of b closest in descriptor within
// radius_px of predicted_in_b[i] (one prediction per feature of a). A match is
// kept when its distance is at most max_hamming, it beats the second best
// candidate by the ratio (best < ratio * second; ratio >= 1 disables the test)
// and it is mutual: a is also the best of the features of a whose prediction
// falls within radius of b. DMatch: queryIdx in a, trainIdx in b, distance =
// Hamming distance. Sorted by queryIdx.
std::vector<cv::DMatch> matchByWindow(const Features& a, const Features& b,
                                      const std::vector<cv::Point2f>& predicted_in_b,
                                      float radius_px, int max_hamming, float ratio);

// The same without a prediction: every feature of b is a candidate.
std::vector<cv::DMatch> matchBruteForce(const Features& a, const Features& b, int max_hamming,
                                        float ratio);

// ORB-SLAM's rotation consistency check: the change of keypoint angle from a to
// b over all matches goes into a histogram of `bins` bins; matches outside the
// three fullest bins are dropped (the second and third only count when they
// hold at least a tenth of the fullest). A camera rotating about its optical
// axis rotates every feature alike; a wrong match rotates at random.
std::vector<cv::DMatch> filterByOrientation(const Features& a, const Features& b,
                                            const std::vector<cv::DMatch>& matches, int bins = 30);

}  // namespace nadir::vo
