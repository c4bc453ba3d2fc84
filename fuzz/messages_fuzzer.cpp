// Any datagram on any of nadir's channels, through the bus's typed subscribe:
// the same bytes are published on one channel per message type, each with its
// own subscription, so every decoder sees every input. What decodes must hold
// what its type promises; what does not is counted, never delivered.
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/lcm_bus.h"
#include "fuzz/fuzz_input.h"
#include "lcmtypes/bus_io.h"

namespace {

using namespace nadir;

void check(const msg::Image& image) {
  NADIR_FUZZ_REQUIRE(image.pixels.empty() || image.pixels.type() == CV_8UC1 ||
                     image.pixels.type() == CV_8UC3);
  NADIR_FUZZ_REQUIRE(image.pixels.empty() || image.pixels.isContinuous());
}

template <class T>
void check(const T&) {}

struct Subscriptions {
  core::LcmBus bus{"memq://"};
  std::vector<std::string> channels;
  std::vector<core::Subscription> subscriptions;
  std::uint64_t delivered = 0;

  template <class T>
  void add() {
    const std::string channel = std::string("FUZZ_") + msg::typeNameOf<T>();
    channels.push_back(channel);
    subscriptions.push_back(
        msg::subscribe<T>(bus, channel, std::function<void(const T&)>([this](const T& message) {
                            check(message);
                            ++delivered;
                          }),
                          [](const std::string& reason) { NADIR_FUZZ_REQUIRE(!reason.empty()); }));
  }
};

Subscriptions& subscriptions() {
  static Subscriptions* const all = [] {
    auto* s = new Subscriptions;
    s->add<msg::Pose>();
    s->add<msg::Imu>();
    s->add<msg::Range>();
    s->add<msg::Gps>();
    s->add<msg::Baro>();
    s->add<msg::Magnetometer>();
    s->add<msg::GeodeticPosition>();
    s->add<msg::Attitude>();
    s->add<msg::Velocity>();
    s->add<msg::BodyRates>();
    s->add<msg::CameraInfo>();
    s->add<msg::Image>();
    s->add<msg::VoEstimate>();
    s->add<msg::NavState>();
    s->add<msg::PpaOdometry>();
    s->add<msg::TargetDetection>();
    s->add<msg::VoCommand>();
    s->add<msg::GatePattern>();
    s->add<msg::DriveCommand>();
    s->add<msg::WaypointReached>();
    s->add<msg::Heartbeat>();
    s->add<msg::BusCheck>();
    return s;
  }();
  return *all;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Subscriptions& s = subscriptions();
  for (const std::string& channel : s.channels) s.bus.publish(channel, data, size, 0);
  while (s.bus.handleAvailable() > 0) {
  }
  (void)msg::typeName(data, size);
  (void)msg::isJpegImage(data, size);
  return 0;
}
