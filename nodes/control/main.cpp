// nadir-control: the rover's reactive controller: the PPA's gate and slalom
// patterns in, steering and speed commands out. Wiring only: nodes/node_main.h.

#include "nodes/node_main.h"

int main(int argc, char** argv) { return nadir::nodes::runNodeMain(argc, argv, "control"); }
