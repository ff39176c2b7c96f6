// SPDX-License-Identifier: MIT
//
// Convergence of the reference world's contact solve over a whole run (issue 16): runs a scene
// with the reference method and a chosen true-Coulomb solver, and records every step's solve
// (contacts, status, iterations or sweeps, Coulomb residual, solve time). The Coulomb residual is
// the dimensionless natural-map residual with De Saxce's velocity of ccp/solver.hpp, as the
// world reports it for the impulses it applied. The summary says how many steps met the
// tolerance, and how far the others are from it (the residual's distribution in multiples of
// the tolerance): whether the unconverged steps are nearly converged or far off.
//
// Outputs: --csv FILE (one row per step with contacts), and the summary on stdout (markdown).
//
// Usage: reference_convergence [--scene NAME|FILE] [--duration S] [--solver nsgs|fixed_point]
//          [--groups] [--sweeps N] [--global-newton N] [--omega W] [--proximal P]
//          [--ipm-max-contacts N] [--newton-max-contacts N] [--csv FILE]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "rheofeed/ccp/fc3d_writer.hpp"
#include "rheofeed/reference/contact_problem.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "rheofeed/simulation/reference_simulation.hpp"

#ifndef RHEOFEED_SOURCE_DIR
#error "RHEOFEED_SOURCE_DIR must name the source tree (scenes)"
#endif

