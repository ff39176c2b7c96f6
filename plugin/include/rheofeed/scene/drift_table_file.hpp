// SPDX-License-Identifier: MIT
/// @file drift_table_file.hpp
/// Drift table files: the local vibration law's point-mass results (LocalDriftTable, in
/// rheofeed/vibration_drift.hpp) saved after a run and read before the next, so that a scene
/// pays the model runs once (on the mesh bowl they are most of a short run's cost).
///
/// A file is JSON:
///
///     {"format": "rheofeed local drift table", "model_revision": 1,
///      "point_mass_settings": {"steps_per_cycle": 16384, "max_cycles": 400,
///                              "average_cycles": 100, "max_period": 8,
///                              "periodic_tolerance": 1e-06},
///      "grid_steps": {"normal_throw": 0.025, "tangential_throw": 0.05, "slope": 0.02},
///      "columns": ["normal_throw_index", "tangential_throw_index", "slope_along_index",
///                  "slope_across_index", "mu", "along", "across", "valid"],
///      "corners": [[40, 23, 0, 0, 0.5, 0.2581, 0, 1], ...]}
///
/// one row per grid corner (DriftTableCorner: dimensionless grid indices, friction coefficient,
/// drift in units of |g_n| / w, 1 or 0). Numbers are written so that they read back to the same
/// doubles: a run on a loaded table gives the same drifts, bit for bit, as one that runs the
/// model. The values do not depend on the feeder or the scene, only on the settings, the grid
/// and the model revision, which a file must match.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "rheofeed/vibration_drift.hpp"

namespace rheofeed::scene {

/// The text of a drift table file holding every corner of `table` (ordered by mu and grid).
std::string driftTableJson(const LocalDriftTable& table);

/// Adds the corners of the drift table file `path` to `table` (LocalDriftTable::addCorners);
/// returns how many were new. Throws SceneFileError (scene_io.hpp) naming the path, the key and
/// what is wrong: the file is missing or unreadable, not JSON (the parser's message), not
/// a drift table, of another model revision, of other point-mass settings or grid steps than
/// `table` (the key, the file's value and the table's), or a corner is malformed (its index and
/// what is wrong). Nothing is added when it throws.
std::size_t loadDriftTable(const std::filesystem::path& path, LocalDriftTable& table);

/// loadDriftTable on the text of a file; `source` names it in the errors (SceneFileError::source).
std::size_t parseDriftTable(const std::string& text, const std::string& source,
                            LocalDriftTable& table);

}  // namespace rheofeed::scene
