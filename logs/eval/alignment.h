#pragma once
// Trajectory alignment by Umeyama's least-squares method (IEEE PAMI 1991), as
// evo's geometry.umeyama_alignment: find R, t (and scale s for Sim(3)) that
// minimise sum |ref_i - (s R est_i + t)|^2 over associated positions.

#include <Eigen/Core>

#include <string>
#include <vector>

#include "logs/eval/trajectory.h"

namespace nadir::eval {

enum class AlignMode { kNone, kSe3, kSim3 };

// "none", "se3", "sim3" <-> AlignMode; parseAlignMode throws EvalError on anything else.
AlignMode parseAlignMode(const std::string& name);
std::string alignModeName(AlignMode mode);

// p_ref ~= scale * R * p_est + t. Identity (scale 1) for AlignMode::kNone.
struct Alignment {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double scale = 1.0;
};

// Umeyama's solution mapping est onto ref (same size, >= 1 point; est_i pairs
// with ref_i). Throws EvalError if the points are degenerate (all on one point,
// or a covariance of rank below 2, as evo refuses) or the sizes differ.
Alignment umeyamaAlignment(const std::vector<Eigen::Vector3d>& est,
                           const std::vector<Eigen::Vector3d>& ref, bool with_scale);

// The alignment of est onto ref (associated pose by pose) for a mode.
Alignment alignTrajectories(const core::Trajectory& ref, const core::Trajectory& est,
                            AlignMode mode);

// Moves every pose of trajectory: p <- scale R p + t, R_world_body <- R R_world_body
// (the scale acts on positions only, as evo's PosePath3D.align).
void applyAlignment(const Alignment& alignment, core::Trajectory& trajectory);

}  // namespace nadir::eval
