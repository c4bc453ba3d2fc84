#pragma once
// `nadir launch`: the live mode. Each node runs as its own process on UDP LCM
// (nadir-sim, nadir-camera, the VO nodes) with `nadir log record` recording; their
// health (message rates against what the scenario expects, VO status, exit
// statuses) is printed while they run, and all are stopped cleanly when the
// scenario ends or on request. A node that dies is reported with its exit
// status and stops the launch, or is restarted (max_restarts); a node that
// falls silent (stopped, hung) is reported. docs/reliability.md says what
// survives which fault.

#include <atomic>
#include <ostream>
#include <string>
#include <vector>

namespace nadir::run {

struct LaunchOptions {
  std::string scenario = "default";
  std::vector<std::string> overrides;
  // Node logs and the recording go here; empty: out/<scenario>-live.
  std::string out_dir;
  bool force = false;
  // Where nadir-sim and nadir-camera are; empty: next to this program.
  std::string bin_dir;
  // Seconds between health reports.
  double report_period_s = 2.0;
  // Where each node runs (run/launch_hosts.h); empty: all on this machine.
  std::string hosts_file;
  // How long the bus may take to join every host before the flight is refused.
  double bus_check_timeout_s = 20.0;
  // A node that dies is started again, up to this many times each; 0: a dead
  // node stops the launch. Never the simulator (the flight is its) nor
  // the logger (the recording is its): either dying stops the launch.
  int max_restarts = 0;
};

// A node whose heartbeat is this late (they come once a second) is reported
// silent, with its channels, at once.
inline constexpr double kSilentAfter_s = 1.5;

// Runs until the scenario ends, a node dies or stop becomes true. Returns the
// exit status for the launch: 0 when the scenario ended and every node exited
// cleanly, 1 when a node failed, 130 when stopped.
int launchScenario(const LaunchOptions& options, std::ostream& out, const std::atomic<bool>& stop);

}  // namespace nadir::run
