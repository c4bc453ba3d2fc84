// The feature VO's registry entry: its scenario group is its params.

#include "nodes/common/vo_node_summary.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"
#include "nodes/vo_feature/vo_feature_node.h"

namespace nadir::nodes {
namespace {

class VoFeatureLiveNode final : public Node {
 public:
  VoFeatureLiveNode(core::Bus& bus, const vo::VoFeatureNodeParams& params) : node_(bus, params) {}

  std::string summary() const override { return voNodeSummary(node_); }
  void continueResetCount(int resets_before) override { node_.continueResetCount(resets_before); }

 private:
  vo::VoFeatureNode node_;
};

class VoFeatureEntry final : public TypedEntry<vo::VoFeatureNodeParams> {
 public:
  VoFeatureEntry()
      : TypedEntry({.name = vo::kFeatureSourceName,
                    .program = "nadir-vo-feature",
                    .description = "feature-based monocular visual odometry over LCM",
                    .default_scenario = "thesis-oscillating",
                    .role = EntryInfo::Role::kProcessing}) {}

  std::optional<core::AnyParams> scenarioGroup() const override {
    return core::AnyParams(vo::VoFeatureNodeParams{});
  }
  std::string scenarioGroupDoc() const override {
    return "the feature-based VO (nadir-vo-feature)";
  }
  bool enabled(const ScenarioParams& scenario) const override {
    return scenario.node<vo::VoFeatureNodeParams>(info().name).enabled;
  }
  // No wall-clock times in the estimates, the local BA at fixed key-frames.
  void makeDeterministic(ScenarioParams& scenario) const override {
    auto& params = scenario.node<vo::VoFeatureNodeParams>(info().name);
    params.wall_clock_timing = false;
    params.vo.background_ba = false;
  }

 protected:
  vo::VoFeatureNodeParams paramsFrom(const ScenarioParams& scenario) const override {
    return scenario.node<vo::VoFeatureNodeParams>(info().name);
  }
  std::unique_ptr<Node> build(core::Bus& bus,
                              const vo::VoFeatureNodeParams& params) const override {
    return std::make_unique<VoFeatureLiveNode>(bus, params);
  }
  std::set<std::string> paced(const vo::VoFeatureNodeParams& params) const override {
    return {params.image_channel};
  }
  std::vector<Stream> publishes(const vo::VoFeatureNodeParams& params) const override {
    return {{.channel = params.pose_channel}, {.channel = params.debug_channel, .bulky = true}};
  }
};

}  // namespace

std::unique_ptr<Entry> voFeatureEntry() { return std::make_unique<VoFeatureEntry>(); }

}  // namespace nadir::nodes
