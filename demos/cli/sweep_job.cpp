// SPDX-License-Identifier: MIT
// The sweep folder, its manifest and records, and one job (sweep.hpp).
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "cli/commands.hpp"
#include "cli/sweep.hpp"
#include "rheofeed/number_format.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/version.hpp"

extern char** environ;

namespace rheofeed::cli::sweep {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Pointer = Json::json_pointer;

namespace {

constexpr const char* kManifestFormat = "rheofeed-sweep-1";

// Signals: the one received, and the children it is forwarded to (one slot per pool worker).
constexpr int kSignalSlots = 1024;
volatile std::sig_atomic_t g_signal = 0;
std::array<std::atomic<int>, kSignalSlots> g_children{};

void onStopSignal(int sig) {
  g_signal = sig;
  for (std::atomic<int>& c : g_children) {
    const int pid = c.load();
    if (pid > 0) ::kill(pid, SIGTERM);
  }
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Json parametersJson(const Manifest& m, const std::vector<double>& values) {
  Json p = Json::object();
  for (std::size_t k = 0; k < m.parameters.size(); ++k) p[m.parameters[k].name] = values[k];
  return p;
}

Json jobsJson(const Spec& spec) {
  Json jobs = Json::array();
  Manifest m;
  m.parameters = spec.parameters;
  for (const Job& job : spec.jobs) {
    jobs.push_back({{"id", jobId(job.index, static_cast<int>(spec.jobs.size()))},
                    {"point", job.point},
                    {"seed", job.seed},
                    {"parameters", parametersJson(m, job.values)},
                    {"scene_hash", job.scene_hash}});
  }
  return jobs;
}

// The manifest's sweep definition (what decides the jobs and records): two manifests with equal
// definitions describe the same sweep.
Json definitionJson(const Spec& spec) {
  Json params = Json::array(), metrics = Json::array();
  for (const Parameter& p : spec.parameters) {
    params.push_back({{"name", p.name}, {"pointer", p.pointer}, {"scale", p.scale}});
  }
  for (const Metric& m : spec.metrics)
    metrics.push_back({{"name", m.name}, {"pointer", m.pointer}});
  return {{"methods", spec.methods},
          {"max_lost_fraction", spec.max_lost_fraction},
          {"parameters", params},
          {"metrics", metrics},
          {"jobs", jobsJson(spec)}};
}

std::string nowUtc() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return b;
}

// The last line of the run's log that names the problem ("rheofeed run: ..."), else its last
// non-empty line.
std::string lastMessage(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last, last_run;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    last = line;
    if (line.rfind("rheofeed run: ", 0) == 0) last_run = line;
  }
  return !last_run.empty() ? last_run : last;
}

std::string hostName() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return host;
}

fs::path jobLockFile(const Folder& folder, const std::string& id) {
  return folder.jobDir(id) / "job.lock";
}

// Job `id`'s lock, held (flock, exclusive) by the one `sweep job` process that runs it, for as
// long as it runs; the file says "PID HOST". The kernel releases it when the process ends, however
// it ends. Not inherited by the run it starts (O_CLOEXEC).
class JobLock {
 public:
  JobLock(const Folder& folder, const std::string& id) {
    const fs::path file = jobLockFile(folder, id);
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) {
      throw std::runtime_error("job " + id + ": cannot open its lock " + file.string() + ": " +
                               std::strerror(errno));
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      if (errno != EWOULDBLOCK) {  // not held by another process: the lock cannot be taken here
        const std::string why = std::strerror(errno);
        ::close(fd_);
        fd_ = -1;
        throw std::runtime_error("job " + id + ": cannot lock " + file.string() + " (flock: " +
                                 why + "); the sweep folder needs a file system with flock");
      }
      const RunningJob other = runningJob(folder, id);
      ::close(fd_);
      fd_ = -1;
      holder_ = other.pid > 0 ? "process " + std::to_string(other.pid) + " on " + other.host
                              : "another process";
      return;
    }
    const std::string text = std::to_string(::getpid()) + " " + hostName() + "\n";
    if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, text.data(), text.size(), 0) < 0) {
      // The lock holds without the text, but an interrupted backend cannot name or stop us.
      std::fprintf(stderr,
                   "rheofeed sweep job: job %s: cannot write its pid into %s (%s); an "
                   "interrupted sweep will not be able to stop this process\n",
                   id.c_str(), file.c_str(), std::strerror(errno));
    }
  }
  ~JobLock() {
    if (fd_ >= 0) ::close(fd_);
  }
  JobLock(const JobLock&) = delete;
  JobLock& operator=(const JobLock&) = delete;
  bool held() const { return fd_ >= 0; }
  const std::string& holder() const { return holder_; }

 private:
  int fd_ = -1;
  std::string holder_;
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Processes and signals.

int availableCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return 1;
  return std::max(1, CPU_COUNT(&set));
}

fs::path selfExe() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find this executable (/proc/self/exe): " + ec.message());
  return exe;
}

int spawnProcess(const std::vector<std::string>& argv, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  if (!log.empty()) {
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
  }
  // The child starts with no blocked signal and default SIGINT/SIGTERM actions.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, stops;
  sigemptyset(&none);
  sigemptyset(&stops);
  sigaddset(&stops, SIGINT);
  sigaddset(&stops, SIGTERM);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &stops);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, args[0], &actions, &attr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(rc));
  return pid;
}

void catchStopSignals() {
  struct sigaction sa {};
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

void forwardSignalsTo(int slot, int pid) {
  if (slot < 0 || slot >= kSignalSlots) return;
  g_children[static_cast<std::size_t>(slot)] = pid;
  if (pid > 0 && g_signal != 0) ::kill(pid, SIGTERM);  // a signal that came before
}

int stopSignal() {
  return g_signal;
}

// ---------------------------------------------------------------------------------------------
// The sweep folder.

void prepareSweep(const Spec& spec, const Folder& folder) {
  std::error_code ec;
  const Json definition = definitionJson(spec);
  if (fs::exists(folder.manifest(), ec)) {
    Json old;
    try {
      old = Json::parse(readText(folder.manifest()));
    } catch (const std::exception& e) {
      throw std::invalid_argument("--out " + folder.root.string() + ": " +
                                  folder.manifest().string() + " cannot be read (" + e.what() +
                                  "); use another --out");
    }
    // Compared without max_lost_fraction, then that alone (in key order: an ordered_json
    // compares its keys in order); a manifest written before the key had run's default.
    Json old_definition = old.contains("definition") ? old["definition"] : Json();
    Json old_fraction = scene::kDefaultMaxLostFraction;
    if (old_definition.is_object() && old_definition.contains("max_lost_fraction")) {
      old_fraction = old_definition["max_lost_fraction"];
      old_definition.erase("max_lost_fraction");
    }
    Json new_definition = definition;
    new_definition.erase("max_lost_fraction");
    if (old_definition != new_definition || old_fraction != definition["max_lost_fraction"]) {
      std::string difference = "its methods, parameters or metrics differ";
      if (old_definition == new_definition) {
        difference = "its max_lost_fraction is " + old_fraction.dump() + ", this spec's " +
                     definition["max_lost_fraction"].dump();
      }
      if (old_definition.contains("jobs") && old_definition["jobs"] != definition["jobs"]) {
        const Json& a = old_definition["jobs"];
        const Json& b = definition["jobs"];
        difference =
            "it has " + std::to_string(a.size()) + " jobs, this spec " + std::to_string(b.size());
        for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
          if (a[k] != b[k]) {
            difference += "; job " + b[k]["id"].get<std::string>() + " differs: " + a[k].dump() +
                          " there, " + b[k].dump() + " here";
            break;
          }
        }
      }
      throw std::invalid_argument("--out " + folder.root.string() + " holds another sweep (" +
                                  difference +
                                  "); its finished jobs would not match this spec: use another "
                                  "--out, or the spec that made it");
    }
  } else if (fs::exists(folder.root / "records", ec) || fs::exists(folder.root / "jobs", ec)) {
    throw std::invalid_argument("--out " + folder.root.string() +
                                ": has jobs/ or records/ but no sweep.json; use another --out");
  }
  // The jobs' scene files (rewritten only when missing or changed), then the manifest.
  for (const Job& job : spec.jobs) {
    const fs::path scene =
        folder.jobDir(jobId(job.index, static_cast<int>(spec.jobs.size()))) / "scene.json";
    if (fs::exists(scene, ec) && readText(scene) == job.scene_text) continue;
    scene::writeFileAtomically(scene, job.scene_text);
  }
  Json spec_json = Json::parse(spec.text);
  Json manifest = {{"format", kManifestFormat},
                   {"name", spec.name},
                   {"spec_file", fs::absolute(spec.file).lexically_normal().string()},
                   {"base_scene", spec.scene_file.string()},
                   {"prepared_by", std::string("rheofeed ") + kVersion},
                   {"map", spec.map_x >= 0 ? Json::array({spec.parameters[spec.map_x].name,
                                                          spec.parameters[spec.map_y].name})
                                           : Json()},
                   {"slurm",
                    {{"jobs_per_task", spec.slurm.jobs_per_task},
                     {"time", spec.slurm.time},
                     {"partition", spec.slurm.partition},
                     {"account", spec.slurm.account},
                     {"sbatch", spec.slurm.sbatch}}},
                   {"spec", spec_json},
                   {"definition", definition}};
  scene::writeFileAtomically(folder.manifest(), manifest.dump(2) + "\n");
}

