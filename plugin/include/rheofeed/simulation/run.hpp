// SPDX-License-Identifier: MIT
/// @file run.hpp
/// The run loop: a Simulation stepped over a scene's duration, watched by observers.
///
/// Who calls what, in which order (as Jolt's ContactListener documents its calls):
///   1. the caller builds the simulation (makeSimulation) and, before the loop, runs the scene
///      check (check.hpp: reportSceneCheck) - the loop does not;
///   2. runSimulation calls every observer's onStart once at t = 0 (the parts spawned at t = 0
///      are present), then, after each step k = 1..steps, every observer's onStep in the order
///      given, then every observer's onEnd once after the last step;
///   3. observers only read the simulation (it is passed const): they measure (measure/
///      metrics.hpp), record (output/animation.hpp) or report (HealthReport below).
/// An observer must not throw from onStep for a state it does not like: it counts it (the run's
/// health is the simulation's own RunHealth).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {

/// Watches a run. Every call has a no-op default; override what you need.
class RunObserver {
 public:
  virtual ~RunObserver() = default;
  /// Once before the first step, at sim.time() = 0 s.
  virtual void onStart(const Simulation& sim) { (void)sim; }
  /// After step `step` (1-based) at sim.time() (s); `sample` is true on the metric sample
  /// steps (every RunSchedule::sample_every steps).
  virtual void onStep(const Simulation& sim, long step, bool sample) {
    (void)sim, (void)step, (void)sample;
  }
  /// Once after the last step.
  virtual void onEnd(const Simulation& sim) { (void)sim; }
};

/// How many steps a run takes and which of them are metric samples.
struct RunSchedule {
  long steps = 0;         ///< round(duration / h)
  long sample_every = 1;  ///< max(1, round(Outputs::sample_interval / h)) steps
};

/// The schedule of `scene` at its own step scene.solver.time_step (s).
RunSchedule runSchedule(const Scene& scene);

/// Progress report: fraction done in [0, 1].
using Progress = std::function<void(double fraction)>;

/// A progress printer for stderr: "label: 42 %" on one refreshed line, at most every 0.5 s.
Progress stderrProgress(const std::string& label);

/// Steps `sim` schedule.steps times with the observers (onStart, onStep after every step, onEnd;
/// nullptr entries are skipped). `progress` (optional) is called about a hundred times and with
/// 1.0 at the end.
void runSimulation(Simulation& sim, const RunSchedule& schedule,
                   const std::vector<RunObserver*>& observers, const Progress& progress = {});

/// Reports the run's health at its end on stderr, prefixed "rheofeed: <scene>, <method>: ": one
/// line naming what it lost, could not trust or ignored (healthSummary) when
/// RunHealth::anything(), and one line of the local vibration law's counts when a feeder used it.
class HealthReport : public RunObserver {
 public:
  explicit HealthReport(std::string scene_name) : scene_name_(std::move(scene_name)) {}
  void onEnd(const Simulation& sim) override;

 private:
  std::string scene_name_;
};

/// One line naming what a run lost, could not trust or ignored, e.g. "3 of 60 parts lost
/// (fell 2, through a fixture 1); ..."; "nothing lost" when RunHealth::anything() is false.
/// `parts` is the number of parts spawned.
std::string healthSummary(const RunHealth& health, int parts);

}  // namespace rheofeed::scene
