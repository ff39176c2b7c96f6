// SPDX-License-Identifier: MIT
// `rheofeed sweep SPEC`, `rheofeed sweep job DIR ID...` and `rheofeed sweep collect DIR`.
#include <chrono>
#include <cstdio>
#include <exception>
#include <stdexcept>

#include "cli/commands.hpp"
#include "cli/sweep.hpp"
#include "rheofeed/number_format.hpp"

namespace rheofeed::cli {

using namespace rheofeed::cli::sweep;
namespace fs = std::filesystem;

namespace {

void printPlan(const Spec& spec) {
  std::printf("sweep '%s': base scene %s, methods", spec.name.c_str(),
              spec.scene_file.string().c_str());
  for (const std::string& m : spec.methods) std::printf(" %s", m.c_str());
  std::printf("\n");
  for (const Parameter& p : spec.parameters) {
    std::printf("  %s (%s%s): ", p.name.c_str(), p.pointer.c_str(),
                p.scale != 1 ? (", x " + formatNumber(p.scale)).c_str() : "");
    if (p.kind == Parameter::Kind::LatinHypercube) {
      std::printf("Latin hypercube in [%s, %s], %d samples, seed %llu\n",
                  formatNumber(p.from).c_str(), formatNumber(p.to).c_str(), spec.lhs_samples,
                  static_cast<unsigned long long>(spec.lhs_seed));
    } else {
      for (std::size_t k = 0; k < p.values.size(); ++k) {
        std::printf("%s%s", k ? ", " : "", formatNumber(p.values[k]).c_str());
      }
      std::printf("\n");
    }
  }
  std::printf("  metrics:");
  for (const Metric& m : spec.metrics) std::printf(" %s (%s)", m.name.c_str(), m.pointer.c_str());
  std::printf("\n  %d points x %zu seeds = %zu jobs\n", spec.points,
              spec.jobs.size() / std::max<std::size_t>(1, static_cast<std::size_t>(spec.points)),
              spec.jobs.size());
  std::fflush(stdout);
}

}  // namespace

int sweepCommand(const SweepArgs& args) {
  Spec spec;
  Folder folder;
  try {
    if (args.backend != "local" && args.backend != "parallel" && args.backend != "slurm") {
      throw std::invalid_argument("--backend " + args.backend +
                                  ": unknown backend; valid backends: local, parallel, slurm");
    }
    if (args.submit && args.backend != "slurm") {
      throw std::invalid_argument("--submit: only with --backend slurm");
    }
    if (!args.sshlogin.empty() && args.backend != "parallel") {
      throw std::invalid_argument("--sshlogin: only with --backend parallel");
    }
    spec = loadSpec(args.spec);
    printPlan(spec);
    if (args.check) {
      std::printf("spec valid; nothing run\n");
      return 0;
    }
    folder.root = args.out_given ? fs::path(args.out) : fs::path("out") / spec.name;
    prepareOutputFolder(folder.root, "--out");
    prepareSweep(spec, folder);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rheofeed sweep: %s\n", e.what());
    return 2;
  }
  int code = 0;
  const int rc = runChecked("rheofeed sweep", [&] {
    const Manifest manifest = readManifest(folder);
    const int jobs = args.jobs > 0 ? args.jobs : availableCores();
    const auto start = std::chrono::steady_clock::now();
    int left = 0;
    if (args.backend == "slurm") {
      const int per_task =
          args.jobs_per_task > 0 ? args.jobs_per_task : manifest.slurm.jobs_per_task;
      if (!writeSlurm(folder, manifest, per_task, args.submit).empty()) return;
      std::printf("slurm: every job has finished; collecting here\n");
    } else {
      left = args.backend == "local" ? runLocal(folder, manifest, jobs)
                                     : runParallel(folder, manifest, jobs, args.sshlogin);
      if (left < 0) {
        code = 130;
        return;
      }
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("sweep: %s backend, %d at a time: %.2f s wall\n", args.backend.c_str(), jobs,
                  wall);
    }
    code = collect(folder, manifest) > 0 ? 1 : 0;
  });
  return rc != 0 ? rc : code;
}

int sweepJobCommand(const SweepJobArgs& args) {
  const Folder folder{fs::path(args.dir)};
  Manifest manifest;
  try {
    manifest = readManifest(folder);
    if (args.ids.empty() == args.tasks.empty()) {
      throw std::invalid_argument("give job ids, or --tasks FILE --task K (not both)");
    }
    if (!args.tasks.empty() && args.task < 0) {
      throw std::invalid_argument("--tasks needs --task K (the array task index, >= 0)");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rheofeed sweep job: %s\n", e.what());
    return 2;
  }
  int code = 0;
  const int rc = runChecked("rheofeed sweep job", [&] {
    if (!args.tasks.empty()) {
      code = runTask(folder, manifest, args.tasks, args.task);
      return;
    }
    for (const std::string& id : args.ids) {
      const int c = runJob(folder, manifest, id);
      if (c > 1) {
        code = c;
        return;
      }
      code = std::max(code, c);
    }
  });
  return rc != 0 ? rc : code;
}

int sweepCollectCommand(const std::string& dir) {
  const Folder folder{fs::path(dir)};
  Manifest manifest;
  try {
    manifest = readManifest(folder);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rheofeed sweep collect: %s\n", e.what());
    return 2;
  }
  int code = 0;
  const int rc =
      runChecked("rheofeed sweep collect", [&] { code = collect(folder, manifest) > 0 ? 1 : 0; });
  return rc != 0 ? rc : code;
}

}  // namespace rheofeed::cli
