// SPDX-License-Identifier: MIT
#include "demo_runner.hpp"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "rheofeed/scene/calibration.hpp"
#include "rheofeed/scene/metrics.hpp"
#include "rheofeed/scene/plot.hpp"
#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::demo {

using namespace rheofeed::scene;

int runDemo(int argc, char** argv, const std::string& name, const std::string& description,
            Scene scene, const DemoOptions& options) {
  std::string scene_file, out_dir = "out/" + name;
  double duration = 0, dt = 0;
  std::vector<std::string> methods = {"ode_rheonomic"};
  bool classical = false;
  CLI::App app{description};
  app.add_option("--scene", scene_file, "scene file (JSON) instead of the built-in scene");
  app.add_option("--duration", duration, "simulated time (s), overrides the scene");
  app.add_option("--dt", dt, "time step of the rheonomic runs (s), overrides the scene");
  app.add_option("--out", out_dir, "output folder");
  app.add_option("--method", methods,
                 "methods to run: ode_rheonomic, ode_full_vibration, reference_rheonomic, "
                 "reference_full_vibration (repeat or list)")
      ->delimiter(',');
  app.add_flag("--classical", classical,
               "calibrate a vibration with the classical single-part model (quick estimate) "
               "instead of a full-vibration sample run");
  CLI11_PARSE(app, argc, argv);

  try {
    if (!scene_file.empty()) scene = loadScene(scene_file);
    if (dt != 0 && (!(dt > 0) || !std::isfinite(dt))) {
      throw std::invalid_argument("--dt = " + std::to_string(dt) + ": must be > 0 (s)");
    }
    if (duration != 0) {
      if (!(duration > 0) || !std::isfinite(duration)) {
        throw std::invalid_argument("--duration = " + std::to_string(duration) + ": must be > 0");
      }
      scene.duration = duration;
    }
    scene.validate();
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

    // A rheonomic run of a vibrating feeder needs its drift field: calibrate it once.
    const double full_step = scene.solver.time_step;
    bool need_calibration = false;
    for (Method m : chosen) need_calibration = need_calibration || !isFullVibration(m);
    for (std::size_t i = 0; i < scene.fixtures.size() && need_calibration; ++i) {
      const FeederLaw& law = scene.fixtures[i].law;
      if (law.kind != FeederLaw::Kind::Vibration || law.has_calibrated_drift) continue;
      std::fprintf(stderr, "%s: calibrating fixture '%s' (%s)...\n", name.c_str(),
                   scene.fixtures[i].name.c_str(),
                   classical ? "classical model" : "short full-vibration sample run");
      const Calibration c = classical ? calibrateClassical(scene, static_cast<int>(i))
                                      : calibrateBySampling(scene, static_cast<int>(i));
      if (law.vibration.torsion_amplitude > 0) {
        std::fprintf(stderr, "%s: angular drift %.5g +- %.2g rad/s, %.1f s CPU\n", name.c_str(),
                     c.value, c.ci95, c.cpu_seconds);
      } else {
        std::fprintf(stderr, "%s: drift %.5g +- %.2g m/s (efficiency %.3f), %.1f s CPU\n",
                     name.c_str(), c.value, c.ci95, c.efficiency, c.cpu_seconds);
      }
      scene = withCalibration(scene, c);
    }

    const std::string unit = scene.outputs.angular_drift ? "rad/s" : "m/s";
    std::printf(
        "| method | h (s) | parts | mean drift (%s) | 95 %% CI | vertical disp. (m) | "
        "throughput (parts/s) | CPU (s) | real-time factor | lost parts | Coulomb fallback "
        "steps |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        unit.c_str());
    std::vector<std::pair<std::string, std::string>> blocks;
    for (Method m : chosen) {
      Scene s = scene;
      if (!isFullVibration(m)) {
        s.solver.time_step =
            dt > 0 ? dt
                   : (scene.hasVibration() ? options.rheonomic_time_step : scene.solver.time_step);
        s.outputs.sample_interval = std::max(s.outputs.sample_interval, s.solver.time_step);
      } else {
        s.solver.time_step = full_step;
      }
      const RunMetrics r = measureRun(s, m, stderrProgress(name + " " + toString(m)));
      writeRunOutputs(r, out_dir, toString(m));
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
