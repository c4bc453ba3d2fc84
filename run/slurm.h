#pragma once
// `nadir sweep FILE --slurm`: a sweep as Slurm jobs (docs/running.md). One
// job array, a task per cell not yet done (the task runs `nadir sweep FILE
// --cell N`, resources from the sweep file's slurm: block, a log per task),
// and a merge job after it (`nadir sweep FILE --tabulate`) that writes the
// same results.csv and results.md as a local sweep. The cluster must see the
// sweep's folder and the nadir programs at the same paths (a shared
// filesystem). Where the sweep stands is read from the cells' files and from
// squeue (sacct where the cluster keeps accounting).

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "run/sweep.h"

namespace nadir::run {

struct SlurmPlan {
  std::string dir;                 // OUT/slurm
  std::string array_script;        // OUT/slurm/cells.sbatch (empty when every cell is done)
  std::string merge_script;        // OUT/slurm/merge.sbatch
  std::string submit_script;       // OUT/slurm/submit.sh: what --submit does, for by hand
  std::vector<std::size_t> cells;  // the array's task ids: cells not done
};

// Writes the scripts. sweep_command: the `nadir sweep FILE [--out] [--set]`
// words every job runs (absolute paths); nadir_program is what the cells'
// `nadir run` commands start with (to tell which cells are done).
SlurmPlan writeSlurmScripts(const SweepSpec& spec, const std::vector<std::string>& sweep_command,
                            const std::string& nadir_program, bool rerun);

struct SlurmJobs {
  std::string array_job;  // empty when no cell needed running
  std::string merge_job;
};

// Submits the plan with sbatch (the merge after every task, however they
// end) and keeps the job ids in OUT/slurm/jobs.txt. Throws std::runtime_error
// with what sbatch said.
SlurmJobs submitSlurm(const SlurmPlan& plan);
// The jobs of the last submission of this sweep; empty ids if none.
SlurmJobs submittedJobs(const SweepSpec& spec);

// Where a submitted sweep stands, from the cells' files and the scheduler.
struct SlurmStatus {
  SweepProgress progress;
  bool merge_active = false;   // the merge job is pending or running
  std::string scheduler_note;  // what squeue/sacct could not say, if anything
};
SlurmStatus slurmStatus(const SweepSpec& spec, const std::string& nadir_program,
                        const SlurmJobs& jobs);

// "0-3,5,7-9": sbatch's --array list.
std::string arrayRanges(const std::vector<std::size_t>& ids);

}  // namespace nadir::run
