// SPDX-License-Identifier: MIT
//
// Scale benchmark (issue 17): what a crowd of parts costs ODE + plugin at the method's own step,
// where the time goes, and what the crowd loses.
//
// Runs (method ode_rheonomic, h = --dt, default 0.01 s, the scene's other solver settings):
//   trough  the main demo's hopper-fed trough (builtin linearTroughScene(N, N / 5): the hopper
//           pours N boxes at N / 5 parts/s, all in by 5 s), --duration s (default 8), for each
//           N of --trough (default 100, 250, 500, 1000, 2000; the table of issue 17);
//   bowl    the bowl feeder of primitives (demos/scenes/bowl_feeder_primitives.json, its
//           calibrated drift whatever its drift_model) with N nuts
//           instead of 12, poured into the scene's spawn region at N / 5 nuts/s as the trough
//           is, for each N of --bowl (default 50, 100, 200, 400).
// Each run goes through measureRun, the scene run's loop with its metrics and health report
// (as `rheofeed run`), with the simulation's stage timing on (simulation.hpp, StageTimes).
//
// Per run: per-step averages of the wall-clock time in collision (dSpaceCollide, dCollide),
// contact creation and the plugin (surface parameters, FeederSet::driveContacts, joint creation),
// the local vibration law's drift table fill (its point-mass model runs, LocalDriftStats::
// model_cpu_seconds, run in one thread here: a one-time cost that a saved table, --drift-table,
// removes, taken out of the contact stage), the solve (dWorldQuickStep) and the scene layer (the
// rest of the run loop: the part checks, metrics, observers: loop time less the three stages);
// contact joints and constraint rows per
// part present; parts lost by kind and sunk (RunHealth); process CPU time, the real-time factor
// (CPU / simulated time) and the cost's log-log slope d ln(CPU per step) / d ln N between
// successive part counts. The overall slope spans the second smallest count to the largest
// (250 -> 2000 in the default trough list: the smallest run is dominated by fixed costs), with
// the slope of each stage over the same span and the stage whose time per step grew the most, and
// the slope without the drift table fill (the cost of a run whose table was saved before).
//
// Times are one run each on one machine: compare them as ratios. The stage times are wall-clock
// (a CPU clock per geom pair would cost more than the stage it measures); the CSV gives them raw
// with CPU / wall per run (1 on an idle core, lower when other work shared it), and the tables,
// slopes and plot turn each into CPU time per step as its share of the loop's wall-clock time
// times the CPU time per step, so that the stages add up to the CPU cost.
//
// Outputs in --out (default demos/results), each written atomically: crowd_scale.csv (one row
// per run), crowd_scale.md (tables, slopes, the command) and crowd_scale.png (log-log: time per
// step against parts, by stage). --quick (2 tiny counts per scene, 1 s) is the smoke test's run.
//
// Usage: crowd_scale_bench [--trough 100,250,...] [--bowl 50,...] [--duration S] [--dt S]
//                          [--out DIR] [--bowl-scene FILE] [--quick]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/builtin_scenes.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/number_format.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/output/plot.hpp"
#include "rheofeed/scene/run_step.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "rheofeed/simulation/check.hpp"
#include "rheofeed/simulation/run.hpp"
#include "rheofeed/simulation/simulation.hpp"
#include "rheofeed/vibration_drift.hpp"

#ifndef RHEOFEED_SOURCE_DIR
#error "RHEOFEED_SOURCE_DIR must name the source tree (the bowl scene, demos/results)"
#endif

