// SPDX-License-Identifier: MIT
// `rheofeed sweep`: design sweeps over a scene on this machine's cores, with GNU parallel or on a
// Slurm cluster, from one spec file (format: demos/sweeps/README.md).
//
// The pieces, in the order a sweep goes through them:
//   loadSpec      reads and checks the spec, expands it into jobs (one per point and seed) and
//                 checks every point's generated scene the way `rheofeed run` would, so that a
//                 bad spec is refused, naming the entry, before any job starts;
//   prepareSweep  writes the sweep folder: sweep.json (the manifest: the job list), and one
//                 generated scene file per job;
//   a backend     runs `rheofeed sweep job DIR ID` for every job without a finished record:
//                 runLocal (a process pool), runParallel (GNU parallel with a job log and
//                 --resume-failed), writeSlurm (an sbatch array script and a collect job that
//                 depends on it);
//   runJob        one job: an ordinary `rheofeed run` of the job's scene file, then its record
//                 (parameters, metrics, health, status, CPU time, version, scene hash) written
//                 atomically; a finished job (status "ok", or "no_answer": the run gave no
//                 answer, kNoAnswerExitCode, and would give none again) is never run again;
//   collect       one CSV of the parameters and the metrics' means and 95 % intervals over the
//                 seeds with an answer, the seeds with none counted apart, plots, and the
//                 failed or missing jobs with the command that reruns them.
//
// The sweep folder (DIR):
//   sweep.json                 manifest: the spec, the base scene, the job list with hashes
//   jobs/<id>/scene.json       the generated scene of the job (an ordinary scene file)
//   jobs/<id>/run/             `rheofeed run`'s outputs; jobs/<id>/run.log its stdout + stderr
//   records/<id>.json          the job's record (written last, atomically)
//   parallel/, slurm/          the backends' job file, job log, scripts and logs
//   results/                   collect's sweep.csv, jobs.csv and plots
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/output/plot.hpp"

