// nadir-ppa: the emulated SCAMP-5 vision sensor as a live node: the PPA
// camera's frames in, POSE_PPA, PPA_ODOMETRY and PPA_TARGET out. Wiring only.
//
//   nadir-ppa [SCENARIO] [--set key=value ...]   (the scenario's ppa group, bus and targets)

#include <memory>
#include <sstream>

#include "nodes/ppa/ppa_node.h"
#include "nodes/node_main.h"

int main(int argc, char** argv) {
  nadir::scenario::ScenarioNodeSpec spec;
  spec.program = "nadir-ppa";
  spec.description = "the emulated SCAMP-5 pixel processor array over LCM";
  spec.default_scenario = "scamp-rectangle";
  spec.format_params = [](nadir::scenario::ScenarioParams& scenario) {
    return nadir::core::formatParamsOf(scenario.ppa);
  };
  spec.start = [](nadir::core::Bus& bus, const nadir::scenario::ScenarioParams& scenario) {
    const nadir::core::LocalNedFrame frame(nadir::scenario::scenarioOrigin(scenario));
    auto node = std::make_shared<nadir::ppa::PpaNode>(
        bus, scenario.ppa, nadir::scenario::knownTargets(scenario, frame));
    return std::function<std::string()>([node] {
      std::ostringstream out;
      out << node->frames() << " frames, "
          << static_cast<long long>(node->meanInstructionsPerFrame())
          << " instructions per frame on average";
      if (node->droppedImages() > 0) {
        out << "; dropped " << node->droppedImages()
            << " images, the first: " << node->firstDropReason();
      }
      return out.str();
    });
  };
  return nadir::scenario::runScenarioNode(argc, argv, spec);
}
