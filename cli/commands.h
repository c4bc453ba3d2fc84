#pragma once
// The verbs of the nadir command. Each registers its subcommand, options and a
// callback that does the work; main.cpp only calls these. A callback ends
// with a non-zero exit status by throwing CLI::RuntimeError(status) (printed
// nothing more) and reports an error by throwing any std::exception (printed
// as "nadir: error: ...", exit status 1).

namespace CLI {
class App;
}

namespace nadir::run {
struct RunResult;
struct RunProgress;
}  // namespace nadir::run

namespace nadir::cli {

void addDoctorCommand(CLI::App& app);
void addDemoCommand(CLI::App& app);
void addSnapshotCommand(CLI::App& app);
void addExportCommand(CLI::App& app);
void addRunCommand(CLI::App& app);
void addLaunchCommand(CLI::App& app);
void addBusCommands(CLI::App& app);
void addSweepCommand(CLI::App& app);
void addLogCommands(CLI::App& app);
void addEvalCommand(CLI::App& app);
void addVoCommands(CLI::App& app);
void addCalibCommand(CLI::App& app);
void addSpyCommand(CLI::App& app);

// nadir run's and nadir demo's progress line, on stderr, and its end.
void printRunProgress(const run::RunProgress& progress);
void endRunProgress();
// The results table and the files a run wrote; then the run's charts
// (nadir-plot --headless into RUN_DIR/plots) and where they are.
void finishRun(const run::RunResult& result);

}  // namespace nadir::cli
