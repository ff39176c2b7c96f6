// SPDX-License-Identifier: MIT
//
// PGS vs APGD on the Siconos fc3d problems.
//
// For every *.dat file of a directory (e.g. tests/data/fc3d), solves the relaxed cone
// complementarity problem from a cold start with block PGS and with APGD until the natural map
// residual (see rheofeed/ccp/solver.hpp) reaches the tolerance, and prints one Markdown table and
// the same data as CSV:
//
//   file, contacts, PGS iterations / time, APGD iterations / time, speed-up = PGS time / APGD time
//
// Times are per solve (cold start, warmed-up workspace), the minimum over repeated runs that
// together take at least kMinSampleTime_s. A solve that stops before the tolerance (iteration or
// time budget) is flagged with its status and final residual.
//
// Usage: ccp_fc3d_bench <fc3d_dir> [tolerance = 1e-6] [time_limit_s per solve = 30]
// Links: rheofeed::ccp only (Eigen and the standard library).

#include "rheofeed/ccp/fc3d_reader.hpp"
#include "rheofeed/ccp/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <ode/ode.h>

#include "rheofeed/reference/contact_problem.hpp"

namespace {

using rheofeed::ccp::Method;
using rheofeed::ccp::Problem;
using rheofeed::ccp::Result;
using rheofeed::ccp::Settings;
using rheofeed::ccp::Solver;
using rheofeed::ccp::Status;

// Repeat a solve until this much time has been spent, to time microsecond solves reliably.
constexpr double kMinSampleTime_s = 0.2;
// At most this many repetitions.
constexpr int kMaxRepeats = 1000;
// Iteration budgets: large, the time limit is the real bound for PGS.
constexpr int kPgsMaxSweeps = 1'000'000;
constexpr int kApgdMaxIterations = 1'000'000;

struct Measurement {
  Result result;       // of the last run
  double best_time_s;  // minimum over runs
  int runs;
};

Measurement measure(const Problem& problem, Method method, double tolerance, double time_limit_s) {
  Settings settings;
  settings.method = method;
  settings.tolerance = tolerance;
  settings.max_iterations = method == Method::Pgs ? kPgsMaxSweeps : kApgdMaxIterations;
  settings.time_limit_s = time_limit_s;
  settings.warm_start = false;  // every run starts from gamma = 0
  Solver solver(settings);
  Eigen::VectorXd gamma;
  solver.solve(problem, gamma);  // warm-up: allocates the workspace
  Measurement m{Result(), 1e300, 0};
  double total = 0.0;
  while (m.runs < kMaxRepeats && (m.runs == 0 || total < kMinSampleTime_s)) {
    const auto start = std::chrono::steady_clock::now();
    m.result = solver.solve(problem, gamma);
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    m.best_time_s = std::min(m.best_time_s, elapsed);
    total += elapsed;
    ++m.runs;
    if (m.result.status != Status::Converged) break;  // budget exhausted: one run is enough
  }
  return m;
}

std::string formatTime(double seconds) {
  char buffer[64];
  if (seconds < 1e-3) {
    std::snprintf(buffer, sizeof buffer, "%.1f us", seconds * 1e6);
  } else if (seconds < 1.0) {
    std::snprintf(buffer, sizeof buffer, "%.2f ms", seconds * 1e3);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.2f s", seconds);
  }
  return buffer;
}

// "iterations / time", flagged when the tolerance was not reached.
std::string cell(const Measurement& m) {
  std::string text = std::to_string(m.result.iterations) + " / " + formatTime(m.best_time_s);
  if (m.result.status != Status::Converged) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, " (%s, residual %.1e)", toString(m.result.status),
                  m.result.residual);
    text += buffer;
  }
  return text;
}

