#pragma once
// The verbs of the nadir command. Each registers its subcommand, options and a
// callback that does the work; main.cpp only calls these. A callback ends
// with a non-zero exit status by throwing CLI::RuntimeError(status) (printed
// nothing more) and reports an error by throwing any std::exception (printed
// as "nadir: error: ...", exit status 1).

namespace CLI {
class App;
}

namespace nadir::cli {

void addDoctorCommand(CLI::App& app);
void addDemoCommand(CLI::App& app);
void addSnapshotCommand(CLI::App& app);

}  // namespace nadir::cli