Manifest readManifest(const Folder& folder) {
  const fs::path file = folder.manifest();
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    throw std::invalid_argument("DIR " + folder.root.string() +
                                ": not a sweep folder (no sweep.json; `rheofeed sweep SPEC --out "
                                "DIR` makes one)");
  }
  Json j;
  try {
    j = Json::parse(readText(file));
  } catch (const std::exception& e) {
    throw std::invalid_argument(file.string() + ": cannot be read: " + e.what());
  }
  if (!j.contains("format") || j["format"] != kManifestFormat) {
    throw std::invalid_argument(file.string() + ": not a manifest of format " + kManifestFormat);
  }
  try {
    Manifest m;
    m.name = j.at("name").get<std::string>();
    const Json& d = j.at("definition");
    m.methods = d.at("methods").get<std::vector<std::string>>();
    // manifests written before the key: run's default
    m.max_lost_fraction = d.value("max_lost_fraction", scene::kDefaultMaxLostFraction);
    for (const Json& p : d.at("parameters")) {
      Parameter q;
      q.name = p.at("name").get<std::string>();
      q.pointer = p.at("pointer").get<std::string>();
      q.scale = p.at("scale").get<double>();
      m.parameters.push_back(q);
    }
    for (const Json& x : d.at("metrics")) {
      m.metrics.push_back({x.at("name").get<std::string>(), x.at("pointer").get<std::string>()});
    }
    if (j.at("map").is_array()) {
      for (std::size_t k = 0; k < m.parameters.size(); ++k) {
        if (m.parameters[k].name == j["map"][0]) m.map_x = static_cast<int>(k);
        if (m.parameters[k].name == j["map"][1]) m.map_y = static_cast<int>(k);
      }
    }
    const Json& s = j.at("slurm");
    m.slurm.jobs_per_task = s.at("jobs_per_task").get<int>();
    m.slurm.time = s.at("time").get<std::string>();
    m.slurm.partition = s.at("partition").get<std::string>();
    m.slurm.account = s.at("account").get<std::string>();
    m.slurm.sbatch = s.at("sbatch").get<std::vector<std::string>>();
    for (const Json& x : d.at("jobs")) {
      Job job;
      job.index = static_cast<int>(m.jobs.size());
      job.point = x.at("point").get<int>();
      job.seed = x.at("seed").get<std::uint64_t>();
      for (const Parameter& p : m.parameters) job.values.push_back(x.at("parameters").at(p.name));
      job.scene_hash = x.at("scene_hash").get<std::string>();
      m.jobs.push_back(job);
    }
    return m;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(file.string() + ": not a valid manifest: " + e.what());
  }
}

