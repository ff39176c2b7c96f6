// SPDX-License-Identifier: MIT
/// @file simulation.hpp
/// A running scene, whatever the method: ODE + plugin, ODE full vibration, or the reference
/// solver in either mode. All four are built from the same Scene, spawn the same parts (same
/// seed) and report the same part states, so their results can be compared directly.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// State of one part (world frame).
struct PartState {
  Vec3 position;                                     ///< centre of mass (m)
  Vec3 velocity;                                     ///< (m/s)
  Vec3 angular_velocity;                             ///< (rad/s)
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< body to world, row-major
  /// False once the part was taken out of the simulation (below Scene::removal_height, beyond
  /// the scene bounds, non-finite or too fast: RunHealth). Its state is then frozen where it
  /// was removed; a part removed for a non-finite state keeps its last finite state.
  bool active = true;
};

/// Contact totals of the last step: sums over all contacts.
struct ContactTotals {
  int count = 0;
  double normal_impulse = 0;  ///< sum of normal impulses (N s)
  Vec3 impulse;               ///< sum of impulse vectors on the first geom's body (N s, world)
};

/// One part counted by RunHealth as lost or sunk: which, when, where and how.
struct PartEvent {
  int part = -1;        ///< the part's index (spawn order)
  std::string family;   ///< the part's family: its name in the outputs (familyKeys, scene.hpp)
  double time = 0;      ///< simulated time of the step that found it (s); for "inside_fixture":
                        ///< the step it went into the fixture it is in (position and velocity
                        ///< are its state now)
  std::string kind;     ///< the count it went to: "through_fixture", "sunk", "left_feeder",
                        ///< "fell", "out_of_bounds", "nonfinite" or "too_fast"; or
                        ///< "inside_fixture" (RunHealth::inside_fixture_now)
  std::string what;     ///< what happened, as printed on stderr for the first of its kind
  std::string fixture;  ///< the fixture it went into (through_fixture, sunk, inside_fixture),
                        ///< else empty
  Vec3 position;        ///< its centre then (m, world frame)
  Vec3 velocity;        ///< its centre's velocity then (m/s, world frame)
};

