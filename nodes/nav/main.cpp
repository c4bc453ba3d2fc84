// nadir-nav: the navigation filter: the IMU, barometer, rangefinder, GPS,
// magnetometer and a VO node's poses in, POSE_NAV and POSE_NAV_STATE out.
// Wiring only: nodes/node_main.h.

#include "nodes/node_main.h"

int main(int argc, char** argv) { return nadir::nodes::runNodeMain(argc, argv, "nav"); }