namespace {

namespace fs = std::filesystem;
using namespace rheofeed::scene;
using rheofeed::formatNumber;

// The hopper and the bowl are filled over this long (s): rate = N / kPourSeconds (issue 17).
constexpr double kPourSeconds = 5.0;

struct Options {
  std::vector<int> trough = {100, 250, 500, 1000, 2000};
  std::vector<int> bowl = {50, 100, 200, 400};
  double duration = 8.0;  // s
  double dt = 0.01;       // s
  std::string out = std::string(RHEOFEED_SOURCE_DIR) + "/demos/results";
  // The bowl of boxes and cylinder nuts (issue 18): the mesh bowl (bowl_feeder.json) loses nuts
  // through its mesh at h = 0.01 s whatever the count.
  std::string bowl_scene =
      std::string(RHEOFEED_SOURCE_DIR) + "/demos/scenes/bowl_feeder_primitives.json";
  bool quick = false;
};

// One run's measurements.
struct Row {
  std::string scene;
  int parts = 0;  // N asked for
  RunMetrics metrics;
  StageTimes stages;
  double wall = 0;         // s, the whole run loop (measureRun)
  double mean_parts = 0;   // parts present (spawned, not exited), averaged over the samples
  int check_warnings = 0;  // lines of the scene check (reportSceneCheck)
  long steps() const { return std::max(1L, stages.steps); }
  double cpuPerStep() const { return metrics.cpu_seconds / steps(); }  // s
  double wallPerStep() const { return wall / steps(); }                // s
  double collision() const { return stages.collision / steps(); }      // s per step
  // The drift table's fill, a part of the contact stage: its model runs' CPU time as wall-clock
  // time on this run's share of the core (the table runs them in one thread here: run()).
  double tableFill() const {  // s per step
    return metrics.health.local_law.model_cpu_seconds / cpuPerWall() / steps();
  }
  double contacts() const {  // s per step, the table fill taken out
    return std::max(0.0, stages.contacts / steps() - tableFill());
  }
  double solve() const { return stages.solve / steps(); }    // s per step
  double checks() const { return stages.checks / steps(); }  // s per step
  double sceneLayer() const {                                // s per step
    return std::max(0.0, wallPerStep() - collision() - stages.contacts / steps() - solve());
  }
  double contactsPerPart() const {
    return mean_parts > 0 ? double(stages.contact_count) / steps() / mean_parts : 0;
  }
  double rowsPerPart() const {
    return mean_parts > 0 ? double(stages.constraint_rows) / steps() / mean_parts : 0;
  }
  // CPU time over wall-clock time of the run loop: 1 on an idle core.
  double cpuPerWall() const { return wall > 0 ? metrics.cpu_seconds / wall : 1; }
  // CPU time per step less the drift table fill: a run with a saved table (s).
  double cpuPerStepSavedTable() const {
    return cpuPerStep() - metrics.health.local_law.model_cpu_seconds / steps();
  }
};

// The stages of a row in the order of the tables and the plot: name, wall-clock seconds per step.
struct Stage {
  const char* name;
  double (Row::*perStep)() const;
};
// A stage's CPU seconds per step, estimated as its share of the loop's wall-clock time times the
// CPU time per step (other work on the core slows every stage alike): the stages of a row then
// add up to its CPU time per step.
double cpuPerStep(const Row& r, const Stage& s) {
  return (r.*s.perStep)() * r.cpuPerWall();
}
const Stage kStages[] = {{"collision", &Row::collision},
                         {"contact creation and the plugin", &Row::contacts},
                         {"drift table fill", &Row::tableFill},
                         {"solve", &Row::solve},
                         {"scene layer", &Row::sceneLayer}};

// d ln y / d ln x between two points (NaN where undefined).
double slope(double x0, double y0, double x1, double y1) {
  if (!(x0 > 0 && x1 > 0 && y0 > 0 && y1 > 0) || x0 == x1) return std::nan("");
  return std::log(y1 / y0) / std::log(x1 / x0);
}

Scene hopperTrough(int parts) {
  return linearTroughScene(parts, parts / kPourSeconds);
}

Scene bowlWithNuts(int parts, const Options& o) {
  Scene s = loadScene(o.bowl_scene);
  if (s.parts.size() != 1) {
    throw std::runtime_error(o.bowl_scene + ": expected one part family (the nuts), found " +
                             std::to_string(s.parts.size()));
  }
  s.parts[0].count = parts;
  s.parts[0].rate = parts / kPourSeconds;
  // The scene's calibrated drift, whatever drift model it ships with: this benchmark measures
  // what the crowd costs per step, and the local law's one-time drift table fill would mix in.
  overrideDriftModel(s, DriftModel::CalibratedDrift);
  return s;
}

// The scene at the benchmark's step and duration (the library's step rule with --dt as the
// override), its warm-up and sample interval shortened to half the duration where longer
// (--quick).
Scene prepared(Scene s, const Options& o) {
  s.duration = o.duration;
  s.outputs.warmup = std::min(s.outputs.warmup, 0.5 * o.duration);
  s.outputs.sample_interval = std::min(s.outputs.sample_interval, 0.5 * o.duration);
  StepOverrides overrides;
  overrides.every_run = o.dt;
  overrides.every_run_name = "--dt";
  return atRunStep(s, runStep(s, Method::OdeRheonomic, overrides));
}

Row measure(const std::string& name, int parts, const Scene& scene, const std::string& label) {
  Row r;
  r.scene = name;
  r.parts = parts;
  r.check_warnings = static_cast<int>(reportSceneCheck(scene, Method::OdeRheonomic).size());
  const std::unique_ptr<Simulation> sim = makeSimulation(scene, Method::OdeRheonomic);
  sim->setStageTiming(true);
  const auto start = std::chrono::steady_clock::now();
  r.metrics = measureRun(*sim, scene, stderrProgress(label));
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.stages = sim->stageTimes();
  double sum = 0;
  for (const DriftSample& d : r.metrics.series) sum += d.parts;
  r.mean_parts = r.metrics.series.empty() ? 0 : sum / r.metrics.series.size();
  return r;
}

const char* kCsvHeader =
    "scene,parts,spawned,mean_parts_present,steps,time_step_s,simulated_s,cpu_s,wall_s,"
    "cpu_per_wall,real_time_factor,cpu_ms_per_step,wall_ms_per_step,collision_ms_per_step,"
    "contacts_ms_per_step,solve_ms_per_step,scene_layer_ms_per_step,checks_ms_per_step,"
    "contacts_per_part,rows_per_part,lost,lost_through_fixture,lost_fell,lost_inside_fixture,"
    "lost_left_feeder,lost_other,sunk,exited,local_law_cells,local_law_model_runs,"
    "local_law_model_cpu_s,scene_check_warnings,cpu_slope_from_previous\n";

std::string csvRow(const Row& r, const Row* previous) {
  const RunHealth& h = r.metrics.health;
  const auto ms = [](double s) { return formatNumber(1e3 * s, 5); };
  std::ostringstream line;
  line << r.scene << ',' << r.parts << ',' << r.metrics.parts << ','
       << formatNumber(r.mean_parts, 5) << ',' << r.stages.steps << ','
       << formatNumber(r.metrics.time_step) << ',' << formatNumber(r.metrics.simulated_seconds)
       << ',' << formatNumber(r.metrics.cpu_seconds, 5) << ',' << formatNumber(r.wall, 5) << ','
       << formatNumber(r.wall > 0 ? r.metrics.cpu_seconds / r.wall : 0, 3) << ','
       << formatNumber(r.metrics.real_time_factor, 4) << ',' << ms(r.cpuPerStep()) << ','
       << ms(r.wallPerStep()) << ',' << ms(r.collision()) << ',' << ms(r.contacts()) << ','
       << ms(r.solve()) << ',' << ms(r.sceneLayer()) << ',' << ms(r.checks()) << ','
       << formatNumber(r.contactsPerPart(), 4) << ',' << formatNumber(r.rowsPerPart(), 4) << ','
       << h.partsLost() << ',' << h.parts_through_fixture << ',' << h.parts_fell << ','
       << h.parts_inside_fixture << ',' << h.parts_left_feeder << ','
       << h.parts_out_of_bounds + h.parts_nonfinite + h.parts_too_fast << ',' << h.parts_sunk << ','
       << h.parts_exited << ',' << h.local_law.cells_computed << ',' << h.local_law.model_runs
       << ',' << formatNumber(h.local_law.model_cpu_seconds, 4) << ',' << r.check_warnings << ',';
  if (previous) {
    line << formatNumber(slope(previous->parts, previous->cpuPerStep(), r.parts, r.cpuPerStep()),
                         3);
  }
  line << '\n';
  return line.str();
}

// The rows of one scene, in increasing part counts.
std::vector<const Row*> rowsOf(const std::vector<Row>& rows, const std::string& scene) {
  std::vector<const Row*> out;
  for (const Row& r : rows) {
    if (r.scene == scene) out.push_back(&r);
  }
  return out;
}

// The span of the overall slope: the second smallest count to the largest (the smallest run is
// dominated by fixed costs); the only two rows when there are two.
std::pair<const Row*, const Row*> overallSpan(const std::vector<const Row*>& rows) {
  if (rows.size() < 2) return {nullptr, nullptr};
  return {rows[rows.size() >= 3 ? 1 : 0], rows.back()};
}

std::string markdownTables(const std::vector<const Row*>& rows, const std::string& title) {
  if (rows.empty()) return "";
  std::ostringstream md;
  const auto ms = [](double s) { return formatNumber(1e3 * s, 3); };
  md << "## " << title << "\n\n"
     << "| parts | CPU (s) | real-time factor | CPU ms/step | collision | contacts + plugin | "
        "drift table fill | solve | scene layer | contacts/part | rows/part | lost (through, "
        "fell, inside) | sunk | point-mass runs | slope |\n|---|---|---|---|---|---|---|---|---|"
        "---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Row& r = *rows[k];
    const RunHealth& h = r.metrics.health;
    md << "| " << r.parts << " | " << formatNumber(r.metrics.cpu_seconds, 3) << " | "
       << formatNumber(r.metrics.real_time_factor, 3) << " | " << ms(r.cpuPerStep()) << " | "
       << ms(cpuPerStep(r, kStages[0])) << " | " << ms(cpuPerStep(r, kStages[1])) << " | "
       << ms(cpuPerStep(r, kStages[2])) << " | " << ms(cpuPerStep(r, kStages[3])) << " | "
       << ms(cpuPerStep(r, kStages[4])) << " | " << formatNumber(r.contactsPerPart(), 3) << " | "
       << formatNumber(r.rowsPerPart(), 3) << " | " << h.partsLost() << " ("
       << h.parts_through_fixture << ", " << h.parts_fell << ", " << h.parts_inside_fixture
       << ") | " << h.parts_sunk << " | " << h.local_law.model_runs << " | "
       << (k ? formatNumber(
                   slope(rows[k - 1]->parts, rows[k - 1]->cpuPerStep(), r.parts, r.cpuPerStep()), 3)
             : std::string("-"))
       << " |\n";
  }
  md << "\n";
  if (const auto [first, last] = overallSpan(rows); first && last) {
    const Row& a = *first;
    const Row& b = *last;
    md << "Overall " << a.parts << " -> " << b.parts << " parts: CPU per step grows as N^"
       << formatNumber(slope(a.parts, a.cpuPerStep(), b.parts, b.cpuPerStep()), 3)
       << " (wall-clock per step N^"
       << formatNumber(slope(a.parts, a.wallPerStep(), b.parts, b.wallPerStep()), 3)
       << "); without the drift table fill (a run with a saved table) N^"
       << formatNumber(slope(a.parts, a.cpuPerStepSavedTable(), b.parts, b.cpuPerStepSavedTable()),
                       3)
       << ".";
    const Stage* top = nullptr;
    double top_growth = -1, total_growth = 0;
    for (const Stage& s : kStages) total_growth += cpuPerStep(b, s) - cpuPerStep(a, s);
    md << " By stage (CPU ms per step):";
    const char* separator = " ";
    for (const Stage& s : kStages) {
      const double growth = cpuPerStep(b, s) - cpuPerStep(a, s);
      // A stage that is zero at either end (the table fill) has no slope.
      const double stage_slope = slope(a.parts, cpuPerStep(a, s), b.parts, cpuPerStep(b, s));
      md << separator << s.name << " "
         << (std::isnan(stage_slope) ? std::string("(no slope)")
                                     : "N^" + formatNumber(stage_slope, 3))
         << " (" << ms(cpuPerStep(a, s)) << " -> " << ms(cpuPerStep(b, s)) << ")";
      separator = ", ";
      if (growth > top_growth) {
        top_growth = growth;
        top = &s;
      }
    }
    md << ".";
    if (top && total_growth > 0) {
      md << " Most of the growth is in the stage \"" << top->name << "\": +" << ms(top_growth)
         << " of +" << ms(total_growth) << " ms per step ("
         << formatNumber(100 * top_growth / total_growth, 3) << " %).";
    }
    md << " At " << b.parts << " parts the CPU time per step is";
    separator = " ";
    for (const Stage& s : kStages) {
      md << separator << formatNumber(100 * cpuPerStep(b, s) / b.cpuPerStep(), 3) << " % "
         << s.name;
      separator = ", ";
    }
    md << ".\n\n";
  }
  return md.str();
}