/// What a run lost, could not trust or ignored, counted since the start (issue 7: no silent
/// failure). The first occurrence of each kind is reported on stderr (part, time, position);
/// measureRun prints the totals and writes them into the run's JSON and CSV outputs.
///
/// Each part is counted at most once, under the first of these that happened to it (checked
/// after every step in the order non-finite, too fast, through a fixture, left the feeder,
/// below the removal height or beyond the bounds), so partsLost() is a number of parts. A part
/// that goes below Scene::removal_height or beyond the scene bounds after it was beyond the exit
/// plane (Outputs::exit_plane, beyondExitPlane) is an exit, not a loss.
///
/// ## Left the feeder (issue 20)
/// The feeders are the fixtures with a law (FeederLaw::Kind != None). A part's carriers are
/// every feeder plus each fixture that supported it before it first touched a feeder (a hopper
/// floor, an inlet chute). A fixture supports a part when one of their contacts has a normal
/// on the part within 60 degrees of "up" (-gravity; kSupportCosine); a feeder carries a part in
/// any contact. From its first contact with a feeder on, a part that is not beyond the exit
/// plane has left the feeder when
///   (a) the line through its centre along gravity misses the bounding box (at rest, world
///       axes) of every geom of its carriers, each grown by kFootprintRadii bounding radii of
///       the part plus the geom's vibration reach (A + theta R): it is beyond the feeder's
///       footprint, in the air or on a catch floor, having gone over a wall, a rim or a side;
///   (b) or its centre is below the bottom of every carrier geom whose grown box that line
///       meets: it fell under the feeder (over an edge within the boxes' corners, or through a
///       gap), in the air or onto a floor (named when a fixture that is not one of its
///       carriers supports it).
/// A carrier that is a plane, or a mesh that is not loaded, has no footprint (it covers every
/// line). The part is counted (parts_left_feeder), reported with where it crossed, and kept.
/// Parts that never touch a feeder are not followed (a scene without feeders never counts).
///
/// ## Through a fixture, sunk, inside a fixture: the part's anchor
/// These three follow one point of each part, its anchor (partAnchor): the centre of mass, which
/// stays at least the smallest half-size from a fixture surface in contact, or, for a mesh part
/// whose centre of mass lies outside its own solid (a nut's, in its hole: threaded on a pin, its
/// centre is inside the pin, at rest), a point deep inside its material, which stays at least
/// its distance to the part's surface (its clearance) from a fixture surface in contact. An
/// anchor that crosses a fixture surface is a part that tunnelled or sank. Positions reported
/// (PartEvent::position, stderr) are the centre's; the stderr line of a sunk part gives the
/// anchor's where it is not the centre.
///
/// ## Too fast (issue 20)
/// Each part is checked against its own physical speed bound (partPhysicalSpeedBound): its
/// speed with the kinetic energy in translation, sqrt(|v|^2 + w.I w / m), may not exceed
///   kPhysicalSpeedFactor [(1 + e) (|v0| + sqrt(2 |g| max(0, z0 - z))) + (1 + e) V + v_c]
///   + kPhysicalSpeedMargin
/// with |v0| the fastest initial speed of the scene, z0 its highest spawn point (a part may be
/// hit by one that fell from there) and z the part's height now (along -gravity), V
/// the fastest feeder surface point (SceneLimits::surface_speed: belt speed, drift, vibration
/// peak velocity), e the restitution and v_c the push-out speed cap
/// (SolverSettings::max_correcting_velocity). A part above it is counted as too fast and kept;
/// a part above the scene's blow-up bound SceneLimits::speed_bound is also removed.
struct RunHealth {
  static constexpr std::size_t kMaxPartEvents = 1000;
  long steps = 0;  ///< steps taken
  /// Parts removed below Scene::removal_height (or beyond the scene bounds) after being beyond
  /// the exit plane: normal flow.
  int parts_exited = 0;
  /// Parts removed below Scene::removal_height without having been beyond the exit plane and
  /// without having been counted as having left the feeder first (a part that never touched a
  /// feeder and fell off an edge).
  int parts_fell = 0;
  /// Parts whose anchor (rule above: the centre, or a point in a hollow part's material) passed
  /// through a fixture (tunnelling: through a floor or a wall): within one step, or into it and
  /// out on another side, or into it and then out of the scene. They stay in the simulation
  /// until they leave it; each part is counted once. Parts beyond the exit plane are not checked
  /// (they are out of the measurement), except one that crossed it inside a fixture: it is
  /// followed until it comes out, which ends its being inside (parts_inside_fixture) and is not
  /// counted.
  int parts_through_fixture = 0;
  /// Parts that left the feeder without crossing the exit plane: over a wall, a rim or a side,
  /// onto a catch floor or into the air beyond the feeder's footprint (rule above). Kept in
  /// the simulation; counted once.
  int parts_left_feeder = 0;
  /// Parts whose anchor went into a fixture (a penetration deeper than the anchor's clearance:
  /// half the part for its centre) and came back out on the side it entered: not lost, but the
  /// contact did not hold them. Counted once per part; not part of partsLost().
  int parts_sunk = 0;
  /// Parts removed because they left the scene bounds (SceneLimits::bounds) sideways or up.
  int parts_out_of_bounds = 0;
  /// Parts whose anchor is inside a fixture now (went in and has not come out yet): a gauge,
  /// not a count over the run. Part of partsLost() while they are inside (a plate stuck in a
  /// wall at the end of a run is lost; one sunk for a few steps counts only during them).
  int parts_inside_fixture = 0;
  /// Parts whose state (position, velocity, angular velocity, orientation) became NaN or
  /// infinite; they are removed at once.
  int parts_nonfinite = 0;
  /// Parts faster than their physical speed bound (rule above; kept), or than the scene's
  /// blow-up bound SceneLimits::speed_bound (an energy blow-up; removed); counted once each.
  int parts_too_fast = 0;
  /// Reference engine: steps whose true-Coulomb fixed point did not settle and that used the
  /// fallback (0 for ODE), and steps with contacts whose contact solve did not converge
  /// (iteration limit or numerical issue; 0 for ODE, which reports no convergence).
  long coulomb_fallback_steps = 0;
  long solver_unconverged_steps = 0;
  /// Reference engine with NSGS: steps that NSGS left unconverged and that were solved again by
  /// the interior-point fixed point alternating with NSGS (reference::Settings::ipm_rounds), and
  /// those of them that then converged (they are not in solver_unconverged_steps).
  long ipm_second_solve_steps = 0;
  long ipm_converged_steps = 0;
  /// ... and steps NSGS left unconverged on which those rounds could not run
  /// (StepReport::ipm_not_run: too many contacts, or refused by the interior-point method).
  long ipm_not_run_steps = 0;
  /// Reference engine: contacts whose friction the Coulomb fallback had to drop to end its
  /// normal re-solve (StepReport's solve.friction_dropped_contacts), and steps in which a
  /// body's implicit gyroscopic solve did not converge and took a dissipative step instead.
  long friction_dropped_contacts = 0;
  long gyroscopic_fallback_steps = 0;
  /// Settings of the scene this engine does not use although they differ from the
  /// SolverSettings / Material defaults (e.g. "solver.coulomb_iterations = 3: ignored by
  /// ode_rheonomic (...)"), listed and printed once when the simulation is built.
  std::vector<std::string> ignored_settings;
  /// Highest speed (partSpeed: fastest point, |v| + |w| r) of a part seen after any step (m/s),
  /// non-finite states excluded, and the bound it is checked against (m/s,
  /// SceneLimits::speed_bound).
  double max_part_speed = 0;
  double speed_bound = 0;
  /// Highest ratio of a part's energy speed to its physical speed bound seen after any step
  /// (dimensionless; above 1 the part was counted too fast).
  double max_speed_ratio = 0;
  /// Rheonomic runs: feeders driven by the local vibration law (DriftModel local or
  /// local_sampled; 0 when none), and that law's counts summed over them since the start
  /// (MotionLaw::localStats): contacts driven, of which walls (the horizontal surface's drift
  /// used: walls, overhangs, slopes beyond the friction angle), drift table cells filled and
  /// point-mass model runs, this run's share when runs share a table (LocalDriftTable::shared:
  /// a second run of the same vibration in one process runs few or no models). Informative, not
  /// a loss: not part of anything().
  int local_law_feeders = 0;
  LocalDriftStats local_law;
  /// Grid corners the local law's tables already held when the run started (from earlier runs of
  /// the process or a saved table: LocalDriftTable::addCorners).
  std::int64_t local_law_corners_at_start = 0;
  /// The friction law the engine solved ("cone" or "pyramid"; odeFrictionModel for ODE, the
  /// reference engine always "cone"). Recorded in the run JSON.
  std::string friction_model;
  /// The broad phase the engine's collision space is ("hash" or "sweep_and_prune";
  /// SolverSettings::broad_phase, collision_space.hpp). Recorded in the run JSON.
  std::string broad_phase;
  /// ODE runs with speculative contacts (SolverSettings::speculative_contacts): contacts made
  /// across a gap over the run (summed over steps; 0 when off and for the reference engine).
  /// Informative, not a loss.
  long speculative_contacts = 0;
  /// ODE runs with speculative contacts: passes of a part's centre through a static fixture
  /// within a step (a part struck by another during the solve, faster than its sweep before it)
  /// that were stopped: the part put back where it was before the step, its velocity into the
  /// fixture and its spin removed (ContactCollider::stopPassesThroughStaticGeoms; summed over
  /// steps; a part stopped in one step is not stopped in the next, and that pass is counted as
  /// any other). Not a loss. The first is named on stderr.
  long passes_stopped = 0;
  /// ODE runs with warm starts (SolverSettings::warm_start): contacts whose solve started from
  /// the previous step's force of the same contact (summed over steps; 0 when off and for the
  /// reference engine). Informative.
  long warm_started_contacts = 0;
  /// Every part counted above (lost, sunk), in the order found: the first kMaxPartEvents of the
  /// run, and how many more there were. Written to the run JSON (health.part_events). Parts
  /// inside a fixture (a gauge) are not listed here until they are counted otherwise.
  std::vector<PartEvent> part_events;
  long part_events_dropped = 0;
  /// The parts counted in parts_inside_fixture now (a gauge, like it), kind "inside_fixture":
  /// the time they went in (s), their centre and its velocity now (m, m/s, world frame), the
  /// fixture. The run JSON lists them after part_events.
  std::vector<PartEvent> inside_fixture_now;
  /// Parts lost in any way but the exit: fell + through_fixture + left_feeder + out_of_bounds +
  /// nonfinite + too_fast, plus those inside a fixture now.
  int partsLost() const {
    return parts_fell + parts_through_fixture + parts_left_feeder + parts_out_of_bounds +
           parts_nonfinite + parts_too_fast + parts_inside_fixture;
  }
  /// Whether anything was lost, not trusted or ignored.
  bool anything() const {
    return partsLost() > 0 || parts_sunk > 0 || passes_stopped > 0 || coulomb_fallback_steps > 0 ||
           solver_unconverged_steps > 0 || friction_dropped_contacts > 0 ||
           gyroscopic_fallback_steps > 0 || !ignored_settings.empty();
  }
};

