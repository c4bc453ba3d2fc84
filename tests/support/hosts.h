#pragma once
// Hosts for the tests of nadir across machines: network namespaces on this
// machine, each with lo up and an eth0 on a bridge that stands in a namespace
// of its own (nothing of the machine's own network is touched), an address
// 10.213.S.N/24 and a multicast route, so that LCM over udpm://...?ttl=1
// crosses from one to another as between machines on a LAN, and ttl=0 stays
// on its host. Made by the constructor and removed by the destructor; the
// namespaces' names carry the owner's pid, so that those of a test killed
// before its destructor ran are removed by the next fixture. Needs root and
// iproute2's ip: available() says whether they are there, whyNot() what is
// missing.

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/run_command.h"

namespace nadir::test {

class TestHosts {
 public:
  explicit TestHosts(int count) {
    if (geteuid() != 0) {
      why_not_ = "hosts need root to make network namespaces (run as root, as CI does)";
      return;
    }
    if (runCommand("ip -V").first != 0) {
      why_not_ = "hosts need iproute2's ip (./nadir setup installs it)";
      return;
    }
    removeStale();
    static int instance = 0;
    const int pid = static_cast<int>(getpid());
    tag_ = "nadirh" + std::to_string(pid) + "x" + std::to_string(instance++);
    subnet_ = 1 + (pid + instance * 37) % 250;
    const std::string sw = tag_ + "sw";
    std::vector<std::string> commands = {
        "ip netns add " + sw,
        "ip -n " + sw + " link add br0 type bridge mcast_snooping 0",
        "ip -n " + sw + " link set br0 up",
    };
    for (int i = 0; i < count; ++i) {
      const std::string host = name(i), port = "p" + std::to_string(i);
      commands.push_back("ip netns add " + host);
      commands.push_back("ip -n " + sw + " link add " + port + " type veth peer name eth0 netns " +
                         host);
      commands.push_back("ip -n " + sw + " link set " + port + " master br0 up");
      commands.push_back("ip -n " + host + " link set lo up");
      commands.push_back("ip -n " + host + " link set eth0 up");
      commands.push_back("ip -n " + host + " addr add " + address(i) + "/24 dev eth0");
      commands.push_back("ip -n " + host + " route add 224.0.0.0/4 dev eth0");
      names_.push_back(host);
    }
    names_.push_back(sw);
    for (const std::string& command : commands) {
      const auto [status, output] = runCommand(command);
      if (status != 0) {
        why_not_ = "could not make the hosts: '" + command + "' failed: " + output;
        removeAll();
        return;
      }
    }
  }
  ~TestHosts() { removeAll(); }
  TestHosts(const TestHosts&) = delete;
  TestHosts& operator=(const TestHosts&) = delete;

  bool available() const { return why_not_.empty(); }
  const std::string& whyNot() const { return why_not_; }
  // Host i's namespace, the prefix that runs a command on it, and its address.
  std::string name(int i) const { return tag_ + "h" + std::to_string(i); }
  std::string prefix(int i) const { return "ip netns exec " + name(i) + " "; }
  std::string address(int i) const {
    return "10.213." + std::to_string(subnet_) + "." + std::to_string(i + 1);
  }

 private:
  void removeAll() {
    for (const std::string& ns : names_) runCommand("ip netns del " + ns);
    names_.clear();
  }
  // Namespaces of fixtures whose process is gone.
  static void removeStale() {
    const auto [status, output] = runCommand("ip netns list");
    if (status != 0) return;
    std::istringstream lines(output);
    std::string ns;
    while (lines >> ns) {
      if (ns.rfind("nadirh", 0) != 0) continue;
      const long pid = std::strtol(ns.c_str() + 6, nullptr, 10);
      if (pid > 0 && !processAlive(pid)) runCommand("ip netns del " + ns);
      std::string rest;
      std::getline(lines, rest);  // "(id: N)" after the name
    }
  }

  std::string tag_;
  int subnet_ = 1;
  std::vector<std::string> names_;
  std::string why_not_;
};

}  // namespace nadir::test
