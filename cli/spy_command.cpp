// nadir spy: LCM's lcm-spy with nadir's message types on its class path, so
// that it decodes every nadir channel. Started with a JVM invocation current
// JVMs accept: Debian's lcm-spy script passes -Xincgc, which they refuse.
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/bus.h"
#include "run/process.h"

namespace nadir::cli {
namespace {

namespace fs = std::filesystem;

constexpr char kTypesJar[] = "nadir-lcmtypes.jar";

struct SpyOptions {
  std::string url;
  bool print_command = false;
};

// $JAVA_HOME's java, else java from PATH.
std::string javaProgram() {
  if (const char* home = std::getenv("JAVA_HOME"); home != nullptr && *home != '\0') {
    const fs::path java = fs::path(home) / "bin" / "java";
    if (access(java.c_str(), X_OK) == 0) return java.string();
    throw std::runtime_error("JAVA_HOME is " + std::string(home) + " but " + java.string() +
                             " is no program");
  }
  return "java";
}

// nadir's jar, built beside bin/ (share/java), and the jars it needs, named in
// the file beside it.
std::vector<std::string> spyClassPath() {
  const fs::path jar = fs::path(run::selfDirectory()).parent_path() / "share" / "java" / kTypesJar;
  if (!fs::exists(jar)) {
    throw std::runtime_error("no " + jar.string() +
                             ": it is built when a JDK and LCM's Java library are installed "
                             "(./nadir setup installs them; then build again)");
  }
  std::vector<std::string> class_path;
  std::ifstream needed(jar.string() + ".classpath");
  std::string line;
  while (std::getline(needed, line)) {
    if (line.empty()) continue;
    if (!fs::exists(line)) {
      throw std::runtime_error("lcm-spy needs " + line + ", which is gone (liblcm-java, " +
                               "libjchart2d-java); ./nadir setup installs them");
    }
    class_path.push_back(line);
  }
  if (class_path.empty())
    throw std::runtime_error("no lcm.jar named in " + jar.string() + ".classpath");
  class_path.push_back(jar.string());
  return class_path;
}

void runSpy(const SpyOptions& options) {
  const std::string url = options.url.empty() ? core::defaultBusUrl() : options.url;
  std::string class_path;
  for (const std::string& entry : spyClassPath()) {
    class_path += (class_path.empty() ? "" : ":") + entry;
  }
  const std::vector<std::string> command = {javaProgram(), "-Djava.net.preferIPv4Stack=true",
                                            "-Xmx512m",    "-ea",
                                            "-cp",         class_path,
                                            "lcm.spy.Spy", "--lcm-url=" + url};
  if (options.print_command) {
    std::cout << run::shellLine(command) << "\n";
    return;
  }
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((display == nullptr || *display == '\0') && (wayland == nullptr || *wayland == '\0')) {
    throw std::runtime_error(
        "lcm-spy is a window and DISPLAY is not set (over ssh: ssh -X; headless: xvfb-run -a "
        "nadir spy)");
  }
  std::cerr << "nadir spy: lcm-spy on " << url << ", decoding nadir's types" << std::endl;
  std::vector<char*> argv;
  for (const std::string& word : command) argv.push_back(const_cast<char*>(word.c_str()));
  argv.push_back(nullptr);
  execvp(argv[0], argv.data());
  if (errno == ENOENT) {
    throw std::runtime_error("no " + command.front() +
                             " on PATH: ./nadir setup installs one (default-jdk-headless)");
  }
  throw std::runtime_error("cannot start " + command.front() + ": " + std::strerror(errno));
}

}  // namespace

void addSpyCommand(CLI::App& app) {
  auto options = std::make_shared<SpyOptions>();
  CLI::App* spy = app.add_subcommand(
      "spy", "LCM's lcm-spy, decoding nadir's messages: every channel, its rate and its fields");
  spy->add_option("--url", options->url, "Bus to watch; default $LCM_DEFAULT_URL or nadir's");
  spy->add_flag("--print-command", options->print_command,
                "Print the Java command instead of running it");
  spy->callback([options] { runSpy(*options); });
}

}  // namespace nadir::cli
