// SPDX-License-Identifier: MIT
/// @file vibration_drift.hpp
/// The local vibration law (issue 8): the drift a vibrating feeder gives a part at one contact,
/// from the feeder's real vibration at that point, with no sampling run.
///
/// ## The point-mass model
/// A point mass rests on a plane (unit outward normal n) that vibrates as x(t) = a sin(w t),
/// w = 2 pi f, with a displacement amplitude vector a (m) - at a point p of a feeder that
/// translates by A d sin(w t) and turns by theta sin(w t) about an axis (k, O), to first order
///     a(p) = A d + theta k x (p - O).
/// Gravity g (m/s^2) and a with it are split by n into normal parts (g_n = g . n < 0 presses
/// the mass onto the plane, a_n = a . n) and in-plane parts g_t, a_t. Relative to the plane the
/// mass feels g + a w^2 sin(w t). While in contact it sticks or slides in any in-plane direction
/// under isotropic Coulomb friction (|f_t| <= mu N, opposite to the slip); when the normal force
/// would become negative it flies; it lands plastically, with a Coulomb friction impulse of at
/// most mu times the normal impulse. The cycle-averaged in-plane velocity of the periodic steady
/// state is the **drift**: a 2-D vector that includes downhill creep on a slope and sideways creep
/// on a cross slope, and reverses on a steep incline. On a straight track (g_t and a_t in one
/// vertical plane) it is the classical feeder model of scene/classical_model.hpp; the tests
/// check it against that model (an independent, event-driven, closed-form integration).
///
/// ## Dimensionless form
/// In units of |g_n| / w (velocity) and w t (time), the drift depends on five numbers only:
///     Gamma = |a_n| w^2 / |g_n|        normal throw number (a is negated when a_n < 0: that is
///                                      half a period of phase, which the steady state ignores)
///     tau   = |a_t| w^2 / |g_n|        in-plane throw number, along e1 = a_t / |a_t|
///     s1, s2 = g_t . e1 / |g_n|, g_t . e2 / |g_n|   in-plane gravity (the slopes' tangents);
///                                      e2 = n x e1
///     mu                               friction coefficient
/// and is drift = (|g_n| / w) (V1 e1 + V2 e2) with (V1, V2) = pointMassDrift(...). Flipping e2
/// flips V2 (mirror symmetry), so only s2 >= 0 is computed.
///
/// ## Integration
/// Moreau's time stepping of the relative motion with a fixed number of steps per cycle (a
/// velocity-level plastic contact with an exact Coulomb disc projection; the forcing is
/// integrated exactly over each step), run from rest until the state at the start of a cycle
/// repeats twice (period 1 to 8) or, for chaotic hopping, averaged over the last cycles. Its
/// error is first order in the step (PointMassSettings::steps_per_cycle says how large).
///
/// ## Where the model does not apply: walls, overhangs, steep slopes
/// Where gravity does not hold the mass on the plane (g_n >= -|g| cos(kWallAngle)) or the plane
/// is steeper than the friction angle (|g_t| >= mu |g_n|: the mass slides away with or without
/// vibration, no steady drift exists), the local law uses the drift of a horizontal surface (n =
/// -g / |g|) at the same point, projected on the contact plane: a side rail or a bowl wall then
/// neither brakes nor pushes a part that the floor drives. LocalDriftStats counts these
/// contacts.
///
/// ## Cost
/// pointMassDrift takes milliseconds (PointMassSettings); the corners one lookup needs run on
/// several threads at once (LocalDriftTable::setThreads). LocalDriftTable fills a grid in
/// (Gamma, tau, s1, s2) lazily, the corners of a cell (up to 16) as contacts need them, and
/// interpolates multilinearly in the cell (a corner of weight 0 - an input on a grid line, as
/// s1 = s2 = 0 on a level floor - is not run); a contact whose inputs equal the previous contact's
/// (every contact of a translating flat feeder) reuses the previous result. The corners do not
/// depend on the feeder: the scene layer shares one table per process (LocalDriftTable::shared)
/// and can save it between runs (rheofeed/scene/drift_table_file.hpp; `rheofeed run
/// --drift-table`). Units SI throughout.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rheofeed/vec3.hpp"