namespace {

namespace fs = std::filesystem;
namespace ccp = rheofeed::ccp;
namespace reference = rheofeed::reference;

struct StepRecord {
  double time = 0;
  int contacts = 0;
  ccp::Status status = ccp::Status::NotRun;
  int iterations = 0;
  double residual = 0;
  double solve_time_s = 0;
  int local_fallbacks = 0;
  bool coulomb_fallback = false;
  int global_newton_tries = 0, global_newton_kept = 0;
  int ipm_rounds = 0;
};

double cpuSeconds() {
  return double(std::clock()) / CLOCKS_PER_SEC;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * double(v.size() - 1) + 0.5)];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Convergence of the reference world's Coulomb solve over a whole run"};
  std::string scene_name = "linear_trough";
  double duration = 5.0;
  std::string solver = "nsgs";
  bool groups = false;
  int sweeps = 0, global_newton = -1, newton_iterations = 0, ipm_rounds = -1, ipm_outer = 0;
  int ipm_max_contacts = -1, newton_max_contacts = -1;
  double omega = 1.0, proximal = 0.0, step_limit = 0.0;
  std::string csv_path, dump_dir;
  app.add_option("--scene", scene_name, "scene name in demos/scenes or a scene file");
  app.add_option("--duration", duration, "simulated time (s)")->check(CLI::Range(1e-3, 1e4));
  app.add_option("--solver", solver, "true-Coulomb solver: nsgs or fixed_point")
      ->check(CLI::IsMember({"nsgs", "fixed_point"}));
  app.add_flag("--groups", groups, "NSGS: solve the contacts of one body pair together");
  app.add_option("--sweeps", sweeps, "NSGS sweep budget (0: the world's default)")
      ->check(CLI::Range(0, 100000000));
  app.add_option("--global-newton", global_newton,
                 "NSGS: global Newton steps every N sweeps (0: never; default: the world's)")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--newton-iterations", newton_iterations,
                 "NSGS: Newton steps per global attempt (0: the default)")
      ->check(CLI::Range(0, 1000));
  app.add_option("--step-limit", step_limit,
                 "NSGS: global Newton step limit (share of the largest impulse; 0: the default)")
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--omega", omega, "NSGS relaxation")->check(CLI::Range(0.01, 1.99));
  app.add_option("--proximal", proximal, "NSGS proximal weight")->check(CLI::Range(0.0, 1e6));
  app.add_option("--ipm-rounds", ipm_rounds,
                 "NSGS: rounds of the interior-point fixed point and NSGS after an unconverged "
                 "solve (-1: the world's default; 0: none)")
      ->check(CLI::Range(-1, 100));
  app.add_option("--ipm-outer", ipm_outer,
                 "fixed-point iterations of that second solve (0: the world's default)")
      ->check(CLI::Range(0, 10000));
  app.add_option("--ipm-max-contacts", ipm_max_contacts,
                 "largest problem the interior-point rounds take (-1: the world's default)")
      ->check(CLI::Range(-1, 100000000));
  app.add_option("--newton-max-contacts", newton_max_contacts,
                 "NSGS: largest problem given global Newton steps (-1: the world's default)")
      ->check(CLI::Range(-1, 100000000));
  app.add_option("--csv", csv_path, "per-step CSV output");
  app.add_option("--dump", dump_dir,
                 "write the contact problem of every unconverged step here (fc3d, <time>.dat)");
  CLI11_PARSE(app, argc, argv);

  try {
    fs::path path = scene_name;
    if (path.extension() != ".json") {
      path = fs::path(RHEOFEED_SOURCE_DIR) / "demos" / "scenes" / (scene_name + ".json");
    }
    rheofeed::scene::Scene scene = rheofeed::scene::loadScene(path);
    if (scene.solver.rheonomic_time_step > 0) {
      scene.solver.time_step = scene.solver.rheonomic_time_step;
    }
    scene.duration = duration;
    scene.outputs.warmup = 0;
    const double tolerance = scene.solver.tolerance;
    std::vector<StepRecord> steps;
    // Progress on stderr every kProgressInterval of wall-clock time.
    constexpr double kProgressInterval = 30.0;  // s
    const auto started = std::chrono::steady_clock::now();
    double next_progress = kProgressInterval;
    int converged_so_far = 0;
    auto observer = [&](const reference::World& world, const reference::StepReport& report) {
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      if (wall >= next_progress) {
        next_progress = wall + kProgressInterval;
        std::fprintf(stderr,
                     "progress: t = %.3f of %g s, %zu steps with contacts, %d converged, %.0f s\n",
                     world.time(), duration, steps.size(), converged_so_far, wall);
      }
      if (report.contacts == 0) return;
      if (report.solve.status == ccp::Status::Converged) ++converged_so_far;
      steps.push_back({world.time(), report.contacts, report.solve.status, report.solve.iterations,
                       report.coulomb_residual, report.solve.solve_time_s,
                       report.solve.local_fallbacks, report.coulomb_fallback,
                       report.solve.global_newton_tries, report.solve.global_newton_kept,
                       report.ipm_rounds});
      if (!dump_dir.empty() && report.solve.status != ccp::Status::Converged) {
        char name[64];
        std::snprintf(name, sizeof name, "%.2f.dat", world.time());
        fs::create_directories(dump_dir);
        const std::string error = ccp::writeFc3dFile(reference::lastContactProblem(world),
                                                     (fs::path(dump_dir) / name).string());
        if (!error.empty()) throw std::runtime_error(error);
      }
    };
    auto adjust = [&](reference::Settings& s) {
      s.coulomb_solver = solver == "nsgs" ? reference::CoulombSolver::Nsgs
                                          : reference::CoulombSolver::RelaxedFixedPoint;
      s.nsgs.group_contacts = groups;
      if (sweeps > 0) s.nsgs.max_iterations = sweeps;
      s.nsgs.omega = omega;
      s.nsgs.proximal_weight = proximal;
      if (global_newton >= 0) s.nsgs.global_newton_interval = global_newton;
      if (newton_iterations > 0) s.nsgs.global_newton_iterations = newton_iterations;
      if (step_limit > 0) s.nsgs.global_newton_step_limit = step_limit;
      if (ipm_rounds >= 0) s.ipm_rounds = ipm_rounds;
      if (ipm_outer > 0) s.ipm.max_outer_iterations = ipm_outer;
      if (ipm_max_contacts >= 0) s.ipm_max_contacts = ipm_max_contacts;
      if (newton_max_contacts >= 0) s.nsgs.global_newton_max_contacts = newton_max_contacts;
    };
    const double cpu_start = cpuSeconds();
    auto sim = rheofeed::scene::makeObservedReferenceSimulation(
        scene, rheofeed::scene::Method::ReferenceRheonomic, observer, adjust);
    double next_report = 1.0;
    while (sim->time() < duration - 0.5 * scene.solver.time_step) {
      sim->step();
      if (sim->time() >= next_report) {
        std::fprintf(stderr, "  t = %.2f s, %zu steps with contacts, CPU %.1f s\n", sim->time(),
                     steps.size(), cpuSeconds() - cpu_start);
        next_report += 1.0;
      }
    }
    const double cpu = cpuSeconds() - cpu_start;

    if (!csv_path.empty()) {
      std::ofstream csv(csv_path + ".partial");
      csv << "time_s,contacts,status,iterations,coulomb_residual,solve_time_s,local_fallbacks,"
             "coulomb_fallback,global_newton_tries,global_newton_kept,ipm_rounds\n";
      for (const StepRecord& r : steps) {
        char line[256];
        std::snprintf(line, sizeof line, "%.4f,%d,%s,%d,%.4e,%.6g,%d,%d,%d,%d,%d\n", r.time,
                      r.contacts, ccp::toString(r.status), r.iterations, r.residual, r.solve_time_s,
                      r.local_fallbacks, r.coulomb_fallback ? 1 : 0, r.global_newton_tries,
                      r.global_newton_kept, r.ipm_rounds);
        csv << line;
      }
      csv.close();
      if (!csv) throw std::runtime_error("cannot write " + csv_path);
      fs::rename(csv_path + ".partial", csv_path);
    }

    int converged = 0, fallbacks = 0, ipm_tried = 0, ipm_converged = 0;
    std::vector<double> unconverged, iterations;
    double solve_time = 0;
    int bands[4] = {0, 0, 0, 0};  // residual <= 2, 10, 100 tolerances, beyond
    for (const StepRecord& r : steps) {
      solve_time += r.solve_time_s;
      iterations.push_back(r.iterations);
      if (r.coulomb_fallback) ++fallbacks;
      if (r.ipm_rounds > 0) {
        ++ipm_tried;
        if (r.status == ccp::Status::Converged) ++ipm_converged;
      }
      if (r.status == ccp::Status::Converged) {
        ++converged;
        continue;
      }
      unconverged.push_back(r.residual / tolerance);
      const double x = r.residual / tolerance;
      ++bands[x <= 2 ? 0 : x <= 10 ? 1 : x <= 100 ? 2 : 3];
    }
    std::printf(
        "| scene | solver | steps with contacts | converged | of them after IPM rounds "
        "(steps with rounds) | Coulomb fallback | "
        "unconverged residual / tol: median, 90 %%, max | <= 2x | <= 10x | <= 100x | "
        "beyond | median iterations | solve CPU (s) | run CPU (s) | CPU per sim. s |\n");
    std::printf("|---|---|---:|---:|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    std::printf(
        "| %s | %s%s | %zu | %d | %d (%d) | %d | %.3g, %.3g, %.3g | %d | %d | %d | %d | %.0f | "
        "%.1f | "
        "%.1f | %.2f |\n",
        scene_name.c_str(), solver.c_str(), groups ? "+groups" : "", steps.size(), converged,
        ipm_converged, ipm_tried, fallbacks, quantile(unconverged, 0.5), quantile(unconverged, 0.9),
        quantile(unconverged, 1.0), bands[0], bands[1], bands[2], bands[3],
        quantile(iterations, 0.5), solve_time, cpu, cpu / duration);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "reference_convergence: %s\n", error.what());
    return 1;
  }
  return 0;
}
