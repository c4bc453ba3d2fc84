#include "cli/doctor_checks.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace nadir::cli {
namespace {

// /proc/net/route as the kernel prints it.
const std::string kHeader =
    "Iface\tDestination\tGateway \tFlags\tRefCnt\tUse\tMetric\tMask\t\tMTU\tWindow\tIRTT\n";
const std::string kDefaultRoute = "eth0\t00000000\t0100A8C0\t0003\t0\t0\t0\t00000000\t0\t0\t0\n";
const std::string kMulticastRoute = "lo\t000000E0\t00000000\t0001\t0\t0\t0\t000000F0\t0\t0\t0\n";
const std::string kSubnetRoute = "eth0\t0000A8C0\t00000000\t0001\t0\t0\t0\t00FFFFFF\t0\t0\t0\n";

// The LCM default group, 239.255.76.67.
constexpr std::uint32_t kLcmGroup = 0xEFFF4C43;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

bool anyContains(const std::vector<std::string>& lines, const std::string& part) {
  for (const std::string& line : lines) {
    if (contains(line, part)) return true;
  }
  return false;
}

// Rows are parsed in order with destination and mask converted to host byte order.
TEST(ParseProcNetRoute, ConvertsToHostOrder) {
  const auto routes = parseProcNetRoute(kHeader + kDefaultRoute + kMulticastRoute + kSubnetRoute);
  ASSERT_EQ(routes.size(), 3u);
  EXPECT_EQ(routes[0].interface, "eth0");
  EXPECT_EQ(routes[0].destination, 0u);
  EXPECT_EQ(routes[0].mask, 0u);
  EXPECT_EQ(routes[1].interface, "lo");
  EXPECT_EQ(routes[1].destination, 0xE0000000u);
  EXPECT_EQ(routes[1].mask, 0xF0000000u);
  EXPECT_EQ(routes[2].interface, "eth0");
  EXPECT_EQ(routes[2].destination, 0xC0A80000u);
  EXPECT_EQ(routes[2].mask, 0xFFFFFF00u);
  EXPECT_EQ(formatIpv4(routes[1].destination), "224.0.0.0");
  EXPECT_EQ(formatIpv4(routes[2].destination), "192.168.0.0");
  EXPECT_EQ(prefixLength(routes[0].mask), 0);
  EXPECT_EQ(prefixLength(routes[1].mask), 4);
  EXPECT_EQ(prefixLength(routes[2].mask), 24);
}

// Only the header, or nothing at all, gives no routes; short or garbled rows are skipped.
TEST(ParseProcNetRoute, SkipsHeaderAndBadRows) {
  EXPECT_TRUE(parseProcNetRoute("").empty());
  EXPECT_TRUE(parseProcNetRoute(kHeader).empty());
  const auto routes =
      parseProcNetRoute(kHeader + "eth0\t00000000\n" + "eth0\tXYZ\t0\t0\t0\t0\t0\tQQ\t0\t0\t0\n" +
                        "\n" + kMulticastRoute);
  ASSERT_EQ(routes.size(), 1u);
  EXPECT_EQ(routes[0].interface, "lo");
}

// Rows padded with trailing spaces, as the kernel pads them to 127 columns, parse the same.
TEST(ParseProcNetRoute, IgnoresTrailingPadding) {
  auto pad = [](std::string line) {
    line.pop_back();
    return line + std::string(40, ' ') + "\n";
  };
  const auto routes = parseProcNetRoute(pad(kHeader) + pad(kMulticastRoute) + pad(kSubnetRoute));
  ASSERT_EQ(routes.size(), 2u);
  EXPECT_EQ(routes[0].destination, 0xE0000000u);
  EXPECT_EQ(routes[0].mask, 0xF0000000u);
  EXPECT_EQ(routes[1].destination, 0xC0A80000u);
  EXPECT_EQ(routes[1].mask, 0xFFFFFF00u);
}

// The most specific route wins: the /4 for multicast, the /24 on the subnet, else the default.
TEST(RouteFor, PicksMostSpecificRoute) {
  const auto routes = parseProcNetRoute(kHeader + kDefaultRoute + kMulticastRoute + kSubnetRoute);

  const auto multicast = routeFor(routes, parseIpv4("239.255.76.67"));
  ASSERT_TRUE(multicast.has_value());
  EXPECT_EQ(multicast->interface, "lo");
  EXPECT_EQ(multicast->mask, 0xF0000000u);

  const auto local = routeFor(routes, parseIpv4("192.168.0.7"));
  ASSERT_TRUE(local.has_value());
  EXPECT_EQ(local->interface, "eth0");
  EXPECT_EQ(local->mask, 0xFFFFFF00u);

  const auto remote = routeFor(routes, parseIpv4("8.8.8.8"));
  ASSERT_TRUE(remote.has_value());
  EXPECT_EQ(remote->interface, "eth0");
  EXPECT_EQ(remote->mask, 0u);
}

// The order of the rows does not change which route is the most specific.
TEST(RouteFor, IndependentOfRowOrder) {
  const auto routes = parseProcNetRoute(kHeader + kSubnetRoute + kMulticastRoute + kDefaultRoute);
  const auto multicast = routeFor(routes, kLcmGroup);
  ASSERT_TRUE(multicast.has_value());
  EXPECT_EQ(multicast->interface, "lo");
  const auto local = routeFor(routes, parseIpv4("192.168.0.255"));
  ASSERT_TRUE(local.has_value());
  EXPECT_EQ(local->mask, 0xFFFFFF00u);
  EXPECT_EQ(routeFor(routes, parseIpv4("192.168.1.1"))->mask, 0u);
}

// With no route covering the address, or no routes at all, there is none.
TEST(RouteFor, NoRouteIsNullopt) {
  EXPECT_FALSE(routeFor({}, kLcmGroup).has_value());
  EXPECT_FALSE(routeFor(parseProcNetRoute(kHeader), kLcmGroup).has_value());
  const auto routes = parseProcNetRoute(kHeader + kSubnetRoute);
  EXPECT_FALSE(routeFor(routes, kLcmGroup).has_value());
  EXPECT_FALSE(routeFor(routes, parseIpv4("8.8.8.8")).has_value());
  EXPECT_TRUE(routeFor(routes, parseIpv4("192.168.0.1")).has_value());
}

// A multicast route on lo with lo's MULTICAST flag set is OK.
TEST(CheckMulticastRoute, OkViaLoopbackMulticastRoute) {
  const auto routes = parseProcNetRoute(kHeader + kDefaultRoute + kMulticastRoute);
  const CheckResult result = checkMulticastRoute(routes, kLcmGroup, true);
  EXPECT_EQ(result.status, CheckStatus::kOk);
  EXPECT_FALSE(result.name.empty());
  EXPECT_TRUE(contains(result.detail, "239.255.76.67")) << result.detail;
  EXPECT_TRUE(contains(result.detail, "224.0.0.0/4 dev lo")) << result.detail;
  EXPECT_TRUE(result.fix.empty());
}

// A route to lo while lo lacks the MULTICAST flag fails, with the command that sets it.
TEST(CheckMulticastRoute, FailsOnLoopbackWithoutMulticastFlag) {
  const auto routes = parseProcNetRoute(kHeader + kDefaultRoute + kMulticastRoute);
  const CheckResult result = checkMulticastRoute(routes, kLcmGroup, false);
  EXPECT_EQ(result.status, CheckStatus::kFail);
  EXPECT_TRUE(contains(result.detail, "MULTICAST")) << result.detail;
  ASSERT_EQ(result.fix.size(), 1u);
  EXPECT_EQ(result.fix[0], "sudo ip link set lo multicast on");
}

// No route at all fails, with fixes that set the flag and add the multicast route on lo.
TEST(CheckMulticastRoute, FailsWithNoRoute) {
  const auto routes = parseProcNetRoute(kHeader + kSubnetRoute);
  for (const bool flag : {true, false}) {
    SCOPED_TRACE(flag);
    const CheckResult result = checkMulticastRoute(routes, kLcmGroup, flag);
    EXPECT_EQ(result.status, CheckStatus::kFail);
    EXPECT_TRUE(contains(result.detail, "239.255.76.67")) << result.detail;
    EXPECT_TRUE(anyContains(result.fix, "ip route add 224.0.0.0/4 dev lo"));
    EXPECT_TRUE(anyContains(result.fix, "ip link set lo multicast on"));
  }
  EXPECT_EQ(checkMulticastRoute({}, kLcmGroup, true).status, CheckStatus::kFail);
}

// Multicast going out by the default route is OK, and the detail says it is the default route.
TEST(CheckMulticastRoute, OkThroughDefaultRoute) {
  const auto routes = parseProcNetRoute(kHeader + kDefaultRoute + kSubnetRoute);
  for (const bool flag : {true, false}) {
    SCOPED_TRACE(flag);
    const CheckResult result = checkMulticastRoute(routes, kLcmGroup, flag);
    EXPECT_EQ(result.status, CheckStatus::kOk);
    EXPECT_TRUE(contains(result.detail, "0.0.0.0/0 dev eth0")) << result.detail;
    EXPECT_TRUE(contains(result.detail, "default route")) << result.detail;
    EXPECT_TRUE(result.fix.empty());
  }
}

// Debian's default 212992-byte buffers fail, with the sysctl commands that raise them.
TEST(CheckReceiveBuffers, DebianDefaultFails) {
  const CheckResult result = checkReceiveBuffers(212992, 212992);
  EXPECT_EQ(result.status, CheckStatus::kFail);
  EXPECT_FALSE(result.name.empty());
  EXPECT_TRUE(contains(result.detail, "208 KiB")) << result.detail;
  EXPECT_TRUE(anyContains(result.fix,
                          "sysctl -w net.core.rmem_max=268435456 net.core.rmem_default=268435456"));
  EXPECT_TRUE(anyContains(result.fix, "/etc/sysctl.d/"));
}

// 256 MiB for both passes with nothing to fix; so does exactly the minimum.
TEST(CheckReceiveBuffers, LargeBuffersPass) {
  const CheckResult result =
      checkReceiveBuffers(kRecommendedReceiveBufferBytes, kRecommendedReceiveBufferBytes);
  EXPECT_EQ(result.status, CheckStatus::kOk);
  EXPECT_TRUE(contains(result.detail, "256 MiB")) << result.detail;
  EXPECT_TRUE(result.fix.empty());
  EXPECT_EQ(checkReceiveBuffers(268435456, 268435456).status, CheckStatus::kOk);
  EXPECT_EQ(checkReceiveBuffers(kMinimumReceiveBufferBytes, kMinimumReceiveBufferBytes).status,
            CheckStatus::kOk);
  EXPECT_EQ(checkReceiveBuffers(kMinimumReceiveBufferBytes - 1, kMinimumReceiveBufferBytes).status,
            CheckStatus::kFail);
}

// A large rmem_max does not help when rmem_default is small, and the other way round.
TEST(CheckReceiveBuffers, EitherSmallValueFails) {
  const CheckResult result = checkReceiveBuffers(kRecommendedReceiveBufferBytes, 212992);
  EXPECT_EQ(result.status, CheckStatus::kFail);
  EXPECT_FALSE(result.fix.empty());
  EXPECT_EQ(checkReceiveBuffers(212992, kRecommendedReceiveBufferBytes).status, CheckStatus::kFail);
}

// Dotted addresses parse to host order and format back unchanged.
TEST(Ipv4, ParseFormatRoundTrip) {
  EXPECT_EQ(parseIpv4("239.255.76.67"), kLcmGroup);
  EXPECT_EQ(parseIpv4("224.0.0.0"), 0xE0000000u);
  EXPECT_EQ(parseIpv4("0.0.0.0"), 0u);
  EXPECT_EQ(parseIpv4("255.255.255.255"), 0xFFFFFFFFu);
  EXPECT_EQ(formatIpv4(0xC0A80007u), "192.168.0.7");
  for (const std::string address :
       {"239.255.76.67", "0.0.0.0", "255.255.255.255", "10.0.0.1", "192.168.0.7", "8.8.8.8"}) {
    EXPECT_EQ(formatIpv4(parseIpv4(address)), address);
  }
}

// Malformed addresses throw std::invalid_argument.
TEST(Ipv4, MalformedAddressThrows) {
  for (const std::string address :
       {"1.2.3", "256.0.0.1", "1.2.3.256", "", "a.b.c.d", "1..2.3", "1,2,3,4", "-1.2.3.4",
        "1.2.3.4.5", "1.2.3.4x", " 1.2.3.4", "1. 2.3.4", "0001.2.3.4"}) {
    SCOPED_TRACE(address);
    EXPECT_THROW(parseIpv4(address), std::invalid_argument);
  }
}

// Prefix lengths count the mask's bits.
TEST(Ipv4, PrefixLength) {
  EXPECT_EQ(prefixLength(0), 0);
  EXPECT_EQ(prefixLength(0xF0000000u), 4);
  EXPECT_EQ(prefixLength(0xFFFFFF00u), 24);
  EXPECT_EQ(prefixLength(0xFFFFFFFFu), 32);
}

// A bus that leaves the host is a warning naming its ttl; ttl=0 (given or
// not) stays here; a URL that is not udpm is only noted.
TEST(CheckExposure, WarnsWhenTheBusLeavesTheHost) {
  EXPECT_EQ(checkExposure("udpm://239.255.76.67:7667?ttl=0").status, CheckStatus::kOk);
  EXPECT_EQ(checkExposure("udpm://239.255.76.67:7667").status, CheckStatus::kOk);
  EXPECT_EQ(checkExposure("memq://").status, CheckStatus::kInfo);
  const CheckResult link = checkExposure("udpm://239.255.76.67:7667?recv_buf_size=4096&ttl=1");
  EXPECT_EQ(link.status, CheckStatus::kWarn);
  EXPECT_NE(link.detail.find("ttl=1, every message leaves this host for the local network"),
            std::string::npos)
      << link.detail;
  EXPECT_FALSE(link.fix.empty());
  EXPECT_NE(checkExposure("udpm://239.255.76.67:7667?ttl=16").detail.find("crosses routers"),
            std::string::npos);
}

}  // namespace
}  // namespace nadir::cli
