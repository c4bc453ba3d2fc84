#include "run/launch_hosts.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "core/params.h"
#include "run/process.h"
#include "run/yaml_file.h"

namespace nadir::run {

namespace fs = std::filesystem;

bool LaunchHost::viaSsh() const {
  return !prefix.empty() && fs::path(prefix.front()).filename() == "ssh";
}

std::string LaunchHost::describe() const {
  if (prefix.empty()) return name + " (this machine)";
  std::string words;
  for (const std::string& word : prefix) words += (words.empty() ? "" : " ") + word;
  return name + " (" + words + ")";
}

const LaunchHost& LaunchHosts::host(const std::string& name) const {
  for (const LaunchHost& candidate : hosts) {
    if (candidate.name == name) return candidate;
  }
  throw std::invalid_argument("no host named '" + name + "'");
}

const LaunchHost& LaunchHosts::hostOf(const std::string& node) const {
  const auto placed = placement.find(node);
  return host(placed == placement.end() ? default_host : placed->second);
}

std::vector<std::string> LaunchHosts::command(const LaunchHost& on, std::vector<std::string> argv,
                                              const std::string& local_bin_dir) const {
  if (!argv.empty() && !on.bin_dir.empty() &&
      fs::path(argv.front()).parent_path() == fs::path(local_bin_dir)) {
    argv.front() = (fs::path(on.bin_dir) / fs::path(argv.front()).filename()).string();
  }
  if (on.prefix.empty()) return argv;
  std::vector<std::string> command = on.prefix;
  if (on.viaSsh()) {
    command.push_back("exec " + shellLine(argv));
  } else {
    command.insert(command.end(), argv.begin(), argv.end());
  }
  return command;
}

LaunchHosts localHosts() {
  LaunchHosts local;
  local.hosts.push_back({"local", {}, {}});
  local.default_host = "local";
  return local;
}

LaunchHosts loadLaunchHosts(const std::string& path, const std::vector<std::string>& node_names) {
  const YAML::Node root = loadYamlFile(path, "hosts file");
  if (!root.IsMap()) throw core::ParamError(path + ": expected a map (hosts, nodes, default_host)");
  LaunchHosts parsed;
  std::optional<YAML::Node> nodes, default_host;
  for (const auto& entry : root) {
    const std::string key = keyText(path, entry.first, "hosts file");
    const YAML::Node& value = entry.second;
    if (key == "hosts") {
      if (!value.IsMap() || value.size() == 0) {
        failAt(path, value, key, "expected a map of host name: {prefix, bin_dir}");
      }
      for (const auto& host_entry : value) {
        LaunchHost host;
        host.name = keyText(path, host_entry.first, "hosts");
        const std::string where = "hosts." + host.name;
        const YAML::Node& fields = host_entry.second;
        if (!fields.IsMap()) failAt(path, fields, where, "expected a map (prefix, bin_dir)");
        for (const auto& field : fields) {
          const std::string name = keyText(path, field.first, where);
          try {
            if (name == "prefix") {
              if (field.second.IsSequence()) {
                host.prefix = field.second.as<std::vector<std::string>>();
              } else {
                host.prefix = splitWords(field.second.IsNull() ? "" : field.second.Scalar());
              }
            } else if (name == "bin_dir") {
              host.bin_dir = field.second.as<std::string>();
            } else {
              failAt(path, field.first, where + "." + name, "unknown key (known: prefix, bin_dir)");
            }
          } catch (const YAML::BadConversion&) {
            failAt(path, field.second, where + "." + name, "has the wrong type");
          } catch (const std::invalid_argument& error) {
            failAt(path, field.second, where + "." + name, error.what());
          }
        }
        for (const LaunchHost& other : parsed.hosts) {
          if (other.name == host.name) failAt(path, host_entry.first, where, "named twice");
        }
        // "launch" is the launch itself in the bus check, which lists hosts with commas.
        const bool plain =
            !host.name.empty() && std::all_of(host.name.begin(), host.name.end(), [](char c) {
              return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_' ||
                     c == '.';
            });
        if (!plain || host.name == "launch") {
          failAt(path, host_entry.first, where,
                 "a host's name is letters, digits, '-', '_' and '.', and not 'launch'");
        }
        parsed.hosts.push_back(std::move(host));
      }
    } else if (key == "nodes") {
      nodes.emplace(value);
    } else if (key == "default_host") {
      default_host.emplace(value);
    } else {
      failAt(path, entry.first, key, "unknown key (known: hosts, nodes, default_host)");
    }
  }
  if (parsed.hosts.empty()) throw core::ParamError(path + ": hosts: missing (no host to run on)");
  const auto knownHost = [&](const YAML::Node& node, const std::string& key) {
    const std::string name = node.IsScalar() ? node.Scalar() : "";
    for (const LaunchHost& host : parsed.hosts) {
      if (host.name == name) return name;
    }
    std::string names;
    for (const LaunchHost& host : parsed.hosts) names += (names.empty() ? "" : ", ") + host.name;
    failAt(path, node, key, "no host named '" + name + "' (hosts: " + names + ")");
  };
  parsed.default_host =
      default_host ? knownHost(*default_host, "default_host") : parsed.hosts.front().name;
  if (nodes) {
    if (!nodes->IsMap()) failAt(path, *nodes, "nodes", "expected a map of node: host");
    std::vector<std::string> known = node_names;
    known.push_back(kLoggerNode);
    for (const auto& placed : *nodes) {
      const std::string node = keyText(path, placed.first, "nodes");
      if (std::find(known.begin(), known.end(), node) == known.end()) {
        std::string names;
        for (const std::string& name : known) names += (names.empty() ? "" : ", ") + name;
        failAt(path, placed.first, "nodes." + node, "no such node (nodes: " + names + ")");
      }
      parsed.placement[node] = knownHost(placed.second, "nodes." + node);
    }
  }
  return parsed;
}

}  // namespace nadir::run
