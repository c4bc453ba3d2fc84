#pragma once
// A top view of the truth and every pose source's track, as a PNG: north up,
// east right, equal scale, a scale bar and a legend.

#include <map>
#include <string>

#include "logs/eval/trajectory.h"

namespace nadir::run {

// Throws std::runtime_error naming the path if it cannot be written.
void writeTrackPlot(const std::string& png_path, const core::Trajectory& truth,
                    const std::map<std::string, core::Trajectory>& sources,
                    const std::string& title);

}  // namespace nadir::run
