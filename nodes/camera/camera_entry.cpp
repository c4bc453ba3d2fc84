// The camera's registry entry: its params are the scenario's world, tiles,
// renderer, cameras and targets, and the truth it rides on.

#include <sstream>

#include "nodes/camera/camera_node.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"

namespace nadir::nodes {
namespace {

using camera::CameraNodeParams;

class CameraLiveNode final : public Node {
 public:
  CameraLiveNode(core::Bus& bus, const CameraNodeParams& params)
      : bus_(bus), pose_channel_(params.pose_channel), node_(bus, withDefaultCamera(params)) {}

  std::string summary() const override {
    const auto stats = bus_.stats();
    const auto pose_stats = stats.find(pose_channel_);
    std::ostringstream out;
    out << node_.framesPublished() << " frames; dropped " << node_.badPoses() << " bad poses and "
        << (pose_stats == stats.end() ? 0 : pose_stats->second.decode_errors)
        << " undecodable messages";
    if (node_.badPoses() > 0) out << "; the first bad pose: " << node_.firstBadPose();
    return out.str();
  }
  std::string describe() const override {
    return "world: " + node_.scene().built.description + "\nrendering with " +
           node_.scene().context.info().gl_renderer + "; poses from " + pose_channel_;
  }

 private:
  // A camera node with no camera given renders one "down" camera of the defaults.
  static CameraNodeParams withDefaultCamera(CameraNodeParams params) {
    if (params.cameras.empty()) params.cameras["down"] = camera::CameraSpec{};
    return params;
  }

  core::Bus& bus_;
  std::string pose_channel_;
  camera::CameraNode node_;
};

class CameraEntry final : public TypedEntry<CameraNodeParams> {
 public:
  CameraEntry()
      : TypedEntry({.name = "camera",
                    .program = "nadir-camera",
                    .description = "virtual downward cameras over LCM",
                    .default_scenario = "default",
                    .role = EntryInfo::Role::kCamera}) {}

  bool enabled(const ScenarioParams&) const override { return true; }

 protected:
  CameraNodeParams paramsFrom(const ScenarioParams& scenario) const override {
    CameraNodeParams params;
    params.pose_channel = scenario.sim.truth.channel;
    params.world = scenario.world;
    params.tiles = scenario.tiles;
    params.renderer = scenario.renderer;
    params.cameras = scenario.allCameras();
    params.targets = scenario.targets;
    params.course = scenario.course;
    return params;
  }
  std::unique_ptr<Node> build(core::Bus& bus, const CameraNodeParams& params) const override {
    return std::make_unique<CameraLiveNode>(bus, params);
  }
  std::vector<Stream> publishes(const CameraNodeParams& params) const override {
    std::vector<Stream> streams;
    for (const auto& [name, spec] : params.cameras) {
      streams.push_back({.channel = spec.channel, .rate_hz = spec.fps, .bulky = true});
      streams.push_back({.channel = spec.info_channel});
    }
    return streams;
  }
};

}  // namespace

std::unique_ptr<Entry> cameraEntry() { return std::make_unique<CameraEntry>(); }

}  // namespace nadir::nodes
