#pragma once
// Reading the YAML files of run/ (sweep files, hosts files): errors name the
// file, the line and the key.

#include <string>

#include <yaml-cpp/yaml.h>

namespace nadir::run {

// The file's root; throws core::ParamError ("PATH: cannot open WHAT",
// "PATH:LINE: not valid YAML: ...").
YAML::Node loadYamlFile(const std::string& path, const std::string& what);

// A map key as text; throws core::ParamError naming where and within when the
// key is a list or a map (YAML's "? [a, b]").
std::string keyText(const std::string& path, const YAML::Node& key, const std::string& within);

// Throws core::ParamError "PATH:LINE: KEY: PROBLEM".
[[noreturn]] void failAt(const std::string& path, const YAML::Node& node, const std::string& key,
                         const std::string& problem);

}  // namespace nadir::run
