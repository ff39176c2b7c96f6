// SPDX-License-Identifier: MIT
/// @file calibration.hpp
/// Turning a real vibration into the drift field that a rheonomic run uses: a constant drift
/// twist (calibrateBySampling, calibrateClassical: drift_model calibrated_drift), or the part
/// family's own efficiency under the local vibration law (calibrateEfficiency: drift_model
/// local_sampled; the local law itself needs no calibration, scene.hpp DriftModel).
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
#include <cstdio>

#include <string>
#include <vector>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// How the sampling calibration runs.
struct CalibrationSettings {
  int sample_parts = 8;        ///< parts in the sample (spawned at t = 0 in the scene's region;
                               ///< fewer when the region does not hold them all: see `how`)
  int steps_per_cycle = 200;   ///< full-vibration time step = 1 / (f steps_per_cycle)
  double warmup_cycles = 25;   ///< cycles before measuring
  double measure_cycles = 75;  ///< cycles measured
  bool use_reference_solver = false;  ///< sample with the reference solver instead of ODE
};

/// The drift field found for one vibrating fixture.
struct Calibration {
  int fixture = -1;
  std::string how;  ///< "full-vibration sample (ODE)" / "classical model" / ...
  /// "sampling" (calibrateBySampling) or "classical" (calibrateClassical): kept with the drift
  /// (CalibrationBasis::method) so that a stale one is redone the same way.
  std::string method = "sampling";
  Twist drift;  ///< the equivalent drift field (world frame)
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
/// and drift_model calibrated_drift: rheonomic methods then use it. Its calibrated_for is set
/// from `scene` by calibrationBasis (scene.hpp: the fixture's vibration, the scene's gravity,
/// mu and what else `calibration.method` took from it, e.g. a sample run's parts): pass the
/// scene that was calibrated, and a later edit of them makes the drift stale
/// (staleCalibration).
Scene withCalibration(Scene scene, const Calibration& calibration);

/// How calibrateEfficiency runs (issue 8: the part's own efficiency under the local law).
struct EfficiencySettings {
  int sample_parts = 8;  ///< parts of the family in the sample (>= 1), spawned at t = 0 (fewer
                         ///< when the spawn region does not hold them all: see `how`)
  /// Full-vibration time step = 1 / (f steps_per_cycle) (>= 4). 1000 by default: at 200 the
  /// sampled drift on an inclined track is off by up to 10 % (issue 8), at 1000 it is not.
  int steps_per_cycle = 1000;
  double warmup_cycles = 25;   ///< vibration cycles before measuring (>= 0)
  double measure_cycles = 75;  ///< vibration cycles measured (> 0)
  /// Time step (s) of the rheonomic run of the sample with the local law (in [1e-6, 1]):
  /// give the step the rheonomic runs take (the demos' default is 0.01 s).
  double rheonomic_time_step = 0.01;
  bool use_reference_solver = false;  ///< both runs with the reference solver instead of ODE
};

/// A part family's own efficiency on one vibrating fixture, and how it was measured.
struct EfficiencyCalibration {
  int fixture = -1;  ///< the vibrating fixture (index into Scene::fixtures)
  int family = -1;   ///< the part family (index into Scene::parts)
  std::string how;   ///< e.g. "full vibration (ODE, 1000 steps/cycle, 8 parts) / local law"
  /// Drift of the full-vibration sample and its 95 % half-width over the sample's parts: m/s
  /// along Outputs::conveying_direction, or rad/s about the vibration's axis for a screw.
  double sampled = 0, sampled_ci95 = 0;
  /// Drift of the same sample run rheonomically with the local law at efficiency 1 (same
  /// engine, same units) and its 95 % half-width.
  double local = 0, local_ci95 = 0;
  /// sampled / local (dimensionless), and its 95 % half-width from the two intervals
  /// (first-order propagation of independent errors).
  double efficiency = 1, ci95 = 0;
  double cpu_seconds = 0;  ///< both runs (process CPU time)
};

/// Measures the own efficiency of part family `family` on vibrating fixture `fixture`: a short
/// full-vibration run of a sample of that family alone (settings), and the same sample run
/// rheonomically with the local law (every vibrating fixture on drift_model local, efficiency
/// 1); efficiency = sampled drift / local drift. Throws std::invalid_argument naming the value
/// for a bad index, a fixture that does not vibrate, bad settings, an invalid scene, or a
/// result that cannot be a factor: a local drift too close to zero (|local| below its own 95 %
/// half-width or below 1 % of the peak vibration speed 2 pi f A, or 2 pi f theta rad/s for a
/// screw: the ratio would be noise), or a ratio outside [0, kMaxPartEfficiency] (the sample and
/// the local law drift in opposite directions).
EfficiencyCalibration calibrateEfficiency(const Scene& scene, int fixture, int family,
                                          const EfficiencySettings& settings = {});

/// A copy of `scene` whose fixture `calibration.fixture` uses drift_model local_sampled with
/// `calibration.efficiency` as the factor of `calibration.family` (the other families keep
/// theirs, 1 when the fixture had none), its calibrated_for set from `scene` as withCalibration
/// does, with `calibration.family`'s digest; the other families keep the digests of their
/// factors where the old record holds one per family and fits this feeder apart from the parts,
/// else they are marked not measured (staleCalibration then asks for them: calibrate every
/// family, as calibrateScene does). A calibrated drift kept beside them is dropped unless it was
/// sampled for this same feeder and parts (one record serves both). Throws
/// std::invalid_argument for a bad index.
Scene withEfficiency(Scene scene, const EfficiencyCalibration& calibration);

/// Why fixture `fixture`'s calibrated drift cannot stay beside the efficiency factors that
/// withEfficiency records (one calibrated_for serves both, and would vouch for it): "" when it
/// has none, or was sampled for this same feeder and parts; else "it records no
/// calibrated_for ...", "it was not measured by sampling (classical)" or "it was measured for
/// another feeder: ..." (staleCalibration's reason). Throws std::out_of_range for a bad index.
std::string driftCannotShareFactorsRecord(const Scene& scene, int fixture);

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
  /// Vibration cycles of the sampling runs (calibrateBySampling, calibrateEfficiency) before
  /// measuring (finite, >= 0) and measured (finite, > 0). The defaults measure the first two
  /// seconds of a 50 Hz feeder; a phase that the parts reach later (a bowl's ramp) needs a
  /// longer warm-up. Checked by the calibrations (std::invalid_argument).
  double warmup_cycles = 25;
  double measure_cycles = 75;
};

