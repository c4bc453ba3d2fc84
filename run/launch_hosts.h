#pragma once
// Where `nadir launch --hosts FILE` runs each node: named hosts, each reached
// through a command prefix (`ssh -tt user@host`, `ip netns exec NAME`, or
// nothing for this machine), and each node placed on one (docs/running.md).
//
//   hosts:
//     ground: {prefix: ""}                       # this machine
//     air: {prefix: ssh -tt pi@10.0.0.2, bin_dir: /opt/nadir/bin}
//   nodes: {vo_feature: air, logger: ground}     # registry names, and logger
//   default_host: ground                         # the nodes not named (default: the first host)

#include <map>
#include <string>
#include <vector>

namespace nadir::run {

// The logger's (`nadir log record`) place in a hosts file (it is no node of the
// registry).
inline constexpr char kLoggerNode[] = "logger";

struct LaunchHost {
  std::string name;
  // Words put before a command to run it there; empty: this machine.
  std::vector<std::string> prefix;
  // The folder of the nadir programs on that host; empty: the same as here.
  std::string bin_dir;

  // A prefix that starts with ssh takes the command as one line for the
  // remote shell (quoted); any other is followed by the command's words.
  bool viaSsh() const;
  // "ground (this machine)" or "air (ssh -tt pi@10.0.0.2)".
  std::string describe() const;
};

struct LaunchHosts {
  std::vector<LaunchHost> hosts;                 // in the file's order
  std::map<std::string, std::string> placement;  // node -> host, as the file says
  std::string default_host;

  const LaunchHost& host(const std::string& name) const;
  const LaunchHost& hostOf(const std::string& node) const;
  // argv run on host: argv[0], a program of this machine's bin_dir
  // (local_bin_dir), moves to the host's bin_dir; then the prefix.
  std::vector<std::string> command(const LaunchHost& host, std::vector<std::string> argv,
                                   const std::string& local_bin_dir) const;
};

// Reads a hosts file; throws core::ParamError naming the file, line and key
// (an unknown key, node or host, an empty prefix word list, no hosts).
LaunchHosts loadLaunchHosts(const std::string& path, const std::vector<std::string>& node_names);

// Every node on this machine: what launch does without --hosts.
LaunchHosts localHosts();

}  // namespace nadir::run
