#pragma once
// The one main() of every node program (nadir-sim, nadir-camera, nadir-ppa,
// nadir-vo-feature, ...):
//
//   PROGRAM [SCENARIO] [--set key=value ...]    the node's part of a scenario
//   PROGRAM --config FILE [--set key=value ...]  the node's own parameters
//   PROGRAM --list                               the built-in scenarios
//
// It prints the node's effective parameters, opens the bus, builds the node
// from its registry entry, publishes a heartbeat_t when the node is ready and
// then once a second (nadir launch waits for the first), runs the node until it
// is done or SIGINT/SIGTERM/SIGHUP, and prints what the node did and, per
// channel, what reached it and what was lost on the way (core/stream_gaps.h).

namespace nadir::nodes {

// Returns the process's exit status: 0, or 1 with the error on stderr.
int runNodeMain(int argc, char** argv, const char* node_name);

}  // namespace nadir::nodes
