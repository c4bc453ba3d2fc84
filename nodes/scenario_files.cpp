#include "nodes/scenario_files.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "core/params.h"

namespace nadir::nodes {
namespace {

namespace fs = std::filesystem;

}  // namespace

std::string scenarioDirectory() {
  if (const char* dir = std::getenv("NADIR_SCENARIO_DIR"); dir != nullptr && *dir != '\0') {
    return dir;
  }
  return NADIR_SOURCE_SCENARIO_DIR;
}

std::vector<std::string> builtinScenarioNames() {
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(scenarioDirectory(), error)) {
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string resolveScenarioPath(const std::string& name_or_path) {
  if (fs::is_regular_file(name_or_path)) return name_or_path;
  const fs::path builtin = fs::path(scenarioDirectory()) / (name_or_path + ".yaml");
  if (name_or_path.find('/') == std::string::npos && fs::is_regular_file(builtin)) {
    return builtin.string();
  }
  std::string names;
  for (const std::string& name : builtinScenarioNames()) {
    names += (names.empty() ? "" : ", ") + name;
  }
  throw core::ParamError("scenario '" + name_or_path +
                         "': no such file and no built-in scenario of that name (built in: " +
                         (names.empty() ? "none found in " + scenarioDirectory() : names) + ")");
}

}  // namespace nadir::nodes
