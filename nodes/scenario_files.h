#pragma once
// Where the built-in scenarios are, and a scenario named or given by path. Kept
// apart from scenario.h so that a program finding a scenario's file (the
// viewer, for its terrain) needs none of the nodes.

#include <string>
#include <vector>

namespace nadir::nodes {

// The folder of the built-in scenarios: $NADIR_SCENARIO_DIR if set, else the
// project's scenarios/ folder.
std::string scenarioDirectory();
// Names of the built-in scenarios, sorted.
std::vector<std::string> builtinScenarioNames();
// A path to an existing file as given, else the built-in NAME; throws
// core::ParamError listing the built-in names if neither exists.
std::string resolveScenarioPath(const std::string& name_or_path);

}  // namespace nadir::nodes
