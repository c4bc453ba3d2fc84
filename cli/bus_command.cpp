// nadir bus check: one host's part in the check that the bus joins every host
// of a launch (run/bus_check.h); nadir launch --hosts runs it on each host.
#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/bus.h"
#include "run/bus_check.h"

namespace nadir::cli {
namespace {

struct BusCheckOptions {
  std::string url;
  std::int64_t launch_id = 0;
  std::string host;
  std::vector<std::string> hosts;
  double timeout_s = 20.0;
  double linger_s = 1.0;
};

}  // namespace

void addBusCommands(CLI::App& app) {
  CLI::App* bus = app.add_subcommand("bus", "Checks of the LCM bus");
  bus->require_subcommand(1);
  auto options = std::make_shared<BusCheckOptions>();
  CLI::App* check = bus->add_subcommand(
      "check",
      "Say who this host is and whom it hears, until every host of the check has heard every "
      "other (what nadir launch --hosts runs on each host before a flight)");
  check->add_option("--url", options->url, "the bus (default $LCM_DEFAULT_URL or LCM's)");
  check->add_option("--launch-id", options->launch_id, "the launch this check belongs to")
      ->required();
  check->add_option("--host", options->host, "this host's name")->required();
  check->add_option("--hosts", options->hosts, "every host of the check, this one among them")
      ->delimiter(',')
      ->required();
  check->add_option("--timeout", options->timeout_s, "give up after this long, s")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  check->add_option("--linger", options->linger_s, "keep saying so this long once complete, s")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  check->callback([options] {
    const std::unique_ptr<core::Bus> bus_handle =
        core::openBus(options->url.empty() ? core::defaultBusUrl() : options->url);
    std::vector<std::string> missing;
    const std::set<std::string> hosts(options->hosts.begin(), options->hosts.end());
    const bool complete = run::runBusCheck(*bus_handle, options->launch_id, options->host, hosts,
                                           options->timeout_s, options->linger_s, &missing);
    if (complete) {
      std::cout << "nadir bus check: " << options->host << " hears every host on "
                << bus_handle->url() << "\n";
      return;
    }
    std::cout << "nadir bus check: " << options->host << " on " << bus_handle->url() << ", after "
              << options->timeout_s << " s:";
    for (const std::string& link : missing) std::cout << "\n  " << link;
    std::cout << std::endl;
    throw CLI::RuntimeError(1);
  });
}

}  // namespace nadir::cli
