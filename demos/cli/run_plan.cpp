// SPDX-License-Identifier: MIT
#include "cli/run_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "cli/commands.hpp"
#include "cli/shipped_scenes.hpp"
#include "rheofeed/number_format.hpp"
#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::cli {

using namespace rheofeed::scene;

namespace {

constexpr Method kMethods[] = {Method::OdeRheonomic, Method::OdeFullVibration,
                               Method::ReferenceRheonomic, Method::ReferenceFullVibration};

void requirePositiveFinite(const std::string& option, double value) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw std::invalid_argument(option + " = " + formatNumber(value) +
                                " s: must be a finite number > 0 (s)");
  }
}

}  // namespace

std::string methodNames() {
  std::string names;
  for (Method m : kMethods) names += (names.empty() ? "" : ", ") + std::string(toString(m));
  return names;
}

DriftModel parseDriftModelOption(const std::string& name) {
  DriftModel model = DriftModel::Local;
  if (!parseDriftModel(name, model)) {
    throw std::invalid_argument("--drift-model " + name +
                                ": unknown drift model; valid drift models: local, "
                                "local_sampled, calibrated_drift");
  }
  return model;
}

Method parseMethod(const std::string& name) {
  for (Method m : kMethods) {
    if (name == toString(m)) return m;
  }
  throw std::invalid_argument("--method " + name +
                              ": unknown method; valid methods: " + methodNames());
}

Plan makePlan(const SceneArgs& args, const std::vector<std::string>& default_methods) {
  // The command line first (cheap, and a typo is reported before a scene is read).
  std::vector<Method> methods;
  for (const std::string& m : args.methods.empty() ? default_methods : args.methods) {
    methods.push_back(parseMethod(m));
  }
  if (args.dt_given) {
    requirePositiveFinite("--dt", args.dt);
  }
  if (args.duration_given) requirePositiveFinite("--duration", args.duration);
  if (args.warmup_given && !(std::isfinite(args.warmup) && args.warmup >= 0)) {
    throw std::invalid_argument("--warmup = " + formatNumber(args.warmup) +
                                " s: must be a finite number >= 0 s (and below the duration)");
  }
  if (!args.drift_model.empty()) {
    (void)parseDriftModelOption(args.drift_model);  // checked before the scene is read
  }

  Plan plan;
  plan.file = resolveScene(args.scene);
  plan.name = plan.file.stem().string();
  plan.scene = loadScene(plan.file);
  Scene& scene = plan.scene;
  if (args.duration_given) scene.duration = args.duration;
  if (args.warmup_given) scene.outputs.warmup = args.warmup;
  if (args.seed_given) scene.seed = args.seed;
  if (!args.drift_model.empty()) overrideDriftModel(scene, parseDriftModelOption(args.drift_model));
  const std::string where =
      "scene " + plan.file.string() +
      (args.duration_given ? " with --duration " + formatNumber(args.duration) + " s"
                           : std::string()) +
      (args.warmup_given ? " with --warmup " + formatNumber(args.warmup) + " s" : std::string()) +
      (args.dt_given ? " with --dt " + formatNumber(args.dt) + " s" : std::string());
  StepOverrides overrides;
  if (args.dt_given) overrides.every_run = args.dt;
  try {
    // What does not depend on the run is checked once here, at the coarsest step a planned run
    // takes (as that run will see the scene: atRunStep), not at steps no run takes: a rheonomic
    // run's --duration is not refused for what it would cost at the full-vibration step, nor a
    // --dt above the sample interval (the run samples once per step and says so below). Each
    // run is then checked at its own step, with its method named.
    RunStep coarsest = runStep(scene, Method::OdeFullVibration, overrides);  // no method: its own
    if (!methods.empty()) coarsest = runStep(scene, methods.front(), overrides);
    for (Method m : methods) {
      if (RunStep s = runStep(scene, m, overrides); s.time_step > coarsest.time_step) coarsest = s;
    }
    try {
      atRunStep(scene, coarsest).validate();
    } catch (const std::invalid_argument& e) {
      // atRunStep names the step solver.time_step: say where it came from when it did not
      if (!coarsest.from_scene || coarsest.field == "solver.time_step") throw;
      throw std::invalid_argument(std::string(e.what()) +
                                  " (checked at h = " + formatNumber(coarsest.time_step) + " s, " +
                                  coarsest.source() + ": the coarsest step of the planned runs)");
    }
  } catch (const std::invalid_argument& e) {
    std::string hint;
    if (args.duration_given && !args.warmup_given &&
        std::string(e.what()).rfind("outputs.warmup", 0) == 0) {
      hint = "; the scene's warmup is longer than the run: give --warmup 0 (or a warmup below " +
             formatNumber(args.duration) + " s) with a short --duration";
    }
    throw std::invalid_argument(where + ": " + e.what() + hint);
  }
  for (Method m : methods) {
    PlannedRun run;
    run.method = m;
    const RunStep step = runStep(scene, m, overrides);
    const double h = step.time_step;
    run.step_source = step.source();
    run.scene = atRunStep(scene, step);
    try {
      run.scene.validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("method ") + toString(m) +
                                  " at h = " + formatNumber(h) + " s (" + run.step_source + "), " +
                                  where + ": " + e.what());
    }
    // Said only of a run that will go ahead.
    if (run.scene.outputs.sample_interval != scene.outputs.sample_interval) {
      std::fprintf(stderr,
                   "rheofeed: %s: outputs.sample_interval = %s s is shorter than this run's step "
                   "h = %s s (%s): it samples once per step, every %s s\n",
                   toString(m), formatNumber(scene.outputs.sample_interval).c_str(),
                   formatNumber(h).c_str(), run.step_source.c_str(),
                   formatNumber(run.scene.outputs.sample_interval).c_str());
    }
    plan.runs.push_back(std::move(run));
  }
  return plan;
}

void prepareOutputFolder(const std::filesystem::path& folder, const std::string& option) {
  if (folder.empty()) {
    throw std::invalid_argument(option + " \"\": must name an output folder (not empty)");
  }
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec || !std::filesystem::is_directory(folder)) {
    throw std::invalid_argument(
        option + " " + folder.string() + ": cannot create the output folder (" +
        (ec ? ec.message() : std::string("exists and is not a folder")) + ")");
  }
  const std::filesystem::path probe = folder / ".rheofeed_write_test";
  std::FILE* f = std::fopen(probe.string().c_str(), "w");
  if (!f) {
    throw std::invalid_argument(option + " " + folder.string() +
                                ": the output folder is not writable");
  }
  std::fclose(f);
  std::filesystem::remove(probe, ec);
}

int runChecked(const char* command, const std::function<void()>& body) {
  try {
    body();
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "%s: %s\n", command, e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: failed: %s\n", command, e.what());
    return 1;
  }
  return 0;
}

}  // namespace rheofeed::cli
