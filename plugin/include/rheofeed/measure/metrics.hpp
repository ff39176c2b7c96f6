// SPDX-License-Identifier: MIT
/// @file metrics.hpp
/// What a feeder simulation is judged by: the drift of the parts along the conveying
/// direction, its spread over parts, vertical displacement (bowls), throughput through an exit
/// plane, and the cost (CPU time, real-time factor).
///
/// Drift velocity is measured from displacements, not instantaneous velocities: over one sample
/// interval dt_s, a part's drift is ((x(t) - x(t - dt_s)) . d) / dt_s with d the conveying
/// direction. In a full vibration run the instantaneous velocity swings with the feeder; the
/// displacement over an interval that spans whole vibration cycles is the transport itself.
/// With Outputs::angular_drift the same is done with the unwrapped angle of each part about the
/// axis: drift velocities are then angular velocities (rad/s).
///
/// Feeder metrics (FeederMetrics) are what a feeder is bought for: the parts per minute through
/// the exit plane over time, the cumulative count, the time to the first part out, and per part
/// family the exit orientation - which body axis points up when the part crosses the exit.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rheofeed/simulation/run.hpp"
#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {

/// One sample of the drift time series.
struct DriftSample {
  double time = 0;           ///< end of the sample interval (s)
  int parts = 0;             ///< parts measured (spawned, not yet exited)
  double mean_velocity = 0;  ///< mean drift velocity over parts (m/s along d, or rad/s)
  double ci95 = 0;           ///< half-width of the 95 % confidence interval of the mean (m/s)
  double mean_height = 0;    ///< mean z of the parts (m)
  int exited = 0;            ///< parts that have crossed the exit plane so far
  /// Parts lost so far, by kind (RunHealth, cumulative at `time`).
  int fell = 0, through_fixture = 0, out_of_bounds = 0, nonfinite = 0, too_fast = 0;
  int left_feeder = 0;  ///< RunHealth::parts_left_feeder
};

/// Exit orientation bins: the body axis that points most nearly up, with its sign.
enum class UpAxis { PlusX, MinusX, PlusY, MinusY, PlusZ, MinusZ };
constexpr int kUpAxisCount = 6;
/// Printable name of an UpAxis: "+x", "-x", "+y", "-y", "+z", "-z".
const char* toString(UpAxis axis);

/// The body axis (with its sign) of a part with `rotation` (body to world, row-major, as in
/// PartState) that points most nearly along `up` (unit, world frame): the largest |component|
/// of R^T up. Ties go to the first of x, y, z.
UpAxis upAxis(const double rotation[9], const Vec3& up);

/// "Up" for the exit orientation: -gravity / |gravity| (world frame, unit); +z when the scene
/// has no gravity.
Vec3 upDirection(const Vec3& gravity);

/// Parts per minute through the exit plane in one window of time.
struct RateWindow {
  double start = 0;         ///< (s)
  double end = 0;           ///< (s), > start; the last window may be shorter than the others
  int exits = 0;            ///< parts that crossed the exit plane in [start, end)
  double rate_per_min = 0;  ///< exits / (end - start) x 60 (parts per minute)
  int cumulative = 0;       ///< parts that crossed the exit plane in [0, end)
};

/// Number of windows over a run's duration for the output rate (exitRateWindow).
constexpr int kRateWindowsPerRun = 50;

/// The window of the output rate (s): max(sample_interval, duration / kRateWindowsPerRun), so
/// that a run has at most 50 windows and no window is shorter than a metric sample.
double exitRateWindow(double duration, double sample_interval);

/// Bins the exit times (s, each in [0, end_time]) into windows of `window` seconds covering
/// [0, end_time] (the last window ends at end_time and may be shorter). Throws
/// std::invalid_argument when window or end_time is not a finite number > 0.
std::vector<RateWindow> exitRate(const std::vector<double>& exit_times, double end_time,
                                 double window);

/// The spawn order's part family: element i is the PartSpec index (Scene::parts) of the i-th
/// spawned part (Simulation::part(i)), the order of drawParts without drawing the parts.
std::vector<int> partFamilies(const Scene& scene);

/// Per part family (one PartSpec): how many parts and how they left through the exit.
struct FamilyExits {
  std::string name;  ///< its PartSpec::name, "name[k]" when repeated (familyKeys, scene.hpp)
  Shape::Kind shape = Shape::Kind::Box;
  int spawned = 0;               ///< parts of this family spawned during the run
  int exited = 0;                ///< crossed the exit plane
  int removed_without_exit = 0;  ///< taken out of the simulation before the exit (RunHealth)
  /// Counted lost (Simulation::partLost: through a fixture, left the feeder...) and kept in the
  /// simulation, before the exit: its measurement (drift, exit) ended there, so a tunnelled part
  /// that later falls across the exit plane is not an exit.
  int lost_before_exit = 0;
  /// Exit orientation histogram, indexed by UpAxis: the body axis pointing up at the crossing.
  std::array<int, kUpAxisCount> up_axis{};
  /// False for spheres: a sphere has no distinguishable axis, the histogram then only records
  /// the body frame of an otherwise symmetric part (still counted).
  bool orientation_meaningful = true;
};

