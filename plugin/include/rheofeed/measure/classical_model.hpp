// SPDX-License-Identifier: MIT
/// @file classical_model.hpp
/// The classical single-part model of a vibratory feeder (Redford & Boothroyd; Boothroyd,
/// "Assembly Automation and Product Design", ch. 3; NOTES section 5), as an independent numerical
/// model: it uses neither ODE nor the cone-complementarity solver, so it can serve as the oracle
/// of full-vibration runs and as the quick estimate of a vibration's drift field in calibration.
///
/// ## Model
/// A point part of unit mass on a straight track inclined at alpha; the track vibrates as
/// A sin(w t) along a direction at angle beta to the track (in the vertical plane of the track,
/// lifting the part while it pushes it up-track). In the track frame (x up-track, y along the
/// track's outward normal) and relative to the track:
///   contact:  du/dt = -g sin(alpha) + A w^2 cos(beta) sin(w t) + f,
///             N = g cos(alpha) (1 - Gamma sin(w t))                     (normal force per mass)
///             f = -s mu N while sliding (s = sign u); |f| <= mu N and u = 0 while sticking;
///   flight:   (N would be < 0) d^2x/dt^2 = -g sin(alpha) + A w^2 cos(beta) sin(w t),
///             d^2y/dt^2 = -g cos(alpha) + A w^2 sin(beta) sin(w t),
///   landing:  plastic: the normal relative velocity is killed by a normal impulse P (per mass);
///             the tangential relative velocity is reduced towards 0 by at most mu P.
/// Gamma = A w^2 sin(beta) / (g cos(alpha)) is the throw number.
///
/// ## Integration
/// Every phase has accelerations of the form p + q sin(w t), so the motion is integrated in
/// closed form and only the events are searched: stick/slip transitions and lift-off are roots
/// of p + q sin(w t) (analytic); the end of a slip (u = 0) and landing (y = 0) are bracketed
/// between the analytic roots of their derivatives (where they are monotone) and refined by
/// bisection to rounding. There is no time-step error. Cycles are run from rest on the track
/// until the state at the start of a cycle repeats (period 1 to `max_period` cycles), or the
/// mean is taken over the last `average_cycles` cycles when none does (chaotic hopping).
/// The cost is a few microseconds per cycle.
///
/// ## Closed forms (the tests check the model against them and against the mean speeds of
/// forward sliding, of a hop with unbounded friction and of the one-cycle hop)
///   forward sliding starts at   Gamma_f = (mu + tan alpha) / (mu + cot beta),
///   backward sliding starts at  Gamma_b = (mu - tan alpha) / (cot beta - mu)  (never if
///                               cot beta <= mu),
///   hopping starts at           Gamma = 1.
/// At a fixed throw number the mean speed scales as g / w (so as 1/f) and it never depends on
/// the part's mass.
#pragma once

#include "rheofeed/scene/scene.hpp"
#include "rheofeed/vec3.hpp"

namespace rheofeed::scene {

/// Parameters of the classical model. Angles in radians, SI units.
struct ClassicalParams {
  /// alpha (rad): inclination of the track; > 0 when the conveying direction (up-track, +x)
  /// climbs. |tan(alpha)| < mu is required (otherwise the part slides away without vibration).
  double track_angle = 0.0;
  /// beta (rad): angle between the vibration direction and the track, in (0, pi/2); the
  /// vibration lifts the part while it moves it up-track.
  double vibration_angle = 0.5235987755982988;  // 30 degrees
  /// A (m): peak displacement of the track along the vibration direction (not peak-to-peak), > 0.
  double amplitude = 1e-4;
  /// f (Hz): vibration frequency, > 0; w = 2 pi f.
  double frequency = 50.0;
  /// mu (dimensionless, > 0): Coulomb friction coefficient between part and track.
  double mu = 0.5;
  /// g (m/s^2, > 0): magnitude of gravity.
  double gravity = 9.81;

  /// Hard limit of simulated cycles (>= 2).
  int max_cycles = 2000;
  /// Cycles averaged when no periodic state is found within max_cycles (1 .. max_cycles).
  int average_cycles = 500;
  /// Longest period (cycles) looked for in the steady state (>= 1).
  int max_period = 8;
  /// Two cycle-start states are equal when their relative velocities differ by less than this
  /// fraction of g / w and their gaps by this fraction of g / w^2 (dimensionless, > 0).
  double periodic_tolerance = 1e-10;