// Issue 17's goals for the trough, against the rows that measure them (the counts asked for):
// cost growth no faster than N^1.1 from 250 to 2000 parts, a real-time factor of at most 0.1 at
// 500 parts and 0.5 at 2000, no part lost through a fixture and none sunk, at every count.
std::string troughGoals(const std::vector<const Row*>& rows) {
  const auto at = [&](int parts) -> const Row* {
    for (const Row* r : rows) {
      if (r->parts == parts) return r;
    }
    return nullptr;
  };
  std::ostringstream md;
  const char* bullet = "- ";
  if (const Row* a = at(250), *b = at(2000); a && b) {
    // The whole run's cost, and the cost with a saved drift table (no fill).
    for (const bool saved : {false, true}) {
      const double ca = saved ? a->cpuPerStepSavedTable() : a->cpuPerStep();
      const double cb = saved ? b->cpuPerStepSavedTable() : b->cpuPerStep();
      const double s = slope(a->parts, ca, b->parts, cb);
      md << bullet << "cost per step N^1.1 or slower from 250 to 2000 parts"
         << (saved ? ", the drift table fill left out" : "") << ": N^" << formatNumber(s, 3)
         << (s <= 1.1 ? " (met)"
                      : " (missed: " +
                            formatNumber(cb / ca / std::pow(double(b->parts) / a->parts, 1.1), 3) +
                            " x the cost per step at 2000 that N^1.1 allows)")
         << "\n";
    }
  }
  for (const auto& [parts, goal] : {std::pair{500, 0.1}, std::pair{2000, 0.5}}) {
    if (const Row* r = at(parts)) {
      const double rtf = r->metrics.real_time_factor;
      md << bullet << "real-time factor at " << parts << " parts <= " << formatNumber(goal) << ": "
         << formatNumber(rtf, 3)
         << (rtf <= goal ? " (met)" : " (missed: " + formatNumber(rtf / goal, 3) + " x)") << "\n";
    }
  }
  int lossy = 0;
  for (const Row* r : rows) {
    lossy += r->metrics.health.parts_through_fixture > 0 || r->metrics.health.parts_sunk > 0;
  }
  md << bullet << "no part through a fixture and none sunk: " << (lossy ? "missed" : "met") << " ("
     << lossy << " of " << rows.size() << " part counts lose or sink parts; table above)\n";
  return "## Issue 17's goals (trough, ODE + plugin)\n\n" + md.str() + "\n";
}

