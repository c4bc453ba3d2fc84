// nadir-vo-direct: the direct (photometric) monocular VO: the downward
// camera's frames in, POSE_VO_DIRECT out. Wiring only: nodes/node_main.h.

#include "nodes/node_main.h"

int main(int argc, char** argv) { return nadir::nodes::runNodeMain(argc, argv, "vo_direct"); }
