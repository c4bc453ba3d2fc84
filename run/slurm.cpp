#include "run/slurm.h"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "run/process.h"

namespace nadir::run {
namespace {

namespace fs = std::filesystem;

std::string sweepName(const SweepSpec& spec) {
  return "nadir-sweep-" + fs::path(fs::absolute(spec.out_dir)).filename().string();
}

// The #SBATCH lines every job of the sweep shares: partition, account, extra.
std::string sharedOptions(const SlurmResources& slurm) {
  std::string lines;
  if (!slurm.partition.empty()) lines += "#SBATCH --partition=" + slurm.partition + "\n";
  if (!slurm.account.empty()) lines += "#SBATCH --account=" + slurm.account + "\n";
  for (const std::string& option : slurm.extra) lines += "#SBATCH " + option + "\n";
  return lines;
}

void writeScript(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
  fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add);
}

// Seconds a finished cell took: from its command written to its metrics.
std::optional<double> cellSeconds(const SweepCell& cell) {
  struct stat started {
  }, finished{};
  const fs::path dir(cell.out_dir);
  if (stat((dir / "sweep_cell.txt").c_str(), &started) != 0 ||
      stat((dir / "metrics.json").c_str(), &finished) != 0) {
    return std::nullopt;
  }
  const double seconds =
      static_cast<double>(finished.st_mtim.tv_sec - started.st_mtim.tv_sec) +
      1e-9 * static_cast<double>(finished.st_mtim.tv_nsec - started.st_mtim.tv_nsec);
  return std::max(0.0, seconds);
}

// State of each array task by task id ("PENDING", "RUNNING", "COMPLETED",
// "FAILED", ...): squeue for those it still holds, sacct for the others when
// the cluster keeps accounting.
std::map<std::size_t, std::string> taskStates(const std::string& array_job, std::string* note) {
  std::map<std::size_t, std::string> states;
  const CommandOutput queued =
      runAndCapture({"squeue", "-h", "-r", "-t", "all", "-j", array_job, "-o", "%K|%T"});
  if (queued.status == 0) {
    std::istringstream lines(queued.output);
    for (std::string line; std::getline(lines, line);) {
      const auto bar = line.find('|');
      if (bar == std::string::npos) continue;
      try {
        states[std::stoul(line.substr(0, bar))] = line.substr(bar + 1);
      } catch (const std::exception&) {
      }
    }
  } else {
    *note = "squeue: " + queued.output;
  }
  const CommandOutput accounted =
      runAndCapture({"sacct", "-n", "-P", "-X", "-j", array_job, "-o", "JobID,State"});
  if (accounted.status == 0) {
    std::istringstream lines(accounted.output);
    for (std::string line; std::getline(lines, line);) {
      const auto underscore = line.find('_'), bar = line.find('|');
      if (underscore == std::string::npos || bar == std::string::npos || bar < underscore) continue;
      try {
        const std::size_t task = std::stoul(line.substr(underscore + 1, bar - underscore - 1));
        std::string state = line.substr(bar + 1);
        state = state.substr(0, state.find(' '));  // "CANCELLED by 0"
        states.emplace(task, state);               // squeue's word first
      } catch (const std::exception&) {
      }
    }
  }
  return states;
}

bool jobActive(const std::string& job) {
  if (job.empty()) return false;
  const CommandOutput queued = runAndCapture({"squeue", "-h", "-j", job, "-o", "%T"});
  if (queued.status != 0) return false;
  return queued.output.find("PENDING") != std::string::npos ||
         queued.output.find("RUNNING") != std::string::npos ||
         queued.output.find("CONFIGURING") != std::string::npos ||
         queued.output.find("COMPLETING") != std::string::npos;
}

}  // namespace

std::string arrayRanges(const std::vector<std::size_t>& ids) {
  std::vector<std::size_t> sorted = ids;
  std::sort(sorted.begin(), sorted.end());
  std::string ranges;
  for (std::size_t i = 0; i < sorted.size();) {
    std::size_t j = i;
    while (j + 1 < sorted.size() && sorted[j + 1] == sorted[j] + 1) ++j;
    if (!ranges.empty()) ranges.push_back(',');
    ranges.append(std::to_string(sorted[i]));
    if (j > i) {
      ranges.push_back('-');
      ranges.append(std::to_string(sorted[j]));
    }
    i = j + 1;
  }
  return ranges;
}