/// The numbers a feeder is judged by (times from the start of the run).
struct FeederMetrics {
  bool exit_plane = false;  ///< the scene has an exit plane (Outputs::exit_plane)
  Vec3 up{0, 0, 1};         ///< upDirection of the scene's gravity (unit, world)
  /// Time of each crossing of the exit plane (s), ascending: linear interpolation of the
  /// signed distance to the plane between the two steps around the crossing.
  std::vector<double> exit_times;
  /// The first crossing (s); NaN when no part crossed (see `note`).
  double first_exit_time = std::numeric_limits<double>::quiet_NaN();
  /// Mean output rate from the first to the last exit: (n - 1) / (t_last - t_first) x 60
  /// (parts per minute); NaN with fewer than two exits or all at one time.
  double mean_rate_per_min = std::numeric_limits<double>::quiet_NaN();
  double rate_window = 0;        ///< width of the rate windows (s), exitRateWindow
  std::vector<RateWindow> rate;  ///< output rate and cumulative count over the run
  /// Parts spawned on the exit side of the plane: never counted as exits (said on stderr).
  int spawned_beyond_exit = 0;
  std::vector<FamilyExits> families;  ///< one per Scene::parts entry, same order
  /// Empty, or why a number is missing: "no part reached the exit in 3 s", "the scene has no
  /// exit plane (outputs.exit_plane is false): no exit metrics".
  std::string note;
};

/// What a rheonomic run drove a vibrating fixture with instead of its vibration (the scene's
/// drift fields as the run used them, calibrated before it or given by the scene).
struct DriftField {
  std::string fixture;      ///< Fixture::name
  std::string drift_model;  ///< "local", "local_sampled" or "calibrated_drift"
  /// local_sampled: each part family's efficiency (dimensionless), as family name (familyKeys,
  /// scene.hpp: "name[k]" when repeated), value;
  /// empty for the other models.
  std::vector<std::pair<std::string, double>> efficiency;
  /// calibrated_drift: the constant drift twist (Twist: m/s, rad/s about the origin, m; world
  /// frame); unset for the other models.
  std::optional<Twist> calibrated_drift;
};

/// The default of RunMetrics::max_lost_fraction (dimensionless): a run that loses more than a
/// tenth of the parts it spawned has no answer. A lost part (tunnelled, fallen, blown up) is not a
/// random one of the parts, so the mean over the others is biased by which were lost; a tenth
/// keeps that bias small next to a typical run's 95 % interval, and is a share a user sees in the
/// run's stderr and JSON well before it reaches the bound.
constexpr double kDefaultMaxLostFraction = 0.1;

