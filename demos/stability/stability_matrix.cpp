// SPDX-License-Identifier: MIT
// The stability matrix (issue 7): every case of stability_cases.cpp through ODE + plugin and the
// reference solver (rheonomic; full vibration where the case vibrates), measured from the part
// states (stability_cases.hpp). Writes <out>/stability.csv (one row per case x method) and
// <out>/stability.md (a table and the failures), rewritten atomically after every run so that
// an interrupted matrix leaves what it finished. Progress on stderr.
//
// Each run is made in a forked child process (ODE keeps global state, so runs cannot share a
// process's threads; a crash is then a row, "crashed: signal N", not the end of the matrix).
//
//   stability_matrix [--out out/stability] [--filter REGEX] [--quick] [--list] [--jobs 1]
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "rheofeed/number_format.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "stability/stability_cases.hpp"

namespace {

using namespace rheofeed;
using namespace rheofeed::stability;

struct Run {
  std::size_t case_index;
  scene::Method method;
};

struct Child {
  std::size_t run;
  int fd;
  std::string text;
};

/// Reads what is left on `fd` into `text` and closes it.
void drain(Child& c) {
  char buf[4096];
  for (;;) {
    const ssize_t n = read(c.fd, buf, sizeof buf);
    if (n <= 0) break;
    c.text.append(buf, static_cast<std::size_t>(n));
  }
  close(c.fd);
}

// Writes every case matching `re` (and `quick`) as `<dir>/<case>.json`; 0 when at least one was
// written, 2 (with the reason on stderr, and no folder made) otherwise.
int writeScenes(const std::vector<StabilityCase>& all, const std::regex& re,
                const std::string& filter, bool quick, const std::string& dir) {
  std::vector<const StabilityCase*> matching;
  for (const StabilityCase& c : all) {
    if ((!quick || c.quick) && std::regex_search(c.name, re)) matching.push_back(&c);
  }
  if (matching.empty()) {
    std::fprintf(stderr, "--write-scenes: no case matches --filter '%s'%s\n", filter.c_str(),
                 quick ? " among the quick cases (--quick)" : "");
    return 2;
  }
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    std::fprintf(stderr, "--write-scenes '%s': cannot create the folder: %s\n", dir.c_str(),
                 error.message().c_str());
    return 2;
  }
  for (const StabilityCase* c : matching) {
    const std::string path = dir + "/" + c->name + ".json";
    // A vibrating case's full-vibration runs take the matrix's step (sceneFor) and its rheonomic
    // runs the case's own, as `rheofeed run` picks them from the file.
    scene::Scene s = c->scene;
    std::string note;
    if (s.hasVibration()) {
      const scene::Scene fv = sceneFor(*c, scene::Method::OdeFullVibration);
      if (s.solver.rheonomic_time_step <= 0) s.solver.rheonomic_time_step = s.solver.time_step;
      s.solver.time_step = fv.solver.time_step;
      note = " (full vibration: the matrix runs " + formatNumber(fv.duration) +
             " s of it, --duration " + formatNumber(fv.duration) + ")";
    }
    try {
      scene::writeFileAtomically(path, scene::toJson(s));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "--write-scenes: %s\n", e.what());
      return 2;
    }
    std::printf("%s%s\n", path.c_str(), note.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Stability matrix: stiff and extreme cases through every method (issue 7)"};
  std::string out = "out/stability";
  std::string filter;
  std::string scenes_dir;
  bool quick = false, list = false;
  int jobs = 1;
  CLI::Option* out_option =
      app.add_option("--out", out, "output folder for stability.csv and stability.md")
          ->capture_default_str();
  app.add_option("--filter", filter, "run only the cases whose name matches this regex (search)");
  app.add_flag("--quick", quick, "only the cases that run in seconds (the ctest reduced matrix)");
  CLI::Option* list_option =
      app.add_flag("--list", list, "list the cases and their methods, run nothing");
  CLI::Option* write_scenes =
      app.add_option("--write-scenes", scenes_dir,
                     "write the matching cases as scene files (<case>.json) to this folder, for "
                     "`rheofeed run`, and run nothing (a vibrating case's file has the matrix's "
                     "full-vibration step as solver.time_step)");
  CLI::Option* jobs_option = app.add_option("--jobs", jobs, "runs in parallel (forked processes)")
                                 ->capture_default_str()
                                 ->check(CLI::Range(1, 64));
  write_scenes->excludes(list_option)->excludes(out_option)->excludes(jobs_option);
  CLI11_PARSE(app, argc, argv);

  const std::vector<StabilityCase> all = stabilityCases();
  std::regex re;
  try {
    re = std::regex(filter.empty() ? ".*" : filter);
  } catch (const std::regex_error& e) {
    std::fprintf(stderr, "--filter '%s': %s\n", filter.c_str(), e.what());
    return 2;
  }
  std::vector<Run> runs;
  std::size_t matched = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const StabilityCase& c = all[i];
    if ((quick && !c.quick) || !std::regex_search(c.name, re)) continue;
    ++matched;
    if (list) {
      std::printf("%-32s %s%s: %s\n", c.name.c_str(), c.quick ? "[quick] " : "",
                  c.scene.hasVibration() ? "4 methods" : "2 methods", c.covers.c_str());
    }
    for (scene::Method m : methodsFor(c)) runs.push_back({i, m});
  }
  if (list) {
    std::printf("%zu cases of %zu, %zu runs\n", matched, all.size(), runs.size());
    return 0;
  }
  if (app.count("--write-scenes") > 0) {
    if (scenes_dir.empty()) {
      std::fprintf(stderr, "--write-scenes: the folder is empty; give a folder to write to\n");
      return 2;
    }
    return writeScenes(all, re, filter, quick, scenes_dir);
  }
  if (runs.empty()) {
    std::fprintf(stderr, "no case matches\n");
    return 2;
  }

