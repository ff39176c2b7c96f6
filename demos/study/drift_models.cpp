// SPDX-License-Identifier: MIT
#include "study/drift_models.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "common/builtin_scenes.hpp"
#include "rheofeed/measure/calibration.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/output/plot.hpp"
#include "rheofeed/scene/run_step.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "study/bowl_phases.hpp"

namespace rheofeed::demo {
namespace {

using namespace rheofeed::scene;

constexpr double kDeg = kPi / 180;

// The drift models of the comparison, in table order.
// "level_constant": the sampled constant of track_level reused on the other tracks (what a user
// who calibrated once on a level track gets on an incline or a cross slope).
// "scene_constant": the constant drift twist the scene file ships (the primitive bowl's, carried
// over from the mesh bowl).
const char* const kModels[] = {"local",     "local_sampled",  "sampled_constant",
                               "classical", "level_constant", "scene_constant"};
constexpr int kModelCount = 6;
constexpr int kSceneConstant = 5;

// A scene of the comparison: how to build it, what its drift is measured as.
struct StudyScene {
  std::string name;
  std::string what;  // one line for the table
  std::function<Scene(bool quick)> build;
  // The judge and the sampling runs use the reference engine (true Coulomb cone): ODE's
  // friction pyramid holds a part sideways on a cross slope while it slides forward (its
  // sideways creep is 0 in ODE full vibration, 18 % of the forward speed with the cone).
  bool reference_judge = false;
  // Steps per cycle of the judge and the sampling runs when not the study's own (0): the bowl's
  // 12 mesh nuts at 1000 steps per cycle take over an hour for its 20 s on the development
  // machine; 200 is twice the bowl scene's own full-vibration step.
  int judge_steps_per_cycle = 0;
};

// The bowl of primitives is measured per bowl phase (bowl_phases.hpp): one table row per phase,
// and the mean height against time. Its judge solves the friction cone, and only the local law
// and the scene's own constant run (no sampling run: the question).
const char* const kBowlPrimitives = "bowl_primitives";
bool byBowlPhase(const StudyScene& s) {
  return s.name == kBowlPrimitives;
}
bool modelRuns(const StudyScene& s, int model) {
  if (byBowlPhase(s)) return model == 0 || model == kSceneConstant;
  return model != kSceneConstant;
}

std::vector<StudyScene> studyScenes(const DriftModelStudyOptions& o) {
  std::vector<StudyScene> list;
  auto track = [&](const std::string& name, const std::string& what, double incline, double cross,
                   bool sideways) {
    list.push_back({name, what,
                    [=](bool quick) {
                      Scene s = tiltedTrackScene(incline, cross, sideways, quick);
                      s.name = name;
                      return s;
                    },
                    cross != 0});
  };
  track("track_level", "one plate, level track (m/s along the track)", 0, 0, false);
  track("track_up5", "one plate, track climbing 5 deg", 5, 0, false);
  track("track_down5", "one plate, track falling 5 deg", -5, 0, false);
  track("track_up10", "one plate, track climbing 10 deg", 10, 0, false);
  track("track_cross5", "one plate, 5 deg cross slope: along the track", 0, 5, false);
  track("track_cross5_sideways", "one plate, 5 deg cross slope: sideways (+y uphill)", 0, 5, true);
  list.push_back({"heap", "40 boxes in a heap, trough (m/s)", [](bool quick) {
                    Scene s = troughScene(40, true);
                    s.name = "heap";
                    if (quick) s.duration = 1.5;
                    return s;
                  }});
  list.push_back(
      {"hopper", "hopper-fed trough, the main demo: 120 boxes at 20/s (m/s)", [](bool quick) {
         Scene s = quick ? linearTroughScene(30, 20) : linearTroughScene(120, 20);
         s.name = "hopper";
         s.duration = quick ? 6.0 : 30.0;
         return s;
       }});
  const std::string bowl = o.bowl_scene;
  auto bowl_phase = [bowl](const std::string& name, double warmup, double end, bool quick) {
    Scene s = loadScene(bowl);
    s.name = name;
    s.duration = quick ? std::min(end, warmup + 1.0) : end;
    s.outputs.warmup = warmup;
    // The sampled constant and the efficiency come from this scene's own sampling runs.
    for (Fixture& f : s.fixtures) f.law.has_calibrated_drift = false;
    return s;
  };
  list.push_back({"bowl_floor", "bowl, 12 nuts on the floor, 1-4 s (rad/s)",
                  [=](bool quick) { return bowl_phase("bowl_floor", 1.0, 4.0, quick); }, false,
                  200});
  list.push_back({"bowl_ramp", "bowl, 12 nuts on the ramp, 8-20 s (rad/s)",
                  [=](bool quick) { return bowl_phase("bowl_ramp", 8.0, 20.0, quick); }, false,
                  200});
  // The bowl of primitives over its whole run (60 s: the nuts reach the ramp's second turn at
  // the calibrated drift), measured by where each nut is. Judge at the scene file's own
  // full-vibration step (the shipped file: 100 steps per cycle; 60 s take about 90 s CPU).
  const std::string primitives = o.bowl_primitives_scene;
  list.push_back({kBowlPrimitives,
                  "bowl of primitives, 12 cylinder nuts, 1-60 s, by where each nut is (rad/s)",
                  [primitives](bool quick) {
                    Scene s = loadScene(primitives);
                    s.name = "bowl_primitives";
                    if (quick) s.duration = 6.0;
                    s.outputs.warmup = 1.0;
                    return s;
                  },
                  false, 0});
  return list;
}

int vibratingFixture(const Scene& s) {
  for (std::size_t i = 0; i < s.fixtures.size(); ++i) {
    if (s.fixtures[i].law.kind == FeederLaw::Kind::Vibration) return static_cast<int>(i);
  }
  throw std::invalid_argument("scene '" + s.name + "' has no vibrating feeder");
}

// One model on one scene.
struct ModelResult {
  bool ran = false;
  std::string note;  // why not, or how calibrated
  double drift = 0, ci95 = 0;
  double run_cpu = 0, calibration_cpu = 0;
  int parts_lost = 0;  // summed over the seeds (RunHealth::partsLost)
};

struct SceneResult {
  std::string name, what;
  double part_seconds = 0;  // bowl phases: the judge's part-seconds in the phase
  Method judge = Method::OdeFullVibration;
  int judge_steps_per_cycle = 0;
  double reference = 0, reference_ci95 = 0, reference_cpu = 0;
  int reference_parts_lost = 0;
  ModelResult models[kModelCount];
};

// What a phase's drift is made of: time in it, stalled windows, drift while moving.
std::string phaseNote(const PhaseDrift& d) {
  char text[200];
  std::snprintf(text, sizeof text,
                "%.0f part-seconds, %.0f %% of %d windows of %.0f s stalled (< %.2g rad/s), "
                "moving at %.4g rad/s",
                d.part_seconds, 100 * d.stalled_share, d.windows, kStallWindow, kStallDrift,
                d.moving_drift);
  return text;
}

Scene withDriftModel(Scene s, int fixture, DriftModel model) {
  s.fixtures[static_cast<std::size_t>(fixture)].law.drift_model = model;
  return s;
}

std::string lossNote(int parts_lost) {
  if (parts_lost == 0) return "";
  return " (" + std::to_string(parts_lost) + " parts lost)";
}

// Writes <scene>_height.csv: the mean height of the parts (m) against time (s), one column per
// run (the judge, then each model), from the first seed's series, and its plot <scene>_height.png
// (said on stderr when gnuplot fails). Throws if it cannot write the CSV.
template <class Measured>
void writeHeightCsv(const DriftModelStudyOptions& o, const std::string& scene,
                    const std::vector<std::pair<int, Measured>>& runs) {
  std::ostringstream csv;
  csv << "time_s";
  std::size_t rows = 0;
  for (const auto& [slot, m] : runs) {
    csv << "," << (slot < 0 ? "full_vibration" : kModels[slot]) << "_m";
    rows = std::max(rows, m.series.size());
  }
  csv << "\n";
  char cell[64];
  for (std::size_t i = 0; i < rows; ++i) {
    std::snprintf(cell, sizeof cell, "%.4f",
                  runs.front().second.series.size() > i ? runs.front().second.series[i].time : NAN);
    csv << cell;
    for (const auto& run : runs) {
      const auto& series = run.second.series;
      std::snprintf(cell, sizeof cell, ",%.6f", i < series.size() ? series[i].mean_height : NAN);
      csv << cell;
    }
    csv << "\n";
  }
  const std::filesystem::path out(o.out_dir);
  writeFileAtomically(out / (scene + "_height.csv"), csv.str());
  std::ostringstream gp;
  gp << "set datafile separator ','\nset key top left\nset grid\nset xlabel 'time (s)'\n"
        "set ylabel 'mean height of the nuts (mm)'\nset title '"
     << scene << ": mean height against time (full vibration: ODE, friction cone)'\nplot ";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const int slot = runs[k].first;
    gp << (k ? ", " : "") << "$data using 1:($" << k + 2 << " * 1000) with lines lw 2 title '"
       << (slot < 0 ? "full vibration" : kModels[slot]) << "'";
  }
  gp << "\n";
  if (!plotPng(gp.str(), {{"data", csv.str()}}, (out / (scene + "_height.png")).string())) {
    std::fprintf(stderr, "drift model study: the height plot was not written (gnuplot failed)\n");
  }
}

// Writes drift_models.{csv,md,png} for the scenes done so far (after every scene, so a long
// study leaves its results behind as it goes). False (message on stderr) if a file could not
// be written.
bool writeOutputs(const DriftModelStudyOptions& o, const std::vector<SceneResult>& results,
                  bool final) {
  // Outputs: CSV (one row per scene and model), markdown table, error bar chart.
  std::ostringstream csv, md, bars;
  csv << "scene,model,drift,ci95,reference,reference_ci95,error,run_cpu_s,calibration_cpu_s,"
         "reference_cpu_s,parts_lost,reference_parts_lost,note\n";
  md << "Drift models against full vibration (the judge: ODE, or the reference engine where "
        "marked, at the steps per cycle given"
     << (o.quick ? ", QUICK run" : "")
     << "); every rheonomic run is ODE + plugin at h = " << o.rheonomic_time_step
     << " s (or the scene's own solver.rheonomic_time_step where it gives one). Error = (drift - "
        "full vibration) / |full vibration|. Cost = CPU of the run plus "
        "its calibration (sampling runs at the judge's steps per cycle).\n\n"
     << "| scene | full vibration | local | local + sampled efficiency | sampled constant | "
        "classical constant | constant sampled on the level track | the scene's own constant "
        "|\n|---|---|---|---|---|---|---|---|\n";
  bars << "scene,local,local_sampled,sampled_constant,classical,level_constant,scene_constant\n";
  char line[512];
  for (const SceneResult& r : results) {
    std::snprintf(line, sizeof line, "| %s | %.4g (%s, %d steps/cycle, %.0f s) |", r.name.c_str(),
                  r.reference,
                  r.judge != Method::OdeFullVibration ? "reference"
                  : r.part_seconds > 0                ? "ODE, cone"
                                                      : "ODE",
                  r.judge_steps_per_cycle, r.reference_cpu);
    md << line;
    bars << r.name;
    for (int k = 0; k < kModelCount; ++k) {
      const ModelResult& m = r.models[k];
      const double error = m.ran ? (m.drift - r.reference) / std::abs(r.reference) : NAN;
      std::snprintf(line, sizeof line,
                    "%s,%s,%.8g,%.4g,%.8g,%.4g,%.6g,%.4g,%.4g,%.4g,%d,%d,\"%s\"\n", r.name.c_str(),
                    kModels[k], m.drift, m.ci95, r.reference, r.reference_ci95, error, m.run_cpu,
                    m.calibration_cpu, r.reference_cpu, m.parts_lost, r.reference_parts_lost,
                    m.note.c_str());
      csv << line;
      if (m.ran) {
        std::snprintf(line, sizeof line, " %.4g (%+.1f %%, %.2g s) |", m.drift, 100 * error,
                      m.run_cpu + m.calibration_cpu);
      } else {
        std::snprintf(line, sizeof line, " n/a |");
      }
      md << line;
      bars << "," << (m.ran ? 100 * std::abs(error) : 0.0);
    }
    md << "\n";
    bars << "\n";
  }
  md << "\nNotes:\n";
  for (const SceneResult& r : results) {
    md << "- " << r.name << ": " << r.what;
    if (!r.models[1].note.empty()) md << "; local_sampled: " << r.models[1].note;
    if (!r.models[3].ran && !r.models[3].note.empty()) md << "; classical: " << r.models[3].note;
    if (r.part_seconds > 0) {  // bowl phases: every model's phase note
      for (int k : {0, kSceneConstant}) {
        if (r.models[k].ran) md << "; " << kModels[k] << ": " << r.models[k].note;
      }
    }
    md << "\n";
  }
  const std::filesystem::path out(o.out_dir);
  try {
    writeFileAtomically(out / "drift_models.csv", csv.str());
    writeFileAtomically(out / "drift_models.md", md.str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drift model study: %s\n", e.what());
    return false;
  }
  std::ostringstream gp;
  gp << "set datafile separator ','\nset style data histograms\nset style histogram clustered "
        "gap 1\nset style fill solid 0.8 border -1\nset key top left\nset grid ytics\n"
        "set logscale y\nset yrange [0.1:*]\nset xtics rotate by -30\n"
        "set ylabel '|drift error| vs full vibration (%)'\n"
        "set title 'Drift models against full vibration (ODE, rheonomic h = "
     << o.rheonomic_time_step << " s)'\n"
     << "plot $data using ($2 > 0.1 ? $2 : 0.1):xtic(1) skip 1 title 'local', '' using ($3 > "
        "0.1 ? $3 : 0.1) skip 1 title 'local + sampled efficiency', '' using ($4 > 0.1 ? $4 : "
        "0.1) skip 1 title 'sampled constant', '' using ($5 > 0.1 ? $5 : 0.1) skip 1 title "
        "'classical constant', '' using ($6 > 0.1 ? $6 : 0.1) skip 1 title 'level-track "
        "constant on this scene', '' using ($7 > 0.1 ? $7 : 0.1) skip 1 title 'the scene''s "
        "own constant'\n";
  if (!plotPng(gp.str(), {{"data", bars.str()}}, (out / "drift_models.png").string())) {
    std::fprintf(stderr, "drift model study: the plot was not written (gnuplot failed)\n");
  }
  if (final) {
    std::printf("%s\nwrote %s/drift_models.{csv,md,png}\n", md.str().c_str(), o.out_dir.c_str());
  }
  return true;
}

}  // namespace

std::vector<std::string> driftModelStudyScenes() {
  std::vector<std::string> names;
  for (const StudyScene& s : studyScenes({})) names.push_back(s.name);
  return names;
}

int runDriftModelStudy(const DriftModelStudyOptions& o) {
  if (o.reference_steps_per_cycle < 100 || !(o.rheonomic_time_step > 0) || o.seeds < 1) {
    std::fprintf(stderr,
                 "drift model study: --ref-steps-per-cycle = %d must be >= 100, --dt = %g s > 0, "
                 "--seeds = %d >= 1\n",
                 o.reference_steps_per_cycle, o.rheonomic_time_step, o.seeds);
    return 2;
  }
  std::vector<StudyScene> scenes = studyScenes(o);
  for (const std::string& want : o.scenes) {
    bool known = false;
    for (const StudyScene& s : scenes) known = known || s.name == want;
    if (!known) {
      std::string names;
      for (const StudyScene& s : scenes) names += " " + s.name;
      std::fprintf(stderr, "drift model study: unknown scene '%s' (known:%s)\n", want.c_str(),
                   names.c_str());
      return 2;
    }
  }
  std::vector<SceneResult> results;
  std::optional<Calibration> level_calibration;  // track_level's sampled constant
  try {
    std::filesystem::create_directories(o.out_dir);
    for (const StudyScene& entry : scenes) {
      if (!o.scenes.empty() &&
          std::find(o.scenes.begin(), o.scenes.end(), entry.name) == o.scenes.end()) {
        continue;
      }
      const Scene scene = entry.build(o.quick);
      scene.validate();
      const int fixture = vibratingFixture(scene);
      const double f = scene.fixtures[static_cast<std::size_t>(fixture)].law.vibration.frequency;
      SceneResult r;
      r.name = entry.name;
      r.what = entry.what;
      std::fprintf(stderr, "\n== %s: %s\n", entry.name.c_str(), entry.what.c_str());

      // The judge: full vibration at the finest step, over the seeds.
      // The primitive bowl's judge steps with its scene file's solver.time_step.
      const int ref_spc = byBowlPhase(entry)
                              ? static_cast<int>(std::lround(1.0 / (f * scene.solver.time_step)))
                          : entry.judge_steps_per_cycle > 0 ? entry.judge_steps_per_cycle
                          : o.quick                         ? 400
                                                            : o.reference_steps_per_cycle;
      r.judge_steps_per_cycle = ref_spc;
      if (!o.quick && ref_spc != o.reference_steps_per_cycle) {
        std::fprintf(stderr,
                     "%s: the judge runs at %d steps per cycle, %s; --ref-steps-per-cycle = %d "
                     "does not apply to it\n",
                     entry.name.c_str(), ref_spc,
                     byBowlPhase(entry) ? "its scene file's solver.time_step"
                                        : "this scene's own judge step",
                     o.reference_steps_per_cycle);
      }
      // The scene's own rheonomic step where it gives one (the bowl: 0.005 s, its trimesh
      // floor lets nuts tunnel at 0.01 s), else the study's.
      StepOverrides study_step;
      study_step.rheonomic_default = o.rheonomic_time_step;
      const double h_rheonomic = runStep(scene, Method::OdeRheonomic, study_step).time_step;
      const Method judge =
          entry.reference_judge ? Method::ReferenceFullVibration : Method::OdeFullVibration;
      r.judge = judge;
      // Every run of this scene: the mean drift over the seeds (the first seed's CI), and for
      // the bowl phases each phase's drift and the first seed's series and nut trace.
      struct Measured {
        PhaseDrift phases[kBowlPhaseCount];
        std::vector<DriftSample> series;
      };
      // By run: -1 the judge, else the model's index in kModels.
      std::vector<std::pair<int, Measured>> phased;
      auto mean_over_seeds = [&](const Scene& base, Method method, const std::string& label,
                                 int slot, double* ci, double* cpu, int* parts_lost) {
        double sum = 0;
        Measured measured;
        for (int k = 0; k < o.seeds; ++k) {
          Scene s = base;
          s.seed = base.seed + static_cast<std::uint64_t>(k);
          BowlPhaseObserver phases(s.outputs.warmup, k == 0);
          std::vector<scene::RunObserver*> observers;
          if (byBowlPhase(entry)) observers.push_back(&phases);
          const RunMetrics m = measureRun(s, method, stderrProgress(label), observers);
          sum += m.mean_drift;
          *cpu += m.cpu_seconds;
          if (k == 0) *ci = m.mean_drift_ci95;
          *parts_lost += m.health.partsLost();
          if (!byBowlPhase(entry)) continue;
          for (int p = 0; p < kBowlPhaseCount; ++p) {
            const PhaseDrift d = phases.drift(static_cast<BowlPhase>(p));
            measured.phases[p].drift += d.drift / o.seeds;
            measured.phases[p].part_seconds += d.part_seconds;
            measured.phases[p].parts += d.parts;
            measured.phases[p].stalled_share += d.stalled_share / o.seeds;
            measured.phases[p].moving_drift += d.moving_drift / o.seeds;
            measured.phases[p].windows += d.windows;
            if (k == 0) measured.phases[p].ci95 = d.ci95;
          }
          if (k == 0) {
            measured.series = m.series;
            const std::string run = slot < 0 ? "full_vibration" : kModels[slot];
            writeFileAtomically(
                std::filesystem::path(o.out_dir) / (entry.name + "_trace_" + run + ".csv"),
                "time_s,part,x_m,y_m,z_m,phase\n" + phases.trace());
          }
        }
        if (byBowlPhase(entry)) phased.emplace_back(slot, measured);
        return sum / o.seeds;
      };
      {
        Scene s = scene;
        s.solver.time_step = 1.0 / (f * ref_spc);
        if (byBowlPhase(entry)) s.solver.friction = FrictionModel::Cone;
        r.reference = mean_over_seeds(
            s, judge, entry.name + " full vibration " + std::to_string(ref_spc) + " steps/cycle",
            -1, &r.reference_ci95, &r.reference_cpu, &r.reference_parts_lost);
      }
      std::fprintf(stderr, "%s: full vibration %.6g +- %.2g (%.1f s CPU)%s\n", entry.name.c_str(),
                   r.reference, r.reference_ci95, r.reference_cpu,
                   lossNote(r.reference_parts_lost).c_str());

      // The rheonomic runs, one per model.
      auto rheonomic = [&](int k, const Scene& s) {
        Scene run = s;
        run.solver.time_step = h_rheonomic;
        run.outputs.sample_interval = std::max(h_rheonomic, scene.outputs.sample_interval);
        ModelResult& m = r.models[k];
        m.drift = mean_over_seeds(run, Method::OdeRheonomic, entry.name + " " + kModels[k], k,
                                  &m.ci95, &m.run_cpu, &m.parts_lost);
        m.ran = true;
        std::fprintf(stderr, "%s: %s %.6g (%+.1f %%)%s\n", entry.name.c_str(), kModels[k], m.drift,
                     100 * (m.drift - r.reference) / std::abs(r.reference),
                     lossNote(m.parts_lost).c_str());
      };
      auto attempt = [&](int k, const std::function<void()>& body) {
        if (!modelRuns(entry, k)) return;
        try {
          body();
        } catch (const std::exception& e) {
          r.models[k].note = e.what();
          std::fprintf(stderr, "%s: %s not run: %s\n", entry.name.c_str(), kModels[k], e.what());
        }
      };
      attempt(0, [&] { rheonomic(0, withDriftModel(scene, fixture, DriftModel::Local)); });
      attempt(1, [&] {
        EfficiencySettings es;
        es.steps_per_cycle = ref_spc;
        es.use_reference_solver = entry.reference_judge;
        es.rheonomic_time_step = h_rheonomic;
        if (o.quick) es.measure_cycles = 40;
        const EfficiencyCalibration c = calibrateEfficiency(scene, fixture, 0, es);
        r.models[1].calibration_cpu = c.cpu_seconds;
        std::ostringstream note;
        note << "efficiency " << c.efficiency << " +- " << c.ci95;
        r.models[1].note = note.str();
        rheonomic(1, withEfficiency(scene, c));
      });
      attempt(2, [&] {
        CalibrationSettings cs;
        cs.steps_per_cycle = ref_spc;
        cs.use_reference_solver = entry.reference_judge;
        if (o.quick) cs.measure_cycles = 40;
        const Calibration c = calibrateBySampling(scene, fixture, cs);
        r.models[2].calibration_cpu = c.cpu_seconds;
        if (entry.name == "track_level") level_calibration = c;
        rheonomic(2, withCalibration(scene, c));
      });
      if (level_calibration && entry.name.rfind("track_", 0) == 0 && entry.name != "track_level") {
        attempt(4, [&] {
          r.models[4].calibration_cpu = level_calibration->cpu_seconds;
          r.models[4].note = "sampled on track_level";
          rheonomic(4, withCalibration(scene, *level_calibration));
        });
      }
      attempt(3, [&] {
        const Calibration c = calibrateClassical(scene, fixture);
        r.models[3].calibration_cpu = c.cpu_seconds;
        rheonomic(3, withCalibration(scene, c));
      });
      attempt(kSceneConstant, [&] {
        rheonomic(kSceneConstant, withDriftModel(scene, fixture, DriftModel::CalibratedDrift));
      });
      if (byBowlPhase(entry)) {
        // One row per phase: the judge's phase drift against each model's.
        for (BowlPhase phase : {BowlPhase::Floor, BowlPhase::Ramp}) {
          const auto p = static_cast<std::size_t>(phase);
          SceneResult row = r;
          row.name = r.name + "_" + toString(phase);
          row.what = r.what + ", " + toString(phase) + " phase";
          const PhaseDrift& judged = phased.front().second.phases[p];  // the judge runs first
          row.reference = judged.drift;
          row.reference_ci95 = judged.ci95;
          row.part_seconds = judged.part_seconds;
          row.what += "; full vibration: " + phaseNote(judged);
          for (const auto& [slot, measured] : phased) {
            if (slot < 0) continue;
            const int k = slot;
            const PhaseDrift& d = measured.phases[p];
            row.models[k].drift = d.drift;
            row.models[k].ci95 = d.ci95;
            row.models[k].note += (row.models[k].note.empty() ? "" : "; ") + phaseNote(d);
          }
          results.push_back(row);
        }
        writeHeightCsv(o, entry.name, phased);
      } else {
        results.push_back(r);
      }
      if (!writeOutputs(o, results, false)) return 2;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drift model study: %s\n", e.what());
    return 2;
  }

  return writeOutputs(o, results, true) ? 0 : 2;
}

}  // namespace rheofeed::demo