const std::vector<std::string>& healthKeys() {
  static const std::vector<std::string> keys = {"parts_lost",
                                                "parts_sunk",
                                                "passes_stopped",
                                                "coulomb_fallback_steps",
                                                "solver_unconverged_steps",
                                                "friction_dropped_contacts",
                                                "gyroscopic_fallback_steps",
                                                "ignored_settings",
                                                "scene_check"};
  return keys;
}

std::optional<Record> readRecord(const Folder& folder, const Manifest& manifest,
                                 const std::string& id) {
  const fs::path file = folder.record(id);
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  try {
    const Json j = Json::parse(readText(file));
    Record r;
    r.id = id;
    r.status = j.at("status").get<std::string>();
    r.error = j.at("error").is_string() ? j["error"].get<std::string>() : "";
    if (j.contains("no_answer") && j["no_answer"].is_string()) {
      r.no_answer = j["no_answer"].get<std::string>();
      // A record of an earlier version: status "ok" beside its no_answer.
      if (r.status == "ok" && !r.no_answer.empty()) r.status = "no_answer";
    }
    r.point = j.at("point").get<int>();
    r.seed = j.at("seed").get<std::uint64_t>();
    r.cpu_seconds = j.at("cpu_seconds").get<double>();
    for (const std::string& method : manifest.methods) {
      std::vector<std::optional<double>> values;
      std::vector<double> health;
      const Json& mj = j.at("metrics").contains(method) ? j["metrics"][method] : Json::object();
      for (const Metric& m : manifest.metrics) {
        values.push_back(mj.contains(m.name) && mj[m.name].is_number()
                             ? std::optional<double>(mj[m.name].get<double>())
                             : std::nullopt);
      }
      const Json& hj = j.at("health").contains(method) ? j["health"][method] : Json::object();
      for (const std::string& key : healthKeys()) {
        const Json& v = hj.contains(key) ? hj[key] : Json();
        health.push_back(v.is_array() ? double(v.size()) : v.is_number() ? v.get<double>() : NAN);
      }
      r.metrics.push_back(values);
      r.health.push_back(health);
      const bool recorded = j.contains("trusted") && j["trusted"].contains(method) &&
                            j["trusted"][method].is_boolean();
      r.trusted.push_back(r.status == "ok" || (r.status == "no_answer" && recorded &&
                                               j["trusted"][method].get<bool>()));
    }
    return r;
  } catch (const std::exception& e) {
    throw std::runtime_error("record " + file.string() + " cannot be read: " + e.what() +
                             "; remove it to rerun the job");
  }
}

bool finished(const Record& record) {
  return record.status == "ok" || record.status == "no_answer";
}

std::vector<std::string> unfinishedJobs(const Folder& folder, const Manifest& manifest) {
  std::vector<std::string> ids;
  const int count = static_cast<int>(manifest.jobs.size());
  for (const Job& job : manifest.jobs) {
    const std::string id = jobId(job.index, count);
    std::optional<Record> r;
    try {
      r = readRecord(folder, manifest, id);
    } catch (const std::exception&) {
      r.reset();
    }
    if (!r || !finished(*r)) ids.push_back(id);
  }
  return ids;
}