/// Axis-aligned box (m, world frame).
struct Bounds {
  Vec3 min, max;
  bool contains(const Vec3& x) const {
    return x.x >= min.x && x.x <= max.x && x.y >= min.y && x.y <= max.y && x.z >= min.z &&
           x.z <= max.z;
  }
};

/// What a scene allows physically, computed once from the scene description (fixtures at
/// rest, spawn regions, laws, gravity). Derivations in simulation.cpp.
struct SceneLimits {
  /// Union of the fixtures' bounding boxes (plane geoms excluded) and the spawn regions (m).
  Bounds extent;
  /// The scene bounds: `extent` expanded by `margin` on every side, except downwards, where
  /// Scene::removal_height takes parts out (its min.z is -infinity).
  Bounds bounds;
  double margin = 0;            ///< (m)
  double removal_height = 0;    ///< Scene::removal_height (m)
  double surface_speed = 0;     ///< fastest feeder surface point (m/s)
  double fall_speed = 0;        ///< free fall from the highest point to the removal height (m/s)
  double initial_speed = 0;     ///< fastest initial part velocity (m/s)
  double correcting_speed = 0;  ///< SolverSettings::max_correcting_velocity (m/s)
  /// initial + fall + 2 surface + correcting: the fastest a part can move (m/s).
  double physical_speed = 0;
  /// kSpeedBoundFactor physical_speed + kSpeedBoundMargin: a part above it is too fast (m/s).
  double speed_bound = 0;
};
/// Factor and margin (m/s) between SceneLimits::physical_speed and speed_bound.
constexpr double kSpeedBoundFactor = 2.0;
constexpr double kSpeedBoundMargin = 1.0;

