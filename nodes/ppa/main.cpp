// nadir-ppa: the emulated SCAMP-5 vision sensor: the PPA camera's frames in,
// POSE_PPA, PPA_ODOMETRY and PPA_TARGET out. Wiring only: nodes/node_main.h.

#include "nodes/node_main.h"

int main(int argc, char** argv) { return nadir::nodes::runNodeMain(argc, argv, "ppa"); }