SlurmPlan writeSlurmScripts(const SweepSpec& spec, const std::vector<std::string>& sweep_command,
                            const std::string& nadir_program, bool rerun) {
  SlurmPlan plan;
  const fs::path out = fs::absolute(spec.out_dir);
  const fs::path dir = out / "slurm";
  fs::create_directories(dir / "logs");
  plan.dir = dir.string();
  std::vector<SweepCell> cells = planSweep(spec);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (rerun || !cellDone(cells[i], cellCommand(spec, cells[i], nadir_program))) {
      plan.cells.push_back(i);
    }
  }
  const std::string name = sweepName(spec);
  const SlurmResources& slurm = spec.slurm;
  if (!plan.cells.empty()) {
    std::vector<std::string> task = sweep_command;
    task.push_back("--cell");
    plan.array_script = (dir / "cells.sbatch").string();
    writeScript(
        plan.array_script,
        "#!/bin/bash\n"
        "# One array task per cell of the sweep not done yet; written by nadir sweep --slurm.\n"
        "#SBATCH --job-name=" +
            name +
            "\n"
            "#SBATCH --array=" +
            arrayRanges(plan.cells) +
            "\n"
            "#SBATCH --cpus-per-task=" +
            std::to_string(slurm.cpus_per_task) +
            "\n"
            "#SBATCH --mem=" +
            slurm.mem +
            "\n"
            "#SBATCH --time=" +
            slurm.time +
            "\n"
            "#SBATCH --output=" +
            (dir / "logs" / "cell_%a.out").string() + "\n" + sharedOptions(slurm) +
            "set -euo pipefail\n" + "exec " + shellLine(task) + " \"$SLURM_ARRAY_TASK_ID\"\n");
  }
  std::vector<std::string> merge = sweep_command;
  merge.push_back("--tabulate");
  plan.merge_script = (dir / "merge.sbatch").string();
  writeScript(plan.merge_script,
              "#!/bin/bash\n"
              "# The sweep's results.csv and results.md from its cells; written by nadir sweep "
              "--slurm.\n"
              "#SBATCH --job-name=" +
                  name +
                  "-merge\n"
                  "#SBATCH --cpus-per-task=1\n"
                  "#SBATCH --mem=1G\n"
                  "#SBATCH --time=00:30:00\n"
                  "#SBATCH --output=" +
                  (dir / "logs" / "merge.out").string() + "\n" + sharedOptions(slurm) +
                  "set -euo pipefail\n" + "exec " + shellLine(merge) + "\n");
  plan.submit_script = (dir / "submit.sh").string();
  std::string submit =
      "#!/bin/bash\n"
      "# Submits the cells, then the merge after them, as nadir sweep --slurm --submit does.\n"
      "set -euo pipefail\n"
      "cd \"$(dirname \"$0\")\"\n";
  if (!plan.cells.empty()) {
    submit +=
        "cells=$(sbatch --parsable cells.sbatch)\n"
        "merge=$(sbatch --parsable --dependency=afterany:${cells%%;*} merge.sbatch)\n";
  } else {
    submit += "cells=\nmerge=$(sbatch --parsable merge.sbatch)\n";
  }
  submit +=
      "echo \"${cells%%;*} ${merge%%;*}\" > jobs.txt\n"
      "echo \"cells: job ${cells:-none}; merge: job $merge\"\n";
  writeScript(plan.submit_script, submit);
  return plan;
}

SlurmJobs submitSlurm(const SlurmPlan& plan) {
  const auto sbatch = [](std::vector<std::string> argv) {
    const CommandOutput result = runAndCapture(argv);
    std::string id = result.output.substr(0, result.output.find_first_of(";\n"));
    const bool numeric = !id.empty() && std::all_of(id.begin(), id.end(),
                                                    [](char c) { return c >= '0' && c <= '9'; });
    if (result.status != 0 || !numeric) {
      throw std::runtime_error("sbatch " + argv.back() + " failed (exit status " +
                               std::to_string(result.status) + "): " + result.output);
    }
    return id;
  };
  SlurmJobs jobs;
  if (!plan.array_script.empty()) {
    jobs.array_job = sbatch({"sbatch", "--parsable", plan.array_script});
    jobs.merge_job = sbatch(
        {"sbatch", "--parsable", "--dependency=afterany:" + jobs.array_job, plan.merge_script});
  } else {
    jobs.merge_job = sbatch({"sbatch", "--parsable", plan.merge_script});
  }
  std::ofstream(fs::path(plan.dir) / "jobs.txt")
      << (jobs.array_job.empty() ? "-" : jobs.array_job) << " " << jobs.merge_job << "\n";
  return jobs;
}

SlurmJobs submittedJobs(const SweepSpec& spec) {
  std::ifstream in(fs::absolute(spec.out_dir) / "slurm" / "jobs.txt");
  SlurmJobs jobs;
  in >> jobs.array_job >> jobs.merge_job;
  if (jobs.array_job == "-") jobs.array_job.clear();
  return jobs;
}

SlurmStatus slurmStatus(const SweepSpec& spec, const std::string& nadir_program,
                        const SlurmJobs& jobs) {
  SlurmStatus status;
  std::vector<SweepCell> cells = planSweep(spec);
  const std::map<std::size_t, std::string> states =
      jobs.array_job.empty() ? std::map<std::size_t, std::string>{}
                             : taskStates(jobs.array_job, &status.scheduler_note);
  SweepProgress& p = status.progress;
  p.total = cells.size();
  double seconds = 0.0;
  std::size_t timed = 0;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const auto state = states.find(i);
    const std::string word = state == states.end() ? "" : state->second;
    if (word == "RUNNING" || word == "COMPLETING" || word == "CONFIGURING") {
      ++p.running;
    } else if (word == "PENDING" || word == "REQUEUED" || word == "SUSPENDED") {
      ++p.pending;
    } else if (cellDone(cells[i], cellCommand(spec, cells[i], nadir_program))) {
      ++p.done;
      if (const auto took = cellSeconds(cells[i])) {
        seconds += *took;
        ++timed;
      }
    } else if (!word.empty()) {
      ++p.failed;  // FAILED, TIMEOUT, CANCELLED, OUT_OF_MEMORY, NODE_FAIL, or no metrics
    } else if (state == states.end() && !jobs.array_job.empty()) {
      ++p.failed;  // not in the array's record and not done: gone without its metrics
    } else {
      ++p.pending;  // nothing submitted: not run yet
    }
  }
  // At the pace of the finished cells, with as many at once as run now.
  if (timed > 0 && p.running + p.pending > 0) {
    p.remaining_s = seconds / static_cast<double>(timed) *
                    static_cast<double>(p.running + p.pending) /
                    static_cast<double>(std::max<std::size_t>(1, p.running));
  }
  status.merge_active = jobActive(jobs.merge_job);
  return status;
}

}  // namespace nadir::run