std::string plotScript(const std::vector<std::pair<std::string, std::vector<const Row*>>>& scenes,
                       double dt) {
  std::ostringstream gp;
  gp << "set datafile separator ','\nset logscale xy\nset autoscale xfix\nset grid\n"
     << "set key top left\nset xlabel 'parts'\nset ylabel 'CPU time per step (ms)'\n"
     << "set multiplot layout 1," << scenes.size()
     << " title 'ODE + plugin, h = " << formatNumber(dt)
     << " s: time per step by stage (log-log)'\n";
  // CSV columns: 1 scene, 2 parts, 5 steps, 10 cpu_per_wall, 12 cpu_ms_per_step, 14 collision,
  // 15 contacts (with the table fill), 16 solve, 17 scene layer (wall-clock: scaled by
  // cpu_per_wall, as the tables), 31 the table fill's CPU seconds (taken out of the contacts).
  const std::pair<std::string, const char*> series[] = {
      {"$12", "CPU total"},
      {"$14 * $10", "collision"},
      {"($15 * $10 - 1e3 * $31 / $5)", "contacts + plugin"},
      {"(1e3 * $31 / $5)", "drift table fill"},
      {"$16 * $10", "solve"},
      {"$17 * $10", "scene layer"}};
  for (const auto& [scene, rows] : scenes) {
    gp << "set title '" << scene << "'\nplot ";
    const char* comma = "";
    for (const auto& [y, title] : series) {
      gp << comma << "$data using (strcol(1) eq '" << scene << "' ? $2 : 1/0):((" << y << " > 0) ? "
         << y << " : 1/0) with linespoints lw 2 pt 7 title '" << title << "'";
      comma = ", ";
    }
    // Linear cost from the start of the overall span: what the measured line is read against.
    const auto [a, b] = overallSpan(rows);
    if (a && b) {
      gp << ", (x >= " << a->parts << " && x <= " << b->parts << ") ? "
         << formatNumber(1e3 * a->cpuPerStep()) << " * x / " << a->parts
         << " : 1/0 with lines dt 2 lw 2 lc rgb 'gray40' title 'N^1 from " << a->parts << "'";
    }
    gp << "\n";
  }
  gp << "unset multiplot\n";
  return gp.str();
}

