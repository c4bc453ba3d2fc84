#pragma once
// The check that the bus joins every host of a launch before its flight:
// every participant (a checker on each host, and the launch itself) publishes
// bus_check_t ten times a second saying whom it has heard. A participant's
// check is complete when it has heard every other and every other says it has
// heard everyone: then messages cross between every pair of hosts, both ways.

#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/bus.h"

namespace nadir::run {

inline constexpr char kBusCheckChannel[] = "NADIR_BUS_CHECK";

class BusCheck {
 public:
  // hosts: every participant's name, self among them. Messages of another
  // launch_id, or from a host not in hosts, are ignored.
  BusCheck(core::Bus& bus, std::int64_t launch_id, std::string self, std::set<std::string> hosts,
           std::string channel = kBusCheckChannel);

  // Publishes this host's word, at most ten times a second.
  void beatIfDue();
  bool complete() const;
  // One line per pair that has not been seen to work: "air has not heard
  // ground", or "nothing from air" when a host has not been heard at all.
  std::vector<std::string> missingLinks() const;
  // The hosts heard so far by this one (itself included).
  const std::set<std::string>& heard() const { return said_.at(self_); }

 private:
  core::Bus& bus_;
  std::int64_t launch_id_;
  std::string self_;
  std::set<std::string> hosts_;
  std::string channel_;
  std::map<std::string, std::set<std::string>> said_;  // by host: whom it has heard
  std::chrono::steady_clock::time_point last_beat_{};
  core::Subscription subscription_;
};

// Runs a checker until the check completes and then linger_s longer (so the
// others hear it say so), or until timeout_s; returns whether it completed.
bool runBusCheck(core::Bus& bus, std::int64_t launch_id, const std::string& self,
                 const std::set<std::string>& hosts, double timeout_s, double linger_s,
                 std::vector<std::string>* missing_links);

}  // namespace nadir::run
