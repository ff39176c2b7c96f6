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
  /// Calibrate every vibrating fixture, also those whose scene already gives the drift.
  bool force = false;
};

/// What calibrateScene did.
struct CalibrateReport {
  int calibrated = 0;      ///< fixtures calibrated now
  int given = 0;           ///< vibrating fixtures whose drift the scene gives (not calibrated)
  double cpu_seconds = 0;  ///< CPU time of the calibrations (s)
  std::string summary;     ///< one line per calibrated fixture: value, 95 % interval, how
};

/// True when a rheonomic run of `scene` would calibrate first (a vibrating fixture without a
/// calibrated drift).
bool needsCalibration(const rheofeed::scene::Scene& scene);

/// Calibrates the vibrating fixtures of `scene` that need it (all with options.force) and stores
/// the results in it (withCalibration). Each calibration is announced on `log` before it starts
/// ("<label>: calibrating fixture ...") and its result printed after. Throws what the
/// calibration throws (std::invalid_argument for a scene it cannot calibrate).
CalibrateReport calibrateScene(rheofeed::scene::Scene& scene, const CalibrateOptions& options,
                               const std::string& label, std::FILE* log);

}  // namespace rheofeed::cli
