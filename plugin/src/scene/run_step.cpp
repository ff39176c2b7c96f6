// SPDX-License-Identifier: MIT
// The time step rule (run_step.hpp).
#include "rheofeed/scene/run_step.hpp"

#include <algorithm>

namespace rheofeed::scene {

RunStep runStep(const Scene& scene, Method method, const StepOverrides& overrides) {
  RunStep step;
  if (overrides.every_run) {
    step.time_step = *overrides.every_run;
    step.field = overrides.every_run_name;
    step.from_scene = false;
  } else if (!isFullVibration(method) && scene.solver.rheonomic_time_step > 0) {
    step.time_step = scene.solver.rheonomic_time_step;
    step.field = "solver.rheonomic_time_step";
  } else if (!isFullVibration(method) && overrides.rheonomic_default) {
    step.time_step = *overrides.rheonomic_default;
    step.field = overrides.rheonomic_default_name;
    step.from_scene = false;
  } else {
    step.time_step = scene.solver.time_step;
    step.field = "solver.time_step";
  }
  return step;
}

Scene atRunStep(const Scene& scene, const RunStep& step) {
  Scene s = scene;
  s.solver.time_step = step.time_step;
  const bool from_rheonomic_field = step.from_scene && step.field == "solver.rheonomic_time_step";
  s.solver.rheonomic_time_step = from_rheonomic_field ? step.time_step : 0;
  s.outputs.sample_interval = std::max(s.outputs.sample_interval, step.time_step);
  return s;
}

const char* stepField(const Scene& scene, Method method) {
  return !isFullVibration(method) && scene.solver.rheonomic_time_step > 0
             ? "solver.rheonomic_time_step"
             : "solver.time_step";
}

}  // namespace rheofeed::scene
