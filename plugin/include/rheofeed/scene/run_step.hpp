// SPDX-License-Identifier: MIT
/// @file run_step.hpp
/// The time step rule: which field or flag sets the step (s) of a run of a scene, for which
/// method. One rule for `rheofeed run`, `check` and `calibrate`, the studies and the scene check:
///   an override (`--dt`) given    every run takes it, rheonomic and full vibration alike;
///   rheonomic run                 the scene's solver.rheonomic_time_step when it gives one
///                                 (> 0), else the caller's rheonomic default when given (a
///                                 study's step), else the scene's solver.time_step;
///   full-vibration run            the scene's solver.time_step.
/// Every run says its step and where it came from (RunStep::source()).
#pragma once
#include <optional>
#include <string>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// What may change the scene's own step.
struct StepOverrides {
  /// A step (s) for every run, and the name it is known by in messages ("--dt").
  std::optional<double> every_run;
  std::string every_run_name = "--dt";
  /// A step (s) for rheonomic runs of scenes without solver.rheonomic_time_step, and its name
  /// ("the study's rheonomic step").
  std::optional<double> rheonomic_default;
  std::string rheonomic_default_name = "the caller's rheonomic step";
};

/// A run's time step and where it came from.
struct RunStep {
  double time_step = 0;  ///< (s)
  /// The scene field that set it ("solver.rheonomic_time_step" or "solver.time_step"), or the
  /// name of the override that did (StepOverrides).
  std::string field;
  bool from_scene = true;  ///< `field` is a field of the scene (not an override)
  /// Where the step came from as a message says it: "the scene's solver.time_step", "--dt".
  std::string source() const { return from_scene ? "the scene's " + field : field; }
};

/// The step of a run of `scene` with `method` under the rule above.
RunStep runStep(const Scene& scene, Method method, const StepOverrides& overrides = {});

/// `scene` set up to run at `step`: solver.time_step = step.time_step, and
/// solver.rheonomic_time_step kept (equal to it) only when it is where the step came from, so
/// that the scene check (stepField) names the field to change; 0 otherwise. The sample interval
/// is raised to the step where it is shorter. Not validated.
Scene atRunStep(const Scene& scene, const RunStep& step);

/// The scene field a user changes to change the step of a run of `scene` (already at its run
/// step, atRunStep) with `method`: "solver.rheonomic_time_step" for a rheonomic run of a scene
/// that gives it, else "solver.time_step".
const char* stepField(const Scene& scene, Method method);

}  // namespace rheofeed::scene
