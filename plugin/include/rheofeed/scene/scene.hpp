// SPDX-License-Identifier: MIT
/// @file scene.hpp
/// One scene description that drives every method: ODE + plugin (rheonomic), ODE full
/// vibration, the reference solver rheonomic, the reference solver full vibration.
///
/// A scene is fixtures (static geometry, some of them feeders with a motion law), parts (shapes
/// drawn from size distributions, spawned at t = 0 or at a flow rate), one material, solver
/// settings and a duration. Units: SI (m, s, kg, m/s, rad/s, Hz); vectors in the world frame;
/// gravity along -z unless the scene says otherwise.
///
/// Limits (Scene::validate; the reasons are in src/scene/scene_limits.hpp): every coordinate
/// (geom positions, plane offsets, spawn bounds, axis origins, exit point, removal height) in
/// [-1e6, 1e6] m (ODE's hash space breaks near 2.2e9 m); every size (box edges, radii, lengths,
/// scaled mesh extents, size distributions) in [1e-5, 1e3] m and densities in [1e-3, 1e6] kg/m^3
/// (mass and inertia stay normal doubles); speeds <= 1e3 m/s and angular speeds <= 1e4 rad/s
/// (the contact's motion1 and fdir1 stay finite); at most 4096 geoms (fixture geoms plus
/// parts: ODE's hash space keeps an n x n bit matrix on the stack).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rheofeed/collision_space.hpp"
#include "rheofeed/friction_model.hpp"
#include "rheofeed/motion_law.hpp"
#include "rheofeed/vec3.hpp"