/// Factor and margin (m/s) of a part's physical speed bound over its case's physics
/// (RunHealth, "Too fast"; partPhysicalSpeedBound).
constexpr double kPhysicalSpeedFactor = 1.25;
constexpr double kPhysicalSpeedMargin = 0.1;
/// A contact supports a part when its normal on the part is within 60 degrees of up (cosine).
constexpr double kSupportCosine = 0.5;
/// The footprint of a carrier geom: its box grown by this many bounding radii of the part
/// (one: the farthest its centre can be while touching it; one more for hops at an edge).
constexpr double kFootprintRadii = 2.0;

/// The physical speed bound (m/s) of a part now at height `height` (m, along -gravity) in a
/// scene with limits `limits`, restitution `restitution`, gravity `g` (m/s^2), fastest initial
/// speed `initial_speed` (m/s) and highest spawn point `spawn_height` (m, along -gravity):
/// RunHealth, "Too fast".
double partPhysicalSpeedBound(const SceneLimits& limits, double restitution, double g,
                              double initial_speed, double spawn_height, double height);
/// The speed (m/s) of a part of mass `mass` (kg) and body-frame inertia `inertia` (kg m^2,
/// row-major 3x3) whose kinetic energy is all in translation: sqrt(|v|^2 + w.I w / m), w the
/// state's angular velocity turned into the body frame.
double energySpeed(const PartState& state, double mass, const double inertia[9]);

/// The limits of `scene` (SI units, world frame). Does not validate the scene.
SceneLimits sceneLimits(const Scene& scene);

