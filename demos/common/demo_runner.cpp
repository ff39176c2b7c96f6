// SPDX-License-Identifier: MIT
#include "demo_runner.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "rheofeed/scene/animation.hpp"
#include "rheofeed/scene/calibration.hpp"
#include "rheofeed/scene/metrics.hpp"
#include "rheofeed/scene/plot.hpp"
#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::demo {

using namespace rheofeed::scene;

namespace {

// A number as a user typed it back (std::to_string prints 1e-12 as "0.000000").
std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// Where a run's time step comes from, for the messages and the line printed before each run.
struct StepChoice {
  double time_step;
  std::string source;
};

}  // namespace

int runDemo(int argc, char** argv, const std::string& name, const std::string& description,
            Scene scene, const DemoOptions& options) {
  std::string scene_file, out_dir = "out/" + name;
  double duration = 0, dt = 0;
  std::vector<std::string> methods = {"ode_rheonomic"};
  bool classical = false, animation = false;
  std::string drift_model;
  CLI::App app{description};
  app.add_option("--scene", scene_file,
                 "scene file (JSON, a regular file) instead of the built-in scene");
  CLI::Option* duration_option = app.add_option(
      "--duration", duration,
      "simulated time (s), overrides the scene: finite, > 0, at least one time step and at most "
      "1e9 steps of every run");
  CLI::Option* dt_option = app.add_option(
      "--dt", dt,
      "time step (s) of the RHEONOMIC runs only (ode_rheonomic, reference_rheonomic); "
      "full-vibration runs always take the scene's solver.time_step. Without --dt a rheonomic "
      "run takes " +
          number(options.rheonomic_time_step) +
          " s when the scene has a vibrating feeder, else the scene's solver.time_step. Finite, "
          "in the scene's range [1e-6, 1] s. Each run prints the step it takes and where it "
          "comes from");
  app.add_option("--out", out_dir, "output folder (not empty)");
  app.add_option("--method", methods,
                 "methods to run: ode_rheonomic, ode_full_vibration, reference_rheonomic, "
                 "reference_full_vibration (repeat or list)")
      ->delimiter(',');
  app.add_flag("--classical", classical,
               "calibrate a vibration with the classical single-part model (quick estimate) "
               "instead of a full-vibration sample run");
  app.add_flag("--animation", animation,
               "also write an animation of the FIRST method's run: <method>.glb (glTF 2.0, opens "
               "in Blender) and view.html, which plays it in a browser with the plots");
  CLI::Option* drift_model_option = app.add_option(
      "--drift-model", drift_model,
      "what the rheonomic runs use instead of a feeder's vibration, for every vibrating feeder: "
      "local (the local vibration law, no calibration), local_sampled (the local law times each "
      "part family's efficiency, measured by a short sampling run unless the scene gives it), "
      "calibrated_drift (one constant drift twist, calibrated unless the scene gives it). "
      "Default: each feeder's drift_model in the scene");
  CLI11_PARSE(app, argc, argv);

  try {
    // Every input is checked here, before any run or calibration starts.
    if (!scene_file.empty()) scene = loadScene(scene_file);
    if (out_dir.empty()) {
      throw std::invalid_argument("--out \"\": must name an output folder (not empty)");
    }
    // The output folder is made (or found writable) now, not after a run of minutes or hours.
    {
      std::error_code ec;
      std::filesystem::create_directories(out_dir, ec);
      if (ec || !std::filesystem::is_directory(out_dir)) {
        throw std::invalid_argument(
            "--out " + out_dir + ": cannot create the output folder (" +
            (ec ? ec.message() : std::string("exists and is not a folder")) + ")");
      }
      const std::filesystem::path probe = std::filesystem::path(out_dir) / ".rheofeed_write_test";
      std::FILE* f = std::fopen(probe.string().c_str(), "w");
      if (!f) {
        throw std::invalid_argument("--out " + out_dir + ": the output folder is not writable");
      }
      std::fclose(f);
      std::filesystem::remove(probe, ec);
    }
    if (drift_model_option->count() > 0) {
      DriftModel model = DriftModel::Local;
      if (!parseDriftModel(drift_model, model)) {
        throw std::invalid_argument("--drift-model " + drift_model +
                                    ": unknown drift model; expected local, local_sampled or "
                                    "calibrated_drift");
      }
      for (Fixture& f : scene.fixtures) {
        if (f.law.kind != FeederLaw::Kind::Vibration || f.law.drift_model == model) continue;
        f.law.drift_model = model;
        f.law.efficiency.clear();  // the scene's factors belong to its own local_sampled
      }
    }
    const bool dt_given = dt_option->count() > 0;
    if (dt_given && (!(dt > 0) || !std::isfinite(dt))) {
      throw std::invalid_argument("--dt = " + number(dt) +
                                  " s: must be a finite number > 0 (s), in the scene's range "
                                  "[1e-6, 1] s");
    }
    if (duration_option->count() > 0) {
      if (!(duration > 0) || !std::isfinite(duration)) {
        throw std::invalid_argument("--duration = " + number(duration) +
                                    " s: must be a finite number > 0 (s)");
      }
      scene.duration = duration;
    }
    try {
      scene.validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(
          std::string(scene_file.empty() ? "built-in scene" : "scene " + scene_file) +
          (duration_option->count() > 0 ? " with --duration " + number(duration) + " s" : "") +
          ": " + e.what());
    }
    std::vector<Method> chosen;
    for (const std::string& m : methods) {
      bool found = false;
      for (Method k : {Method::OdeRheonomic, Method::OdeFullVibration, Method::ReferenceRheonomic,
                       Method::ReferenceFullVibration}) {
        if (m == toString(k)) {
          chosen.push_back(k);
          found = true;
        }
      }
      if (!found) throw std::invalid_argument("--method " + m + ": unknown method");
    }
    bool any_rheonomic = false;
    for (Method m : chosen) any_rheonomic = any_rheonomic || !isFullVibration(m);
    if (dt_given && !any_rheonomic) {
      throw std::invalid_argument(
          "--dt " + number(dt) +
          " s applies to the rheonomic methods only (ode_rheonomic, reference_rheonomic), and "
          "none was chosen: full-vibration runs take the scene's solver.time_step (" +
          number(scene.solver.time_step) + " s); drop --dt or change the scene");
    }

    // Each run's scene, validated now: a time step, duration or sampling that would take no
    // step, no sample or too many steps is refused before anything runs.
    const double full_step = scene.solver.time_step;
    std::vector<std::pair<Scene, StepChoice>> runs;
    for (Method m : chosen) {
      Scene s = scene;
      StepChoice step{full_step, "the scene's solver.time_step"};
      if (!isFullVibration(m)) {
        if (dt_given) {
          step = {dt, "--dt"};
        } else if (scene.hasVibration()) {
          step = {options.rheonomic_time_step, "this demo's rheonomic default"};
        }
        s.solver.time_step = step.time_step;
        s.outputs.sample_interval = std::max(s.outputs.sample_interval, s.solver.time_step);
      }
      try {
        s.validate();
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("method ") + toString(m) +
                                    " at h = " + number(step.time_step) + " s (" + step.source +
                                    "), duration " + number(s.duration) + " s: " + e.what());
      }
      runs.emplace_back(std::move(s), step);
    }

    // A rheonomic run of a vibrating feeder uses its drift model (scene.hpp DriftModel): the
    // local law needs nothing; a calibrated drift or local_sampled factors the scene does not
    // give are measured once, here.
    bool any_rheonomic_run = false;
    for (Method m : chosen) any_rheonomic_run = any_rheonomic_run || !isFullVibration(m);
    for (std::size_t i = 0; i < scene.fixtures.size() && any_rheonomic_run; ++i) {
      const FeederLaw law = scene.fixtures[i].law;
      if (law.kind != FeederLaw::Kind::Vibration) continue;
      const int fixture = static_cast<int>(i);
      const char* fixture_name = scene.fixtures[i].name.c_str();
      if (law.drift_model == DriftModel::Local) {
        std::fprintf(stderr, "%s: fixture '%s': drift model local (the local vibration law)\n",
                     name.c_str(), fixture_name);
      } else if (law.drift_model == DriftModel::CalibratedDrift && law.has_calibrated_drift) {
        std::fprintf(stderr, "%s: fixture '%s': drift model calibrated_drift (from the scene)\n",
                     name.c_str(), fixture_name);
      } else if (law.drift_model == DriftModel::CalibratedDrift) {
        std::fprintf(stderr, "%s: calibrating fixture '%s' (%s)...\n", name.c_str(), fixture_name,
                     classical ? "classical model" : "short full-vibration sample run");
        const Calibration c =
            classical ? calibrateClassical(scene, fixture) : calibrateBySampling(scene, fixture);
        if (law.vibration.torsion_amplitude > 0) {
          std::fprintf(stderr, "%s: angular drift %.5g +- %.2g rad/s, %.1f s CPU\n", name.c_str(),
                       c.value, c.ci95, c.cpu_seconds);
        } else {
          std::fprintf(stderr, "%s: drift %.5g +- %.2g m/s (efficiency %.3f), %.1f s CPU\n",
                       name.c_str(), c.value, c.ci95, c.efficiency, c.cpu_seconds);
        }
        scene = withCalibration(scene, c);
      } else if (!law.efficiency.empty()) {
        std::fprintf(stderr,
                     "%s: fixture '%s': drift model local_sampled (factors from the "
                     "scene)\n",
                     name.c_str(), fixture_name);
      } else {
        EfficiencySettings settings;
        settings.rheonomic_time_step = dt_given ? dt : options.rheonomic_time_step;
        for (std::size_t k = 0; k < scene.parts.size(); ++k) {
          std::fprintf(stderr,
                       "%s: calibrating fixture '%s', part family '%s' (the part's own "
                       "efficiency under the local law: full-vibration sample at %d steps per "
                       "cycle and the local law)...\n",
                       name.c_str(), fixture_name, scene.parts[k].name.c_str(),
                       settings.steps_per_cycle);
          const EfficiencyCalibration c =
              calibrateEfficiency(scene, fixture, static_cast<int>(k), settings);
          std::fprintf(stderr,
                       "%s: efficiency %.4f +- %.2g (sampled %.5g +- %.2g, local law %.5g +- "
                       "%.2g %s), %.1f s CPU\n",
                       name.c_str(), c.efficiency, c.ci95, c.sampled, c.sampled_ci95, c.local,
                       c.local_ci95, law.vibration.torsion_amplitude > 0 ? "rad/s" : "m/s",
                       c.cpu_seconds);
          scene = withEfficiency(scene, c);
        }
      }
    }

    const std::string unit = scene.outputs.angular_drift ? "rad/s" : "m/s";
    std::printf(
        "| method | h (s) | parts | mean drift (%s) | 95 %% CI | vertical disp. (m) | "
        "throughput (parts/s) | CPU (s) | real-time factor | lost parts | Coulomb fallback "
        "steps |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        unit.c_str());
    std::vector<std::pair<std::string, std::string>> blocks;
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      const Method m = chosen[k];
      // The validated scene of this run, with the drift field calibrated above.
      Scene s = scene;
      s.solver.time_step = runs[k].first.solver.time_step;
      s.outputs.sample_interval = runs[k].first.outputs.sample_interval;
      std::fprintf(stderr, "%s: %s runs at h = %s s (%s)\n", name.c_str(), toString(m),
                   number(s.solver.time_step).c_str(), runs[k].second.source.c_str());
      std::unique_ptr<AnimationRecorder> recorder;
      if (animation && k == 0) recorder = std::make_unique<AnimationRecorder>(s, m);
      const RunMetrics r =
          measureRun(s, m, stderrProgress(name + " " + toString(m)), recorder.get());
      writeRunOutputs(r, out_dir, toString(m));
      if (recorder)
        recorder->write(std::filesystem::path(out_dir) / (toString(m) + std::string(".glb")));
      blocks.emplace_back(toString(m), seriesCsv(r));
      // Lost parts and fallback steps (RunHealth): the kinds are in the JSON output and the
      // stderr summary of measureRun.
      const RunHealth& h = r.health;
      std::printf("| %s | %.3g | %d | %.5f | %.5f | %.4f | %.2f | %.2f | %.4f | %d | %.1f %% |\n",
                  toString(m), r.time_step, r.parts, r.mean_drift, r.mean_drift_ci95,
                  r.vertical_displacement, r.throughput, r.cpu_seconds, r.real_time_factor,
                  h.partsLost(), 100.0 * h.coulomb_fallback_steps / std::max(1L, h.steps));
    }
    if (blocks.size() > 1) {  // one plot with every method's drift
      std::string gp =
          "set datafile separator ','\nset grid\nset key bottom right\n"
          "set xlabel 'time (s)'\nset ylabel 'mean drift (" +
          unit + ")'\nset title '" + scene.name + ": methods compared'\nplot ";
      for (std::size_t k = 0; k < blocks.size(); ++k) {
        gp += (k ? ", " : "") + std::string("$") + blocks[k].first +
              " using 1:3 with lines lw 2 title '" + blocks[k].first + "'";
      }
      plotPng(gp, blocks, (std::filesystem::path(out_dir) / "methods.png").string());
    }
    if (options.plot_height && !blocks.empty()) {  // mean height of the parts, every method
      std::string gp =
          "set datafile separator ','\nset grid\nset key bottom right\n"
          "set xlabel 'time (s)'\nset ylabel 'mean height of the parts (mm)'\n"
          "set title '" +
          scene.name + ": mean height of the parts'\nplot ";
      for (std::size_t k = 0; k < blocks.size(); ++k) {
        gp += (k ? ", " : "") + std::string("$") + blocks[k].first +
              " using 1:(1000 * $5) with lines lw 2 title '" + blocks[k].first + "'";
      }
      plotPng(gp, blocks, (std::filesystem::path(out_dir) / "mean_height.png").string());
    }
    if (animation && !chosen.empty()) {  // the page shows every plot of the folder
      std::vector<std::string> plots;
      for (const auto& entry : std::filesystem::directory_iterator(out_dir)) {
        if (entry.path().extension() == ".png") plots.push_back(entry.path().filename().string());
      }
      std::sort(plots.begin(), plots.end());
      const std::filesystem::path page =
          writeViewer(out_dir, toString(chosen[0]) + std::string(".glb"), plots);
      std::printf("\nanimation: open %s\n", page.string().c_str());
    }
    std::printf("\noutputs in %s/\n", out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", name.c_str(), e.what());
    return 2;
  }
  return 0;
}

int runSceneFileDemo(int argc, char** argv, const std::string& name, const std::string& description,
                     const std::string& file_name, const DemoOptions& options) {
  Scene scene;
  try {
    scene = loadScene(std::filesystem::path(RHEOFEED_DEMO_SCENES_DIR) / file_name);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: built-in scene: %s\n", name.c_str(), e.what());
    return 2;
  }
  return runDemo(argc, argv, name, description, scene, options);
}

}  // namespace rheofeed::demo
