#pragma once
// The checks behind `nadir doctor`, split from the probing so they can be tested.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace nadir::cli {

enum class CheckStatus { kOk, kWarn, kFail, kInfo };

struct CheckResult {
  CheckStatus status = CheckStatus::kInfo;
  std::string name;
  std::string detail;
  // Commands that fix a failure, one per line; empty when nothing is to be done.
  std::vector<std::string> fix;
};

struct Ipv4Route {
  std::string interface;
  std::uint32_t destination = 0;  // host byte order
  std::uint32_t mask = 0;
};

// Parses the text of /proc/net/route (destinations and masks are little-endian hex).
std::vector<Ipv4Route> parseProcNetRoute(const std::string& text);

// The most specific route carrying address, if any.
std::optional<Ipv4Route> routeFor(const std::vector<Ipv4Route>& routes, std::uint32_t address);

std::uint32_t parseIpv4(const std::string& dotted);
std::string formatIpv4(std::uint32_t address);
int prefixLength(std::uint32_t mask);

// Does the bus nadir opens by default (LCM_DEFAULT_URL) leave this host?
// ttl=0 keeps every message here; ttl >= 1 puts them on the network, where
// anyone may read them and send on nadir's channels: a warning.
CheckResult checkExposure(const std::string& url);

// Is there a route for the LCM multicast group, and is it sane?
CheckResult checkMulticastRoute(const std::vector<Ipv4Route>& routes, std::uint32_t group,
                                bool loopback_has_multicast_flag);

// Receive buffer sizes against what camera images need over udpm.
CheckResult checkReceiveBuffers(std::int64_t rmem_max_bytes, std::int64_t rmem_default_bytes);

// The commands that raise the receive buffers to the recommended size.
std::vector<std::string> receiveBufferFix();

// Receive buffer sizes, bytes: below the minimum, 1280x960 gray frames are lost
// over loopback udpm (docs/benchmarks.md has the measurement).
constexpr std::int64_t kMinimumReceiveBufferBytes = 32LL * 1024 * 1024;
constexpr std::int64_t kRecommendedReceiveBufferBytes = 256LL * 1024 * 1024;

}  // namespace nadir::cli