  std::vector<RunRecord> records(runs.size());
  std::vector<bool> done(runs.size(), false);
  std::map<pid_t, Child> children;
  std::size_t next = 0, finished = 0;
  int failed = 0;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto write = [&] {
    std::string csv = csvHeader() + "\n";
    std::vector<RunRecord> rows;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (!done[i]) continue;
      csv += csvRow(records[i]) + "\n";
      rows.push_back(records[i]);
    }
    char header[256];
    std::snprintf(header, sizeof header,
                  "%zu of %zu runs; wall time %.0f s with --jobs %d. Columns and bounds: "
                  "demos/stability/stability_cases.hpp.",
                  rows.size(), runs.size(), elapsed(), jobs);
    scene::writeFileAtomically(out + "/stability.csv", csv);
    scene::writeFileAtomically(out + "/stability.md", markdownReport(rows, header));
  };

  while (finished < runs.size()) {
    while (next < runs.size() && static_cast<int>(children.size()) < jobs) {
      int fds[2];
      if (pipe(fds) != 0) {
        std::perror("pipe");
        return 1;
      }
      const Run run = runs[next];
      std::fflush(nullptr);
      const pid_t pid = fork();
      if (pid < 0) {
        std::perror("fork");
        return 1;
      }
      if (pid == 0) {  // child: one run, its CSV row on the pipe
        close(fds[0]);
        const std::string row = csvRow(runCase(all[run.case_index], run.method)) + "\n";
        std::size_t off = 0;
        while (off < row.size()) {
          const ssize_t n = ::write(fds[1], row.data() + off, row.size() - off);
          if (n <= 0) _exit(3);
          off += static_cast<std::size_t>(n);
        }
        close(fds[1]);
        _exit(0);
      }
      close(fds[1]);
      children[pid] = {next, fds[0], {}};
      ++next;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      std::perror("waitpid");
      return 1;
    }
    auto it = children.find(pid);
    if (it == children.end()) continue;
    Child child = it->second;
    children.erase(it);
    drain(child);
    const Run run = runs[child.run];
    const StabilityCase& c = all[run.case_index];
    RunRecord r;
    try {
      if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error("no row");
      r = parseCsvRow(child.text.substr(0, child.text.find('\n')));
    } catch (const std::exception&) {
      r.case_name = c.name;
      r.method = scene::toString(run.method);
      r.covers = c.covers;
      r.status = "crashed";
      r.message = WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status))
                                      : "exit status " + std::to_string(WEXITSTATUS(status));
      r.pass = false;
      r.verdict = "FAIL";
      r.cause = "the run crashed (" + r.message + ")";
    }
    records[child.run] = r;
    done[child.run] = true;
    ++finished;
    failed += r.pass ? 0 : 1;
    const double t = elapsed();
    std::fprintf(stderr, "[%zu/%zu] %-30s %-24s %-5s %6.1f s | elapsed %.0f s, left ~%.0f s%s%s\n",
                 finished, runs.size(), r.case_name.c_str(), r.method.c_str(), r.verdict.c_str(),
                 r.wall_seconds, t, t / double(finished) * double(runs.size() - finished),
                 r.verdict == "pass" ? "" : ": ",
                 r.verdict == "pass" ? "" : r.cause.substr(0, 160).c_str());
    try {
      write();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return 1;
    }
  }
  std::fprintf(stderr, "%zu runs, %d fail, %.0f s; wrote %s/stability.csv and .md\n", runs.size(),
               failed, elapsed(), out.c_str());
  return 0;
}
