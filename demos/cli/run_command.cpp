// SPDX-License-Identifier: MIT
// `rheofeed run SCENE`.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cli/commands.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/number_format.hpp"
#include "rheofeed/output/animation.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/output/plot.hpp"
#include "rheofeed/scene/drift_table_file.hpp"
#include "rheofeed/simulation/check.hpp"
#include "rheofeed/vibration_drift.hpp"

namespace rheofeed::cli {

using namespace rheofeed::scene;

namespace {

// Progress of a run on stderr as whole lines (never a "\r" line that a diagnostic printed
// during the run would run into): at every 10 % and at least every 10 s of wall time, with the
// simulated time and the wall time left (extrapolated from the elapsed time).
Progress lineProgress(const std::string& label, double simulated_seconds) {
  using Clock = std::chrono::steady_clock;
  struct State {
    Clock::time_point start = Clock::now(), last = Clock::now();
    int next_tenth = 1;
    bool done = false;
  };
  auto state = std::make_shared<State>();
  return [label, simulated_seconds, state](double f) {
    const Clock::time_point now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - state->start).count();
    if (f >= 1.0) {
      if (state->done) return;
      state->done = true;
      std::fprintf(stderr, "%s: 100 %% (%.4g s simulated) in %.1f s\n", label.c_str(),
                   simulated_seconds, elapsed);
      return;
    }
    if (!(f > 0)) return;
    const bool tenth = f * 10 >= state->next_tenth;
    if (!tenth && now - state->last < std::chrono::seconds(10)) return;
    while (state->next_tenth <= f * 10) ++state->next_tenth;
    state->last = now;
    std::fprintf(stderr,
                 "%s: %3.0f %% (%.4g of %.4g s simulated), %.0f s elapsed, about %.0f s left\n",
                 label.c_str(), 100 * f, f * simulated_seconds, simulated_seconds, elapsed,
                 elapsed * (1 - f) / f);
    std::fflush(stderr);
  };
}

// One gnuplot figure with a line per run, from the series CSV blocks (column `column`).
void plotRuns(const std::vector<std::pair<std::string, std::string>>& blocks,
              const std::string& title, const std::string& ylabel, const std::string& using_expr,
              const std::string& path) {
  std::string gp =
      "set datafile separator ','\nset grid\nset key bottom right\n"
      "set xlabel 'time (s)'\nset ylabel '" +
      ylabel + "'\nset title '" + title + "'\nplot ";
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    gp += (k ? ", " : "") + std::string("$") + blocks[k].first + " using " + using_expr +
          " with lines lw 2 title '" + blocks[k].first + "'";
  }
  plotPng(gp, blocks, path);
}

}  // namespace

namespace {

// --drift-table: the shared table's corners from FILE, when it exists (a bad file is bad input).
void openDriftTable(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    const std::filesystem::path folder =
        file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
    if (!std::filesystem::is_directory(folder, ec)) {
      throw std::invalid_argument("--drift-table " + file.string() + ": the folder " +
                                  folder.string() + " does not exist");
    }
    std::fprintf(stderr,
                 "rheofeed run: drift table %s does not exist yet: it is written after the runs\n",
                 file.string().c_str());
    return;
  }
  LocalDriftTable& table = *LocalDriftTable::shared();
  const std::size_t added = loadDriftTable(file, table);
  std::fprintf(stderr, "rheofeed run: drift table %s: %zu point-mass corners read\n",
               file.string().c_str(), added);
}

// After the runs: the shared table written back to FILE (atomically), or why not.
void saveDriftTable(const std::filesystem::path& file, bool used) {
  if (!used) {
    std::fprintf(stderr,
                 "rheofeed run: --drift-table %s ignored: no run used the local vibration law "
                 "(the file is left as it was)\n",
                 file.string().c_str());
    return;
  }
  const LocalDriftTable& table = *LocalDriftTable::shared();
  writeFileAtomically(file, driftTableJson(table));
  std::fprintf(stderr, "rheofeed run: drift table %s written: %zu point-mass corners\n",
               file.string().c_str(), table.numCorners());
}

}  // namespace

