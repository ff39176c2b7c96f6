// SPDX-License-Identifier: MIT
/// @file calibration.hpp
/// Turning a real vibration into the drift field that a rheonomic run uses.
///
/// A vibration's peak velocity is not the drift (NOTES 1 and 5): parts advance at a fraction
/// of A w cos(beta), set by friction, throw number and hopping. Two ways to find the drift:
///  - by sampling: a short full-vibration run of a small sample of the scene's parts, the
///    drift measured from their displacements over whole cycles (with a 95 % interval);
///  - by the classical single-part model of Redford & Boothroyd (classical_model.hpp), a
///    quick estimate for straight tracks.
/// For a straight (translating) vibration the drift is a pure translation along the scene's
/// conveying direction (no rotation terms); for a screw motion (torsion about an axis) it is a
/// rotation about that axis.
#pragma once

#include <string>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// How the sampling calibration runs.
struct CalibrationSettings {
  int sample_parts = 8;        ///< parts in the sample (spawned at t = 0 in the scene's region)
  int steps_per_cycle = 200;   ///< full-vibration time step = 1 / (f steps_per_cycle)
  double warmup_cycles = 25;   ///< cycles before measuring
  double measure_cycles = 75;  ///< cycles measured
  bool use_reference_solver = false;  ///< sample with the reference solver instead of ODE
};

/// The drift field found for one vibrating fixture.
struct Calibration {
  int fixture = -1;
  std::string how;  ///< "full-vibration sample (ODE)" / "classical model" / ...
  Twist drift;      ///< the equivalent drift field (world frame)
  /// Translation: drift speed along the conveying direction (m/s); screw: angular drift about
  /// the axis (rad/s).
  double value = 0;
  double ci95 = 0;  ///< 95 % half-width of `value` over the sample's parts
  /// Conveying efficiency value / (A w cos(beta)) for a translation (dimensionless), where
  /// beta is the angle between vibration and conveying directions; 0 for a screw.
  double efficiency = 0;
  double cpu_seconds = 0;
};

/// Calibrates fixture `fixture` (which must vibrate) of `scene` by a full-vibration sample run.
/// Throws std::invalid_argument if it does not vibrate or the scene is invalid.
Calibration calibrateBySampling(const Scene& scene, int fixture,
                                const CalibrationSettings& settings = {});

/// Quick estimate of the drift of fixture `fixture` (which must vibrate) from the classical
/// single-part model (classical_model.hpp), evaluated at the centre of the spawn region of the
/// scene's first part family, on a track along Outputs::conveying_direction (translation) or
/// around the vibration's axis (screw), pressed by gravity. Milliseconds; no uncertainty
/// (ci95 = 0); it ignores what the single-part model ignores (other parts, walls, rocking).
/// Throws std::invalid_argument when the model does not apply there (classicalTrack's reasons).
Calibration calibrateClassical(const Scene& scene, int fixture);

/// A copy of `scene` whose vibrating fixture carries `calibration` as its calibrated drift
/// ("vibration, calibrated"): rheonomic methods then use it.
Scene withCalibration(Scene scene, const Calibration& calibration);

}  // namespace rheofeed::scene