RunningJob runningJob(const Folder& folder, const std::string& id) {
  const int fd = ::open(jobLockFile(folder, id).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return {};
  RunningJob r;
  if (::flock(fd, LOCK_SH | LOCK_NB) == 0) {
    ::close(fd);  // nobody holds it
    return r;
  }
  char text[320] = {};
  const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
  ::close(fd);
  std::istringstream in(std::string(text, n > 0 ? static_cast<std::size_t>(n) : 0));
  in >> r.pid >> r.host;
  if (r.pid <= 0) r.pid = -1;  // held, by a process that has not written its pid yet
  return r;
}

int stopStrayJobs(const Folder& folder, const std::vector<std::string>& ids,
                  const std::string& who) {
  const std::string here = hostName();
  std::vector<std::string> stray;
  for (const std::string& id : ids) {
    const RunningJob r = runningJob(folder, id);
    if (r.pid == 0) continue;
    stray.push_back(id);
    if (r.pid > 0 && r.host == here) {
      std::printf("%s: job %s still running (process %d) after the backend stopped: stopping it\n",
                  who.c_str(), id.c_str(), r.pid);
      ::kill(r.pid, SIGTERM);
      ::kill(r.pid, SIGCONT);  // a stopped process handles the TERM when it runs again
    }
  }
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  bool killed = false;
  while (!stray.empty()) {
    std::vector<std::string> left;
    for (const std::string& id : stray) {
      if (runningJob(folder, id).pid != 0) left.push_back(id);
    }
    stray = left;
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (stray.empty() || t > 15.0) break;
    if (t > 10.0 && !killed) {
      for (const std::string& id : stray) {
        const RunningJob r = runningJob(folder, id);
        if (r.pid > 0 && r.host == here) ::kill(r.pid, SIGKILL);
      }
      killed = true;
    }
    ::usleep(20000);
  }
  for (const std::string& id : stray) {
    const RunningJob r = runningJob(folder, id);
    std::printf("%s: job %s is still running (process %d on %s); its record may appear later\n",
                who.c_str(), id.c_str(), r.pid,
                r.host.empty() ? "an unknown host" : r.host.c_str());
  }
  std::fflush(stdout);
  return static_cast<int>(stray.size());
}

std::string jobCommand(const Folder& folder, const std::string& id) {
  return "rheofeed sweep job " +
         shellQuoted(fs::absolute(folder.root).lexically_normal().string()) + " " + id;
}

// ---------------------------------------------------------------------------------------------
// One job.

int runJob(const Folder& folder, const Manifest& manifest, const std::string& id) {
  const int count = static_cast<int>(manifest.jobs.size());
  const Job* job = nullptr;
  for (const Job& j : manifest.jobs) {
    if (jobId(j.index, count) == id) job = &j;
  }
  if (!job) {
    throw std::invalid_argument("job " + id + ": no such job in " + folder.manifest().string() +
                                " (ids " + jobId(0, count) + " to " + jobId(count - 1, count) +
                                ")");
  }
  // The lock first, then the record: a process that held the lock has written its record.
  const JobLock lock(folder, id);
  if (!lock.held()) {
    std::printf("job %s: not started: %s is running it (lock %s)\n", id.c_str(),
                lock.holder().c_str(), jobLockFile(folder, id).string().c_str());
    std::fflush(stdout);
    return 1;
  }
  if (const char* stop = std::getenv(kStopFileVariable); stop && *stop) {
    std::error_code ec;
    if (fs::exists(stop, ec)) {
      std::printf("job %s: not started: the sweep that started it was interrupted (%s)\n",
                  id.c_str(), stop);
      std::fflush(stdout);
      return 128 + SIGTERM;
    }
  }
  std::optional<Record> done;
  try {
    done = readRecord(folder, manifest, id);
  } catch (const std::exception& e) {  // only a hand-edited record: records are written whole
    std::fprintf(stderr, "rheofeed sweep job: %s; running the job again\n", e.what());
  }
  if (done && finished(*done)) {
    std::printf("job %s: finished before (record %s, %s), not run again\n", id.c_str(),
                folder.record(id).string().c_str(), done->status.c_str());
    std::fflush(stdout);
    return 0;
  }
  const fs::path dir = folder.jobDir(id);
  const fs::path scene_file = dir / "scene.json";
  const fs::path run_dir = dir / "run";
  const fs::path log = dir / "run.log";
  std::error_code ec;
  fs::remove_all(run_dir, ec);  // outputs of an interrupted attempt are never read

  std::string methods;
  for (const std::string& m : manifest.methods) methods += (methods.empty() ? "" : ",") + m;
  // The jobs share one drift table (the local law's point-mass results, the same for every
  // scene): each reads what the jobs before it wrote and writes back what it added.
  const std::vector<std::string> argv = {selfExe().string(),
                                         "run",
                                         scene_file.string(),
                                         "--out",
                                         run_dir.string(),
                                         "--no-animation",
                                         "--method",
                                         methods,
                                         "--drift-table",
                                         folder.driftTable().string(),
                                         "--max-lost-fraction",
                                         formatNumber(manifest.max_lost_fraction, 17)};
  std::string command = "rheofeed";
  for (std::size_t k = 1; k < argv.size(); ++k) command += " " + shellQuoted(argv[k]);

  Json record = {{"id", id},
                 {"point", job->point},
                 {"seed", job->seed},
                 {"parameters", parametersJson(manifest, job->values)},
                 {"status", "failed"},
                 {"error", nullptr},
                 {"no_answer", nullptr},
                 {"exit_code", nullptr},
                 {"methods", manifest.methods},
                 {"metrics", Json::object()},
                 {"metric_errors", Json::array()},
                 {"health", Json::object()},
                 {"cpu_seconds", 0.0},
                 {"wall_seconds", 0.0},
                 {"rheofeed_version", kVersion},
                 {"scene", fs::relative(scene_file, folder.root, ec).string()},
                 {"scene_hash", job->scene_hash},
                 {"command", command},
                 {"host", ""},
                 {"finished_utc", ""}};
  record["host"] = hostName();

  std::string scene_text;
  try {
    scene_text = readText(scene_file);
  } catch (const std::exception&) {
    scene_text.clear();
  }
  const auto t0 = std::chrono::steady_clock::now();
  struct rusage usage {};
  int status = 0;
  std::string error;
  bool no_answer = false;  // the run exited with kNoAnswerExitCode
  if (scene_text.empty() && !fs::exists(scene_file, ec)) {
    error = "the job's scene file " + scene_file.string() +
            " is missing (rerun `rheofeed sweep SPEC --out DIR`)";
  } else if (sceneHash(scene_text) != job->scene_hash) {
    // A hand-edited scene file would make the record lie about its parameters.
    error = "the job's scene file " + scene_file.string() + " has hash " + sceneHash(scene_text) +
            ", the sweep generated " + job->scene_hash +
            " (changed by hand?); `rheofeed sweep SPEC --out DIR` writes it again";
  }
  if (error.empty()) {
    fs::create_directories(dir, ec);
    catchStopSignals();
    sigset_t stops, old;
    sigemptyset(&stops);
    sigaddset(&stops, SIGINT);
    sigaddset(&stops, SIGTERM);
    sigprocmask(SIG_BLOCK, &stops, &old);  // the child is registered before a signal is handled
    int pid = 0;
    try {
      pid = spawnProcess(argv, log);
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (pid > 0) forwardSignalsTo(0, pid);
    sigprocmask(SIG_SETMASK, &old, nullptr);
    if (pid > 0) {
      while (wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
      }
      forwardSignalsTo(0, 0);
      if (stopSignal() != 0) {
        std::printf("job %s: interrupted (signal %d), no record written\n", id.c_str(),
                    stopSignal());
        std::fflush(stdout);
        return 128 + stopSignal();
      }
      record["exit_code"] = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      if (WIFSIGNALED(status)) {
        error = "rheofeed run killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
                strsignal(WTERMSIG(status)) + ")";
      } else if (WEXITSTATUS(status) == kNoAnswerExitCode) {
        // parts lost beyond the bound, none measured: a finished point of the sweep (the run
        // is deterministic), read with its health and recorded apart from the answers
        no_answer = true;
      } else if (WEXITSTATUS(status) != 0) {
        error = "rheofeed run exited with code " + std::to_string(WEXITSTATUS(status)) + ": " +
                lastMessage(log) + " (log: " + log.string() + ")";
      }
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  record["cpu_seconds"] = usage.ru_utime.tv_sec + usage.ru_utime.tv_usec * 1e-6 +
                          usage.ru_stime.tv_sec + usage.ru_stime.tv_usec * 1e-6;
  record["wall_seconds"] = wall;

  // Metrics and health from each method's run JSON.
  std::string no_answer_why;
  if (error.empty()) {
    for (const std::string& method : manifest.methods) {
      const fs::path json_file = run_dir / (method + ".json");
      Json run;
      try {
        run = Json::parse(readText(json_file));
      } catch (const std::exception& e) {
        error = json_file.string() + ": " + e.what();
        break;
      }
      Json values = Json::object();
      for (const Metric& m : manifest.metrics) {
        const Pointer p(m.pointer);
        if (!run.contains(p)) {
          values[m.name] = nullptr;
          record["metric_errors"].push_back(method + " " + m.name + ": " + m.pointer +
                                            " names nothing in " + json_file.string());
          continue;
        }
        const Json& v = run.at(p);
        if (v.is_number() || v.is_null()) {
          values[m.name] = v;
        } else if (v.is_boolean()) {
          values[m.name] = v.get<bool>() ? 1 : 0;
        } else {
          values[m.name] = nullptr;
          record["metric_errors"].push_back(method + " " + m.name + ": " + m.pointer +
                                            " is not a number in " + json_file.string());
        }
      }
      record["metrics"][method] = values;
      if (run.contains("answer") && run["answer"].contains("trusted")) {
        record["trusted"][method] = run["answer"]["trusted"];
      }
      record["health"][method] = run.contains("health") ? run["health"] : Json();
      // The scene check's hazards of the run (a unit slip warns there): counted in sweep.csv.
      if (run.contains("scene_check")) record["health"][method]["scene_check"] = run["scene_check"];
      // Why a run has no answer, from its own verdict (runAnswer).
      const Json* why =
          run.contains("answer") && run["answer"].contains("why") ? &run["answer"]["why"] : nullptr;
      if (no_answer && why && why->is_array()) {
        for (const Json& w : *why) {
          if (!w.is_string()) continue;
          no_answer_why +=
              (no_answer_why.empty() ? "" : "; ") + method + " " + w.get<std::string>();
        }
      }
    }
  }
  if (error.empty() && no_answer) {
    record["no_answer"] = no_answer_why.empty() ? lastMessage(log) : no_answer_why;
  }
  record["status"] = !error.empty() ? "failed" : no_answer ? "no_answer" : "ok";
  if (!error.empty()) record["error"] = error;
  record["finished_utc"] = nowUtc();
  scene::writeFileAtomically(folder.record(id), record.dump(2) + "\n");

  std::string line = "job " + id + " " + record["status"].get<std::string>() + " (";
  for (std::size_t k = 0; k < manifest.parameters.size(); ++k) {
    char b[64];
    std::snprintf(b, sizeof b, "%.6g", job->values[k]);
    line += manifest.parameters[k].name + " " + b + ", ";
  }
  char b[96];
  std::snprintf(b, sizeof b, "seed %llu), %.1f s CPU", static_cast<unsigned long long>(job->seed),
                record["cpu_seconds"].get<double>());
  line += b;
  if (!error.empty()) line += ": " + error + "; rerun: " + jobCommand(folder, id);
  if (error.empty() && no_answer) line += ": " + record["no_answer"].get<std::string>();
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
  return error.empty() ? 0 : 1;
}

}  // namespace rheofeed::cli::sweep