/// The result of one run.
struct RunMetrics {
  std::string scene;  ///< Scene::name
  /// The scene file the run's scene was read from (Scene::source_file, set by loadScene; a
  /// caller may name another); empty for a scene built in code or parsed from text (the run
  /// JSON then says "built-in").
  std::string scene_file;
  Method method = Method::OdeRheonomic;
  double time_step = 0;    ///< (s)
  std::uint64_t seed = 0;  ///< Scene::seed of the run (to reproduce it)
  /// "fixture name: drift model" of every vibrating fixture (what a rheonomic run used instead
  /// of the vibration; full-vibration runs ignore it).
  std::vector<std::string> drift_models;
  /// The same fixtures with the values their drift model used (efficiencies, calibrated drift).
  std::vector<DriftField> drift_fields;
  /// The calibrations of the scene's drift fields that were found stale and redone, or reported
  /// imprecise, before the run (CalibrateReport::stale and ::imprecise, calibration.hpp); filled
  /// by the caller of measureRun, which alone calibrated.
  std::vector<std::string> calibration_warnings;
  bool angular = false;  ///< the drift is an angular velocity (rad/s) instead of m/s
  std::vector<DriftSample> series;
  /// Start (s) of the window of mean_drift and throughput (the scene's outputs.warmup); the
  /// series covers the whole run.
  double warmup = 0;
  /// Mean drift (m/s along d, or rad/s about the axis) over [warmup, end]: total displacement of
  /// the measured parts divided by time, averaged over parts. Parts counted lost
  /// (Simulation::partLost, and those inside a fixture at the end: RunHealth::inside_fixture_now)
  /// are left out: a tunnelled or fallen part's motion is not the feeder's.
  double mean_drift = 0;
  /// 95 % CI half-width over parts (the drift's unit); 0 with fewer than two parts, where it is
  /// not defined (the outputs write null, an empty field or n/a).
  double mean_drift_ci95 = 0;
  /// Parts whose drift entered mean_drift (not lost, and measured over some time after the
  /// warm-up before they left or were removed). 0: no mean drift (0 here; the outputs write null
  /// or n/a), and with fewer than two no confidence interval.
  int drift_parts = 0;
  double vertical_displacement = 0;  ///< mean z change of the parts not lost since they spawned (m)
  /// Parts vertical_displacement is the mean over (0: none was left to measure, and it is 0).
  int displacement_parts = 0;
  double throughput = 0;   ///< parts per second through the exit plane (after warmup)
  int parts = 0;           ///< spawned parts
  double cpu_seconds = 0;  ///< process CPU time of the run
  double simulated_seconds = 0;
  /// CPU time / simulated time (dimensionless; < 1 is faster than real time).
  double real_time_factor = 0;
  /// What the run lost, could not trust or ignored (simulation.hpp).
  RunHealth health;
  /// The largest share of the spawned parts the run may lose (RunHealth::partsLost() / parts,
  /// in [0, 1]) and still have an answer (runAnswer). measureRun sets the default; a caller with
  /// its own bound (`rheofeed run --max-lost-fraction`) sets it before writing the outputs.
  double max_lost_fraction = kDefaultMaxLostFraction;
  /// The dynamics settings the engine applied (Simulation::appliedSolver: iterations, warm
  /// start, ERP, CFM, contact surface...; empty where they do not apply to the method).
  AppliedSolver solver;
  /// The scene check's warnings before the run (reportSceneCheck, simulation/check.hpp: kind,
  /// values, safe setting), one formatted line each; filled by the caller of measureRun.
  std::vector<std::string> scene_check;
  /// Output rate, first exit, exit orientation per family.
  FeederMetrics feeder;
};

/// Whether a run's numbers are its answer (runAnswer). Not trusted: the run's outputs are written
/// as measured, but its mean drift, throughput and exit metrics are not the scene's (a
/// `rheofeed run` exits with its no-answer code, a sweep leaves the seed out of its means).
struct RunAnswer {
  bool trusted = true;
  /// Why not, one reason each, worded to follow the method's name ("ode_rheonomic lost all 2
  /// parts it spawned"); empty when trusted.
  std::vector<std::string> why;
};

/// The one rule of whether a run has an answer: it has none when it
///   - spawned no part ("spawned no part");
///   - measured no part and saw none cross the exit plane: every part lost ("lost all N parts
///     it spawned"), or none measured ("measured none of its N parts (L lost, B spawned beyond
///     the exit plane)");
///   - lost more than run.max_lost_fraction of the parts it spawned, RunHealth::partsLost() /
///     RunMetrics::parts > max_lost_fraction ("lost L of N parts (P %), more than
///     <bound_name> F"; not said again when it lost them all).
/// A bound that is not a number in [0, 1] judges nothing: the run then has no answer either
/// ("has no bound to judge its L lost parts by: ..."). `bound_name` names the bound in these
/// reasons: the run JSON's own key by default, a command's option (e.g. "--max-lost-fraction")
/// in that command's messages.
RunAnswer runAnswer(const RunMetrics& run, const std::string& bound_name = "max_lost_fraction");

/// Runs `scene` with `method` for its duration (runSimulation, run.hpp) and measures it (drift,
/// health, and with an exit plane the FeederMetrics; a run with an exit plane that no part
/// reached says so on stderr). `observers` (optional) watch the same run after the measurement
/// (e.g. an AnimationRecorder, output/animation.hpp); the run's HealthReport comes last and
/// prints what the run lost, could not trust or ignored (RunHealth::anything) on stderr.
/// `progress` (optional) is called about a hundred times. The scene check is the caller's:
/// run reportSceneCheck (simulation/check.hpp) before and put its lines into
/// RunMetrics::scene_check. Throws std::invalid_argument for an invalid scene.
RunMetrics measureRun(const Scene& scene, Method method, const Progress& progress = {},
                      const std::vector<RunObserver*>& observers = {});

/// measureRun on a simulation the caller built from `scene` (makeSimulation(scene, method),
/// not stepped yet) and set up, e.g. with stage timing on (Simulation::setStageTiming); the
/// method is sim.method(). The same run, measures and reports as above.
RunMetrics measureRun(Simulation& sim, const Scene& scene, const Progress& progress = {},
                      const std::vector<RunObserver*>& observers = {});

}  // namespace rheofeed::scene
