// nadir vo reset: one RESET on VO_COMMAND (cli/vo_reset.h), and what was sent.
#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/vo_reset.h"
#include "core/bus.h"

namespace nadir::cli {

void addVoCommands(CLI::App& app) {
  CLI::App* vo = app.add_subcommand("vo", "Commands to the live VO nodes (vo_command_t)");
  vo->require_subcommand(1);
  auto options = std::make_shared<VoResetOptions>();
  CLI::App* reset = vo->add_subcommand(
      "reset",
      "Restart a VO node (or every one): its map dropped, from the truth's next pose, a pose "
      "given, or the pose it estimates now");
  addVoResetOptions(*reset, *options);
  reset->callback([options] {
    // Checked before the bus opens: a wrong name is no network problem.
    checkVoResetOptions(*options, resettableSources());
    const std::unique_ptr<core::Bus> bus = core::openBus(options->url);
    if (options->to_truth) {
      std::cout << "nadir vo reset: waiting for the truth on " << options->truth_channel << " ("
                << bus->url() << ")" << std::endl;
    }
    const msg::VoCommand command = sendVoReset(*bus, *options);
    std::cout << "nadir vo reset: sent " << describeCommand(command, options->channel) << " ("
              << bus->url() << ")\n";
  });
}

}  // namespace nadir::cli