// The contact problem of one step of a settled pile of `boxes` 10 cm boxes (1 kg) on a static
// ground, built by the reference world (ODE collision, h = 0.01 s, ERP 0.2, CFM 1e-5).
Problem pileProblem(int boxes) {
  using namespace rheofeed::reference;
  dInitODE2(0);
  rheofeed::reference::Settings settings;
  settings.solver.tolerance = 1e-6;
  settings.solver.max_iterations = 500;
  World world(settings);
  dGeomID ground = dCreateBox(world.space(), 20, 20, 0.2);
  dGeomSetPosition(ground, 0, 0, -0.1);
  const double inertia[9] = {1.0 / 600, 0, 0, 0, 1.0 / 600, 0, 0, 0, 1.0 / 600};
  for (int i = 0; i < boxes; ++i) {
    const int layer = i / 100, k = i % 100;
    BodyState state;
    state.position = {(k % 10) * 0.105 + 0.02 * (layer % 2), (k / 10) * 0.105,
                      0.05 + layer * 0.1005};
    const BodyId body = world.addBody(1.0, inertia, state);
    world.attachGeom(dCreateBox(world.space(), 0.1, 0.1, 0.1), body);
  }
  for (int step = 0; step < 60; ++step) world.step(0.01);
  return rheofeed::reference::lastContactProblem(world);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s <fc3d_dir> [tolerance = 1e-6] [time_limit_s = 30]\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  const double tolerance = argc > 2 ? std::atof(argv[2]) : 1e-6;
  const double time_limit_s = argc > 3 ? std::atof(argv[3]) : 30.0;
  if (!std::filesystem::is_directory(dir)) {
    std::fprintf(stderr, "error: %s is not a directory\n", dir.string().c_str());
    return 1;
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".dat") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "error: no .dat file in %s\n", dir.string().c_str());
    return 1;
  }

  struct Row {
    std::string file;
    long contacts;
    Measurement pgs, apgd;
  };
  std::vector<Row> rows;
  for (const auto& path : files) {
    Problem problem;
    try {
      problem = rheofeed::ccp::readFc3dFile(path.string());
    } catch (const std::exception& error) {
      std::fprintf(stderr, "error: %s\n", error.what());
      return 1;
    }
    rows.push_back({path.filename().string(), long(problem.numContacts()),
                    measure(problem, Method::Pgs, tolerance, time_limit_s),
                    measure(problem, Method::Apgd, tolerance, time_limit_s)});
  }
  {
    std::fprintf(stderr, "building the 500-box pile step...\n");
    const Problem pile = pileProblem(500);
    rows.push_back({"500-box pile step (reference world)", long(pile.numContacts()),
                    measure(pile, Method::Pgs, tolerance, time_limit_s),
                    measure(pile, Method::Apgd, tolerance, time_limit_s)});
  }

  std::printf(
      "Relaxed CCP, natural map residual <= %g, cold start; time per solve (min of runs)\n\n",
      tolerance);
  std::printf("| file | contacts | PGS iterations / time | APGD iterations / time | speed-up |\n");
  std::printf("|---|---:|---:|---:|---:|\n");
  for (const Row& row : rows) {
    std::printf("| %s | %ld | %s | %s | %.2f |\n", row.file.c_str(), row.contacts,
                cell(row.pgs).c_str(), cell(row.apgd).c_str(),
                row.pgs.best_time_s / row.apgd.best_time_s);
  }
  std::printf(
      "\nfile,contacts,pgs_status,pgs_iterations,pgs_time_s,pgs_residual,apgd_status,"
      "apgd_iterations,apgd_time_s,apgd_residual,speedup\n");
  for (const Row& row : rows) {
    std::printf("%s,%ld,%s,%d,%.9g,%.3e,%s,%d,%.9g,%.3e,%.4g\n", row.file.c_str(), row.contacts,
                toString(row.pgs.result.status), row.pgs.result.iterations, row.pgs.best_time_s,
                row.pgs.result.residual, toString(row.apgd.result.status),
                row.apgd.result.iterations, row.apgd.best_time_s, row.apgd.result.residual,
                row.pgs.best_time_s / row.apgd.best_time_s);
  }
  return 0;
}
