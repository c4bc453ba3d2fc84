#pragma once
// A single-node Slurm cluster on this machine for the tests of `nadir sweep
// --slurm`: munged (as the munge user, its socket in a folder of its own),
// slurmctld and slurmd with a slurm.conf generated in a temporary folder, on
// ports of their own; nothing of the machine's configuration is touched.
// Clients find it through SLURM_CONF, which env() gives. Needs root and
// Debian's slurmctld, slurmd, slurm-client and munge (./nadir setup installs
// them): available() says whether it runs, whyNot() why not, startFailed()
// whether it should have. Stopped and removed by the destructor.

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "tests/support/run_command.h"

namespace nadir::test {

class SlurmCluster {
 public:
  SlurmCluster() {
    namespace fs = std::filesystem;
    if (geteuid() != 0) {
      why_not_ = "a Slurm cluster needs root (run as root, as CI does)";
      return;
    }
    for (const char* program : {"munged", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo"}) {
      if (runCommand(std::string("command -v ") + program).first != 0) {
        why_not_ = std::string("no ") + program + " (./nadir setup installs Slurm and munge)";
        return;
      }
    }
    dir_ = fs::temp_directory_path() / ("nadir_slurm_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "state");
    fs::create_directories(dir_ / "spool");
    fs::create_directories(dir_ / "munge");
    const std::string node =
        runCommand("hostname -s").second.substr(0, runCommand("hostname -s").second.find('\n'));
    const int port = 20000 + static_cast<int>(getpid() % 20000);
    long memory_mb = 1024;
    {
      std::ifstream meminfo("/proc/meminfo");
      std::string key;
      long kb = 0;
      meminfo >> key >> kb;
      memory_mb = kb / 1024 * 9 / 10;
    }
    const int cpus = static_cast<int>(std::thread::hardware_concurrency());
    std::ofstream(dir_ / "slurm.conf")
        << "ClusterName=nadirtest\n"
        << "SlurmctldHost=" << node << "(127.0.0.1)\n"
        << "SlurmctldPort=" << port << "\n"
        << "SlurmdPort=" << port + 1 << "\n"
        << "SlurmUser=root\nSlurmdUser=root\n"
        << "AuthType=auth/munge\nCredType=cred/munge\n"
        << "AuthInfo=socket=" << (dir_ / "munge" / "munge.socket").string() << "\n"
        << "StateSaveLocation=" << (dir_ / "state").string() << "\n"
        << "SlurmdSpoolDir=" << (dir_ / "spool").string() << "\n"
        << "SlurmctldPidFile=" << (dir_ / "slurmctld.pid").string() << "\n"
        << "SlurmdPidFile=" << (dir_ / "slurmd.pid").string() << "\n"
        << "SlurmctldLogFile=" << (dir_ / "slurmctld.log").string() << "\n"
        << "SlurmdLogFile=" << (dir_ / "slurmd.log").string() << "\n"
        << "ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n"
        << "SchedulerType=sched/builtin\nSelectType=select/cons_tres\n"
        << "SelectTypeParameters=CR_Core_Memory\n"
        << "JobAcctGatherType=jobacct_gather/none\nAccountingStorageType=accounting_storage/none\n"
        << "MpiDefault=none\nReturnToService=2\nMinJobAge=600\n"
        << "NodeName=" << node << " NodeAddr=127.0.0.1 CPUs=" << cpus << " RealMemory=" << memory_mb
        << " State=UNKNOWN\n"
        << "PartitionName=nadir Nodes=" << node << " Default=YES MaxTime=INFINITE State=UP\n";
    env_ = "SLURM_CONF=" + (dir_ / "slurm.conf").string() + " ";
    const std::string munge_dir = (dir_ / "munge").string();
    const std::string steps[] = {
        "chown munge:munge " + munge_dir + " && chmod 711 " + munge_dir,
        "runuser -u munge -- munged --socket=" + munge_dir +
            "/munge.socket --pid-file=" + munge_dir + "/munged.pid --log-file=" + munge_dir +
            "/munged.log --seed-file=" + munge_dir + "/munged.seed",
        env_ + "slurmctld -i",
        env_ + "slurmd",
    };
    // The munge socket's folder must be reachable by the daemons (root) and
    // the folder above it by munge.
    fs::permissions(dir_, fs::perms::owner_all | fs::perms::group_exec | fs::perms::others_exec);
    for (const std::string& step : steps) {
      const auto [status, output] = runCommand(step);
      if (status != 0) {
        why_not_ = "could not start the cluster: '" + step + "' failed: " + output + log();
        start_failed_ = true;
        stop();
        return;
      }
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      const auto [status, output] = runCommand(env_ + "sinfo -h -N -o %T");
      if (status == 0 && output.rfind("idle", 0) == 0) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
    why_not_ = "the cluster's node never came up (sinfo: " +
               runCommand(env_ + "sinfo -h -N -o %T").second + ")" + log();
    start_failed_ = true;
    stop();
  }
  ~SlurmCluster() { stop(); }
  SlurmCluster(const SlurmCluster&) = delete;
  SlurmCluster& operator=(const SlurmCluster&) = delete;

  bool available() const { return why_not_.empty(); }
  const std::string& whyNot() const { return why_not_; }
  // Root and the programs were there, yet it did not start: a failure, not a skip.
  bool startFailed() const { return start_failed_; }
  // "SLURM_CONF=... ": put before a command that should use this cluster.
  const std::string& env() const { return env_; }
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::string log() const {
    std::string text;
    for (const char* name : {"slurmctld.log", "slurmd.log", "munge/munged.log"}) {
      std::ifstream in(dir_ / name);
      std::stringstream content;
      content << in.rdbuf();
      if (!content.str().empty()) text += "\n" + std::string(name) + ":\n" + content.str();
    }
    return text;
  }
  void stop() {
    if (dir_.empty()) return;
    for (const char* pid_file : {"slurmd.pid", "slurmctld.pid", "munge/munged.pid"}) {
      std::ifstream in(dir_ / pid_file);
      long pid = 0;
      if (!(in >> pid) || pid <= 0) continue;
      ::kill(static_cast<pid_t>(pid), SIGTERM);
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (processAlive(pid) && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    }
    std::filesystem::remove_all(dir_);
    dir_.clear();
  }

  std::filesystem::path dir_;
  std::string env_;
  std::string why_not_;
  bool start_failed_ = false;
};

}  // namespace nadir::test