  /// Throws std::invalid_argument naming the first bad value (e.g. "mu = -1: must be > 0").
  void validate() const;
};

/// Regime of the steady state, from what happens during the averaged cycles.
enum class ClassicalRegime {
  NoMotion,                ///< the part sticks to the track all the time
  ForwardSliding,          ///< it slides up-track (and sticks), never down-track nor flies
  BackwardSliding,         ///< it slides down-track only (steep track, Gamma_b < Gamma_f)
  ForwardBackwardSliding,  ///< it slides both ways during a cycle, never flies
  Hopping,                 ///< it leaves the track during the cycle (Gamma > 1)
};
/// Printable name of a regime ("no_motion", "forward_sliding", ...).
const char* toString(ClassicalRegime regime);

/// Steady state of the classical model.
struct ClassicalDrift {
  /// Mean conveying speed of the part (m/s) along the track, > 0 up-track (the +x of
  /// ClassicalParams), averaged over whole cycles of the steady state.
  double mean_speed = 0.0;
  /// What the part does during the averaged cycles (flight takes precedence over sliding).
  ClassicalRegime regime = ClassicalRegime::NoMotion;
  double throw_number = 0.0;  ///< Gamma (dimensionless)
  /// eta = mean_speed / (A w cos(beta)) (dimensionless; signed like mean_speed).
  double efficiency = 0.0;
  // Fractions of the time over the averaged cycles (0..1; the four sum to 1):
  double flight_fraction = 0.0;         ///< off the track
  double forward_slip_fraction = 0.0;   ///< sliding up-track (relative velocity > 0)
  double backward_slip_fraction = 0.0;  ///< sliding down-track (relative velocity < 0)
  double stick_fraction = 0.0;          ///< moving with the track
  /// Period of the steady state (cycles); 0 when none was found within max_cycles (chaotic
  /// hopping) and the last average_cycles cycles were averaged instead.
  int period = 0;
  int cycles = 0;  ///< cycles simulated (from rest on the track at phase 0)
  int events = 0;  ///< phase changes (stick/slip/lift-off/landing/slip reversal) simulated
};

/// Runs the classical model to its periodic steady state. Cost: a few microseconds per cycle;
/// measured over 20000 random parameter sets 0.3 ms on average, at most ~25 ms (chaotic hopping,
/// which runs max_cycles). Throws std::invalid_argument on bad parameters.
ClassicalDrift classicalDrift(const ClassicalParams& params);

/// Throw number Gamma = A w^2 sin(beta) / (g cos(alpha)) (dimensionless).
double throwNumber(const ClassicalParams& params);
/// Amplitude A (m) that gives throw number `gamma` with the other parameters of `params`.
double amplitudeForThrowNumber(const ClassicalParams& params, double gamma);
/// Throw number at which forward (up-track) sliding starts: (mu + tan alpha) / (mu + cot beta).
double forwardOnsetThrowNumber(const ClassicalParams& params);
/// Throw number at which backward (down-track) sliding starts: (mu - tan alpha) /
/// (cot beta - mu); +infinity when cot beta <= mu (then, for alpha + beta < 90 deg, a part in
/// contact never starts sliding down-track before it hops).
double backwardOnsetThrowNumber(const ClassicalParams& params);
/// Throw number at which the part starts to hop (normal force reaches zero): 1.
constexpr double kHoppingOnsetThrowNumber = 1.0;
/// Conveying efficiency eta = mean_speed / (A w cos(beta)) (dimensionless).
double conveyingEfficiency(const ClassicalParams& params, double mean_speed);

/// The classical model seen by one part at a point of a vibrating feeder, for calibration.
struct ClassicalTrack {
  ClassicalParams params;  ///< the local parameters (numerical settings left at defaults)
  /// Unit vector (world) of the model's +x: the track direction, flipped if the vibration
  /// pushes the other way, so that the drift velocity is mean_speed * conveying_direction.
  Vec3 conveying_direction;
  // What the planar model ignores; large values mean it does not describe the point:
  double lateral_amplitude = 0.0;  ///< peak vibration displacement across the track (m)
  double lateral_gravity = 0.0;    ///< gravity across the track (m/s^2), e.g. a banked track
};

/// Local classical parameters at `point` (m, world) of a track surface with unit direction
/// `track_direction` and unit outward normal `track_normal` (world, orthogonal), under
/// `gravity` (m/s^2, world), friction `mu`. The local vibration is the first-order
/// displacement amplitude * direction + torsion_amplitude * (axis x (point - axis_origin)) of
/// `vibration` (both in phase; its phase does not change the steady state). Throws
/// std::invalid_argument when the directions are not unit or not orthogonal, gravity does not press
/// the part onto the track, or the local vibration has no normal or no tangential component (no
/// conveying).
ClassicalTrack classicalTrack(const Vibration& vibration, const Vec3& point,
                              const Vec3& track_direction, const Vec3& track_normal,
                              const Vec3& gravity, double mu);

}  // namespace rheofeed::scene
