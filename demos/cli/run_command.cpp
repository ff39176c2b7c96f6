// SPDX-License-Identifier: MIT
// `rheofeed run SCENE`.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cli/commands.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/measure/statistics.hpp"
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
// simulated time and the wall time left: extrapolated at the pace since the last line (a run
// whose parts pour in grows dearer as it goes), or from the start for the first line.
Progress lineProgress(const std::string& label, double simulated_seconds) {
  using Clock = std::chrono::steady_clock;
  struct State {
    Clock::time_point start = Clock::now(), last = Clock::now();
    double last_f = 0;
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
    const double since = std::chrono::duration<double>(now - state->last).count();
    const double left = state->last_f > 0 && f > state->last_f
                            ? since * (1 - f) / (f - state->last_f)
                            : elapsed * (1 - f) / f;
    state->last = now;
    state->last_f = f;
    std::fprintf(stderr,
                 "%s: %3.0f %% (%.4g of %.4g s simulated), %.0f s elapsed, about %.0f s left\n",
                 label.c_str(), 100 * f, f * simulated_seconds, simulated_seconds, elapsed, left);
    std::fflush(stderr);
  };
}

// One gnuplot figure with a line per run, from the series CSV blocks (column `column`), each
// titled by its label (`labels`, one per block).
void plotRuns(const std::vector<std::pair<std::string, std::string>>& blocks,
              const std::vector<std::string>& labels, const std::string& title,
              const std::string& ylabel, const std::string& using_expr, const std::string& path) {
  std::string gp =
      "set datafile separator ','\nset grid\nset key bottom right\n"
      "set xlabel 'time (s)'\nset ylabel '" +
      ylabel + "'\nset title '" + title + "'\nplot ";
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    gp += (k ? ", " : "") + std::string("$") + blocks[k].first + " using " + using_expr +
          " with lines lw 2 title '" + labels[k] + "'";
  }
  plotPng(gp, blocks, path);
}

}  // namespace

namespace {

// --drift-table FILE: the process's drift table (LocalDriftTable::shared) read before the runs
// and written back after them.
class DriftTableFile {
 public:
  // Checks FILE against the plan and the output folder `out` (a refusal is bad input:
  // std::invalid_argument naming --drift-table) and reads it when it exists and a run of the
  // plan uses the local vibration law; else says up front that it is ignored.
  DriftTableFile(const std::string& file, const Plan& plan, const std::filesystem::path& out) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (file.empty()) throw std::invalid_argument("--drift-table \"\": must name a file");
    path_ = file;
    for (int k = 0; k < 40 && fs::is_symlink(path_, ec); ++k) {  // write through links
      const fs::path target = fs::read_symlink(path_, ec);
      path_ = target.is_absolute() ? target : path_.parent_path() / target;
    }
    const std::string name = "--drift-table " + file;
    used_ = usesLocalLaw(plan);
    if (!used_) {
      std::fprintf(stderr,
                   "rheofeed run: %s ignored: no run of this command uses the local vibration "
                   "law (the file is neither read nor written)\n",
                   name.c_str());
      return;
    }
    const fs::path folder = path_.has_parent_path() ? path_.parent_path() : fs::path(".");
    const fs::path filename = path_.filename();
    // In --out (created before the runs): any name but the runs' own outputs.
    std::error_code ec_folder, ec_out;  // a path that cannot be resolved is not --out
    const fs::path resolved_folder = fs::weakly_canonical(folder, ec_folder);
    const fs::path resolved_out = fs::weakly_canonical(out, ec_out);
    const bool in_out = !ec_folder && !ec_out && resolved_folder == resolved_out;
    if (in_out && isRunOutput(filename.string(), plan)) {
      throw std::invalid_argument(name + ": the run writes " + filename.string() + " into --out " +
                                  out.string() + "; give the table another name or folder");
    }
    if (!in_out && !fs::exists(folder, ec)) {
      throw std::invalid_argument(name + ": the folder " + folder.string() + " does not exist");
    }
    if (!in_out && !fs::is_directory(folder, ec)) {
      throw std::invalid_argument(name + ": " + folder.string() + " is not a folder");
    }
    if (!fs::exists(path_, ec)) {
      if (!in_out) {  // --out is checked by prepareOutputFolder
        const fs::path probe = folder / (".rheofeed_write_test_" + std::to_string(::getpid()));
        std::FILE* f = std::fopen(probe.string().c_str(), "w");
        if (!f) {
          throw std::invalid_argument(name + ": the folder " + folder.string() +
                                      " is not writable");
        }
        std::fclose(f);
        fs::remove(probe, ec);
      }
      std::fprintf(stderr,
                   "rheofeed run: drift table %s does not exist yet: it is written after the "
                   "runs\n",
                   file.c_str());
      return;
    }
    try {
      const std::size_t read = loadDriftTable(path_, *LocalDriftTable::shared());
      std::fprintf(stderr, "rheofeed run: drift table %s: %zu point-mass corners read\n",
                   file.c_str(), read);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("--drift-table: " + std::string(e.what()) +
                                  " (delete the file to start a new table)");
    }
    known_ = LocalDriftTable::shared()->numCorners();
  }