/// Whether x (m) is on the exit side of the Outputs exit plane: (x - exit_point) . exit_normal
/// >= 0. False when the scene has no exit plane. Shared by the simulations and the metrics.
bool beyondExitPlane(const Outputs& outputs, const Vec3& x);

/// What the checks after a step say about a part's state (RunHealth), in the order tried.
enum class PartCheck {
  Ok,                  ///< stays
  NonFinite,           ///< a NaN or infinite value in position, velocity, w or rotation
  TooFast,             ///< speed above SceneLimits::speed_bound
  BelowRemovalHeight,  ///< z < Scene::removal_height
  OutOfBounds,         ///< outside SceneLimits::bounds
};
/// Printable name of a PartCheck ("ok", "non-finite", "too fast", ...).
const char* toString(PartCheck check);
/// Speed of the fastest point of a part (m/s): |v| + |w| radius, `radius` (m) its bounding
/// radius about the centre of mass.
double partSpeed(const PartState& state, double radius);
/// Classifies a part's state after a step; `radius` (m) is its bounding radius (partSpeed).
/// Tunnelling, the physical speed bound and leaving the feeder need the part's history and the
/// geometry and are checked by the simulation itself.
PartCheck checkPartState(const PartState& state, const SceneLimits& limits, double radius);

/// The point of a part that the tunnelling checks follow (RunHealth: through a fixture, sunk,
/// inside a fixture) and how far it stays from the part's surface.
struct PartAnchor {
  Vec3 point;            ///< body frame, from the centre of mass (m)
  double clearance = 0;  ///< the least distance from `point` to the part's surface (m)
};
/// The anchor of a part of shape `shape` (body frame: a mesh part's mesh centred on its centre
/// of mass, as drawParts gives it). Its centre of mass, with the smallest half-size as the
/// clearance (a primitive's centre is that far from its surface; a mesh's bounding box's), when
/// that lies inside the part: every primitive, and a mesh whose generalized winding number there
/// is above 1/2. A mesh part whose centre of mass lies outside its own solid (a nut's, in its
/// hole) gets a point deep inside its material instead, with its distance to the nearest
/// triangle as the clearance: of the midpoints between consecutive crossings of rays from the
/// centre along 26 directions (a cube's faces, edges and corners) and towards the centroids of
/// up to 256 of its triangles that lie inside, the farthest from the surface (a ray towards a
/// triangle meets it, so any closed mesh gets one, in any orientation in its file; should none
/// be found, the centre is kept). A part colliding as its convex hull
/// (Shape::collision_mesh_data) is judged by its hull. Runs compute it once per part family at
/// scale 1 and scale it. Derivation in simulation.cpp ("Tunnelling").
PartAnchor partAnchor(const Shape& shape);

/// Where a simulation's steps spend their time, summed over the steps taken while stage timing
/// was on (Simulation::setStageTiming), with the contacts of those steps. For benchmarks
/// (demos/bench/crowd_scale_bench.cpp); off by default, when no clock is read.
///
/// Times are wall-clock seconds (steady clock) of the stages of Simulation::step, in order:
///   ODE (ode_rheonomic, ode_full_vibration)   collision: dSpaceCollide with dCollide of every
///     candidate pair (broad and narrow phase; ContactCollider::collide less `contacts`,
///     so also the emptying of the last step's joint group);
///     contacts: what follows dCollide for the pairs in touch - surface parameters, the
///     plugin's FeederSet::driveContacts, dJointCreateContact and dJointAttach
///     (ContactCollider::setContactTimer); solve: dWorldQuickStep (or dWorldStep), with the
///     kinematic drive of full-vibration feeders;
///   reference engine                           solve: its whole step (collision and contact
///     building included: World::step does not split them); collision and contacts stay 0;
///   both                                       checks: the part checks after the step
///     (RunHealth: limits, tunnelling rays, leaving the feeder), the contact totals and the
///     spawning of the parts that are due.
/// What the run loop (run.hpp) does around step() - observers, metrics, progress - is not in
/// any of them: a caller that times its loop gets it as the remainder.
struct StageTimes {
  long steps = 0;          ///< steps timed
  double collision = 0;    ///< (s)
  double contacts = 0;     ///< (s)
  double solve = 0;        ///< (s)
  double checks = 0;       ///< (s)
  long contact_count = 0;  ///< contact joints (ODE) or contacts (reference), summed over the steps
  /// Constraint rows of those contacts, summed over the steps: ODE's dxJointContact::getInfo1
  /// counts 1 normal row plus 2 friction rows when mu > 0 (no rolling friction here); the
  /// reference's cone has 3 rows per contact.
  long constraint_rows = 0;
};

