// SPDX-License-Identifier: MIT
// The engines that run a sweep's jobs (sweep.hpp): a local process pool, GNU parallel and Slurm.
// Each runs the same job command, `rheofeed sweep job DIR ID`, so every backend writes the same
// records; none decides by itself which jobs are done (a job with a finished record, "ok" or
// "no_answer", returns at once).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "cli/sweep.hpp"
#include "rheofeed/output/output.hpp"

namespace rheofeed::cli::sweep {

namespace fs = std::filesystem;

namespace {

std::string absolutePath(const fs::path& p) {
  return fs::absolute(p).lexically_normal().string();
}

// The job command as a list of arguments.
std::vector<std::string> jobArgv(const Folder& folder, const std::string& id) {
  return {selfExe().string(), "sweep", "job", absolutePath(folder.root), id};
}

std::string elapsed(double seconds) {
  char b[32];
  std::snprintf(b, sizeof b, "%d:%02d", static_cast<int>(seconds) / 60,
                static_cast<int>(seconds) % 60);
  return b;
}

// Waits for `pid`, forwarding stop signals (catchStopSignals) to it; returns its wait status.
int waitFor(int pid) {
  int status = 0;
  forwardSignalsTo(0, pid);
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  forwardSignalsTo(0, 0);
  return status;
}

}  // namespace

int runLocal(const Folder& folder, const Manifest& manifest, int jobs) {
  const std::vector<std::string> todo = unfinishedJobs(folder, manifest);
  const int total = static_cast<int>(manifest.jobs.size());
  std::printf("local: %zu of %d jobs to run, %d at a time (%d cores available)\n", todo.size(),
              total, jobs, availableCores());
  std::fflush(stdout);
  catchStopSignals();
  const auto start = std::chrono::steady_clock::now();
  std::map<int, int> running;  // pid -> signal slot
  std::vector<int> free_slots;
  for (int s = jobs - 1; s >= 0; --s) free_slots.push_back(s);
  std::size_t next = 0;
  int done = 0, failed = 0;
  while (next < todo.size() || !running.empty()) {
    while (stopSignal() == 0 && next < todo.size() && !free_slots.empty()) {
      const int slot = free_slots.back();
      const int pid = spawnProcess(jobArgv(folder, todo[next]));
      free_slots.pop_back();
      running[pid] = slot;
      forwardSignalsTo(slot, pid);
      ++next;
    }
    if (running.empty()) break;  // stopped before starting the rest
    int status = 0;
    const int pid = waitpid(-1, &status, 0);
    if (pid < 0) continue;  // EINTR: the handler forwarded the signal; wait for the children
    auto it = running.find(pid);
    if (it == running.end()) continue;
    forwardSignalsTo(it->second, 0);
    free_slots.push_back(it->second);
    running.erase(it);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (code == 0) ++done;
    if (code == 1) ++failed;
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int finished = done + failed;
    if (stopSignal() == 0 && finished > 0) {
      const double left = t / finished * static_cast<double>(todo.size() - finished);
      std::printf("local: %d of %zu jobs run (%d failed), %s elapsed, about %s left\n", finished,
                  todo.size(), failed, elapsed(t).c_str(), elapsed(left).c_str());
      std::fflush(stdout);
    }
  }
  if (stopSignal() != 0) {
    std::printf(
        "local: interrupted by signal %d after %d of %zu jobs; run the same command to "
        "resume (finished jobs are not run again)\n",
        stopSignal(), done + failed, todo.size());
    std::fflush(stdout);
    return -1;
  }
  return static_cast<int>(unfinishedJobs(folder, manifest).size());
}

int runParallel(const Folder& folder, const Manifest& manifest, int jobs,
                const std::string& sshlogin) {
  // The job file lists every job, in job order, always the same lines: GNU parallel's
  // --resume-failed matches the job log by line number. Lines of finished jobs return at once.
  const fs::path dir = folder.root / "parallel";
  const fs::path job_file = dir / "jobs.txt";
  const fs::path joblog = dir / "joblog";
  std::string lines;
  const int total = static_cast<int>(manifest.jobs.size());
  for (const Job& job : manifest.jobs) {
    std::string line;
    for (const std::string& a : jobArgv(folder, jobId(job.index, total))) {
      line += (line.empty() ? "" : " ") + shellQuoted(a);
    }
    lines += line + "\n";
  }
  scene::writeFileAtomically(job_file, lines);
  std::vector<std::string> argv = {"parallel",           "--jobs",
                                   std::to_string(jobs), "--joblog",
                                   absolutePath(joblog), "--resume-failed"};
  if (!sshlogin.empty()) {
    argv.insert(argv.end(), {"--sshlogin", sshlogin});
  }
  argv.insert(argv.end(), {"::::", absolutePath(job_file)});
  std::string shown;
  for (const std::string& a : argv) shown += (shown.empty() ? "" : " ") + shellQuoted(a);
  // This run's stop file (kStopFileVariable); an earlier run's is stale.
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().filename().string().rfind("stop.", 0) == 0) fs::remove(entry.path(), ec);
  }
  const fs::path stop_file = dir / ("stop." + std::to_string(::getpid()));
  ::setenv(kStopFileVariable, absolutePath(stop_file).c_str(), 1);
  catchStopSignals();  // before the line: once it is printed, a stop signal is handled
  std::printf("parallel: %zu of %d jobs to run: %s\n", unfinishedJobs(folder, manifest).size(),
              total, shown.c_str());
  std::fflush(stdout);
  int pid = 0;
  try {
    pid = spawnProcess(argv);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string(e.what()) + " (GNU parallel: Debian package `parallel`)");
  }
  const int status = waitFor(pid);
  if (stopSignal() != 0) {
    // GNU parallel signals the jobs it lists as running; one it had just started may not be
    // listed yet, and would write its record after this command said it was interrupted. The
    // stop file first, then the locks (kStopFileVariable says why that order leaves none).
    scene::writeFileAtomically(stop_file,
                               "interrupted by signal " + std::to_string(stopSignal()) + "\n");
    stopStrayJobs(folder, unfinishedJobs(folder, manifest), "parallel");
    std::printf(
        "parallel: interrupted by signal %d; run the same command to resume (finished "
        "jobs are not run again)\n",
        stopSignal());
    std::fflush(stdout);
    return -1;
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 255) {
    throw std::runtime_error("GNU parallel failed (exit code 255); see its messages above");
  }
  return static_cast<int>(unfinishedJobs(folder, manifest).size());
}