/// What calibrateScene did.
struct CalibrateReport {
  int calibrated = 0;  ///< fixtures calibrated now
  int given = 0;       ///< vibrating fixtures whose calibration the scene gives (not calibrated)
  int local = 0;       ///< vibrating fixtures on the local law (nothing to calibrate)
  double cpu_seconds = 0;  ///< CPU time of the calibrations (s)
  std::string summary;     ///< one line per calibrated fixture: value, 95 % interval, how
  /// One message per calibration whose 95 % half-width exceeds kImpreciseCalibration of its
  /// value (a calibrated drift, or a part family's efficiency): the runs that use it carry that
  /// uncertainty. Also printed on the log as a warning, with the longer sampling that narrows it.
  std::vector<std::string> imprecise;
  /// One message per fixture whose calibration the scene gave but measured for another feeder
  /// (staleCalibration): calibrated again. Also printed on the log as a warning.
  std::vector<std::string> stale;
};

/// A calibration is reported imprecise (CalibrateReport::imprecise) when its 95 % half-width is
/// above this fraction of its value.
inline constexpr double kImpreciseCalibration = 0.1;

/// Calibrates the vibrating fixtures of `scene` that need it (lacking or stale calibrations;
/// all but the local-law ones with options.force) and stores the results in it: calibrated_drift by
/// calibrateBySampling (or calibrateClassical) and withCalibration, local_sampled by
/// calibrateEfficiency per part family and withEfficiency. Each calibration is announced on `log`
/// before it starts
/// ("<label>: calibrating fixture ...") and its result printed after. Throws what the
/// calibration throws (std::invalid_argument for a scene it cannot calibrate).
CalibrateReport calibrateScene(Scene& scene, const CalibrateOptions& options,
                               const std::string& label, std::FILE* log);

}  // namespace rheofeed::scene
