#pragma once
// The calibration report, as text: what nadir calib prints and the
// nadir-calib window shows. OpenCV-free plain text so that a log of a run
// carries it too.

#include <string>
#include <vector>

#include "calib/board.h"
#include "calib/calibrate.h"
#include "calib/coverage.h"
#include "calib/session.h"
#include "render/camera_model.h"

namespace nadir::calib {

// Names of a model's distortion coefficients, in Calibration::distortion's
// order: radtan k1 k2 p1 p2 k3, fisheye k1 k2 k3 k4.
std::vector<std::string> distortionNames(LensModel model);

// A bar of width cells for a progress in 0..1: "[######----]".
std::string progressBar(double progress, int width = 20);

// The four coverage bars (ROS's X, Y, size, skew) and the view counts.
std::string formatCoverage(const Coverage& coverage, const OfferTally& tally);

// The intrinsics with their standard deviations, the RMS, the outliers, the
// held-out error and what it says, each view's RMS and the worst corners.
// views are the ones given to calibrate (for their names).
std::string formatReport(const Calibration& calibration, const BoardSpec& board,
                         const std::vector<View>& views);

// The calibration against the lens the images were made with (the virtual
// camera's): each intrinsic's error in its unit and in standard deviations.
// The fisheye model's coefficients are not the lens's: only fx fy cx cy are
// compared then.
std::string formatComparison(const Calibration& calibration,
                             const render::CameraIntrinsics& true_lens);

}  // namespace nadir::calib
