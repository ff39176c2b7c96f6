// SPDX-License-Identifier: MIT
// What a rheonomic run of a vibrating feeder needs before it starts: the drift field that
// replaces the vibration (calibration.hpp). Shared by `rheofeed run` (calibrates what the scene
// does not give, every launch) and `rheofeed calibrate` (calibrates once and writes the result
// into a copy of the scene, so that later runs start at once).
#pragma once

#include <cstdio>
#include <string>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::cli {

/// How the drift fields are found.
struct CalibrateOptions {
  /// The classical single-part model (calibrateClassical: milliseconds, a straight-track
  /// estimate) instead of a full-vibration sample run (calibrateBySampling: seconds to a minute).
  bool classical = false;
  /// Calibrate every vibrating fixture whose drift model takes a calibration, also when the
  /// scene already gives it.
  bool force = false;
  /// The step (s) of the rheonomic runs: calibrateEfficiency runs the local law at it.
  double rheonomic_time_step = 0.01;
};

/// What calibrateScene did.
struct CalibrateReport {
  int calibrated = 0;  ///< fixtures calibrated now
  int given = 0;       ///< vibrating fixtures whose calibration the scene gives (not calibrated)
  int local = 0;       ///< vibrating fixtures on the local law (nothing to calibrate)
  double cpu_seconds = 0;  ///< CPU time of the calibrations (s)
  std::string summary;     ///< one line per calibrated fixture: value, 95 % interval, how
};

/// Sets the drift model named `name` (local, local_sampled, calibrated_drift) on every vibrating
/// fixture of `scene` (dropping the scene's efficiency factors of fixtures whose model changes).
/// Throws std::invalid_argument naming --drift-model and the valid names for another name.
void overrideDriftModel(rheofeed::scene::Scene& scene, const std::string& name);

/// True when a rheonomic run of `scene` would calibrate first: a vibrating fixture whose drift
/// model (scene.hpp DriftModel) lacks its data (calibrated_drift without the drift,
/// local_sampled without the efficiency factors; the local law needs none).
bool needsCalibration(const rheofeed::scene::Scene& scene);

/// Calibrates the vibrating fixtures of `scene` that need it (all but the local-law ones with
/// options.force) and stores the results in it: calibrated_drift by calibrateBySampling (or
/// calibrateClassical) and withCalibration, local_sampled by calibrateEfficiency per part family
/// and withEfficiency. Each calibration is announced on `log` before it starts
/// ("<label>: calibrating fixture ...") and its result printed after. Throws what the
/// calibration throws (std::invalid_argument for a scene it cannot calibrate).
CalibrateReport calibrateScene(rheofeed::scene::Scene& scene, const CalibrateOptions& options,
                               const std::string& label, std::FILE* log);

}  // namespace rheofeed::cli
