// SPDX-License-Identifier: MIT
/// @file metrics.hpp
/// What a feeder simulation is judged by: the drift of the parts along the conveying
/// direction, its spread over parts, vertical displacement (bowls), throughput through an exit
/// plane, and the cost (CPU time, real-time factor).
///
/// Drift velocity is measured from displacements, not instantaneous velocities: over one sample
/// interval dt_s, a part's drift is ((x(t) - x(t - dt_s)) . d) / dt_s with d the conveying
/// direction. In a full vibration run the instantaneous velocity swings with the feeder; the
/// displacement over an interval that spans whole vibration cycles is the transport itself.
/// With Outputs::angular_drift the same is done with the unwrapped angle of each part about the
/// axis: drift velocities are then angular velocities (rad/s).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "rheofeed/scene/simulation.hpp"

namespace rheofeed::scene {

/// One sample of the drift time series.
struct DriftSample {
  double time = 0;           ///< end of the sample interval (s)
  int parts = 0;             ///< parts measured (spawned, not yet exited)
  double mean_velocity = 0;  ///< mean drift velocity over parts (m/s along d, or rad/s)
  double ci95 = 0;           ///< half-width of the 95 % confidence interval of the mean (m/s)
  double mean_height = 0;    ///< mean z of the parts (m)
  int exited = 0;            ///< parts that have crossed the exit plane so far
  /// Parts lost so far, by kind (RunHealth, cumulative at `time`).
  int fell = 0, through_fixture = 0, out_of_bounds = 0, nonfinite = 0, too_fast = 0;
};

/// The result of one run.
struct RunMetrics {
  std::string scene;
  Method method = Method::OdeRheonomic;
  double time_step = 0;  ///< (s)
  bool angular = false;  ///< the drift is an angular velocity (rad/s) instead of m/s
  std::vector<DriftSample> series;
  /// Mean drift (m/s along d, or rad/s about the axis) over [warmup, end]: total displacement of
  /// the measured parts divided by time, averaged over parts.
  double mean_drift = 0;
  double mean_drift_ci95 = 0;        ///< 95 % CI half-width over parts (m/s)
  double vertical_displacement = 0;  ///< mean z change of the parts since they spawned (m)
  double throughput = 0;             ///< parts per second through the exit plane (after warmup)
  int parts = 0;                     ///< spawned parts
  double cpu_seconds = 0;            ///< process CPU time of the run
  double simulated_seconds = 0;
  /// CPU time / simulated time (dimensionless; < 1 is faster than real time).
  double real_time_factor = 0;
  /// What the run lost, could not trust or ignored (simulation.hpp).
  RunHealth health;
  /// The scene check's warnings before the run (check.hpp: kind, values, safe setting), one
  /// formatted line each; also printed on stderr when the run starts.
  std::vector<std::string> scene_check;
};

/// Progress report: fraction done in [0, 1].
using Progress = std::function<void(double fraction)>;

/// Runs `scene` with `method` for its duration and measures it. Before the first step the scene
/// check (checkScene) runs and its warnings go to stderr and into RunMetrics::scene_check.
/// `progress` (optional) is called about a hundred times. Throws std::invalid_argument for an
/// invalid scene. When the run lost parts, had reference steps it cannot trust or ignored settings
/// (RunHealth::anything), one summary line is printed on stderr at the end (healthSummary).
RunMetrics measureRun(const Scene& scene, Method method, const Progress& progress = {});

/// A progress printer for stderr: "label: 42 %" on one refreshed line, at most every 0.5 s.
Progress stderrProgress(const std::string& label);

/// Two-sided 95 % Student-t quantile for `dof` degrees of freedom (1.96 for large dof).
double studentT95(int dof);

/// CSV of the series: time_s,parts,mean_velocity_mps,ci95_mps,mean_height_m,exited, then the
/// parts lost so far by kind (cumulative counts, RunHealth): lost_fell,lost_through_fixture,
/// lost_out_of_bounds,lost_nonfinite,lost_too_fast.
std::string seriesCsv(const RunMetrics& run);
/// One-line JSON summary of a run: all scalar fields and a "health" object with every count of
/// RunHealth, parts_lost, the share of Coulomb fallback steps, the maximum part speed and its
/// bound, and the list of ignored settings; the scene check's warnings; and a "local_law"
/// object (RunHealth::local_law: feeders, contacts, wall_contacts, cells_computed, model_runs).
std::string summaryJson(const RunMetrics& run);
/// One line naming what a run lost, could not trust or ignored, e.g. "3 of 60 parts lost
/// (fell 2, through a fixture 1); ..."; "nothing lost" when RunHealth::anything() is false.
std::string healthSummary(const RunHealth& health, int parts);

/// Writes <stem>.csv, <stem>.json and, when gnuplot is available, <stem>.png (mean drift vs time
/// with the 95 % band) into `folder`, each atomically. Returns the paths written; a missing
/// gnuplot is reported on stderr and the PNG skipped.
std::vector<std::string> writeRunOutputs(const RunMetrics& run, const std::string& folder,
                                         const std::string& stem);

}  // namespace rheofeed::scene
