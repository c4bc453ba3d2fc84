// nadir sweep: resumed (only the cells not done run again), and on a real
// single-node Slurm cluster (tests/support/slurm_cluster.h) as a job array
// and a merge job whose table equals a local sweep's, each cell's
// metrics.json byte for byte. The cluster needs root and Debian's Slurm and
// munge; elsewhere those tests are skipped with the reason.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "run/slurm.h"
#include "tests/support/run_command.h"
#include "tests/support/slurm_cluster.h"

namespace nadir::test {
namespace {

namespace fs = std::filesystem;

const std::string kNadir = (fs::path(NADIR_BIN_DIR) / "nadir").string();
const std::string kQuick = (fs::path(NADIR_SOURCE_DIR) / "scenarios/sweeps/quick.yaml").string();
// quick.yaml's four cells, each a 20 s flight.
constexpr char kShort[] = " --set duration_s=20";

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

fs::path tempDir(const std::string& name) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("nadir_sweep_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  return dir;
}

std::vector<fs::path> cellDirs(const fs::path& out) {
  std::vector<fs::path> cells;
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.is_directory() && entry.path().filename().string().rfind("cell_", 0) == 0) {
      cells.push_back(entry.path());
    }
  }
  std::sort(cells.begin(), cells.end());
  return cells;
}

// Run again, a sweep runs only the cells not done: the one whose metrics.json
// is gone, and all four once the command of every cell changes.
TEST(Sweep, RunsOnlyTheCellsNotDone) {
  const fs::path out = tempDir("resume");
  const std::string sweep = kNadir + " sweep " + kQuick + " --out " + out.string() + kShort;
  const auto [first_status, first] = runCommand(sweep);
  ASSERT_EQ(first_status, 0) << first;
  const std::vector<fs::path> cells = cellDirs(out);
  ASSERT_EQ(cells.size(), 4u);
  const std::string table = readText(out / "results.csv");
  std::vector<fs::file_time_type> ran_at;
  for (const fs::path& cell : cells) ran_at.push_back(fs::last_write_time(cell / "run.out"));

  fs::remove(cells[2] / "metrics.json");
  const auto [second_status, second] = runCommand(sweep);
  ASSERT_EQ(second_status, 0) << second;
  EXPECT_NE(second.find("sweep: 4/4 done (3 before)"), std::string::npos) << second;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    EXPECT_EQ(fs::last_write_time(cells[i] / "run.out") == ran_at[i], i != 2) << cells[i];
  }
  EXPECT_EQ(readText(out / "results.csv"), table);

  const auto [third_status, third] = runCommand(sweep + " --set camera.fps=4");
  ASSERT_EQ(third_status, 0) << third;
  EXPECT_NE(third.find("sweep: 4/4 done,"), std::string::npos) << third;
  EXPECT_EQ(third.find("before"), std::string::npos) << third;
  fs::remove_all(out);
}

// The scripts say what each cell asks for, and the array holds only the cells not done.
TEST(SweepOnSlurm, ScriptsAskForTheSweepsResources) {
  const fs::path dir = tempDir("scripts");
  fs::create_directories(dir);
  std::ofstream(dir / "sweep.yaml") << "scenario: default\n"
                                       "out: "
                                    << (dir / "out").string()
                                    << "\n"
                                       "axes: {camera.fps: [5, 10, 20]}\n"
                                       "slurm: {cpus_per_task: 3, mem: 6G, time: \"00:20:00\", "
                                       "partition: gpu, extra: [--qos=low]}\n";
  const auto [status, output] =
      runCommand(kNadir + " sweep " + (dir / "sweep.yaml").string() + " --slurm");
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("3 of 3 cells to run"), std::string::npos) << output;
  const std::string cells = readText(dir / "out" / "slurm" / "cells.sbatch");
  for (const char* line :
       {"#SBATCH --array=0-2\n", "#SBATCH --cpus-per-task=3\n", "#SBATCH --mem=6G\n",
        "#SBATCH --time=00:20:00\n", "#SBATCH --partition=gpu\n", "#SBATCH --qos=low\n",
        " --cell \"$SLURM_ARRAY_TASK_ID\"\n"}) {
    EXPECT_NE(cells.find(line), std::string::npos) << line << " in\n" << cells;
  }
  EXPECT_NE(cells.find("/slurm/logs/cell_%a.out"), std::string::npos) << cells;
  const std::string merge = readText(dir / "out" / "slurm" / "merge.sbatch");
  EXPECT_NE(merge.find(" --tabulate\n"), std::string::npos) << merge;
  const std::string submit = readText(dir / "out" / "slurm" / "submit.sh");
  EXPECT_NE(submit.find("--dependency=afterany:"), std::string::npos) << submit;
  EXPECT_EQ(run::arrayRanges({0, 1, 2, 4, 6, 7, 9}), "0-2,4,6-7,9");
  fs::remove_all(dir);
}

