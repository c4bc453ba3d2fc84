#include "run/bus_check.h"

#include <unistd.h>

#include <optional>
#include <utility>

#include "core/clock.h"
#include "lcmtypes/bus_io.h"

namespace nadir::run {

BusCheck::BusCheck(core::Bus& bus, std::int64_t launch_id, std::string self,
                   std::set<std::string> hosts, std::string channel)
    : bus_(bus),
      launch_id_(launch_id),
      self_(std::move(self)),
      hosts_(std::move(hosts)),
      channel_(std::move(channel)) {
  hosts_.insert(self_);
  said_[self_].insert(self_);
  subscription_ = msg::subscribe<msg::BusCheck>(bus_, channel_, [this](const msg::BusCheck& word) {
    // Its own words (multicast loops back) say nothing new and are older than what it knows.
    if (word.launch_id != launch_id_ || word.host == self_ || hosts_.count(word.host) == 0) return;
    said_[self_].insert(word.host);
    said_[word.host] = word.heard;
  });
}

void BusCheck::beatIfDue() {
  const auto now = std::chrono::steady_clock::now();
  if (now - last_beat_ < std::chrono::milliseconds(100)) return;
  last_beat_ = now;
  msg::publish(bus_, channel_,
               msg::BusCheck{core::wallClockUtime(), launch_id_, self_,
                             static_cast<std::int32_t>(::getpid()), said_.at(self_)});
}

std::vector<std::string> BusCheck::missingLinks() const {
  std::vector<std::string> missing;
  for (const std::string& listener : hosts_) {
    const auto said = said_.find(listener);
    if (said == said_.end()) {
      missing.push_back("nothing from " + listener);
      continue;
    }
    for (const std::string& speaker : hosts_) {
      if (said->second.count(speaker) == 0) {
        missing.push_back(listener + " has not heard " + speaker);
      }
    }
  }
  return missing;
}

bool BusCheck::complete() const { return missingLinks().empty(); }

bool runBusCheck(core::Bus& bus, std::int64_t launch_id, const std::string& self,
                 const std::set<std::string>& hosts, double timeout_s, double linger_s,
                 std::vector<std::string>* missing_links) {
  using Clock = std::chrono::steady_clock;
  BusCheck check(bus, launch_id, self, hosts);
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  std::optional<Clock::time_point> done_at;
  while (Clock::now() < deadline) {
    check.beatIfDue();
    bus.handle(std::chrono::milliseconds(20));
    if (!done_at && check.complete()) done_at = Clock::now();
    if (done_at && Clock::now() - *done_at >= std::chrono::duration<double>(linger_s)) break;
  }
  if (missing_links != nullptr) *missing_links = check.missingLinks();
  return done_at.has_value();
}

}  // namespace nadir::run