fs::path writeSlurm(const Folder& folder, const Manifest& manifest, int jobs_per_task,
                    bool submit) {
  const std::vector<std::string> todo = unfinishedJobs(folder, manifest);
  if (todo.empty()) return {};
  // A new folder per submission: an array still running keeps its task file.
  int n = 1;
  std::error_code ec;
  while (fs::exists(folder.root / "slurm" / ("submit_" + std::to_string(n)), ec)) ++n;
  const fs::path dir = folder.root / "slurm" / ("submit_" + std::to_string(n));
  fs::create_directories(dir / "logs", ec);
  std::string tasks;
  int task_count = 0;
  for (std::size_t k = 0; k < todo.size(); k += static_cast<std::size_t>(jobs_per_task)) {
    for (std::size_t i = k; i < todo.size() && i < k + std::size_t(jobs_per_task); ++i) {
      tasks += (i == k ? "" : " ") + todo[i];
    }
    tasks += "\n";
    ++task_count;
  }
  scene::writeFileAtomically(dir / "tasks.txt", tasks);
  const std::string exe = shellQuoted(selfExe().string());
  const std::string root = shellQuoted(absolutePath(folder.root));
  const SlurmSettings& s = manifest.slurm;
  std::string options;
  if (!s.time.empty()) options += "#SBATCH --time=" + s.time + "\n";
  if (!s.partition.empty()) options += "#SBATCH --partition=" + s.partition + "\n";
  if (!s.account.empty()) options += "#SBATCH --account=" + s.account + "\n";
  for (const std::string& o : s.sbatch) options += "#SBATCH " + o + "\n";
  const std::string array =
      "#!/bin/bash\n"
      "# rheofeed sweep '" +
      manifest.name + "': " + std::to_string(todo.size()) + " jobs in " +
      std::to_string(task_count) + " array tasks of up to " + std::to_string(jobs_per_task) +
      " jobs (line SLURM_ARRAY_TASK_ID + 1 of tasks.txt). Each job is `rheofeed sweep job`,\n"
      "# which skips a job that has finished (its record is written last, atomically).\n"
      "#SBATCH --job-name=rheofeed-" +
      manifest.name +
      "\n"
      "#SBATCH --array=0-" +
      std::to_string(task_count - 1) +
      "\n"
      "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n"
      "#SBATCH --output=" +
      absolutePath(dir / "logs") + "/task_%a.out\n" + options + "exec " + exe + " sweep job " +
      root + " --tasks " + shellQuoted(absolutePath(dir / "tasks.txt")) +
      " --task \"$SLURM_ARRAY_TASK_ID\"\n";
  const std::string collect_script =
      "#!/bin/bash\n"
      "# Collects the sweep once the array has ended, whatever its tasks' exit codes "
      "(submitted with --dependency=afterany on the array).\n"
      "#SBATCH --job-name=rheofeed-" +
      manifest.name +
      "-collect\n"
      "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n"
      "#SBATCH --output=" +
      absolutePath(dir / "logs") + "/collect.out\n" +
      (s.partition.empty() ? "" : "#SBATCH --partition=" + s.partition + "\n") +
      (s.account.empty() ? "" : "#SBATCH --account=" + s.account + "\n") + "exec " + exe +
      " sweep collect " + root + "\n";
  const std::string submit_script =
      "#!/bin/bash\n"
      "# Submits the array, then the collection as a job that waits for the array to end.\n"
      "set -euo pipefail\n"
      "cd \"$(dirname \"$0\")\"\n"
      "array=$(sbatch --parsable array.sh)\n"
      "array=${array%%;*}\n"
      "collect=$(sbatch --parsable --dependency=afterany:$array collect.sh)\n"
      "collect=${collect%%;*}\n"
      "echo \"$array\" > array.jobid\n"
      "echo \"$collect\" > collect.jobid\n"
      "echo \"slurm: array job $array (" +
      std::to_string(task_count) + " tasks), collect job $collect (after the array ends)\"\n";
  scene::writeFileAtomically(dir / "array.sh", array);
  scene::writeFileAtomically(dir / "collect.sh", collect_script);
  scene::writeFileAtomically(dir / "submit.sh", submit_script);
  for (const char* f : {"array.sh", "collect.sh", "submit.sh"}) {
    fs::permissions(dir / f, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add,
                    ec);
  }
  std::printf(
      "slurm: %zu of %zu jobs in %d array tasks (%d jobs per task): %s/array.sh, "
      "then collect.sh after it (afterany)\n",
      todo.size(), manifest.jobs.size(), task_count, jobs_per_task, absolutePath(dir).c_str());
  if (task_count > 1000) {
    std::fprintf(stderr,
                 "slurm: %d array tasks; Slurm's MaxArraySize is 1001 by default (a site may "
                 "set less): raise slurm.jobs_per_task or --jobs-per-task\n",
                 task_count);
  }
  std::fflush(stdout);
  if (!submit) {
    std::printf("slurm: submit with: bash %s\n",
                shellQuoted(absolutePath(dir / "submit.sh")).c_str());
    return dir;
  }
  const int pid = spawnProcess({"bash", absolutePath(dir / "submit.sh")});
  const int status = waitFor(pid);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error("submitting " + absolutePath(dir / "submit.sh") +
                             " failed (is sbatch on the PATH and the cluster up?)");
  }
  return dir;
}

int runTask(const Folder& folder, const Manifest& manifest, const fs::path& tasks, int task) {
  std::ifstream in(tasks);
  if (!in) throw std::invalid_argument("--tasks " + tasks.string() + ": cannot be read");
  std::string line;
  for (int k = 0; k <= task; ++k) {
    if (!std::getline(in, line)) {
      throw std::invalid_argument("--task " + std::to_string(task) + ": " + tasks.string() +
                                  " has " + std::to_string(k) + " tasks");
    }
  }
  std::istringstream ids(line);
  int worst = 0;
  for (std::string id; ids >> id;) {
    const int code = runJob(folder, manifest, id);
    if (code > 1) return code;  // interrupted: the rest of the task is not started
    worst = std::max(worst, code);
  }
  return worst;
}

}  // namespace rheofeed::cli::sweep