  // After the runs: corners another process wrote meanwhile are merged in, then the table is
  // written back (atomically) when it grew. Throws std::runtime_error naming --drift-table
  // when it cannot be written (the runs' own outputs are written before).
  void save() {
    if (!used_) return;
    LocalDriftTable& table = *LocalDriftTable::shared();
    std::error_code ec;
    if (std::filesystem::exists(path_, ec)) {
      try {
        loadDriftTable(path_, table);
      } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "rheofeed run: --drift-table: %s: replaced by this run's table\n",
                     e.what());
      }
    }
    const std::size_t corners = table.numCorners();
    if (corners == known_ && std::filesystem::exists(path_, ec)) {
      std::fprintf(stderr, "rheofeed run: drift table %s unchanged: %zu point-mass corners\n",
                   path_.string().c_str(), corners);
      return;
    }
    try {
      writeFileAtomically(path_, driftTableJson(table));
    } catch (const std::exception& e) {
      throw std::runtime_error("--drift-table " + path_.string() +
                               ": the table could not be written: " + e.what());
    }
    std::fprintf(stderr, "rheofeed run: drift table %s written: %zu point-mass corners (%zu new)\n",
                 path_.string().c_str(), corners, corners - known_);
  }

 private:
  // A rheonomic run of a vibrating fixture on the local law (local or local_sampled).
  static bool usesLocalLaw(const Plan& plan) {
    for (const PlannedRun& r : plan.runs) {
      if (isFullVibration(r.method)) continue;
      for (const Fixture& f : r.scene.fixtures) {
        if (f.law.kind == FeederLaw::Kind::Vibration &&
            (f.law.drift_model == DriftModel::Local ||
             f.law.drift_model == DriftModel::LocalSampled)) {
          return true;
        }
      }
    }
    return false;
  }
  // A file name the runs of `plan` write into --out.
  static bool isRunOutput(const std::string& name, const Plan& plan) {
    for (const char* fixed : {"mean_height.png", "methods.png", "view.html", "three"}) {
      if (name == fixed) return true;
    }
    for (const PlannedRun& r : plan.runs) {
      if (name.rfind(toString(r.method), 0) == 0) return true;
    }
    return false;
  }

  std::filesystem::path path_;  // FILE with symbolic links followed
  bool used_ = false;
  std::size_t known_ = 0;  // corners after reading FILE
};

}  // namespace

