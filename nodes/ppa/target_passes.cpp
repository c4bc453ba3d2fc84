#include "nodes/ppa/target_passes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace nadir::ppa {
namespace {

// Horizontal error of the TRACKING estimate nearest t_s (within 0.1 s).
std::optional<double> errorAt(const TargetPassInput& input, double t_s) {
  const logs::SourceEstimate* best = nullptr;
  for (const logs::SourceEstimate& estimate : input.estimates) {
    if (estimate.status != logs::SourceEstimate::kTracking) continue;
    if (best == nullptr || std::abs(estimate.t_s - t_s) < std::abs(best->t_s - t_s)) {
      best = &estimate;
    }
  }
  if (best == nullptr || std::abs(best->t_s - t_s) > 0.1) return std::nullopt;
  const auto truth = core::interpolate(input.truth, best->t_s);
  if (!truth) return std::nullopt;
  return (best->p_ned_m - truth->p_ned_m).head<2>().norm();
}

// Horizontal error of the last TRACKING estimate before t_s (the state before a
// correction at t_s), if it is within 0.1 s.
std::optional<double> errorBefore(const TargetPassInput& input, double t_s) {
  const logs::SourceEstimate* best = nullptr;
  for (const logs::SourceEstimate& estimate : input.estimates) {
    if (estimate.status == logs::SourceEstimate::kTracking && estimate.t_s < t_s) best = &estimate;
  }
  if (best == nullptr || t_s - best->t_s > 0.1) return std::nullopt;
  const auto truth = core::interpolate(input.truth, best->t_s);
  if (!truth) return std::nullopt;
  return (best->p_ned_m - truth->p_ned_m).head<2>().norm();
}

}  // namespace

std::vector<TargetPass> targetPasses(const TargetPassInput& input) {
  std::vector<TargetPass> passes;
  const double tan_half = std::tan(0.5 * input.hfov_rad);
  for (std::size_t k = 0; k < input.targets_ne_m.size(); ++k) {
    std::optional<TargetPass> open;
    for (std::size_t i = 0; i < input.truth.size(); ++i) {
      const double reach_m = input.view_fraction * input.truth_height_m[i] * tan_half;
      const bool in_view =
          (input.truth[i].p_ned_m.head<2>() - input.targets_ne_m[k]).norm() < reach_m;
      const double t = input.truth[i].t_s;
      if (in_view && !open) open = TargetPass{static_cast<int>(k), t, t, 0, 0, {}, {}};
      if (in_view) open->end_s = t;
      if ((!in_view || i + 1 == input.truth.size()) && open) {
        passes.push_back(*open);
        open.reset();
      }
    }
  }
  for (TargetPass& pass : passes) {
    // The first detection as the target came into view (it may come before the
    // pass proper begins): the error just before it is the error before correction.
    std::optional<double> first_found_s;
    for (const auto& [t, found] : input.detector_frames) {
      if (found && t >= pass.start_s - 2.0 && t <= pass.end_s && !first_found_s) first_found_s = t;
      if (t < pass.start_s || t > pass.end_s) continue;
      ++pass.frames;
      pass.detections += found ? 1 : 0;
    }
    pass.error_before_m = errorBefore(input, first_found_s.value_or(pass.start_s));
    pass.error_after_m = errorAt(input, pass.end_s);
  }
  std::sort(passes.begin(), passes.end(),
            [](const TargetPass& a, const TargetPass& b) { return a.start_s < b.start_s; });
  return passes;
}

std::string formatTargetPasses(const std::vector<TargetPass>& passes) {
  std::string text =
      "target passes (target well inside the view):\n"
      "  target  from s    to s  frames  found  error before m  error after m\n";
  char line[160];
  for (const TargetPass& pass : passes) {
    std::snprintf(
        line, sizeof(line), "  %6d %7.2f %7.2f %7d %6d %15s %14s\n", pass.target, pass.start_s,
        pass.end_s, pass.frames, pass.detections,
        pass.error_before_m ? std::to_string(*pass.error_before_m).substr(0, 6).c_str() : "-",
        pass.error_after_m ? std::to_string(*pass.error_after_m).substr(0, 6).c_str() : "-");
    text += line;
  }
  if (passes.empty()) text += "  (no pass over a known target)\n";
  return text;
}

std::string targetPassesCsv(const std::vector<TargetPass>& passes) {
  std::string csv = "target,start_s,end_s,frames,detections,error_before_m,error_after_m\n";
  char line[200];
  for (const TargetPass& pass : passes) {
    std::snprintf(line, sizeof(line), "%d,%.6f,%.6f,%d,%d,%s,%s\n", pass.target, pass.start_s,
                  pass.end_s, pass.frames, pass.detections,
                  pass.error_before_m ? std::to_string(*pass.error_before_m).c_str() : "",
                  pass.error_after_m ? std::to_string(*pass.error_after_m).c_str() : "");
    csv += line;
  }
  return csv;
}

}  // namespace nadir::ppa
