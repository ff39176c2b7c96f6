// SPDX-License-Identifier: MIT
/// @file output.hpp
/// Writing result files so that no reader ever sees a half-written one: a run's series CSV and
/// JSON summary (RunMetrics, measure/metrics.hpp) and the feeder metrics' files (FeederMetrics):
/// CSV, JSON object and plots.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "rheofeed/measure/metrics.hpp"

namespace rheofeed::scene {

/// Writes `text` to `path` through a temporary file in the same folder and a rename, creating
/// the folder if needed. Throws std::runtime_error naming the path on failure (the old file,
/// if any, is then untouched). Each call has its own temporary file, so concurrent writers of
/// one path (threads or processes) leave one writer's whole text, never a mix.
void writeFileAtomically(const std::filesystem::path& path, const std::string& text);

/// `text` as a JSON string literal (quotes, backslashes and control characters escaped).
std::string jsonQuoted(const std::string& text);
/// `x` as a JSON number (8 significant digits), or null when it is not finite.
std::string jsonNumber(double x);

/// CSV of the output rate over time, one row per window (RateWindow):
/// window_start_s,window_end_s,exits,rate_per_min,cumulative_exits.
std::string exitsCsv(const FeederMetrics& feeder);
/// CSV of the exit orientations, one row per part family:
/// family,shape,spawned,exited,removed_without_exit,orientation_meaningful,+x,-x,+y,-y,+z,-z.
std::string orientationCsv(const FeederMetrics& feeder);
/// The JSON object of the feeder metrics (no surrounding key; numbers in their shortest form
/// that reads back exactly, null where not finite):
/// {"exit_plane", "up", "first_exit_time_s" (null when none), "note" (null when empty),
/// "mean_exit_rate_per_min" (null with fewer than two exits), "rate_window_s", "parts_exited",
/// "spawned_beyond_exit", "exit_rate_per_min": [{"t_s" (window centre), "t_start_s", "t_end_s",
/// "exits", "rate_per_min", "cumulative_exits"}], "exit_times_s": [...], "families": {name:
/// {"shape", "spawned", "exited", "removed_without_exit", "orientation_meaningful"}},
/// "exit_orientation": {name: {"+x": n,
/// ..., "-z": n}}}. A family whose name repeats an earlier one is keyed "name[k]" (k its index
/// in Scene::parts).
std::string feederJson(const FeederMetrics& feeder);
/// With an exit plane: writes <stem>_exits.csv and <stem>_orientation.csv into `folder`
/// atomically and, when gnuplot works, <stem>_exits.png (rate and cumulative count vs time) and
/// one <stem>_orientation_<family>.png per family (histogram of the up axis at the exit).
/// `title` heads the plots. Returns the paths written; nothing without an exit plane.
std::vector<std::string> writeFeederOutputs(const FeederMetrics& feeder,
                                            const std::filesystem::path& folder,
                                            const std::string& stem, const std::string& title);

/// CSV of the series: time_s,parts,mean_velocity_mps,ci95_mps (the mean drift along the conveying
/// direction, m/s, and its 95 % half-width; for an angular drift mean_drift_radps,ci95_radps, rad/s
/// about its axis),mean_height_m,exited, then the parts lost so far by kind (cumulative counts,
/// RunHealth): lost_fell,lost_through_fixture,lost_out_of_bounds,lost_nonfinite,lost_too_fast,
/// lost_left_feeder. A sample with no part measured has empty mean and height fields (no value,
/// not 0); one with fewer than two an empty ci95.
std::string seriesCsv(const RunMetrics& run);

/// One-line JSON summary of a run: all scalar fields; "scene_source" (RunMetrics::scene_file, or
/// "built-in" for a scene built in code) and "rheofeed_version" (kVersion, version.hpp); before
/// the mean drift, the verdict on it, "answer" (runAnswer, metrics.hpp): {"trusted" (false: the
/// run's numbers are not its answer), "why" (the reasons, empty when trusted), "parts_lost",
/// "lost_fraction" (parts_lost / parts; null with no part spawned), "max_lost_fraction" (the
/// bound, RunMetrics::max_lost_fraction)}; a
/// "solver" object with the settings the engine applied (RunMetrics::solver, AppliedSolver:
/// engine, mode, iterations, tolerance, relaxed_solver, coulomb_iterations, ipm_rounds,
/// warm_start, speculative_contacts, erp, cfm, max_correcting_velocity_mps, surface_layer_m and
/// "surface": {mu, restitution, bounce_velocity_mps}; null where one does not apply); a "health"
/// object with every count of RunHealth, parts_lost, the share of Coulomb fallback steps, the
/// maximum part speed and its bound, the list of ignored settings and the part events (part,
/// family, kind, t_s, position_m, velocity_mps, fixture, what); the scene check's warnings; a
/// "feeder" object (feederJson); and a "local_law" object (RunHealth::local_law: feeders,
/// contacts, wall_contacts, cells_computed, model_runs, model_cpu_s (s); corners_at_start from
/// RunHealth::local_law_corners_at_start). Numbers are written in their shortest form that reads
/// back exactly; a number that is not finite, a mean drift or vertical displacement with no
/// part measured, the throughput of a scene without an exit plane and a 95 % interval over
/// fewer than two parts are null. "drift_parts" is the number of parts behind the mean drift
/// ("parts": all spawned).
std::string summaryJson(const RunMetrics& run);

/// Writes <stem>.csv, <stem>.json and, when gnuplot is available, <stem>.png (mean drift vs time
/// with the 95 % band) into `folder`, each atomically; with an exit plane also the feeder
/// outputs (writeFeederOutputs: <stem>_exits.csv, <stem>_orientation.csv and their plots).
/// Returns the paths written; a missing gnuplot is reported on stderr and the PNGs skipped.
std::vector<std::string> writeRunOutputs(const RunMetrics& run, const std::string& folder,
                                         const std::string& stem);

}  // namespace rheofeed::scene
