#pragma once
// The --frame option of the verbs that write poses (export, eval, run): ned,
// nadir's axes, or enu, REP-103's (core/axes.h).
#include <CLI/CLI.hpp>

#include <map>
#include <string>

#include "core/axes.h"

namespace nadir::cli {

inline CLI::Option* addFrameOption(CLI::App* command, core::Axes& axes, const std::string& what) {
  const std::map<std::string, core::Axes> names = {{"ned", core::Axes::kNed},
                                                   {"enu", core::Axes::kEnu}};
  return command
      ->add_option("--frame", axes,
                   "axes of " + what +
                       ": ned (nadir's: world NED, body FRD; the default) or enu (REP-103's: "
                       "world ENU, body FLU, as ROS and evo take them)")
      ->transform(CLI::CheckedTransformer(names));
}

}  // namespace nadir::cli