namespace rheofeed {

/// Largest efficiency factor (dimensionless) of a local law or a part (LocalVibration::efficiency,
/// FeederSet::setPartEfficiency, reference::World::setBodyEfficiency, scene files): a part 100x
/// faster than a point mass would be a wrong calibration, not a shape effect.
constexpr double kMaxEfficiency = 100;

/// The dimensionless inputs of the point-mass model (file comment).
struct PointMassParams {
  double normal_throw = 0;      ///< Gamma >= 0
  double tangential_throw = 0;  ///< tau >= 0, along e1
  double slope_along = 0;       ///< s1 = g_t . e1 / |g_n|
  double slope_across = 0;      ///< s2 = g_t . e2 / |g_n|
  double mu = 0.5;              ///< >= 0; sqrt(s1^2 + s2^2) < mu is required
};

/// Numerical settings of pointMassDrift.
struct PointMassSettings {
  /// Moreau steps per vibration cycle (>= 16, even). The error is first order in the step and
  /// irregular (events fall between steps); measured against the classical model's exact
  /// solution on straight tracks (inclines -10..10 deg, vibration angles 15..45 deg, throws
  /// 0.6..3, mu 0.3..0.8): worst error 5.2 %, 1.8 %, 0.6 % of max(|drift|, 2 % of the peak
  /// tangential speed) at 2048, 8192, 16384 on 220 grid cases, and 0.75 % at 16384 on the 200
  /// random cases of tests/validation/local_drift_test.cpp (which asserts 1 %). The transient
  /// from rest runs at 1/16 of this resolution first (pointMassDrift).
  int steps_per_cycle = 16384;
  int max_cycles = 400;      ///< cycles simulated at most per resolution (>= 8)
  int average_cycles = 100;  ///< cycles averaged when no period is found (1 .. max_cycles)
  int max_period = 8;        ///< longest period looked for (cycles, >= 1)
  /// Two cycle-start states are equal when their velocities differ by less than this (units of
  /// |g_n| / w) and their gaps by this (units of |g_n| / w^2). 1e-6 against drifts of order
  /// 0.01..1 in these units; 1e-9 made the bowl's table 2.6x slower for no measurable change.
  double periodic_tolerance = 1e-6;
};

/// The steady state of the point-mass model.
struct PointMassDrift {
  double along = 0;            ///< V1: mean in-plane velocity along e1 (units |g_n| / w)
  double across = 0;           ///< V2: along e2 (units |g_n| / w)
  double flight_fraction = 0;  ///< share of the time off the plane (0..1)
  double stick_fraction = 0;   ///< share of the time stuck to the plane (0..1)
  int period = 0;              ///< cycles; 0 when none was found (chaotic), then averaged
  bool valid = false;          ///< false when the inputs are outside the model (message says)
  std::string problem;         ///< why not valid
};

/// Runs the point-mass model (file comment). Never throws; invalid inputs (non-finite,
/// negative throws or mu, a slope at or beyond the friction angle) give valid = false.
PointMassDrift pointMassDrift(const PointMassParams& params,
                              const PointMassSettings& settings = {});

/// A feeder's real vibration, for the local law (world frame; a stationary feeder at rest):
/// displacement at a point p, x(t) = (amplitude + torsion_amplitude axis x (p - axis_origin))
/// sin(2 pi frequency t) to first order. Its phase does not change a steady drift.
struct LocalVibration {
  double frequency = 50;         ///< f (Hz, > 0)
  Vec3 amplitude;                ///< A d: peak translation displacement vector (m)
  double torsion_amplitude = 0;  ///< theta: peak rotation about the axis (rad, right hand)
  Vec3 axis_origin;              ///< O: a point of the torsion axis (m)
  Vec3 axis_direction{0, 0, 1};  ///< k: unit torsion axis
  Vec3 gravity{0, 0, -9.81};     ///< g (m/s^2)
  /// The part's own efficiency: a factor on the point-mass drift (dimensionless, >= 0; 1 = a
  /// point mass). Measured by a sampling run as sampled drift / local drift (issue 8).
  double efficiency = 1;
  /// Friction coefficient used where a caller gives no contact mu (the two-argument
  /// StepLaw::tangentialVelocity); FeederSet and the reference world pass the contact's own.
  double mu = 0.5;
  /// Throws std::invalid_argument naming the bad value, `where` it came from and the range:
  /// frequency in (0, 1e5] Hz, |amplitude| <= 1e3 m, theta in [0, pi], k unit (|k| within 1e-6
  /// of 1), gravity finite and non-zero, efficiency in [0, 100], mu in [0, 1e3], everything
  /// finite.
  void validate(const std::string& where) const;
  /// Whether the local amplitude is the same at every point (no torsion).
  bool isTranslation() const { return torsion_amplitude == 0; }
};

/// Walls: a contact plane whose outward normal is within this angle (rad) of horizontal, or
/// faces down, uses the horizontal surface's drift (file comment). 80 degrees.
constexpr double kWallAngle = 1.3962634015954636;

/// Counts of a local law's contacts (for reporting).
struct LocalDriftStats {
  std::int64_t contacts = 0;        ///< contacts driven
  std::int64_t wall_contacts = 0;   ///< of which used the horizontal surface's drift (walls,
                                    ///< overhangs, steeper than the friction angle)
  std::int64_t cells_computed = 0;  ///< table cells filled
  std::int64_t model_runs = 0;      ///< pointMassDrift calls (grid corners)
  std::int64_t corners_added = 0;   ///< grid corners taken from elsewhere (addCorners: a saved
                                    ///< table), not run here
  double model_cpu_seconds = 0;     ///< CPU time of those model runs (s, summed over the threads
                                    ///< that ran them): what a saved table saves
};

/// One grid corner of a LocalDriftTable: the point-mass drift (V1, V2) = (along, across), units
/// |g_n| / w, at Gamma = grid[0] kNormalThrowStep, tau = grid[1] kTangentialThrowStep, s1 =
/// grid[2] kSlopeStep, s2 = grid[3] kSlopeStep and friction mu (dimensionless); valid = false
/// where the model refuses the corner (a slope at or beyond the friction angle).
struct DriftTableCorner {
  std::int64_t grid[4] = {0, 0, 0, 0};
  double mu = 0;
  double along = 0;
  double across = 0;
  bool valid = false;
};

/// The lazily filled drift table of one vibration (thread-safe; copies of a MotionLaw share
/// it). Grid steps: Gamma 0.025, tau 0.05, s1 and s2 0.02 (a 1.15 degree slope).
///
/// A corner's value depends only on its grid point, mu, the PointMassSettings and the model's
/// numerics (kModelRevision), not on any feeder: one table serves every feeder and scene with the
/// same settings, and a table saved after one run (corners()) and added to the next
/// (addCorners) gives that run bit-identical drifts without running the model again.
class LocalDriftTable {
 public:
  /// Grid steps (dimensionless): normal throw Gamma, in-plane throw tau, slopes s1 and s2.
  static constexpr double kNormalThrowStep = 0.025;
  static constexpr double kTangentialThrowStep = 0.05;
  static constexpr double kSlopeStep = 0.02;
  /// Revision of pointMassDrift's numerics: a saved table records it and a table of another
  /// revision is refused. Raise it with every change of the model's results.
  static constexpr int kModelRevision = 1;