int runCommand(const RunArgs& args) {
  Plan plan;
  std::filesystem::path out;
  std::unique_ptr<DriftTableFile> table;
  try {
    plan = makePlan(args.scene, {"ode_rheonomic"});
    out = !args.out_given ? std::filesystem::path("out") / plan.name
                          : std::filesystem::path(args.out);
    if (args.drift_table_given)
      table = std::make_unique<DriftTableFile>(args.drift_table, plan, out);
    prepareOutputFolder(out, "--out");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rheofeed run: %s\n", e.what());
    return 2;
  }

  std::vector<std::string> no_answer;  // runs with no answer (runAnswer; kNoAnswerExitCode)
  const int code = runChecked("rheofeed run", [&] {
    // A rheonomic run of a vibrating feeder needs its drift field: calibrated once, here, when
    // the scene does not give it (`rheofeed calibrate` saves it into the scene).
    bool any_rheonomic = false;
    for (const PlannedRun& r : plan.runs)
      any_rheonomic = any_rheonomic || !isFullVibration(r.method);
    Scene calibrated = plan.scene;
    // CalibrateReport::stale and ::imprecise, into each rheonomic run's JSON
    std::vector<std::string> calibration_warnings;
    const bool calibrating = any_rheonomic && needsCalibration(calibrated);
    noteIgnoredCycleOptions("rheofeed run", args.cycles_given, calibrating,
                            args.calibrate.classical);
    if (calibrating) {
      CalibrateOptions options = args.calibrate;
      for (const PlannedRun& r : plan.runs) {  // local_sampled: measured at the rheonomic step
        if (!isFullVibration(r.method)) options.rheonomic_time_step = r.scene.solver.time_step;
      }
      const CalibrateReport c = calibrateScene(calibrated, options, "rheofeed run", stderr);
      calibration_warnings = c.stale;
      calibration_warnings.insert(calibration_warnings.end(), c.imprecise.begin(),
                                  c.imprecise.end());
      std::fprintf(stderr,
                   "rheofeed run: calibration took %.1f s CPU; `rheofeed calibrate %s --out "
                   "NEW.json` saves it so that runs of NEW.json start at once\n",
                   c.cpu_seconds,
                   (args.scene.scene +
                    (args.scene.drift_model.empty() ? std::string()
                                                    : " --drift-model " + args.scene.drift_model) +
                    (args.calibrate.classical ? " --classical" : ""))
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
    for (const Fixture& f : calibrated.fixtures) {  // a calibration that cannot be checked
      if (!any_rheonomic) continue;
      if (!uncheckedCalibration(f.law) && missingDigests(f.law).empty()) continue;
      const std::string why = uncheckedCalibration(f.law)
                                  ? uncheckedCalibrationNote(f, args.scene.scene)
                                  : partlyCheckedCalibrationNote(f, args.scene.scene);
      std::fprintf(stderr, "rheofeed run: warning: %s\n", why.c_str());
      calibration_warnings.push_back(why);
    }

    const std::string unit = plan.scene.outputs.angular_drift ? "rad/s" : "m/s";
    std::printf(
        "| method | h (s) | parts | mean drift (%s) | 95 %% CI | vertical disp. (m) | "
        "throughput (parts/s) | CPU (s) | real-time factor | lost parts | Coulomb fallback "
        "steps | answer |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        unit.c_str());
    std::fflush(stdout);
    std::vector<std::pair<std::string, std::string>> blocks;
    std::vector<std::string> labels;  // the method, and whether its run has no answer
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
      if (!isFullVibration(m)) r.calibration_warnings = calibration_warnings;
      r.scene_file = std::filesystem::absolute(plan.file).lexically_normal().string();
      r.max_lost_fraction = args.max_lost_fraction;
      writeRunOutputs(r, out.string(), toString(m));
      if (recorder) recorder->write(out / (toString(m) + std::string(".glb")));
      blocks.emplace_back(toString(m), seriesCsv(r));
      const RunHealth& h = r.health;
      const RunAnswer answer = runAnswer(r, "--max-lost-fraction");
      char ci[32] = "n/a";  // no confidence interval over fewer than two parts
      if (ci95Defined(r.drift_parts)) std::snprintf(ci, sizeof ci, "%.5f", r.mean_drift_ci95);
      char drift[32] = "n/a", height[32] = "n/a";  // no part measured
      if (r.drift_parts > 0) std::snprintf(drift, sizeof drift, "%.5f", r.mean_drift);
      // the mean over fewer parts than spawned (lost, inside a fixture, beyond the exit) says so
      if (r.drift_parts > 0 && r.drift_parts < r.parts) {
        std::snprintf(drift, sizeof drift, "%.5f (of %d)", r.mean_drift, r.drift_parts);
      }
      char throughput[32] = "n/a";  // no exit plane: nothing to count through
      if (r.feeder.exit_plane) std::snprintf(throughput, sizeof throughput, "%.2f", r.throughput);
      if (r.displacement_parts > 0) {
        std::snprintf(height, sizeof height, "%.4f", r.vertical_displacement);
      }
      std::printf("| %s | %.3g | %d | %s | %s | %s | %s | %.2f | %.4f | %d | %.1f %% | %s |\n",
                  toString(m), r.time_step, r.parts, drift, ci, height, throughput, r.cpu_seconds,
                  r.real_time_factor, h.partsLost(),
                  100.0 * h.coulomb_fallback_steps / std::max(1L, h.steps),
                  answer.trusted ? "yes" : "no (see stderr)");
      std::fflush(stdout);
      labels.push_back(toString(m) + std::string(answer.trusted ? "" : " (no answer)"));
      for (const std::string& why : answer.why) {
        no_answer.push_back(std::string(toString(m)) + " " + why);
      }
    }
    if (blocks.size() > 1) {
      plotRuns(blocks, labels, plan.scene.name + ": methods compared", "mean drift (" + unit + ")",
               "1:3", (out / "methods.png").string());
    }
    plotRuns(blocks, labels, plan.scene.name + ": mean height of the parts",
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
    if (table) table->save();  // last: a table that cannot be written costs no other output
    // Written and said, but a run that measured no part and saw none leave, or lost more than
    // --max-lost-fraction of its parts, has no answer (runAnswer).
    for (const std::string& a : no_answer) {
      std::fprintf(stderr,
                   "rheofeed run: no answer: %s (its outputs are written; the JSON's answer "
                   "and health say why); exit code %d\n",
                   a.c_str(), kNoAnswerExitCode);
    }
  });
  return code != 0 ? code : no_answer.empty() ? 0 : kNoAnswerExitCode;
}

namespace {
// `rheofeed calibrate` of `fixture`'s drift model again, recording what it is measured for.
std::string recalibrateHint(const Fixture& fixture, const std::string& scene) {
  return "`rheofeed calibrate " + scene + " --drift-model " + toString(fixture.law.drift_model) +
         " --force --out NEW.json` measures it again and records what for";
}
const char* calibrationName(const Fixture& fixture) {
  return fixture.law.drift_model == DriftModel::CalibratedDrift ? "calibrated drift"
                                                                : "efficiency factors";
}
}  // namespace

std::string uncheckedCalibrationNote(const Fixture& fixture, const std::string& scene) {
  return "fixture '" + fixture.name + "': the scene gives its calibration (" +
         calibrationName(fixture) +
         ") without calibrated_for: after a change of the vibration, gravity, mu, parts or "
         "fixtures since it was measured it would be stale, and the run cannot tell (" +
         recalibrateHint(fixture, scene) + ")";
}

std::string partlyCheckedCalibrationNote(const Fixture& fixture, const std::string& scene) {
  const std::string missing = missingDigests(fixture.law);
  return "fixture '" + fixture.name + "': the calibrated_for of its " + calibrationName(fixture) +
         " records the feeder but no " + missing +
         " digests (written before they were kept): a change of the " +
         (missing == "part"      ? "parts"
          : missing == "fixture" ? "fixtures' geometry"
                                 : "parts or of the fixtures' geometry") +
         " since it was measured is not noticed (" + recalibrateHint(fixture, scene) + ")";
}

}  // namespace rheofeed::cli
