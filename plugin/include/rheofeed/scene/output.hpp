// SPDX-License-Identifier: MIT
/// @file output.hpp
/// Writing result files so that no reader ever sees a half-written one, and the feeder metrics'
/// files (FeederMetrics, metrics.hpp): CSV, JSON object and plots.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "rheofeed/scene/metrics.hpp"

namespace rheofeed::scene {

/// Writes `text` to `path` through a temporary file in the same folder and a rename, creating
/// the folder if needed. Throws std::runtime_error naming the path on failure (the old file,
/// if any, is then untouched).
void writeFileAtomically(const std::filesystem::path& path, const std::string& text);

/// `text` as a JSON string literal (quotes, backslashes and control characters escaped).
std::string jsonQuoted(const std::string& text);

/// CSV of the output rate over time, one row per window (RateWindow):
/// window_start_s,window_end_s,exits,rate_per_min,cumulative_exits.
std::string exitsCsv(const FeederMetrics& feeder);
/// CSV of the exit orientations, one row per part family:
/// family,shape,spawned,exited,removed_without_exit,orientation_meaningful,+x,-x,+y,-y,+z,-z.
std::string orientationCsv(const FeederMetrics& feeder);
/// The JSON object of the feeder metrics (no surrounding key):
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

}  // namespace rheofeed::scene
