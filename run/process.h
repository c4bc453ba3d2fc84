#pragma once
// A child program with its output in a log file: started, polled, stopped
// (SIGINT, then SIGKILL after a grace period). Used by launch and sweep.

#include <sys/types.h>

#include <string>
#include <vector>

namespace nadir::run {

// The folder of the running program (where its sibling programs are); "." if unknown.
std::string selfDirectory();

// Runs a program to its end (found on PATH if argv[0] has no slash) and
// returns its exit status (as a shell reports it) and what it wrote on stdout
// and stderr. Throws std::runtime_error when it cannot start.
struct CommandOutput {
  int status = -1;
  std::string output;
};
CommandOutput runAndCapture(const std::vector<std::string>& argv);

// Splits text as a shell would split words (single and double quotes,
// backslash); throws std::invalid_argument for an unclosed quote.
std::vector<std::string> splitWords(const std::string& text);
// One word for a POSIX shell: 'it'\''s' style quoting where needed.
std::string shellQuote(const std::string& word);
// Words as one line a POSIX shell splits back into the same words.
std::string shellLine(const std::vector<std::string>& words);

class ChildProcess {
 public:
  ChildProcess(std::string name, std::vector<std::string> argv, std::string log_path);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Starts the program (found on PATH if argv[0] has no slash), stdout and
  // stderr to the log file, stdin from /dev/null. Throws std::runtime_error.
  void start();
  // Reaps the child if it has exited; true while it runs.
  bool running();
  // SIGINT, then SIGKILL after grace_s; no-op if not running.
  void stop(double grace_s);

  const std::string& name() const { return name_; }
  const std::string& logPath() const { return log_path_; }
  bool started() const { return pid_ > 0; }
  // As a shell reports it: the exit code, or 128 + the signal.
  int exitStatus() const { return exit_status_; }
  bool stoppedByUs() const { return stopped_by_us_; }
  // "exit status 3" or "killed by signal 9".
  std::string describeExit() const;
  // The last line the program wrote (its log's), at most 300 bytes; empty if none.
  std::string lastWords() const;

 private:
  std::string name_;
  std::vector<std::string> argv_;
  std::string log_path_;
  pid_t pid_ = -1;
  bool running_ = false;
  int exit_status_ = 0;
  bool stopped_by_us_ = false;
};

}  // namespace nadir::run