  explicit LocalDriftTable(PointMassSettings settings = {});
  ~LocalDriftTable();
  LocalDriftTable(const LocalDriftTable&) = delete;
  LocalDriftTable& operator=(const LocalDriftTable&) = delete;

  /// The process's table for `settings` (one per distinct settings, created on first use, kept
  /// until exit): the scene layer's local laws share it, so that the runs of one process (a
  /// study, a command with several methods, several feeders of one scene) fill each corner
  /// once. Thread-safe.
  static std::shared_ptr<LocalDriftTable> shared(const PointMassSettings& settings = {});

  /// Threads that run the model at the corners one lookup needs (up to 16 per cell, about 5 ms
  /// each; the caller's thread is one of them): >= 1, 1 runs them in the caller's thread. The
  /// values do not depend on it. Default: the machine's hardware threads, at most 16.
  void setThreads(int threads);
  int threads() const;
  /// The settings every corner of this table was computed with.
  const PointMassSettings& settings() const;
  /// Number of corners computed or added so far.
  std::size_t numCorners() const;
  /// Every corner computed or added so far, ordered by (mu, grid): a snapshot to save.
  std::vector<DriftTableCorner> corners() const;
  /// Adds corners computed with this table's settings and model revision (a saved table);
  /// corners already known are kept. Returns how many were new (counted in
  /// stats().corners_added). Throws std::invalid_argument naming the first bad corner (its
  /// index in `corners`): non-finite drift, mu non-finite or negative, or a grid index beyond
  /// +-1e9.
  std::size_t addCorners(const std::vector<DriftTableCorner>& corners);

  /// The interpolated (V1, V2) at `params` (file comment; units |g_n| / w). Where a corner the
  /// interpolation weights is outside the model, the exact model is tried at the point (valid =
  /// false when that refuses it too).
  PointMassDrift drift(const PointMassParams& params);
  LocalDriftStats stats() const;
  /// Adds to the contact counts of stats() (localDrift and the callers' caches count here).
  void countContacts(std::int64_t contacts, std::int64_t wall_contacts);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The local drift velocity (m/s, world, in the contact plane) at contact point `p` (m, world)
/// with unit normal `n_out` pointing out of the feeder into the part, friction `mu`: the
/// point-mass drift of `vibration` there times vibration.efficiency (walls and steep slopes: file
/// comment). `table` may be null (exact model, milliseconds per call). `wall` (optional) is set
/// when the horizontal surface's drift was used.
Vec3 localDrift(const LocalVibration& vibration, const Vec3& p, const Vec3& n_out, double mu,
                LocalDriftTable* table, bool* wall = nullptr);

}  // namespace rheofeed