/// The dynamics settings a simulation applied, as its engine took them (ODE: read back from its
/// world with dWorldGet*; the reference engine: its World's settings), for the record of a run
/// (RunMetrics::solver, the run JSON's "solver"). A setting that does not apply to the engine or
/// to its mode is empty (null in the JSON). The time step is Scene::solver.time_step; the
/// friction law and the broad phase are RunHealth::friction_model and broad_phase.
struct AppliedSolver {
  std::string engine;  ///< "ode" or "reference"; empty until a simulation fills it
  /// How each step's contacts are solved. ODE: "quickstep" (dWorldQuickStep, iterative) or
  /// "world_step" (dWorldStep, ODE's direct solver; SolverSettings::ode_quickstep = false). The
  /// reference engine: "relaxed_ccp" (the convex relaxation: solver.coulomb_iterations = 0),
  /// "coulomb_nsgs" (the true Coulomb law by NSGS, reference::CoulombSolver::Nsgs) or
  /// "coulomb_fixed_point" (relaxed solves inside De Saxce's fixed point).
  std::string mode;
  /// Iteration budget of one step's contact solve. ODE quickstep: its iterations
  /// (dWorldGetQuickStepNumIterations). Reference: the sweeps of NSGS in coulomb_nsgs
  /// (reference::Settings::nsgs, not solver.iterations), else the APGD or PGS iterations of each
  /// relaxed solve (solver.iterations). Empty for dWorldStep (a direct solver).
  std::optional<int> iterations;
  /// Reference: the relative residual (dimensionless) at which a contact solve stops
  /// (solver.tolerance). Empty for ODE: quickstep runs all its iterations.
  std::optional<double> tolerance;
  /// Reference relaxed_ccp and coulomb_fixed_point: the relaxed solver, "apgd" or "pgs"
  /// (solver.apgd). Empty otherwise.
  std::string relaxed_solver;
  /// Reference coulomb_fixed_point: its outer iterations (solver.coulomb_iterations). Empty
  /// otherwise (NSGS solves the Coulomb law itself and only needs the count to be above 0).
  std::optional<int> coulomb_iterations;
  /// Reference coulomb_nsgs: rounds of the interior-point fixed point and NSGS after an
  /// unconverged NSGS solve (reference::Settings::ipm_rounds). Empty otherwise.
  std::optional<int> ipm_rounds;
  /// Whether each step's contact solve starts from the last step's forces: ODE's contacts
  /// (ContactCollider::Settings::warm_start, odeWarmStartsContacts: never with dWorldStep), the
  /// reference's solves (reference::Settings::warm_start).
  bool warm_start = false;
  /// ODE: contacts across gaps (ContactCollider::Settings::speculative). Empty for the reference
  /// engine, which makes contacts only where geoms overlap.
  std::optional<bool> speculative_contacts;
  double erp = 0;                      ///< error reduction parameter (dimensionless, [0, 1])
  double cfm = 0;                      ///< constraint force mixing (ODE's units, >= 0)
  double max_correcting_velocity = 0;  ///< cap on the push-out speed of a penetration (m/s)
  double surface_layer = 0;            ///< penetration left uncorrected (m)
  /// Every contact's surface (one material for all pairs: Scene::material): the friction
  /// coefficient (dimensionless), the restitution (dimensionless) and the approach speed above
  /// which a contact bounces (m/s; 0 in both engines).
  double mu = 0, restitution = 0, bounce_velocity = 0;
};

