#pragma once
// Passes over the known ground targets and what a pose source made of them:
// McConville et al.'s (2020) test of target correction (section 3.2). A pass is a stretch of
// the truth during which a target lies well inside the camera's view; for
// each, whether the detector reported the target, and the source's position
// error as the pass began and as it ended.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/trajectory.h"
#include "logs/run_log.h"

namespace nadir::ppa {

struct TargetPass {
  int target = 0;  // index into the targets given
  double start_s = 0.0, end_s = 0.0;
  int frames = 0;      // detector frames during the pass
  int detections = 0;  // of them, with the target found
  // Horizontal errors, m: just before the first detection of the pass (before
  // any correction), and as the target leaves the view.
  std::optional<double> error_before_m, error_after_m;
};

struct TargetPassInput {
  core::Trajectory truth;
  // Height of the body above the ground at each truth pose, m.
  std::vector<double> truth_height_m;
  std::vector<logs::SourceEstimate> estimates;
  // Time of every detector frame, and whether it found a target.
  std::vector<std::pair<double, bool>> detector_frames;
  std::vector<Eigen::Vector2d> targets_ne_m;
  // In view: within this fraction of the half footprint h tan(hfov / 2).
  double hfov_rad = 0.0;
  double view_fraction = 0.6;
};

std::vector<TargetPass> targetPasses(const TargetPassInput& input);
std::string formatTargetPasses(const std::vector<TargetPass>& passes);
std::string targetPassesCsv(const std::vector<TargetPass>& passes);

}  // namespace nadir::ppa