int runCommand(const RunArgs& args) {
  Plan plan;
  std::filesystem::path out;
  try {
    plan = makePlan(args.scene, {"ode_rheonomic"});
    out = !args.out_given ? std::filesystem::path("out") / plan.name
                          : std::filesystem::path(args.out);
    prepareOutputFolder(out, "--out");
    if (!args.drift_table.empty()) openDriftTable(args.drift_table);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rheofeed run: %s\n", e.what());
    return 2;
  }

  return runChecked("rheofeed run", [&] {
    // A rheonomic run of a vibrating feeder needs its drift field: calibrated once, here, when
    // the scene does not give it (`rheofeed calibrate` saves it into the scene).
    bool any_rheonomic = false;
    for (const PlannedRun& r : plan.runs)
      any_rheonomic = any_rheonomic || !isFullVibration(r.method);
    Scene calibrated = plan.scene;
    if (any_rheonomic && needsCalibration(calibrated)) {
      CalibrateOptions options = args.calibrate;
      for (const PlannedRun& r : plan.runs) {  // local_sampled: measured at the rheonomic step
        if (!isFullVibration(r.method)) options.rheonomic_time_step = r.scene.solver.time_step;
      }
      const CalibrateReport c = calibrateScene(calibrated, options, "rheofeed run", stderr);
      std::fprintf(stderr,
                   "rheofeed run: calibration took %.1f s CPU; `rheofeed calibrate %s --out "
                   "NEW.json` saves it so that runs of NEW.json start at once\n",
                   c.cpu_seconds,
                   (args.scene.scene + (args.scene.drift_model.empty()
                                            ? std::string()
                                            : " --drift-model " + args.scene.drift_model))
                       .c_str());
    } else if (any_rheonomic) {
      for (const Fixture& f : calibrated.fixtures) {
        if (f.law.kind != FeederLaw::Kind::Vibration) continue;
        std::fprintf(stderr, "rheofeed run: fixture '%s': drift model %s%s\n", f.name.c_str(),
                     toString(f.law.drift_model),
                     f.law.drift_model == DriftModel::Local ? " (the local vibration law)"
                                                            : " (from the scene)");
      }
    }

    const std::string unit = plan.scene.outputs.angular_drift ? "rad/s" : "m/s";
    std::printf(
        "| method | h (s) | parts | mean drift (%s) | 95 %% CI | vertical disp. (m) | "
        "throughput (parts/s) | CPU (s) | real-time factor | lost parts | Coulomb fallback "
        "steps |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        unit.c_str());
    std::fflush(stdout);
    std::vector<std::pair<std::string, std::string>> blocks;
    bool any_local_law = false;
    for (std::size_t k = 0; k < plan.runs.size(); ++k) {
      const PlannedRun& run = plan.runs[k];
      const Method m = run.method;
      // The scene with the drift fields calibrated above, at this run's step and sampling.
      Scene s = calibrated;
      s.solver = run.scene.solver;
      s.outputs.sample_interval = run.scene.outputs.sample_interval;
      std::fprintf(stderr, "rheofeed run: %s runs at h = %s s (%s), %s s simulated\n", toString(m),
                   formatNumber(s.solver.time_step).c_str(), run.step_source.c_str(),
                   formatNumber(s.duration).c_str());
      std::unique_ptr<AnimationRecorder> recorder;
      if (args.animation && k == 0) recorder = std::make_unique<AnimationRecorder>(s, m);
      const std::vector<std::string> hazards = reportSceneCheck(s, m);
      RunMetrics r =
          measureRun(s, m, lineProgress(std::string("rheofeed run: ") + toString(m), s.duration),
                     {recorder.get()});
      r.scene_check = hazards;
      writeRunOutputs(r, out.string(), toString(m));
      if (recorder) recorder->write(out / (toString(m) + std::string(".glb")));
      blocks.emplace_back(toString(m), seriesCsv(r));
      const RunHealth& h = r.health;
      any_local_law = any_local_law || h.local_law_feeders > 0;
      std::printf("| %s | %.3g | %d | %.5f | %.5f | %.4f | %.2f | %.2f | %.4f | %d | %.1f %% |\n",
                  toString(m), r.time_step, r.parts, r.mean_drift, r.mean_drift_ci95,
                  r.vertical_displacement, r.throughput, r.cpu_seconds, r.real_time_factor,
                  h.partsLost(), 100.0 * h.coulomb_fallback_steps / std::max(1L, h.steps));
      std::fflush(stdout);
    }
    if (!args.drift_table.empty()) saveDriftTable(args.drift_table, any_local_law);
    if (blocks.size() > 1) {
      plotRuns(blocks, plan.scene.name + ": methods compared", "mean drift (" + unit + ")", "1:3",
               (out / "methods.png").string());
    }
    plotRuns(blocks, plan.scene.name + ": mean height of the parts",
             "mean height of the parts (mm)", "1:(1000 * $5)", (out / "mean_height.png").string());
    std::printf("\noutputs in %s/\n", out.string().c_str());
    if (args.animation) {  // the page shows every plot of the folder
      std::vector<std::string> plots;
      for (const auto& entry : std::filesystem::directory_iterator(out)) {
        if (entry.path().extension() == ".png") plots.push_back(entry.path().filename().string());
      }
      std::sort(plots.begin(), plots.end());
      const std::filesystem::path page =
          writeViewer(out, toString(plan.runs[0].method) + std::string(".glb"), plots);
      std::printf("animation (%s): open %s\n", toString(plan.runs[0].method),
                  page.string().c_str());
    }
  });
}

}  // namespace rheofeed::cli
