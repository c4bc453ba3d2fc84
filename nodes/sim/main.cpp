// nadir-sim: flies a scenario's vehicle (or replays a recorded flight) and
// publishes the truth and the sensor streams in sim time. Wiring only: nodes/node_main.h.

#include "nodes/node_main.h"

int main(int argc, char** argv) { return nadir::nodes::runNodeMain(argc, argv, "sim"); }
