// nadir-camera: renders the virtual cameras riding on the body whose true pose
// arrives over LCM, and publishes their images and camera_info_t. Wiring only: nodes/node_main.h.

#include "nodes/node_main.h"

int main(int argc, char** argv) { return nadir::nodes::runNodeMain(argc, argv, "camera"); }