std::string commandLine(const Options& o) {
  std::ostringstream c;
  c << "nice -n 10 build/demos/crowd_scale_bench";
  if (o.quick) {
    c << " --quick";
  } else {
    auto list = [](const std::vector<int>& v) {
      std::string s = v.empty() ? "0" : "";  // a lone 0: no run of the scene
      for (std::size_t k = 0; k < v.size(); ++k) s += (k ? "," : "") + std::to_string(v[k]);
      return s;
    };
    c << " --trough " << list(o.trough) << " --bowl " << list(o.bowl) << " --duration "
      << formatNumber(o.duration) << " --dt " << formatNumber(o.dt);
  }
  c << " --out demos/results";
  return c.str();
}

int run(const Options& o) {
  struct Job {
    std::string scene;
    int parts;
  };
  std::vector<Job> jobs;
  for (int n : o.trough) jobs.push_back({"trough", n});
  for (int n : o.bowl) jobs.push_back({"bowl", n});
  if (jobs.empty()) throw std::invalid_argument("--trough and --bowl are both empty: no run");
  std::sort(jobs.begin(), jobs.end(), [](const Job& a, const Job& b) {
    return a.scene != b.scene ? a.scene > b.scene : a.parts < b.parts;  // trough first
  });
  // Every scene is built (and its file read) before the first run: a bad input stops here.
  std::vector<Scene> scenes;
  for (const Job& j : jobs) {
    try {
      scenes.push_back(
          prepared(j.scene == "trough" ? hopperTrough(j.parts) : bowlWithNuts(j.parts, o), o));
      scenes.back().validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(j.scene + " with " + std::to_string(j.parts) +
                                  " parts, --duration " + formatNumber(o.duration) + " s, --dt " +
                                  formatNumber(o.dt) + " s: " + e.what());
    }
  }
  // The drift table's model runs in the runs' own thread, so that their time is one core's, as
  // the rest of the step (the default uses every hardware thread).
  rheofeed::LocalDriftTable::shared()->setThreads(1);
  std::vector<Row> rows;
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    std::fprintf(stderr, "crowd_scale: run %zu of %zu: %s, %d parts, %g s at h = %g s\n", k + 1,
                 jobs.size(), jobs[k].scene.c_str(), jobs[k].parts, o.duration, o.dt);
    const std::string label = "crowd_scale: " + jobs[k].scene + " " + std::to_string(jobs[k].parts);
    rows.push_back(measure(jobs[k].scene, jobs[k].parts, scenes[k], label));
    const Row& r = rows.back();
    std::fprintf(stderr,
                 "crowd_scale: %s %d: CPU %.3g s (real-time factor %.3g), %.3g ms/step, "
                 "%d lost, %d sunk\n",
                 r.scene.c_str(), r.parts, r.metrics.cpu_seconds, r.metrics.real_time_factor,
                 1e3 * r.cpuPerStep(), r.metrics.health.partsLost(), r.metrics.health.parts_sunk);
  }

  std::ostringstream csv;
  csv << kCsvHeader;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const bool same = k > 0 && rows[k - 1].scene == rows[k].scene;
    csv << csvRow(rows[k], same ? &rows[k - 1] : nullptr);
  }

  double cpu = 0, wall = 0;
  for (const Row& r : rows) {
    cpu += r.metrics.cpu_seconds;
    wall += r.wall;
  }
  std::ostringstream md;
  md << "# Crowd scale: ODE + plugin at h = " << formatNumber(o.dt) << " s\n\n"
     << "Method ode_rheonomic, each scene's default solver settings, " << formatNumber(o.duration)
     << " s simulated per run; parts poured in at N / " << formatNumber(kPourSeconds)
     << " per s (issue 17). trough: the main demo's hopper-fed trough (linearTroughScene(N, N / "
        "5)); bowl: "
     << std::filesystem::path(o.bowl_scene).filename().string()
     << " with N nuts (its calibrated drift; its own rheonomic step is "
     << formatNumber(loadScene(o.bowl_scene).solver.rheonomic_time_step)
     << " s). One run each on one machine: read ratios. CPU / wall over all runs: "
     << formatNumber(wall > 0 ? cpu / wall : 0, 3) << " (1 on an idle core).\n\n"
     << "Regenerate: `" << commandLine(o) << "` (after `cmake --build build --target "
     << "crowd_scale_bench`). Data: crowd_scale.csv; plot: crowd_scale.png.\n\n";
  md << markdownTables(rowsOf(rows, "trough"), "Hopper-fed trough (linear_trough)");
  md << markdownTables(rowsOf(rows, "bowl"), "Bowl feeder (bowl_feeder)");
  if (!rowsOf(rows, "trough").empty()) md << troughGoals(rowsOf(rows, "trough"));
  md << "Columns: CPU (s) and real-time factor (CPU / simulated time) of the whole run; CPU "
        "ms/step and the stages per step, each stage its share of the run loop's wall-clock "
        "time times the CPU time per step (they add up to the CPU column; crowd_scale.csv has "
        "the raw wall-clock times and CPU / wall per run). Collision: dSpaceCollide and "
        "dCollide; contact creation and the plugin: surface parameters, "
        "FeederSet::driveContacts (the vibration law), joint creation; drift table fill: the local "
        "law's point-mass model runs (in one thread; the runs share one table in increasing "
        "part counts, so a later run fills only what earlier ones did not; a saved table "
        "removes it); solve: dWorldQuickStep; "
        "scene layer: the rest of the loop (part checks, metrics, observers). Contacts and "
        "rows per part: contact joints and constraint rows per step over the parts present "
        "(spawned, not exited), averaged over the run. Lost: RunHealth::partsLost, every kind "
        "(through a fixture, fell and inside a fixture shown; left the feeder, out of bounds, "
        "non-finite and too fast in the CSV); sunk: parts whose centre went deeper than half "
        "their size into a fixture and came back. Slope: d ln(CPU per step) / d ln(parts) from "
        "the row above.\n";

  const fs::path out(o.out);
  writeFileAtomically(out / "crowd_scale.csv", csv.str());
  writeFileAtomically(out / "crowd_scale.md", md.str());
  std::vector<std::pair<std::string, std::vector<const Row*>>> plotted;
  for (const char* scene : {"trough", "bowl"}) {
    if (!rowsOf(rows, scene).empty()) plotted.emplace_back(scene, rowsOf(rows, scene));
  }
  const bool plot =
      plotPng(plotScript(plotted, o.dt), {{"data", csv.str()}}, (out / "crowd_scale.png").string());
  std::fprintf(stderr, "crowd_scale: wrote %s/crowd_scale.{csv,md%s}\n", o.out.c_str(),
               plot ? ",png" : "");
  if (!plot) std::fprintf(stderr, "crowd_scale: warning: the plot was not written (gnuplot)\n");
  std::fputs(md.str().c_str(), stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "Scale benchmark: ODE + plugin on the hopper-fed trough and the bowl feeder at "
      "growing part counts; time per step by stage, contacts, losses, log-log slope"};
  app.add_option("--trough", o.trough, "part counts of the trough runs (a lone 0: none)")
      ->delimiter(',')
      ->check(CLI::Range(0, 4000))
      ->capture_default_str();
  app.add_option("--bowl", o.bowl, "nut counts of the bowl runs (a lone 0: none)")
      ->delimiter(',')
      ->check(CLI::Range(0, 4000))
      ->capture_default_str();
  app.add_option("--duration", o.duration, "simulated time per run (s)")
      ->check(CLI::Range(1e-3, 1e4))
      ->capture_default_str();
  app.add_option("--dt", o.dt, "time step (s)")
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  app.add_option("--out", o.out, "output folder")->capture_default_str();
  app.add_option("--bowl-scene", o.bowl_scene, "the bowl's scene file")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  app.add_flag("--quick", o.quick,
               "smoke run: trough 20, 40 and bowl 10, 20 parts, 1 s (overrides the counts and "
               "the duration)");
  CLI11_PARSE(app, argc, argv);
  if (o.quick) {
    o.trough = {20, 40};
    o.bowl = {10, 20};
    o.duration = 1.0;
  }
  for (const auto& [name, counts] : {std::pair{"--trough", &o.trough}, {"--bowl", &o.bowl}}) {
    if (counts->size() == 1 && counts->front() == 0) {
      counts->clear();  // a lone 0: no runs of that scene
    } else if (std::count(counts->begin(), counts->end(), 0) > 0) {
      std::fprintf(stderr,
                   "crowd_scale_bench: %s: a part count of 0 in a list; counts are in [1, 4000], "
                   "a lone 0 asks for no run of the scene\n",
                   name);
      return 2;
    }
  }
  for (const auto& [name, value] : {std::pair{"--duration", o.duration}, {"--dt", o.dt}}) {
    if (!std::isfinite(value)) {  // CLI::Range lets NaN through
      std::fprintf(stderr, "crowd_scale_bench: %s = %s: must be a finite number\n", name,
                   formatNumber(value).c_str());
      return 2;
    }
  }
  if (o.out.empty()) {
    std::fprintf(stderr, "crowd_scale_bench: --out \"\": must name an output folder\n");
    return 2;
  }
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crowd_scale_bench: %s\n", e.what());
    return 2;
  }
}