namespace rheofeed::scene {

/// A triangle mesh in its own frame (m): vertices and counter-clockwise (outward) triangles.
struct TriangleMesh {
  std::vector<double> vertices;  ///< x, y, z per vertex (m)
  std::vector<int> triangles;    ///< three vertex indices per triangle
  std::string source;            ///< where it came from (file path), for messages
};

/// A collision shape. Sizes in metres; cylinders and capsules lie along their local z axis.
struct Shape {
  enum class Kind { Box, Sphere, Cylinder, Capsule, Plane, Mesh };
  Kind kind = Kind::Box;
  Vec3 size{0.1, 0.1, 0.1};  ///< Box: edge lengths (m, each in [1e-5, 1e3])
  double radius = 0.05;      ///< Sphere, Cylinder, Capsule (m, in [1e-5, 1e3])
  double length = 0.1;       ///< Cylinder, Capsule: length along local z (m, in [1e-5, 1e3])
  /// Plane: unit normal (world) and offset d (m, in [-1e6, 1e6]): points p with
  /// normal . p = d. Static only.
  Vec3 plane_normal{0, 0, 1};
  double plane_offset = 0;
  std::string mesh;  ///< Mesh: file path (any format assimp reads)
  /// Mesh: scale applied to the file's coordinates (> 0); the scaled mesh must span
  /// [1e-5, 1e3] m and stay within [-1e6, 1e6] m once placed.
  double mesh_scale = 1.0;
  /// Mesh: the loaded triangles (already scaled), filled by the scene loader (scene_io.hpp);
  /// geoms are built from it, so a scene without meshes never loads any.
  std::shared_ptr<const TriangleMesh> mesh_data;
  /// Mesh parts colliding as their convex hull (PartSpec::Collision::ConvexHull): the hull,
  /// scaled as mesh_data, which the engines collide instead of it; null: they collide
  /// mesh_data. Drawings and mass properties always use mesh_data.
  std::shared_ptr<const TriangleMesh> collision_mesh_data;
};

/// Printable name of a shape kind ("box", "sphere", ...).
const char* toString(Shape::Kind kind);

/// A real vibration of a feeder (the conventional method): the feeder's kinematic body moves as
///   x(t) = amplitude sin(2 pi frequency t + phase) direction            (m)
///   theta(t) = torsion_amplitude sin(2 pi frequency t + phase)          (rad, about the axis)
/// A screw motion (bowl feeders) has both: vertical translation along the axis and torsion.
struct Vibration {
  /// Peak displacement (m, in [0, 1e3], not peak-to-peak); peak speed 2 pi frequency
  /// amplitude <= 1e3 m/s.
  double amplitude = 0;
  double frequency = 0;     ///< (Hz, in (0, 1e5])
  Vec3 direction{1, 0, 0};  ///< unit translation direction (world)
  double phase = 0;         ///< (rad, finite)
  /// Peak rotation about the axis (rad, in [0, pi]); peak angular speed 2 pi frequency
  /// torsion_amplitude <= 1e4 rad/s. Amplitude or torsion amplitude must be > 0.
  double torsion_amplitude = 0;
  Vec3 axis_origin{0, 0, 0};  ///< a point of the torsion axis (m, each coordinate in [-1e6, 1e6])
  Vec3 axis_direction{0, 0, 1};  ///< unit torsion axis
  /// Pose of the vibrating feeder at time t relative to its rest pose (apply to the rest pose).
  Pose displacement(double t) const;
  bool isZero() const { return amplitude == 0 && torsion_amplitude == 0; }
};

/// How a rheonomic run replaces a feeder's vibration (FeederLaw::Kind::Vibration; issue 8).
enum class DriftModel {
  /// The local vibration law (MotionLaw::localVibration, vibration_drift.hpp): at each contact
  /// the point-mass drift of the feeder's real vibration at that point, for that contact's
  /// normal, the scene's gravity and the material's mu. No sampling run. The default.
  Local,
  /// The local law times the part family's own efficiency (FeederLaw::efficiency), measured by
  /// a short sampling run (calibration.hpp, calibrateEfficiency).
  LocalSampled,
  /// One constant drift twist per feeder (FeederLaw::calibrated_drift), from a sampling run or
  /// the classical model: exact only where it was calibrated (issue 8).
  CalibratedDrift,
};
/// Printable name, as in scene files: "local", "local_sampled", "calibrated_drift".
const char* toString(DriftModel model);
/// The model named `name` (as toString writes it); false if there is none.
bool parseDriftModel(const std::string& name, DriftModel& model);

/// What a feeder's calibrated drift or efficiency factors were measured for: the vibration and
/// the scene's gravity and friction at the time, and what else the measurement depended on
/// (calibrationBasis sets it; withCalibration, withEfficiency call it; scene files keep it as
/// "calibrated_for"). A calibration is stale when the scene's now differ (staleCalibration): it
/// would answer for another feeder, or for other parts.
struct CalibrationBasis {
  Vibration vibration;
  Vec3 gravity{0, 0, -9.81};  ///< (m/s^2, world)
  double mu = 0;              ///< the material's friction coefficient (dimensionless)
  /// How it was measured: "classical" (the classical single-part model), "sampling" (a
  /// full-vibration sample run), "" (not known). A stale calibration is redone the same way.
  std::string method;
  /// A straight track's (no torsion): the direction the drift was measured along (unit,
  /// world; Outputs::conveying_direction then). Unset: not recorded (a file written before it
  /// was kept, or a screw, whose drift turns about its axis), not compared.
  std::optional<Vec3> conveying_direction;
  /// A classical calibration of a screw: the point whose track the model took (m, world; the
  /// first part family's spawn-region centre); its distance from the axis is compared. Unset:
  /// not recorded.
  std::optional<Vec3> track_point;
  /// A sampling calibration's: the material's restitution (in [0, 1]), and the digests (16 hex
  /// digits) of each part family (partDigest, in the order of Scene::parts) and of each
  /// fixture's geometry (fixtureDigest, in the order of Scene::fixtures) that the sample runs
  /// ran. A calibrated drift is compared on the first family only (its sample run's family),
  /// efficiency factors on every family; "" marks a family whose factor this record did not
  /// measure (withEfficiency after a change of the feeder). Unset or empty: not recorded (a
  /// classical calibration, or a file written before they were kept), not compared.
  std::optional<double> restitution;
  std::vector<std::string> part_digests;
  std::vector<std::string> fixture_digests;
};

/// Largest part efficiency factor (dimensionless), as FeederSet::setPartEfficiency accepts.
constexpr double kMaxPartEfficiency = kMaxEfficiency;

/// How a feeder moves.
struct FeederLaw {
  enum class Kind {
    None,       ///< not a feeder: plain static geometry
    Drift,      ///< a drift field: rheonomic twist, the homogenised transport velocity itself
    Belt,       ///< a belt of speed `belt_speed` along `belt_direction`
    Vibration,  ///< a real vibration; rheonomic methods use its drift model (drift_model)
  };
  Kind kind = Kind::None;
  /// Vibration: what rheonomic runs use instead of it (default: the local law). Ignored by
  /// other kinds and by full-vibration runs.
  DriftModel drift_model = DriftModel::Local;
  /// Drift: v (m/s, |v| <= 1e3), w (rad/s, |w| <= 1e4) about origin (m, in [-1e6, 1e6]),
  /// world frame.
  Twist drift;
  Vec3 belt_direction{1, 0, 0};
  double belt_speed = 0;  ///< (m/s, in [-1e3, 1e3])
  Vibration vibration;    ///< Vibration
  /// Vibration: the drift field that replaces it in rheonomic runs (from calibration). Set by
  /// the calibration step or given by the scene ("vibration, calibrated"); limits as drift.
  bool has_calibrated_drift = false;
  Twist calibrated_drift;
  /// Vibration with DriftModel::LocalSampled: the part families' own efficiency under the
  /// local law, indexed like Scene::parts (dimensionless, each in [0, kMaxPartEfficiency]; 1 =
  /// a point mass). Empty: not measured yet (a rheonomic run then refuses the scene; the demos
  /// calibrate first). Must be empty for the other drift models. A rheonomic run applies the
  /// factor of family k to every contact of its parts with every local-law feeder
  /// (FeederSet::setPartEfficiency is per body), so all local-law feeders of a scene must
  /// agree on each family's factor (a `local` feeder counts as 1); Scene::validate refuses
  /// feeders that disagree.
  std::vector<double> efficiency;
  /// What calibrated_drift and efficiency were measured for (CalibrationBasis); none: not
  /// known (a drift given by hand, or a scene file written before it was kept), never stale.
  std::optional<CalibrationBasis> calibrated_for;
};

/// A fixture: static geometry, optionally a feeder. All its geoms move together in a full
/// vibration run.
struct Fixture {
  std::string name;
  struct Geom {
    Shape shape;
    Pose pose;  ///< pose of the geom in the world (at rest)
  };
  std::vector<Geom> geoms;
  FeederLaw law;
};

/// A normally distributed size, truncated to [min, max] and to the size limits [1e-5, 1e3] m
/// (m; for a mesh part the scale factor, truncated so that the scaled mesh stays within the
/// size limits). Requires 0 <= min <= mean <= max, stddev >= 0 (<= 1e3 m for a size) and the
/// mean within the size limits (a mesh part: mean times the mesh's bounding radius).
struct Distribution {
  double mean = 0.01;
  double stddev = 0;
  double min = 0;
  double max = 1e300;
};

/// How many size distributions a part of this shape has: box 3 (x, y, z edges), cylinder and
/// capsule 2 (radius, length), sphere and mesh 1 (radius; mesh scale).
int partSizeCount(Shape::Kind kind);

/// A family of parts.
struct PartSpec {
  std::string name = "parts";
  Shape::Kind shape = Shape::Kind::Box;
  Distribution size[3];  ///< Box: x, y, z edges; Sphere: [0] radius; Cyl/Capsule: [0] r, [1] length
  std::string mesh;      ///< Mesh parts: file (assimp); size[0] is the scale factor
  /// Mesh parts: loaded triangles at scale 1, centred on their centre of mass (scene loader).
  std::shared_ptr<const TriangleMesh> mesh_data;
  /// Mesh parts: what the engines collide. Mesh: the mesh itself. ConvexHull: its convex hull
  /// (convexHull, mesh.hpp; JSON "collision": "convex_hull"): holes and recesses filled, coplanar
  /// faces merged, so ODE's trimesh-trimesh test has far fewer triangles to try (an M6 nut: 20
  /// instead of 192); mass and inertia still come from the mesh. For parts whose recesses
  /// nothing in the scene can enter.
  enum class Collision { Mesh, ConvexHull };
  Collision collision = Collision::Mesh;
  /// ConvexHull: the hull of mesh_data (scale 1, the same frame), filled by the scene loader.
  std::shared_ptr<const TriangleMesh> collision_mesh_data;
  double density = 7800;  ///< (kg/m^3, in [1e-3, 1e6])
  /// Spawn region, axis-aligned box (m, world; coordinates in [-1e6, 1e6], spawn_min <=
  /// spawn_max per axis).
  Vec3 spawn_min, spawn_max;
  bool random_orientation = false;
  /// Total number of parts (>= 1); all counts plus the fixture geoms at most 4096.
  int count = 1;
  double rate = 0;        ///< parts per second (finite, >= 0); 0: all at t = 0
  Vec3 initial_velocity;  ///< (m/s, |v| <= 1e3)
};

/// Contact material (one for all pairs).
struct Material {
  double mu = 0.5;           ///< friction coefficient (in [0, 10])
  double restitution = 0.0;  ///< (in [0, 1])
};

/// The dynamics engine and its settings.
struct SolverSettings {
  /// (s, in [1e-6, 1], <= Scene::duration; duration / time_step <= 1e9 steps)
  double time_step = 0.01;
  int iterations = 50;        ///< ODE quickstep iterations or CCP iteration budget ([1, 1e6])
  bool ode_quickstep = true;  ///< ODE: dWorldQuickStep (true) or dWorldStep (Dantzig)
  double erp = 0.2;           ///< ODE and reference (in [0, 1])
  double cfm = 1e-5;          ///< ODE and reference (ODE's units, finite, >= 0)
  double tolerance = 1e-6;    ///< CCP residual tolerance (finite, > 0)
  bool apgd = true;           ///< CCP: APGD (true) or PGS
  /// Reference solver: outer fixed-point iterations of the true Coulomb law ([0, 1e6]). 0 solves
  /// the relaxed CCP, whose sliding contacts separate at mu |u_t| (parts hop off a sliding
  /// surface: +16 % slip at 400 steps per cycle on a vibrated plate, tests/reference).
  int coulomb_iterations = 10;
  /// Cap on the speed at which a penetration is pushed out (m/s, in (0, 1e3]), ODE's
  /// dWorldSetContactMaxCorrectingVel, mirrored by the reference. Without it ERP depth / h
  /// becomes a launch speed at small h (0.2 x 5 mm / 0.1 ms = 10 m/s).
  double max_correcting_velocity = 0.5;
  /// Penetration depth (m, in [0, 1e3]) left uncorrected by ERP, ODE's
  /// dWorldSetContactSurfaceLayer, mirrored by the reference. Without it every landing on a
  /// vibrating surface is followed by an ERP push that can lock a part into a chattering
  /// orbit of its own (parts at 0.26x or 1.3x the drift of their neighbours, depending on ERP;
  /// 1e-4 m removes it in the trough scenes of builtin_scenes.hpp).
  double surface_layer = 0.0;
  /// Time step (s) of the rheonomic runs (ode_rheonomic, reference_rheonomic) when it differs
  /// from time_step, which then is the full-vibration step of a scene with a vibrating feeder
  /// (a rheonomic run of such a scene takes tens to hundreds of times larger steps). 0: the
  /// rheonomic runs take time_step too. Else in [1e-6, 1], with the duration limits of
  /// time_step. Read by the runners (the `rheofeed` command), not by makeSimulation, which
  /// always steps with time_step.
  double rheonomic_time_step = 0;
  /// ODE's friction law (friction_model.hpp; JSON "cone" or "pyramid"). Unset: the cone where
  /// the linked ODE has it (rheofeed's patched ODE) and ode_quickstep is true, else the pyramid
  /// (simulation.hpp, odeFrictionModel). Asking for the cone with ode_quickstep = false is
  /// refused by validate(), on a stock ODE by the ODE simulation. The reference engine always
  /// solves the cone (a pyramid asked of it is an ignored setting).
  std::optional<FrictionModel> friction;
  /// ODE runs: speculative contacts (contact_collider.hpp, ContactCollider::Settings::
  /// speculative): a part that would move more than a quarter of its smallest half extent in a
  /// step gets contacts across the gap to whatever its leading points reach within the step,
  /// so that it lands on a fixture or a part instead of sinking into it or passing through.
  /// Unset: on (JSON true or false sets it). The reference engine makes contacts only where
  /// geoms overlap; a scene that sets it true says so there (an ignored setting).
  std::optional<bool> speculative_contacts;
  /// ODE runs with quickstep: warm starts (contact_collider.hpp, ContactCollider::Settings::
  /// warm_start): each contact's solve starts from the force the same contact applied in the
  /// previous step, so that a heap's weight is carried over instead of rebuilt from zero by the
  /// iterations. Unset: on for rheonomic steps of small parts (X = e / (|g| h^2) below 50), off
  /// for fine steps (odeWarmStartsContacts, simulation.hpp, says the rule, what it gains and
  /// costs). Needs rheofeed's patched ODE (patches/0005): true on a stock ODE is refused by the
  /// ODE simulation;
  /// true with ode_quickstep = false (a direct solver) and in the reference engine is an
  /// ignored setting.
  std::optional<bool> warm_start;
  /// Both engines' broad phase (collision_space.hpp; JSON "hash" or "sweep_and_prune"). Unset:
  /// the hash space where the linked ODE has rheofeed's fix (patches/0004), else
  /// sweep-and-prune (createCollisionSpace). Both pair every overlapping pair; sweep-and-prune
  /// costs 10-25 % less per step in crowds of 1000-2000 parts (demos/results/crowd_leaks.md,
  /// section 6). The scene check's mass-ratio limits were measured with the hash space. "hash"
  /// on an ODE without the fix is refused by the simulation.
  std::optional<BroadPhase> broad_phase;
};

/// The four methods.
enum class Method {
  OdeRheonomic,            ///< ODE + plugin, stationary feeders
  OdeFullVibration,        ///< ODE, feeders on kinematic bodies that really vibrate
  ReferenceRheonomic,      ///< reference CCP solver, stationary feeders
  ReferenceFullVibration,  ///< reference CCP solver, vibrating feeders
};
const char* toString(Method method);
bool isFullVibration(Method method);

/// What to measure.
struct Outputs {
  Vec3 conveying_direction{1, 0, 0};  ///< unit direction of the drift metric
  /// Measure the drift as an angular velocity (rad/s) about an axis (bowls, turntables)
  /// instead of a velocity along conveying_direction.
  bool angular_drift = false;
  Vec3 axis_origin{0, 0, 0};     ///< a point of the drift axis (m, in [-1e6, 1e6])
  Vec3 axis_direction{0, 0, 1};  ///< unit drift axis; positive drift turns by the right hand
  bool exit_plane = false;       ///< count parts crossing the plane
  Vec3 exit_point;               ///< a point of the exit plane (m, in [-1e6, 1e6])
  Vec3 exit_normal{1, 0, 0};     ///< unit normal of the exit plane, pointing out
  /// (s) metric sampling period, in (0, duration]: a run must take at least one sample.
  double sample_interval = 0.01;
  /// (s) excluded from the mean drift, in [0, duration - time_step]: a drift must be
  /// measured after it.
  double warmup = 0.0;
};

struct Scene {
  std::string name = "scene";
  /// The file loadScene read the scene from (absolute, normalised); empty for a scene built in
  /// code or parsed from text. Not part of the scene file (toJson does not write it): a run
  /// reports it (RunMetrics::scene_file).
  std::string source_file;
  Vec3 gravity{0, 0, -9.81};  ///< (m/s^2, world, |g| <= 1e3)
  std::vector<Fixture> fixtures;
  std::vector<PartSpec> parts;
  Material material;
  SolverSettings solver;
  /// Parts that fall below this height (m) have left the scene: they are removed from the
  /// simulation (no more contacts or motion) and from the drift metrics. In [-1e6, 1e6].
  double removal_height = -2.0;
  /// (s, >= solver.time_step; duration / time_step <= 1e9 steps)
  double duration = 1.0;
  std::uint64_t seed = 1;
  Outputs outputs;
  /// A drift table file (scene/drift_table_file.hpp: the local vibration law's point-mass
  /// results), its name relative to the scene file's folder; empty: none. Read when the scene is
  /// loaded from a file, when the name becomes absolute; every rheonomic run of a feeder on the
  /// local law adds its corners to the process's table (LocalDriftTable::shared), so that even a
  /// scene's first run skips those model runs, with the same drifts bit for bit. Corners the file
  /// lacks are computed as without it. A malformed table (or one of another model revision or
  /// settings) is an error naming "drift_table", the file and its problem; a table that is not
  /// there (a scene file copied elsewhere) is not: drift_table_problem says so, and the runs that
  /// use the local law report it as an ignored setting (stderr and the run's JSON). Written by
  /// `rheofeed run SCENE --drift-table FILE`; the shipped local-law scenes name theirs.
  std::string drift_table;
  /// Why drift_table was not read (the file is not there), or empty.
  std::string drift_table_problem;
  /// The corners read from drift_table (null until the scene is loaded from a file).
  std::shared_ptr<const std::vector<DriftTableCorner>> drift_table_corners;