class Simulation {
 public:
  virtual ~Simulation() = default;
  /// Advance one time step of scene.solver.time_step (s), spawning the parts that are due. After
  /// the step every active part is checked (RunHealth): a part with a non-finite state, faster
  /// than the scene's speed bound, below Scene::removal_height or beyond the scene bounds is
  /// taken out of the simulation and counted; a part whose anchor (partAnchor) crossed a fixture
  /// surface, that left the feeder or that is faster than its physical bound is counted and kept.
  /// Nothing is thrown for a bad state: the first part of each kind is named on stderr, the counts
  /// are in health().
  virtual void step() = 0;
  /// Simulated time (s).
  virtual double time() const = 0;
  /// Parts spawned so far.
  virtual int numParts() const = 0;
  virtual PartState part(int index) const = 0;
  /// Mass of a part (kg).
  virtual double partMass(int index) const = 0;
  /// Contact totals of the last step (impulses of the contacts touching parts).
  virtual ContactTotals contactTotals() const = 0;
  virtual Method method() const = 0;
  /// What the run lost, could not trust or ignored so far.
  virtual const RunHealth& health() const = 0;
  /// The dynamics settings the engine applied (set when the simulation is built).
  virtual const AppliedSolver& appliedSolver() const = 0;
  /// Whether part `index` (0 <= index < numParts()) has been counted lost (RunHealth: through a
  /// fixture, left the feeder, fell, out of bounds, non-finite, too fast), whether or not it is
  /// still in the simulation. Not for a part that only sank and came back, nor for one inside a
  /// fixture now (a gauge: it may still come out).
  virtual bool partLost(int index) const = 0;
  /// Switches stage timing on or off (off at construction); switching it on again keeps the
  /// sums. Timing reads the clock a few times per step and per touching geom pair; it does
  /// not change the results (the same part states, bit for bit).
  virtual void setStageTiming(bool on) = 0;
  /// The stage times summed so far (StageTimes; all zero while timing was never on).
  virtual const StageTimes& stageTimes() const = 0;
};

/// Builds the scene for `method`. Throws std::invalid_argument for an invalid scene or a
/// rheonomic method on a vibrating feeder without calibrated drift. Settings the engine ignores
/// are listed in health().ignored_settings and printed on stderr.
///
/// Determinism: the same scene gives bit-identical part states in every run. ODE's quickstep
/// reorders its constraints with ODE's process-wide random generator (dRandSetSeed); an ODE
/// simulation seeds its own generator state from Scene::seed, swaps it in around each of its
/// steps and swaps the application's state back afterwards, so simulations interleaved in one
/// thread do not disturb each other or the application. Simulations stepped concurrently in
/// several threads do share (and race on) that global.
std::unique_ptr<Simulation> makeSimulation(const Scene& scene, Method method);

/// The friction law an ODE run of a scene with these settings solves: solver.friction when
/// given, else the cone where the linked ODE has it (odeHasFrictionCone: rheofeed's patched
/// ODE) and solver.ode_quickstep is true, else the pyramid. Throws std::invalid_argument naming
/// solver.friction for the cone with ode_quickstep = false or on an ODE without the cone.
FrictionModel odeFrictionModel(const SolverSettings& solver);

/// Below this X = e / (|g| h^2) (e the thinnest part's smallest size, m; h the run's step, s) an
/// ODE quickstep run warm-starts its contacts unless the scene says otherwise: the mass-ratio
/// probe held stacks of unequal parts as well with warm starts as from zero there, and worse at
/// some grid points above (demos/results/crowd_leaks.md, sections 5 and 11).
constexpr double kWarmStartMaxX = 50;

/// Whether an ODE run of this scene (solver.time_step its run step) warm-starts its contacts
/// (ContactCollider::Settings::warm_start). Never without ode_quickstep (dWorldStep has no use
/// for it). solver.warm_start when given; unset, on where the linked ODE has them
/// (odeHasContactWarmStart: rheofeed's patched ODE) and X = e / (|g| h^2) < kWarmStartMaxX
/// (rheonomic steps of millimetre parts: the main demo's X is 5.1 at h = 0.01 s; full-vibration
/// steps are far above). At X = 5 they take a heap's drift error at 30 iterations from +10 % to
/// +5 % at 500 parts and cost no more; at 2000 parts they sank 1 part against 9 (crowd_leaks.md,
/// section 11).
bool odeWarmStartsContacts(const Scene& scene);
/// The same at another step `time_step` (s; the scene check's search for a safe step).
bool odeWarmStartsContacts(const Scene& scene, double time_step);

}  // namespace rheofeed::scene
