// Every program's command line: --help prints its usage and exits 0; a usage
// error (an unknown option, a missing argument, a value out of range) says what
// is wrong and exits 2; a failure of the work itself exits 1.
#include <gtest/gtest.h>

#include <string>

#include "tests/support/run_command.h"

namespace nadir {
namespace {

std::pair<int, std::string> run(const std::string& program, const std::string& arguments) {
  return test::runCommand(std::string("'") + NADIR_BIN_DIR + "/" + program + "' " + arguments +
                          " </dev/null");
}

TEST(Usage, HelpExitsZeroWithTheUsage) {
  for (const char* program : {"nadir", "nadir-sim", "nadir-camera", "nadir-vo-feature"}) {
    const auto [status, output] = run(program, "--help");
    EXPECT_EQ(status, 0) << program << "\n" << output;
    EXPECT_NE(output.find("Usage:"), std::string::npos) << program << "\n" << output;
  }
  const auto [status, output] = run("nadir", "export --help");
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("--frame"), std::string::npos) << output;
}

TEST(Usage, UsageErrorsExitTwoAndSayWhatIsWrong) {
  const auto unknown = run("nadir", "run --no-such-option");
  EXPECT_EQ(unknown.first, 2) << unknown.second;
  EXPECT_NE(unknown.second.find("--no-such-option"), std::string::npos) << unknown.second;
  const auto missing = run("nadir", "export");
  EXPECT_EQ(missing.first, 2) << missing.second;
  EXPECT_NE(missing.second.find("RUN_DIR"), std::string::npos) << missing.second;
  const auto frame = run("nadir", "export somewhere --format euroc --frame nwu");
  EXPECT_EQ(frame.first, 2) << frame.second;
  EXPECT_NE(frame.second.find("nwu"), std::string::npos) << frame.second;
  const auto node = run("nadir-sim", "--no-such-option");
  EXPECT_EQ(node.first, 2) << node.second;
}

TEST(Usage, AFailureOfTheWorkExitsOne) {
  const auto [status, output] = run("nadir", "eval /nonexistent/run");
  EXPECT_EQ(status, 1) << output;
  EXPECT_NE(output.find("nadir: error: /nonexistent/run"), std::string::npos) << output;
}

}  // namespace
}  // namespace nadir
