// SPDX-License-Identifier: MIT
// The runs one `rheofeed` command line asks for: the scene (a shipped name or a file), the
// command-line overrides (duration, seed, time step) and one scene per method with the time step
// it takes. Every input is checked here, before anything runs or calibrates.
//
// The time step of each run follows the library's rule (rheofeed/scene/run_step.hpp, --dt as its
// override); every run prints its step and where it came from.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "rheofeed/scene/run_step.hpp"
#include "rheofeed/scene/scene.hpp"

namespace rheofeed::cli {

/// The scene and overrides of a command line.
struct SceneArgs {
  std::string scene;                 ///< shipped scene name or scene file (shipped_scenes.hpp)
  std::vector<std::string> methods;  ///< method names (toString(Method)); empty: the default
  double dt = 0;                     ///< --dt (s), when dt_given
  bool dt_given = false;
  double duration = 0;  ///< --duration (s), when duration_given
  bool duration_given = false;
  double warmup = 0;  ///< --warmup (s): time excluded from the mean drift, when warmup_given
  bool warmup_given = false;
  std::uint64_t seed = 0;  ///< --seed, when seed_given
  bool seed_given = false;
  /// --drift-model: empty keeps each vibrating feeder's drift model; else local, local_sampled
  /// or calibrated_drift for all of them (overrideDriftModel, scene.hpp).
  std::string drift_model;
};

/// One run: its method, its scene (the overrides and its time step applied, validated) and where
/// the step came from ("--dt", "the scene's solver.time_step", ...).
struct PlannedRun {
  rheofeed::scene::Method method = rheofeed::scene::Method::OdeRheonomic;
  rheofeed::scene::Scene scene;
  std::string step_source;
};

/// A command line's scene and runs.
struct Plan {
  std::filesystem::path file;    ///< the scene file loaded
  std::string name;              ///< the argument's stem (the shipped name, or the file's stem)
  rheofeed::scene::Scene scene;  ///< the scene with the overrides (not the per-run step)
  std::vector<PlannedRun> runs;  ///< one per method, in command-line order
};

/// The names of the four methods, comma-separated ("ode_rheonomic, ode_full_vibration, ...").
std::string methodNames();

/// The drift model named `name` (--drift-model); throws std::invalid_argument naming
/// --drift-model and the valid names for another name.
rheofeed::scene::DriftModel parseDriftModelOption(const std::string& name);

/// The method named `name`; throws std::invalid_argument listing the valid names.
rheofeed::scene::Method parseMethod(const std::string& name);

/// Checks the overrides, loads the scene and builds every run (the step rule above; the sample
/// interval is raised to the step where it is shorter). The scene's limits that do not depend on
/// the run are checked at the coarsest planned step, and each run's scene at its own step (a
/// step-count limit only a finer run breaks names that run's method). `default_methods` are used
/// when args.methods is empty. Throws std::invalid_argument naming the value, where it came from
/// and the allowed range (the scene loader's SceneFileError for a bad file).
Plan makePlan(const SceneArgs& args, const std::vector<std::string>& default_methods);

/// Creates `folder` (and its parents) and checks that a file can be written in it. Throws
/// std::invalid_argument naming it (and `option`, e.g. "--out") when it cannot.
void prepareOutputFolder(const std::filesystem::path& folder, const std::string& option);

}  // namespace rheofeed::cli