namespace rheofeed::cli::sweep {

/// A parameter the sweep varies: a number in the scene, addressed by a JSON pointer (RFC 6901)
/// into the base scene file. The scene gets value x scale; the CSV and the plots show value.
struct Parameter {
  std::string name;     ///< column name ([A-Za-z0-9_.-]+)
  std::string pointer;  ///< e.g. "/fixtures/0/law/vibration/amplitude"
  double scale = 1;     ///< factor from the spec's value to the scene's unit
  enum class Kind { List, Range, LatinHypercube } kind = Kind::List;
  std::vector<double> values;  ///< List and Range: the values, in order
  double from = 0, to = 0;     ///< LatinHypercube: the interval sampled
};

/// A number to collect from each run's JSON (<method>.json of `rheofeed run`).
struct Metric {
  std::string name;     ///< column name ([A-Za-z0-9_.-]+)
  std::string pointer;  ///< e.g. "/feeder/mean_exit_rate_per_min"
};

/// Settings of the Slurm scripts (the spec's "slurm" object).
struct SlurmSettings {
  int jobs_per_task = 1;            ///< jobs run one after the other by one array task
  std::string time;                 ///< --time of an array task ("" : the partition's default)
  std::string partition;            ///< --partition ("" : the default partition)
  std::string account;              ///< --account ("" : none)
  std::vector<std::string> sbatch;  ///< further sbatch options, one per entry
};

/// One job: one point of the parameter space and one seed.
struct Job {
  int index = 0;               ///< position in the job list (the id is its zero-padded form)
  int point = 0;               ///< index of the point (jobs of one point differ by seed only)
  std::uint64_t seed = 0;      ///< the scene's seed
  std::vector<double> values;  ///< one per Spec::parameters
  std::string scene_text;      ///< the generated scene file
  std::string scene_hash;      ///< "fnv1a64:<16 hex digits>" of scene_text
};

/// A checked and expanded spec.
struct Spec {
  std::filesystem::path file;        ///< the spec file
  std::string text;                  ///< its text (copied into the manifest)
  std::string name;                  ///< "name", else the file's stem
  std::filesystem::path scene_file;  ///< the base scene file (absolute)
  std::vector<std::string> methods;  ///< method names (run's --method)
  /// Run's --max-lost-fraction ("max_lost_fraction", in [0, 1]): beyond it a job has no answer.
  double max_lost_fraction = scene::kDefaultMaxLostFraction;
  std::vector<Parameter> parameters;
  int lhs_samples = 0;         ///< Latin hypercube samples (0: no such parameter)
  std::uint64_t lhs_seed = 0;  ///< its random seed
  std::vector<std::uint64_t> seeds;
  std::vector<Metric> metrics;
  int map_x = -1, map_y = -1;  ///< parameters of the map plot (-1: none)
  SlurmSettings slurm;
  int points = 0;
  std::vector<Job> jobs;  ///< point-major: job = point x seeds.size() + seed index
};

/// Reads, checks and expands the spec in `file` (see the file comment). Throws
/// std::invalid_argument naming the spec file, the entry (e.g. "parameters[1] 'angle_deg'") and
/// what is wrong; nothing is written.
Spec loadSpec(const std::filesystem::path& file);

/// "fnv1a64:<16 hex digits>": the 64-bit FNV-1a hash of a scene file's text (an identity check
/// of a job's scene file, not a cryptographic hash).
std::string sceneHash(const std::string& text);

/// The id of job `index` of `count` jobs: zero-padded to at least 4 digits ("0007").
std::string jobId(int index, int count);

/// The sweep folder of a spec: DIR's paths (see the file comment).
struct Folder {
  std::filesystem::path root;
  std::filesystem::path manifest() const { return root / "sweep.json"; }
  std::filesystem::path jobDir(const std::string& id) const { return root / "jobs" / id; }
  std::filesystem::path record(const std::string& id) const {
    return root / "records" / (id + ".json");
  }
  std::filesystem::path results() const { return root / "results"; }
  /// The local law's drift table the jobs share (`rheofeed run --drift-table`).
  std::filesystem::path driftTable() const { return root / "drift_table.json"; }
};

/// Creates DIR and writes the manifest and the jobs' scene files. A folder that already holds a
/// sweep must hold this spec's (the same job list and scenes): it is then resumed and nothing
/// is rewritten. Throws std::invalid_argument naming DIR and the first difference.
void prepareSweep(const Spec& spec, const Folder& folder);

/// What a sweep folder's manifest says (enough to run and collect the jobs without the spec).
struct Manifest {
  std::string name;
  std::vector<std::string> methods;
  double max_lost_fraction = scene::kDefaultMaxLostFraction;  ///< Spec::max_lost_fraction
  std::vector<Parameter> parameters;                          ///< name, pointer and scale
  std::vector<Metric> metrics;
  int map_x = -1, map_y = -1;
  SlurmSettings slurm;
  std::vector<Job> jobs;  ///< without scene_text
};

/// Reads DIR/sweep.json. Throws std::invalid_argument naming the file when it is missing or
/// not a manifest of this version.
Manifest readManifest(const Folder& folder);

/// The record of a job, as far as collect needs it.
struct Record {
  std::string id;
  /// "ok"; "no_answer": the run finished without an answer (`rheofeed run` exited with
  /// kNoAnswerExitCode: parts lost beyond its bound, none measured), its metrics and health
  /// recorded but left out of the means; or "failed".
  std::string status;
  std::string error;      ///< failed: why (the run's last message, or the signal)
  std::string no_answer;  ///< no_answer: why, per method ("ode_rheonomic lost 3 of 4 parts ...")
  int point = 0;
  std::uint64_t seed = 0;
  /// metrics[method][metric]: the value, or nullopt when the run's JSON has null (e.g. no exit).
  std::vector<std::vector<std::optional<double>>> metrics;
  /// health[method]: parts lost, solver trouble and ignored settings (summed in the CSV).
  std::vector<std::vector<double>> health;
  /// trusted[method]: that method's run has an answer (its JSON's answer.trusted): all of an ok
  /// job's; a no_answer job's as recorded (a job has no answer when one of its methods has
  /// none; the others' still count), none where not recorded.
  std::vector<bool> trusted;
  double cpu_seconds = 0;
};

/// The health counts of a run's JSON that collect sums over the seeds (each a key of the run
/// JSON's "health" object; "ignored_settings" is the length of its list).
const std::vector<std::string>& healthKeys();

/// The record of job `id`, or nullopt when there is none (not run, or interrupted). Throws
/// std::runtime_error for a record that cannot be read.
std::optional<Record> readRecord(const Folder& folder, const Manifest& manifest,
                                 const std::string& id);

/// A job of this record has finished: its status is "ok" or "no_answer" (a deterministic run
/// with no answer gives none again). Every other status is run again.
bool finished(const Record& record);

/// The ids of the jobs without a finished record (finished), in job order.
std::vector<std::string> unfinishedJobs(const Folder& folder, const Manifest& manifest);

/// The `sweep job` process running job `id`: it holds the job's lock, jobs/<id>/job.lock (an
/// exclusive flock, released by the kernel when the process ends), which names its pid and host.
struct RunningJob {
  int pid = 0;  ///< 0: no process holds the lock (or it named no pid)
  std::string host;
};
/// The process running job `id` now, if any (pid 0 otherwise).
RunningJob runningJob(const Folder& folder, const std::string& id);
/// Stops the `sweep job` processes of this host still running one of `ids` (SIGTERM; SIGKILL
/// after 10 s) and waits until their locks are free, printing each on stdout after `who: `. For
/// a backend that lost track of a job (GNU parallel stopped by a signal before it listed a job
/// it had just started, which then ran on and wrote its record after the sweep had returned).
/// Returns how many are still running (on another host, or not stopped in 15 s), each printed.
int stopStrayJobs(const Folder& folder, const std::vector<std::string>& ids,
                  const std::string& who);

/// The environment variable a backend sets to its stop file before it starts the jobs. A `sweep
/// job` started with it that finds the file once it holds its job's lock does not run: the
/// backend was interrupted before it could signal that job (it writes the file, then stops the
/// jobs holding a lock; a job takes its lock, then looks for the file; so no job runs on).
constexpr const char* kStopFileVariable = "RHEOFEED_SWEEP_STOP_FILE";

/// The command that runs (or reruns) job `id` by hand.
std::string jobCommand(const Folder& folder, const std::string& id);

/// Runs job `id` unless it has a finished record: `rheofeed run` of its scene file into
/// jobs/<id>/run, then writes its record (status "ok", "no_answer" with why, or "failed").
/// Returns 0 for a finished job (now or before, with or without an answer), 1 for a
/// failed one (its record says why) or one another process is running (no record; the line
/// names that process), 130/143 when interrupted by SIGINT/SIGTERM (no record; the run is
/// stopped too) or started by a backend that has since been interrupted (kStopFileVariable). Holds
/// the job's lock while it runs. Prints one line on stdout per job.
int runJob(const Folder& folder, const Manifest& manifest, const std::string& id);

/// Backends. Each runs `rheofeed sweep job DIR ID` for the unfinished jobs and returns the
/// number of jobs that failed or were not run (0: all finished); throws std::runtime_error when
/// the engine cannot be started.
/// The local pool: `jobs` processes at a time; SIGINT/SIGTERM stop it (running jobs are stopped
/// and leave no record; finished ones stay) and it returns -1.
int runLocal(const Folder& folder, const Manifest& manifest, int jobs);
/// GNU parallel over the job file DIR/parallel/jobs.txt with the job log DIR/parallel/joblog
/// and --resume-failed; `sshlogin` (may be empty) is passed as --sshlogin. Returns -1 when
/// interrupted.
int runParallel(const Folder& folder, const Manifest& manifest, int jobs,
                const std::string& sshlogin);
/// Writes DIR/slurm/submit_<n>/{tasks.txt,array.sh,collect.sh,submit.sh} for the unfinished
/// jobs (jobs_per_task per array task) and, with `submit`, runs submit.sh (sbatch) and prints
/// the job ids. Returns the folder written.
std::filesystem::path writeSlurm(const Folder& folder, const Manifest& manifest, int jobs_per_task,
                                 bool submit);
/// Runs the jobs of line `task` of a Slurm task file (one array task). Returns runJob's worst
/// code.
int runTask(const Folder& folder, const Manifest& manifest, const std::filesystem::path& tasks,
            int task);

/// collect: writes results/sweep.csv (one row per point and method: the parameters, the seeds
/// ok, failed, missing and with no answer, then for each metric its mean over the ok seeds, the
/// 95 % interval half-width and the count, then the health counts summed over the seeds that
/// ran: ok and no answer), results/jobs.csv (one row per job) and the plots. Lists the jobs with
/// no answer, with why, on stderr (they are finished: not counted). Prints the failed and
/// missing jobs with the commands that rerun them. Returns their number.
int collect(const Folder& folder, const Manifest& manifest);

/// Number of processors this process may run on (sched_getaffinity; at least 1).
int availableCores();

/// This executable's absolute path (/proc/self/exe): what the backends' job lines run.
std::filesystem::path selfExe();

/// Starts `argv` (argv[0] a path) with posix_spawn, stdin from /dev/null and, when `log` is not
/// empty, stdout and stderr into `log` (truncated). Returns the process id; throws
/// std::runtime_error naming the program when it cannot be started.
int spawnProcess(const std::vector<std::string>& argv, const std::filesystem::path& log = {});

/// `text` quoted for a POSIX shell (plot.hpp).
using rheofeed::scene::shellQuoted;

/// Installs SIGINT and SIGTERM handlers that record the signal and forward it to the processes
/// registered with forwardSignalsTo (no SA_RESTART: a blocking wait returns with EINTR).
void catchStopSignals();
/// Registers (pid > 0) or unregisters (pid <= 0 in the same slot) a child to forward to.
void forwardSignalsTo(int slot, int pid);
/// The stop signal received since catchStopSignals (0: none).
int stopSignal();

}  // namespace rheofeed::cli::sweep