  /// Throws std::invalid_argument naming the path of the first bad value, the value and the
  /// allowed range (e.g. "parts[0].density = 1e+300: must be a finite number in [0.001, 1e+06]
  /// kg/m^3"): every limit stated on the fields above.
  void validate() const;
  bool hasMeshes() const;
  bool hasVibration() const;
};

/// The local vibration of `vibration` for the local law (vibration_drift.hpp): translation
/// amplitude vector amplitude * direction (m), torsion_amplitude (rad) about the axis, the
/// scene's `gravity` (m/s^2, world) and the material's `mu` (used where a caller passes no
/// contact mu), efficiency 1 (part families get theirs per body: partEfficiencies).
LocalVibration localVibration(const Vibration& vibration, const Vec3& gravity, double mu);

/// The motion law a rheonomic method uses for fixture `fixture` of `scene` (None: a stationary
/// surface). A vibrating fixture gives, by its drift model, the local law
/// (MotionLaw::localVibration of localVibration(vibration, scene.gravity, scene.material.mu),
/// on the process's shared drift table LocalDriftTable::shared()) or its calibrated drift twist.
/// Throws std::invalid_argument naming the fixture when the index is out of range, a
/// calibrated_drift model has no calibrated drift, a local_sampled model has no efficiency
/// factors ("run the calibration first"), or the calibration is stale (staleCalibration).
MotionLaw rheonomicLaw(const Scene& scene, int fixture);

/// True when `law` is a vibration whose drift model (DriftModel) lacks its data for a rheonomic
/// run: calibrated_drift without the drift, local_sampled without the efficiency factors (the
/// local law needs none). rheonomicLaw refuses such a law.
bool lacksCalibration(const FeederLaw& law);

/// The basis of a calibration of fixture `fixture` (a vibrating feeder) of `scene` measured by
/// `method` ("classical" or "sampling"): the vibration, gravity and mu; a straight track's
/// conveying direction; a classical screw calibration's track point; a sampling calibration's
/// restitution and the digests of every part family and fixture. Throws std::out_of_range for a
/// fixture index out of range.
CalibrationBasis calibrationBasis(const Scene& scene, int fixture, const std::string& method);

/// A digest (16 hex digits, 64-bit FNV-1a) of what a sampling calibration's run takes from a
/// part family: its shape, size distributions, mesh (the loaded triangles, not the file's path),
/// collision shape, density, spawn region, orientation and initial velocity (not its name,
/// count or rate, nor the solver's settings). Numbers are taken to 9 significant digits
/// (locale-independent), so that a scene read back from its file gives the same digest. A mesh
/// is hashed as loaded (after assimp's processing and centring): another assimp may change it,
/// which makes its calibrations stale, said.
std::string partDigest(const PartSpec& family);
/// A digest, as partDigest, of a fixture's geoms: shapes, sizes, meshes and poses at rest (not
/// its name or law).
std::string fixtureDigest(const Fixture& fixture);

/// Why the calibration that fixture `fixture`'s drift model uses (its calibrated drift, or its
/// efficiency factors under local_sampled) no longer fits `scene`: the fields of its
/// CalibrationBasis that differ from the fixture's vibration, the scene's gravity, mu,
/// conveying direction (straight tracks), track point (classical screws), restitution, part
/// families and fixtures' geometry (sampling calibrations) now, each with both values ("its
/// calibrated drift was measured for another feeder: amplitude (m) 0.0005 when calibrated,
/// 0.0008 now"; "... measured with other parts: parts[0] 'plates' (the digest of ...) 3f2a...
/// when calibrated, 91c0... now"); "" when it fits, when the law uses no calibration, or when
/// its basis is not known. Fields the basis does not record are not compared. Phase is not
/// compared (it does not change a steady drift).
std::string staleCalibration(const Scene& scene, int fixture);

/// Which digests the calibrated_for of the calibration `law`'s drift model uses lacks ("part",
/// "fixture", "part or fixture"; "" when it has both, needs neither (a classical calibrated
/// drift), uses no calibration or has no calibrated_for): a record written before they were
/// kept, whose changes of the parts or fixtures cannot be noticed. Callers say so.
std::string missingDigests(const FeederLaw& law);

/// True when `law`'s drift model uses a calibration (a calibrated drift, or local_sampled's
/// efficiency factors) that does not say what it was measured for (no calibrated_for: given by
/// hand, or written before it was kept): a change of the vibration, gravity or mu since cannot
/// be noticed. Callers say so (`rheofeed run`, `rheofeed check`).
bool uncheckedCalibration(const FeederLaw& law);

/// True when a rheonomic run of `scene` needs a calibration first (a fixture lacksCalibration,
/// or its calibration is stale: staleCalibration).
bool needsCalibration(const Scene& scene);

/// Sets `model` on every vibrating fixture of `scene`, dropping the efficiency factors of the
/// fixtures whose model changes (they belong to their own local_sampled calibration).
void overrideDriftModel(Scene& scene, DriftModel model);

/// The efficiency factor (dimensionless) of each part family (indexed like Scene::parts) on
/// the scene's local-law feeders: the local_sampled feeders' factors, 1 where none is given.
/// Throws std::invalid_argument naming both fixtures when two local-law feeders disagree on a
/// family's factor (as Scene::validate does).
std::vector<double> partEfficiencies(const Scene& scene);

/// One part instance, drawn from a PartSpec (deterministic from the scene seed).
struct PartInstance {
  int spec = 0;
  Shape shape;
  double mass = 0;         ///< (kg)
  double inertia[9] = {};  ///< body frame, about the centre of mass (kg m^2)
  Pose pose;
  Vec3 velocity;
  double spawn_time = 0;  ///< (s)
};

/// All parts of the scene in spawn order (mesh parts get their inertia from the mesh).
std::vector<PartInstance> drawParts(const Scene& scene);

/// The name each part family goes by in a run's outputs (part events, drift fields, feeder
/// metrics and the files named after a family), indexed like `parts`: its PartSpec::name, or
/// "name[k]" (k its index) when an earlier family has that name, so that no two are alike
/// (uniqueNames of the names).
std::vector<std::string> familyKeys(const std::vector<PartSpec>& parts);
/// `names` with each name that an earlier one already took suffixed by its index, "name[k]";
/// names that are already unique are returned unchanged.
std::vector<std::string> uniqueNames(const std::vector<std::string>& names);

}  // namespace rheofeed::scene
