#include "cli/doctor_checks.h"

#include <bit>
#include <charconv>
#include <sstream>
#include <stdexcept>

#include "core/bus.h"

namespace nadir::cli {
namespace {

std::uint32_t swapBytes(std::uint32_t value) {
  return ((value & 0xFF) << 24) | ((value & 0xFF00) << 8) | ((value >> 8) & 0xFF00) | (value >> 24);
}

std::string mebibytes(std::int64_t bytes) {
  std::ostringstream out;
  if (bytes >= 1024 * 1024) {
    out << bytes / (1024 * 1024) << " MiB";
  } else {
    out << bytes / 1024 << " KiB";
  }
  return out.str();
}

}  // namespace

std::vector<Ipv4Route> parseProcNetRoute(const std::string& text) {
  std::vector<Ipv4Route> routes;
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);  // header
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string interface, destination, gateway, flags, refcnt, use, metric, mask;
    if (!(fields >> interface >> destination >> gateway >> flags >> refcnt >> use >> metric >>
          mask)) {
      continue;
    }
    try {
      // The kernel prints the address in network byte order read as a
      // little-endian integer: 224.0.0.0 appears as 000000E0.
      const auto destination_le = static_cast<std::uint32_t>(std::stoul(destination, nullptr, 16));
      const auto mask_le = static_cast<std::uint32_t>(std::stoul(mask, nullptr, 16));
      routes.push_back({interface, swapBytes(destination_le), swapBytes(mask_le)});
    } catch (const std::exception&) {
      continue;
    }
  }
  return routes;
}

std::optional<Ipv4Route> routeFor(const std::vector<Ipv4Route>& routes, std::uint32_t address) {
  std::optional<Ipv4Route> best;
  for (const Ipv4Route& route : routes) {
    if ((address & route.mask) != route.destination) continue;
    if (!best || prefixLength(route.mask) > prefixLength(best->mask)) best = route;
  }
  return best;
}

std::uint32_t parseIpv4(const std::string& dotted) {
  const auto invalid = [&] {
    return std::invalid_argument("not an IPv4 address: '" + dotted + "'");
  };
  std::uint32_t address = 0;
  const char* at = dotted.data();
  const char* const end = dotted.data() + dotted.size();
  for (int i = 0; i < 4; ++i) {
    if (i > 0) {
      if (at == end || *at != '.') throw invalid();
      ++at;
    }
    unsigned part = 0;
    const auto [next, error] = std::from_chars(at, end, part);
    if (error != std::errc() || next == at || next - at > 3 || part > 255) throw invalid();
    at = next;
    address = (address << 8) | part;
  }
  if (at != end) throw invalid();
  return address;
}

std::string formatIpv4(std::uint32_t address) {
  return std::to_string(address >> 24) + "." + std::to_string((address >> 16) & 0xFF) + "." +
         std::to_string((address >> 8) & 0xFF) + "." + std::to_string(address & 0xFF);
}

int prefixLength(std::uint32_t mask) { return std::popcount(mask); }

CheckResult checkMulticastRoute(const std::vector<Ipv4Route>& routes, std::uint32_t group,
                                bool loopback_has_multicast_flag) {
  CheckResult result;
  result.name = "multicast route";
  const std::optional<Ipv4Route> route = routeFor(routes, group);
  const std::vector<std::string> fix = {"sudo ip link set lo multicast on",
                                        "sudo ip route add 224.0.0.0/4 dev lo"};
  if (!route) {
    result.status = CheckStatus::kFail;
    result.detail = "no route carries " + formatIpv4(group) + ": LCM's udpm:// cannot start";
    result.fix = fix;
    return result;
  }
  const std::string via = formatIpv4(route->destination) + "/" +
                          std::to_string(prefixLength(route->mask)) + " dev " + route->interface;
  if (route->interface == "lo" && !loopback_has_multicast_flag) {
    result.status = CheckStatus::kFail;
    result.detail =
        formatIpv4(group) + " is routed to lo (" + via + ") but lo has no MULTICAST flag";
    result.fix = {fix[0]};
    return result;
  }
  result.status = CheckStatus::kOk;
  result.detail = formatIpv4(group) + " goes out by " + via;
  if (route->mask == 0) {
    result.detail +=
        " (the default route: with ttl=0 messages stay on this host; for other "
        "hosts ttl=1 and a multicast route on the shared link)";
  }
  return result;
}

CheckResult checkReceiveBuffers(std::int64_t rmem_max_bytes, std::int64_t rmem_default_bytes) {
  CheckResult result;
  result.name = "UDP receive buffers";
  result.detail = "net.core.rmem_max = " + mebibytes(rmem_max_bytes) +
                  ", net.core.rmem_default = " + mebibytes(rmem_default_bytes);
  if (rmem_max_bytes >= kMinimumReceiveBufferBytes &&
      rmem_default_bytes >= kMinimumReceiveBufferBytes) {
    result.status = CheckStatus::kOk;
    return result;
  }
  result.status = CheckStatus::kFail;
  result.detail += ": camera images over udpm:// need at least " +
                   mebibytes(kMinimumReceiveBufferBytes) + " (recommended " +
                   mebibytes(kRecommendedReceiveBufferBytes) + ")";
  result.fix = receiveBufferFix();
  return result;
}

std::vector<std::string> receiveBufferFix() {
  const std::string value = std::to_string(kRecommendedReceiveBufferBytes);
  return {"sudo sysctl -w net.core.rmem_max=" + value + " net.core.rmem_default=" + value,
          "printf 'net.core.rmem_max=" + value + "\\nnet.core.rmem_default=" + value +
              "\\n' | sudo tee /etc/sysctl.d/60-nadir-lcm.conf   # keep it after reboot"};
}

CheckResult checkExposure(const std::string& url) {
  const std::optional<int> ttl = core::udpmTtl(url);
  if (!ttl) {
    return {CheckStatus::kInfo, "exposure", url + ": not UDP multicast, nothing leaves by it", {}};
  }
  if (*ttl == 0) {
    return {CheckStatus::kOk, "exposure", url + ": ttl=0, every message stays on this host", {}};
  }
  return {
      CheckStatus::kWarn,
      "exposure",
      url + ": ttl=" + std::to_string(*ttl) + ", every message leaves this host" +
          (*ttl > 1 ? " and crosses routers" : " for the local network") +
          ", where anyone may read it and send on nadir's channels; keep ttl=0 unless "
          "the nodes run on several machines",
      {"unset LCM_DEFAULT_URL   # or: export LCM_DEFAULT_URL='udpm://239.255.76.67:7667?ttl=0'"}};
}

}  // namespace nadir::cli
