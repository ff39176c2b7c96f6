// SPDX-License-Identifier: MIT
/// @file stability_cases.hpp
/// The stability matrix (issue 7): stiff and extreme scenes built in code, and one run of a scene
/// measured from the part states alone, independently of the engine's own counters.
///
/// ## Conventions of every case
/// Gravity -9.81 m/s^2 along z; the top of the floor (or belt, table, track) at z = 0 at rest;
/// SI units, world frame. A case lists the surfaces whose penetration it measures (the floor and
/// the walls that matter) and the box outside of which a part is lost.
///
/// ## What a run measures (RunRecord), from the part states after every step
///  - non-finite: any NaN or infinity in position, velocity, angular velocity or rotation;
///  - maximum speed |v| of a part's centre of mass, against the case's physical bound
///      v_bound = (1 + e) v_surface + v_correct + sqrt(|v0|^2 + 2 g H)
///    where v_surface is the fastest surface of the case (belt speed, w r at the table's rim,
///    the vibration's peak velocity A 2 pi f plus torsion), e the restitution, v_correct the
///    solver's cap on penetration push-out (SolverSettings::max_correcting_velocity: parts
///    spawned overlapping leave at up to that speed), v0 the spawn velocity and H the highest
///    spawn height above the lowest point a part can reach on the floor;
///  - energy growth: max over time of E(t) / E_budget, with E = sum over the parts still in the
///    scene of 1/2 m |v|^2 + 1/2 w.I w + m g (z - z_ref) (z_ref: the lowest spawn height minus the
///    largest part size, or 0 if lower, so that E >= 0), and
///      E_budget = E(0) + sum_i m_i ((1 + e)^2 v_surface^2 + v_correct^2)
///    i.e. the initial energy plus, per part, twice the kinetic energy of the fastest surface
///    contact it can get (translation plus as much in rotation) and of the push-out;
///  - maximum penetration: the deepest part point behind a measured surface (from the part's
///    pose and shape), for parts whose centre is still in front of it (m); and the excess
///    penetration relative to the part's thinnest dimension, i.e. depth minus what the scene or
///    a discrete step puts there unavoidably: the part's depth when it spawned, and the landing
///    overshoot h (approach speed before the step + in full vibration the surface speed). A
///    full-vibration floor is taken at its lowest position during the step;
///  - parts lost, counted once each: removed by the engine (below Scene::removal_height),
///    non-finite, centre behind a measured surface by more than the part's size at the end of
///    the run (tunnelled; a part pushed back out is only a deep penetration), or centre outside
///    the case's bounds box; compared with Simulation::health().partsLost().
#pragma once

#include <string>
#include <vector>

#include "rheofeed/scene/scene.hpp"
#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::stability {

/// A plane face of a fixture whose penetration is measured: points p with normal . p = offset
/// are on it, the solid is on the side normal . p < offset. Only parts whose centre lies in the
/// region (axis-aligned box, or a vertical cylinder about `disc_centre` when disc_radius > 0)
/// are measured against it.
struct Surface {
  std::string name;
  Vec3 normal{0, 0, 1};                                          ///< unit outward normal (world)
  double offset = 0;                                             ///< (m)
  Vec3 region_min{-1e9, -1e9, -1e9}, region_max{1e9, 1e9, 1e9};  ///< (m, world)
  Vec3 disc_centre;        ///< (m) region as a vertical cylinder when disc_radius > 0
  double disc_radius = 0;  ///< (m)
  /// Index of the fixture that carries it: a vibrating fixture moves it in full-vibration runs.
  int fixture = -1;
};

/// One case of the matrix.
struct StabilityCase {
  std::string name;
  std::string covers;  ///< what extreme it exercises ("mass ratio 1e4, light under heavy")
  std::string note;    ///< expected hazard, in numbers, written into the row's cause
  scene::Scene scene;  ///< rheonomic settings (time step, duration); calibrated drift if vibrating
  /// Full vibration (only when the scene vibrates): steps per vibration cycle and duration (s).
  int fv_steps_per_cycle = 100;
  double fv_duration = 0.5;
  std::vector<Surface> surfaces;                     ///< the floor first
  Vec3 bounds_min{-1, -1, -1}, bounds_max{1, 1, 1};  ///< outside: the part is lost (m, world)
  /// Fastest surface speed of the case (m/s): belt, rim w r, vibration peak velocity.
  double surface_speed = 0;
  bool quick = false;  ///< runs in seconds (all methods): part of the ctest reduced matrix
  /// The scene is expected to be refused at construction (e.g. overlapping parts at t = 0).
  bool expect_refusal = false;
  /// Parts leave the scene by the physics of the case itself (a turntable faster than its
  /// friction holds them, w^2 r > mu g): their loss is the right answer, and is checked to be
  /// counted and reported like any other, but needs no scene-check warning.
  bool expect_losses = false;
};

