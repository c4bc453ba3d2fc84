#include "run/yaml_file.h"

#include "core/params.h"

namespace nadir::run {

YAML::Node loadYamlFile(const std::string& path, const std::string& what) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw core::ParamError(path + ": cannot open " + what);
  } catch (const YAML::ParserException& e) {
    throw core::ParamError(path + ":" + std::to_string(e.mark.line + 1) +
                           ": not valid YAML: " + e.msg);
  }
}

void failAt(const std::string& path, const YAML::Node& node, const std::string& key,
            const std::string& problem) {
  const std::string where =
      node.Mark().is_null() ? path : path + ":" + std::to_string(node.Mark().line + 1);
  throw core::ParamError(where + ": " + key + ": " + problem);
}

std::string keyText(const std::string& path, const YAML::Node& key, const std::string& within) {
  if (!key.IsScalar()) failAt(path, key, within, "a key must be a name, not a list or a map");
  return key.Scalar();
}

}  // namespace nadir::run
