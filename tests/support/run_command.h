#pragma once
// Runs a shell command for the tests of the programs: its exit status (-1 if
// it did not exit) and what it wrote on stdout and stderr.

#include <sys/wait.h>

#include <cstdio>
#include <string>
#include <utility>

namespace nadir::test {

inline std::pair<int, std::string> runCommand(const std::string& command) {
  std::string output;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return {-1, ""};
  char buffer[4096];
  while (std::fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

// A process that has not exited (a zombie has: only its parent has not yet
// collected it).
inline bool processAlive(long pid) {
  FILE* stat = std::fopen(("/proc/" + std::to_string(pid) + "/stat").c_str(), "r");
  if (stat == nullptr) return false;
  char line[512] = {};
  const std::size_t n = std::fread(line, 1, sizeof(line) - 1, stat);
  std::fclose(stat);
  const std::string text(line, n);
  const std::size_t close = text.rfind(')');
  return close == std::string::npos || close + 2 >= text.size() || text[close + 2] != 'Z';
}

}  // namespace nadir::test
