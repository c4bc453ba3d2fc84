// The simulator's registry entry: it drives time, so its live node steps the
// vehicle and paces the streams instead of waiting for messages.

#include <chrono>
#include <cstdio>
#include <sstream>
#include <thread>

#include "core/clock.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"
#include "nodes/sim/sim_node.h"
#include "nodes/sim/simulator.h"
#include "terrain/world.h"
#include "terrain/world_factory.h"

namespace nadir::nodes {
namespace {

using sim::SimNodeParams;

class SimLiveNode final : public Node {
 public:
  SimLiveNode(core::Bus& bus, const SimNodeParams& params)
      : params_(params),
        built_((terrain::requireFlightWorld(params.world), terrain::makeWorld(params.world))),
        frame_(built_.origin),
        simulator_(params.sim, built_.world, frame_,
                   sim::loadFlight(params.sim.flight, frame_, &flight_warning_)),
        publisher_(bus, params.sim, simulator_),
        commands_(bus, params.sim, simulator_),
        guidance_(bus, params.sim, simulator_),
        utime_(simulator_.startUtime()),
        last_report_utime_(utime_) {}

  bool turn(core::Bus& bus) override {
    if (simulator_.finished()) return false;
    if (!wall_start_) wall_start_ = std::chrono::steady_clock::now();
    const sim::SimOutput output = simulator_.step();
    utime_ = output.truth.utime;
    if (steps_++ > 0) track_length_m_ += (output.truth.p_ned_m - previous_p_).norm();
    previous_p_ = output.truth.p_ned_m;
    if (params_.time.mode == "realtime") {
      const double elapsed_s = elapsedSimSeconds() / params_.time.speed;
      std::this_thread::sleep_until(*wall_start_ + std::chrono::duration<double>(elapsed_s));
    }
    publisher_.publish(output);
    if (utime_ - last_report_utime_ >= 10'000'000) {
      last_report_utime_ = utime_;
      const Eigen::Vector3d& p = output.truth.p_ned_m;
      std::printf("t %7.1f s  north %8.1f m  east %8.1f m  height %7.1f m AGL  track %7.0f m\n",
                  elapsedSimSeconds(), p.x(), p.y(),
                  terrain::heightAboveGround_m(*built_.world, p.x(), p.y(), p.z()),
                  track_length_m_);
      std::fflush(stdout);
    }
    bus.handleAvailable();
    return true;
  }

  std::string summary() const override {
    std::ostringstream out;
    out << elapsedSimSeconds() << " s of sim time; track " << static_cast<long>(track_length_m_)
        << " m";
    for (const auto& [channel, count] : publisher_.counts()) {
      out << "; " << channel << " " << count;
    }
    if (params_.sim.guidance.source != "truth") {
      out << "; guidance on " << params_.sim.guidance.source << " (" << guidance_.fixes()
          << " fixes)";
    }
    if (simulator_.externalControl()) {
      out << "; drive commands " << commands_.received();
      if (commands_.dropped() > 0) out << " (" << commands_.dropped() << " invalid, dropped)";
    }
    return out.str();
  }

  std::string describe() const override {
    std::string text =
        "world: " + built_.description + "\ntime: " +
        (params_.time.mode == "realtime" ? std::to_string(params_.time.speed) + " x real time"
                                         : std::string("batch"));
    if (!flight_warning_.empty()) text += "\nflight log: " + flight_warning_;
    return text;
  }

 private:
  double elapsedSimSeconds() const {
    return core::secondsFromUtime(utime_ - simulator_.startUtime());
  }

  SimNodeParams params_;
  terrain::BuiltWorld built_;
  core::LocalNedFrame frame_;
  std::string flight_warning_;
  sim::Simulator simulator_;
  sim::SimPublisher publisher_;
  sim::DriveCommandInput commands_;
  sim::GuidanceInput guidance_;
  std::optional<std::chrono::steady_clock::time_point> wall_start_;
  std::int64_t utime_ = 0;
  std::int64_t last_report_utime_ = 0;
  std::uint64_t steps_ = 0;
  double track_length_m_ = 0.0;
  Eigen::Vector3d previous_p_ = Eigen::Vector3d::Zero();
};

class SimEntry final : public TypedEntry<SimNodeParams> {
 public:
  SimEntry()
      : TypedEntry({.name = "sim",
                    .program = "nadir-sim",
                    .description = "the vehicle, its truth and its sensors over LCM",
                    .default_scenario = "default",
                    .role = EntryInfo::Role::kSimulator}) {}

  bool enabled(const ScenarioParams&) const override { return true; }

 protected:
  SimNodeParams paramsFrom(const ScenarioParams& scenario) const override {
    return {scenario.sim, scenario.world, scenario.time};
  }
  std::unique_ptr<Node> build(core::Bus& bus, const SimNodeParams& params) const override {
    return std::make_unique<SimLiveNode>(bus, params);
  }
  std::vector<Stream> publishes(const SimNodeParams& params) const override {
    return {{.channel = params.sim.truth.channel, .rate_hz = params.sim.truth.rate_hz}};
  }
};

}  // namespace

std::unique_ptr<Entry> simEntry() { return std::make_unique<SimEntry>(); }

}  // namespace nadir::nodes