// On the cluster: the merged table is the local sweep's, each cell's
// metrics byte for byte; resumed after a cell is lost, the array holds that
// cell alone and the table comes out the same again.
TEST(SweepOnSlurm, MergedTableEqualsTheLocalSweep) {
  SlurmCluster cluster;
  ASSERT_FALSE(cluster.startFailed()) << cluster.whyNot();
  if (!cluster.available()) GTEST_SKIP() << cluster.whyNot();
  const fs::path local = tempDir("local"), on_slurm = tempDir("slurm");
  const auto [local_status, local_output] =
      runCommand(kNadir + " sweep " + kQuick + " --out " + local.string() + kShort);
  ASSERT_EQ(local_status, 0) << local_output;

  const std::string slurm_sweep = cluster.env() + kNadir + " sweep " + kQuick + " --out " +
                                  on_slurm.string() + kShort + " --slurm --submit --wait";
  const auto [status, output] = runCommand(slurm_sweep);
  ASSERT_EQ(status, 0) << output << readText(on_slurm / "slurm" / "logs" / "merge.out");
  EXPECT_NE(output.find("4 of 4 cells to run"), std::string::npos) << output;
  EXPECT_NE(output.find("sweep: 4/4 done, 0 failed, 0 running, 0 waiting"), std::string::npos)
      << output;
  const std::vector<fs::path> local_cells = cellDirs(local), slurm_cells = cellDirs(on_slurm);
  ASSERT_EQ(local_cells.size(), 4u);
  ASSERT_EQ(slurm_cells.size(), 4u);
  for (std::size_t i = 0; i < local_cells.size(); ++i) {
    EXPECT_EQ(local_cells[i].filename(), slurm_cells[i].filename());
    EXPECT_EQ(readText(slurm_cells[i] / "metrics.json"), readText(local_cells[i] / "metrics.json"))
        << slurm_cells[i];
    EXPECT_TRUE(fs::exists(on_slurm / "slurm" / "logs" / ("cell_" + std::to_string(i) + ".out")));
  }
  EXPECT_EQ(readText(on_slurm / "results.csv"), readText(local / "results.csv"));
  EXPECT_EQ(readText(on_slurm / "results.md"), readText(local / "results.md"));

  fs::remove(slurm_cells[1] / "metrics.json");
  const auto [resumed_status, resumed] = runCommand(slurm_sweep);
  ASSERT_EQ(resumed_status, 0) << resumed;
  EXPECT_NE(resumed.find("1 of 4 cells to run (the others are done)"), std::string::npos)
      << resumed;
  EXPECT_NE(readText(on_slurm / "slurm" / "cells.sbatch").find("#SBATCH --array=1\n"),
            std::string::npos);
  EXPECT_EQ(readText(slurm_cells[1] / "metrics.json"), readText(local_cells[1] / "metrics.json"));
  EXPECT_EQ(readText(on_slurm / "results.csv"), readText(local / "results.csv"));

  const auto [status_status, where] =
      runCommand(cluster.env() + kNadir + " sweep " + kQuick + " --out " + on_slurm.string() +
                 kShort + " --status");
  EXPECT_EQ(status_status, 0) << where;
  EXPECT_NE(where.find("sweep: 4/4 done, 0 failed, 0 running, 0 waiting; Slurm jobs"),
            std::string::npos)
      << where;
  fs::remove_all(local);
  fs::remove_all(on_slurm);
}

}  // namespace
}  // namespace nadir::test
