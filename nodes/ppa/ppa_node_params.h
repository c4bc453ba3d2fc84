#pragma once
// Everything nadir-ppa reads from its parameters (a scenario's `ppa` group).

#include <string>

#include "core/params.h"
#include "nodes/ppa/gate_tracker.h"
#include "nodes/ppa/ppa_array.h"
#include "nodes/ppa/ppa_host.h"
#include "nodes/ppa/target_extraction.h"
#include "nodes/ppa/visual_odometry.h"

namespace nadir::ppa {

struct PpaNodeParams {
  // In a scenario: run the PPA (nadir run composes it, nadir launch starts nadir-ppa).
  bool enabled = false;
  // "odometry": visual odometry and target extraction (McConville et al. 2020);
  // "gates": gate and slalom pattern tracking (Liu et al. 2021) on PPA_PATTERN.
  std::string mode = "odometry";
  std::string image_channel = "CAMERA_PPA";
  std::string info_channel = "CAMERA_PPA_INFO";
  std::string range_channel = "RANGE";
  // The flight controller's attitude (McConville et al. 2020 used the vehicle's IMU attitude).
  std::string attitude_channel = "NAV_ATTITUDE";
  // Read once: the start pose the estimate is anchored to.
  std::string truth_channel = "POSE_TRUTH";
  std::string pose_channel = "POSE_PPA";
  std::string odometry_channel = "PPA_ODOMETRY";
  std::string target_channel = "PPA_TARGET";
  // gate_pattern_t out (mode gates).
  std::string pattern_channel = "PPA_PATTERN";
  // vo_command_t in: resets addressed to ppa or to every VO node.
  std::string command_channel = "VO_COMMAND";
  bool target_extraction = true;
  // The emulated chip's instruction rate, Hz: processing_time_s = instructions / rate.
  double chip_instruction_rate_hz = 10e6;
  PpaParams array;
  VisualOdometryParams vo;
  TargetExtractionParams target;
  GateTrackerParams gate;
  PpaHostParams host;

  void visit(core::ParamVisitor& v);
};

// What the nadir-ppa process reads: its scenario group's fields at the top level,
// and the known targets (which a scenario gives by its concentric targets).
struct PpaProcessParams {
  PpaNodeParams node;
  // [north_m, east_m] of each known concentric target, world frame.
  core::NumberRows known_targets_ne_m;

  void visit(core::ParamVisitor& v);
};

}  // namespace nadir::ppa
