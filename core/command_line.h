#pragma once
// Every nadir program's command line, parsed the same way (CLI11): --help and
// --version print and exit 0; a usage error (an unknown option, a missing or
// impossible value) prints what is wrong and exits 2, as POSIX tools do, apart
// from the program's own failures (exit 1).
#include <CLI/CLI.hpp>

#include <optional>

namespace nadir::core {

inline constexpr int kUsageErrorExit = 2;

// The status for a ParseError thrown by app (printed here): a callback's own
// CLI::RuntimeError(status) keeps its status.
inline int exitAfter(CLI::App& app, const CLI::ParseError& error) {
  const int status = app.exit(error);
  if (status == 0 || dynamic_cast<const CLI::RuntimeError*>(&error) != nullptr) return status;
  return kUsageErrorExit;
}

// Nothing when the program goes on; otherwise the status it should exit with.
inline std::optional<int> parseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return exitAfter(app, error);
  }
  return std::nullopt;
}

}  // namespace nadir::core
