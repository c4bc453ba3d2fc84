// The PPA's registry entry: its scenario group with the scenario's known
// targets, and the target passes it adds to a batch run's results.

#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>

#include "core/lcm_log.h"
#include "lcmtypes/codec.h"
#include "logs/run_log.h"
#include "nodes/ppa/ppa_node.h"
#include "nodes/ppa/target_passes.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"
#include "terrain/world.h"

namespace nadir::nodes {
namespace {

using ppa::PpaNodeParams;
using ppa::PpaProcessParams;

std::vector<Eigen::Vector2d> targetsOf(const core::NumberRows& rows) {
  std::vector<Eigen::Vector2d> targets;
  for (const std::vector<double>& row : rows) targets.emplace_back(row[0], row[1]);
  return targets;
}

class PpaLiveNode final : public Node {
 public:
  PpaLiveNode(core::Bus& bus, const PpaProcessParams& params)
      : node_(bus, params.node, targetsOf(params.known_targets_ne_m)) {}

  void continueResetCount(int resets_before) override { node_.continueResetCount(resets_before); }
  std::string summary() const override {
    std::ostringstream out;
    out << node_.frames() << " frames, " << static_cast<long long>(node_.meanInstructionsPerFrame())
        << " instructions per frame on average";
    if (node_.droppedImages() > 0) {
      out << "; dropped " << node_.droppedImages()
          << " images, the first: " << node_.firstDropReason();
    }
    const nodes::VoCommandListener& commands = node_.commands();
    if (commands.resetsReceived() > 0) out << "; " << commands.resetsReceived() << " resets";
    if (commands.droppedCommands() > 0) {
      out << "; dropped " << commands.droppedCommands()
          << " commands, the first: " << commands.firstDropReason();
    }
    return out.str();
  }

 private:
  ppa::PpaNode node_;
};

// Each detector frame of the recording: its time and whether it found a target.
std::vector<std::pair<double, bool>> detectorFrames(const std::string& log_path,
                                                    const std::string& channel) {
  std::vector<std::pair<double, bool>> frames;
  core::LcmLogReader reader(log_path);
  while (const std::optional<core::LogEvent> event = reader.next()) {
    if (event->channel != channel) continue;
    try {
      const msg::TargetDetection detection = msg::decode<msg::TargetDetection>(event->data);
      frames.emplace_back(core::secondsFromUtime(detection.utime), detection.detected);
    } catch (const std::exception&) {
    }
  }
  return frames;
}

class PpaEntry final : public TypedEntry<PpaProcessParams> {
 public:
  PpaEntry()
      : TypedEntry({.name = ppa::kSourceName,
                    .program = "nadir-ppa",
                    .description = "the emulated SCAMP-5 pixel processor array over LCM",
                    .default_scenario = "scamp-rectangle",
                    .role = EntryInfo::Role::kProcessing}) {}

  std::optional<core::AnyParams> scenarioGroup() const override {
    return core::AnyParams(PpaNodeParams{});
  }
  std::string scenarioGroupDoc() const override {
    return "the emulated SCAMP-5 vision sensor (nadir-ppa)";
  }
  bool enabled(const ScenarioParams& scenario) const override {
    return scenario.node<PpaNodeParams>(info().name).enabled;
  }

 protected:
  PpaProcessParams paramsFrom(const ScenarioParams& scenario) const override {
    PpaProcessParams params;
    params.node = scenario.node<PpaNodeParams>(info().name);
    const core::LocalNedFrame frame(scenarioOrigin(scenario));
    for (const Eigen::Vector2d& target : knownTargets(scenario, frame)) {
      params.known_targets_ne_m.push_back({target.x(), target.y()});
    }
    return params;
  }
  std::unique_ptr<Node> build(core::Bus& bus, const PpaProcessParams& params) const override {
    return std::make_unique<PpaLiveNode>(bus, params);
  }
  std::vector<Stream> publishes(const PpaProcessParams& params) const override {
    if (params.node.mode == "gates") return {{.channel = params.node.pattern_channel}};
    return {{.channel = params.node.pose_channel},
            {.channel = params.node.odometry_channel},
            {.channel = params.node.target_channel}};
  }

  // Passes over the known targets with the chip's detections and the errors
  // around them (target_passes.csv beside the run).
  std::string report(const BatchReportInput& input, const PpaProcessParams& params) const override {
    if (params.node.mode != "odometry" || !params.node.target_extraction ||
        params.known_targets_ne_m.empty()) {
      return {};
    }
    const logs::LogTrajectories& recorded = input.recorded;
    if (recorded.sources.count(info().name) == 0) return {};
    ppa::TargetPassInput passes;
    passes.truth = recorded.truth;
    for (const core::StampedPose& pose : recorded.truth) {
      passes.truth_height_m.push_back(terrain::heightAboveGround_m(
          input.world, pose.p_ned_m.x(), pose.p_ned_m.y(), pose.p_ned_m.z()));
    }
    passes.estimates = recorded.sources.at(info().name);
    passes.detector_frames = detectorFrames(input.log_path, params.node.target_channel);
    passes.targets_ne_m = targetsOf(params.known_targets_ne_m);
    double hfov_deg = params.node.host.hfov_deg;
    for (const auto& [name, spec] : input.scenario.allCameras()) {
      if (spec.channel == params.node.image_channel) hfov_deg = spec.camera.hfov_deg;
    }
    passes.hfov_rad = hfov_deg * std::numbers::pi / 180.0;
    const std::vector<ppa::TargetPass> found = ppa::targetPasses(passes);
    std::ofstream(std::filesystem::path(input.out_dir) / "target_passes.csv")
        << ppa::targetPassesCsv(found);
    return ppa::formatTargetPasses(found);
  }
};

}  // namespace

std::unique_ptr<Entry> ppaEntry() { return std::make_unique<PpaEntry>(); }

}  // namespace nadir::nodes