/// All cases of the matrix (at least 60), deterministic.
std::vector<StabilityCase> stabilityCases();

/// The methods a case runs through: both rheonomic ones, plus both full-vibration ones when the
/// scene vibrates.
std::vector<scene::Method> methodsFor(const StabilityCase& c);

/// The scene a method runs: the case's scene, or for full vibration the same with
/// h = 1 / (f fv_steps_per_cycle) and fv_duration.
scene::Scene sceneFor(const StabilityCase& c, scene::Method method);

/// Pass/fail thresholds (the reasons are in stability_cases.cpp).
struct Limits {
  double speed_slack = 1.2;        ///< max speed may reach speed_slack * v_bound
  double energy_slack = 1.1;       ///< max E may reach energy_slack * E_budget
  double penetration_ratio = 0.2;  ///< excess penetration / thinnest part dimension
};

/// One run of a case through one method, measured from the part states.
struct RunRecord {
  std::string case_name, method, covers;
  double time_step = 0;            ///< (s)
  long steps = 0;                  ///< steps taken
  double duration = 0;             ///< simulated (s)
  int parts = 0;                   ///< parts spawned
  std::string status = "not run";  ///< finished / refused (at construction) / aborted (mid-run)
  std::string message;             ///< the exception's message when refused or aborted
  double wall_seconds = 0;
  int nonfinite_parts = 0;       ///< parts with a NaN/inf anywhere in their state, ever
  std::string nonfinite_where;   ///< first one: which field, which part, when
  double max_speed = 0;          ///< (m/s)
  double speed_bound = 0;        ///< v_bound (m/s)
  double energy_budget = 0;      ///< E_budget (J)
  double energy_ratio = 0;       ///< max E(t) / E_budget
  double max_penetration = 0;    ///< (m)
  double penetration_ratio = 0;  ///< max over parts of penetration / thinnest dimension
  std::string penetration_where;
  int lost_measured = 0;  ///< our count
  std::string lost_how;   ///< "3 through floor, 1 out of bounds, 2 removed"
  // What the engine reported (Simulation::health()):
  int lost_reported = 0;  ///< RunHealth::partsLost()
  int parts_fell = 0, parts_through_fixture = 0, parts_out_of_bounds = 0, parts_nonfinite = 0,
      parts_too_fast = 0;
  long fallback_steps = 0, unconverged_steps = 0;
  std::string ignored_settings;  ///< joined with "; "
  /// Warnings of the scene check (checkScene) for this scene and method, their kinds and the
  /// safe settings they name (joined with "; ").
  int check_warnings = 0;
  std::string hazards, safe_settings;
  /// The verdict: "pass" (within every limit), "warned" (beyond a physical limit - penetration
  /// or energy - that the scene check named before the run: a known, documented limit), "FAIL"
  /// (a silent failure: NaN, a blow-up past the speed bound, a lost part the run did not
  /// report, an abort or an unexpected refusal, or a physical limit nobody warned about).
  std::string verdict = "FAIL";
  bool pass = false;  ///< verdict != "FAIL": nothing went wrong silently
  std::string cause;  ///< why it is not "pass" (and the case's note)
};

/// Runs `c` through `method` and measures it; never throws (a refusal is a record).
RunRecord runCase(const StabilityCase& c, scene::Method method, const Limits& limits = {});

/// CSV header and one row (RFC 4180 quoting), and a one-line serialisation for child processes.
std::string csvHeader();
std::string csvRow(const RunRecord& r);
/// Parses a csvRow line back (for runs made in child processes). Throws on a malformed line.
RunRecord parseCsvRow(const std::string& line);

/// Markdown report: a table of all rows and a summary of the failures.
std::string markdownReport(const std::vector<RunRecord>& records, const std::string& header);

}  // namespace rheofeed::stability
