// nadir-plot as a program: its exit codes and the files --headless writes.

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "gui_test_util.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

int runPlot(const std::string& arguments) {
  const std::string command = std::string(NADIR_PLOT_BIN) + " " + arguments + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(GuiPlotCli, HeadlessWritesThePngsAndTheResultsTable) {
  const fs::path run = test::writeTumRun("cli_run");
  const fs::path out = test::freshDir("cli_out") / "plots";
  ASSERT_EQ(runPlot("--headless " + run.string() + " --out " + out.string()), 0);
  for (const char* name : {"position.png", "attitude.png", "error.png", "top_view.png"}) {
    EXPECT_GT(fs::file_size(out / name), 1000u) << name;
  }
  std::ifstream csv(out / "results.csv");
  const std::string text((std::istreambuf_iterator<char>(csv)), {});
  // Position RMSE 5 m (every error is |(3, 4, 0)|), no rotation error, 95 % tracked.
  EXPECT_EQ(text.rfind("source,position_rmse_m,rotation_rmse_deg,tracked_pct,", 0), 0u) << text;
  EXPECT_NE(text.find("\nvo_test,5,"), std::string::npos) << text;
}

TEST(GuiPlotCli, HeadlessRendersEveryRunOfATree) {
  const fs::path root = test::freshDir("cli_tree");
  fs::create_directories(root / "cell_a");
  fs::create_directories(root / "cell_b");
  for (const char* cell : {"cell_a", "cell_b"}) {
    fs::copy(test::writeTumRun(std::string("cli_tree_") + cell), root / cell);
  }
  const fs::path out = test::freshDir("cli_tree_out");
  ASSERT_EQ(runPlot("--headless " + root.string() + " --out " + out.string()), 0);
  EXPECT_TRUE(fs::exists(out / "cell_a" / "top_view.png"));
  EXPECT_TRUE(fs::exists(out / "cell_b" / "results.csv"));
}

// A loose log in a tree is plotted into a folder named after it.
TEST(GuiPlotCli, HeadlessRendersALooseLog) {
  const fs::path root = test::freshDir("cli_logs");
  fs::create_directories(root / "flights");
  fs::copy_file(test::writeLogRun("cli_log_run") / "run.lcmlog", root / "flights" / "a.lcmlog");
  const fs::path out = test::freshDir("cli_logs_out");
  ASSERT_EQ(runPlot("--headless " + root.string() + " --out " + out.string()), 0);
  std::ifstream csv(out / "flights" / "a" / "results.csv");
  const std::string text((std::istreambuf_iterator<char>(csv)), {});
  // Every error is |(3, 4, 0)| = 5 m, to the microsecond the log's stamps keep.
  const std::size_t row = text.find("\nvo_feature,");
  ASSERT_NE(row, std::string::npos) << text;
  EXPECT_NEAR(std::stod(text.substr(row + 12)), 5.0, 1e-6) << text;
  EXPECT_TRUE(fs::exists(out / "flights" / "a" / "top_view.png"));
}

// --truth vo_test: the table holds the recorded truth against vo_test, 5 m off.
TEST(GuiPlotCli, HeadlessComparesWithTheTruthGiven) {
  const fs::path run = test::writeTumRun("cli_truth");
  const fs::path out = test::freshDir("cli_truth_out");
  ASSERT_EQ(runPlot("--headless " + run.string() + " --out " + out.string() + " --truth vo_test"),
            0);
  std::ifstream csv(out / "results.csv");
  const std::string text((std::istreambuf_iterator<char>(csv)), {});
  EXPECT_NE(text.find("\ntruth,5,"), std::string::npos) << text;
  EXPECT_EQ(text.find("\nvo_test,"), std::string::npos) << text;
  // A truth the run does not have fails, and writes no table.
  const fs::path none = test::freshDir("cli_truth_none");
  EXPECT_EQ(runPlot("--headless " + run.string() + " --out " + none.string() + " --truth vo_nope"),
            1);
  EXPECT_FALSE(fs::exists(none / "results.csv"));
}

// The window from the command line: a run and a figure chosen, saved as PNG.
TEST(GuiPlotCli, WindowScreenshotOfAChosenRunAndFigure) {
  const fs::path root = test::freshDir("cli_window");
  fs::create_directories(root / "sweep");
  fs::copy(test::writeTumRun("cli_window_a"), root / "sweep" / "a");
  fs::copy(test::writeTumRun("cli_window_b"), root / "sweep" / "b");
  const fs::path png = root / "window.png";
  const std::string window = "env QT_QPA_PLATFORM=offscreen " + std::string(NADIR_PLOT_BIN) + " " +
                             root.string() + " --screenshot " + png.string();
  const auto run = [](const std::string& command) {
    const int status = std::system((command + " >/dev/null 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  ASSERT_EQ(run(window + " --run sweep/b --figure top_view --wait 0.2"), 0);
  EXPECT_GT(fs::file_size(png), 10000u);
  fs::remove(png);
  EXPECT_EQ(run(window + " --run sweep/c"), 1);               // no such run
  EXPECT_EQ(run(window + " --figure sideways"), 1);           // no such figure
  EXPECT_EQ(run(window + " --truth vo_nope --wait 0.2"), 0);  // a preference, not an error
  EXPECT_TRUE(fs::exists(png));
}

TEST(GuiPlotCli, BadInputFails) {
  const fs::path empty = test::freshDir("cli_empty");
  const fs::path out = test::freshDir("cli_bad_out");
  EXPECT_EQ(runPlot("--headless " + (empty / "missing").string() + " --out " + out.string()), 1);
  EXPECT_EQ(runPlot("--headless " + empty.string() + " --out " + out.string()), 1);  // no run
  EXPECT_EQ(runPlot("--headless " + empty.string()), 1);                             // no --out
  const fs::path damaged = test::writeTumRun("cli_damaged");
  std::ofstream(damaged / "truth.tum", std::ios::app) << "oops\n";
  EXPECT_EQ(runPlot("--headless " + damaged.string() + " --out " + out.string()), 1);
  // The window needs a folder or a log, and --out is for --headless only.
  EXPECT_EQ(runPlot((empty / "missing").string()), 1);
  EXPECT_EQ(runPlot(empty.string() + " --out " + out.string()), 1);
  // --screenshot is for the window.
  EXPECT_EQ(
      runPlot("--headless " + damaged.string() + " --out " + out.string() + " --screenshot x.png"),
      1);
}

}  // namespace
}  // namespace nadir::gui
