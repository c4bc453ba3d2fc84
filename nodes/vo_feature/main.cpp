// nadir-vo-feature: the feature-based monocular VO as a live node: the
// downward camera's frames in, POSE_VO_FEATURE out. Wiring only.
//
//   nadir-vo-feature [SCENARIO] [--set key=value ...]   (the scenario's vo_feature group and bus)

#include <memory>
#include <sstream>

#include "nodes/vo_feature/vo_feature_node.h"
#include "nodes/node_main.h"

int main(int argc, char** argv) {
  nadir::scenario::ScenarioNodeSpec spec;
  spec.program = "nadir-vo-feature";
  spec.description = "feature-based monocular visual odometry over LCM";
  spec.default_scenario = "thesis-oscillating";
  spec.format_params = [](nadir::scenario::ScenarioParams& scenario) {
    return nadir::core::formatParamsOf(scenario.vo_feature);
  };
  spec.start = [](nadir::core::Bus& bus, const nadir::scenario::ScenarioParams& scenario) {
    auto node = std::make_shared<nadir::vo::VoFeatureNode>(bus, scenario.vo_feature);
    return std::function<std::string()>([node] {
      std::ostringstream out;
      out << node->frames() << " frames, "
          << (node->frames() ? 1000.0 * node->processingSeconds() / node->frames() : 0.0)
          << " ms per frame";
      if (node->droppedImages() > 0) {
        out << "; dropped " << node->droppedImages()
            << " images, the first: " << node->firstDropReason();
      }
      return out.str();
    });
  };
  return nadir::scenario::runScenarioNode(argc, argv, spec);
}
