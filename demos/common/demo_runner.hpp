// SPDX-License-Identifier: MIT
// Shared command line and run loop of the feeder demos: each demo file builds its scene (or
// loads one with --scene), and this runs it headless with the chosen methods, calibrating a
// vibrating feeder first when its drift model needs it, and writes CSV + JSON + PNG outputs.
#pragma once

#include <string>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::demo {

/// What a demo may change in the runner.
struct DemoOptions {
  /// Time step of the rheonomic runs of a scene with a vibrating feeder when --dt is not given
  /// (s); scenes without vibration use their own solver.time_step.
  double rheonomic_time_step = 0.01;
  /// Also plot the parts' mean height against time for every method (mean_height.png).
  bool plot_height = false;
};

/// Parses the demo's command line (--scene, --duration, --dt, --out, --method, --classical,
/// --drift-model), runs the scene and prints a summary. Rheonomic runs of a vibrating feeder
/// use its drift model (scene.hpp DriftModel; --drift-model local|local_sampled|
/// calibrated_drift overrides it for every vibrating feeder): nothing is calibrated for
/// `local`, nor when the scene gives the calibrated drift or the local_sampled factors;
/// otherwise they are measured once before the runs (calibrateBySampling or, with --classical,
/// calibrateClassical; calibrateEfficiency per part family at the rheonomic step) and the time
/// it took is printed. `--dt` sets the time step of the rheonomic runs only
/// (full-vibration runs keep the scene's solver.time_step; --dt with only full-vibration
/// methods is refused), and every run prints its step and where it comes from. Every input is
/// checked before anything runs or calibrates: the scene file (a regular file), --out (not
/// empty), --dt and --duration (finite, > 0), and the scene of every chosen run after the
/// command-line overrides (Scene::validate: step range, at most 1e9 steps, a sample interval
/// and warm-up within the duration). Returns the process exit code: 0 on success, 2 on bad
/// input (message on stderr naming the value, where it came from and the allowed range),
/// CLI11's own codes for a malformed command line.
int runDemo(int argc, char** argv, const std::string& name, const std::string& description,
            scene::Scene builtin, const DemoOptions& options = {});

/// runDemo with the scene file `file_name` of demos/scenes/ as the built-in scene (a file that
/// cannot be loaded exits with 2 and the loader's message).
int runSceneFileDemo(int argc, char** argv, const std::string& name, const std::string& description,
                     const std::string& file_name, const DemoOptions& options = {});

}  // namespace rheofeed::demo
