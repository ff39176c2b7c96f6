// SPDX-License-Identifier: MIT
/// @file check.hpp
/// A scene check before the run (issue 7): the known hazards of a scene for one method, each
/// with its numbers, where they come from (a JSON path of the scene file, as scene_io.hpp
/// names values) and the setting that avoids it. The check reads the scene only; it never
/// runs it. Units: SI (m, s, kg, m/s); heights are measured against gravity (along -gravity).
///
/// What is checked (each Hazard::Kind documents its criterion and where its limit comes from):
/// tunnelling at the expected part speed, walls that end flush with a floor, mass ratios beyond
/// what the solver's iteration count holds, coarse full-vibration steps, spawn regions inside
/// fixtures or below the removal height, and settings the engine ignores.
#pragma once

#include <string>
#include <vector>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// One warning of the scene check.
struct Hazard {
  enum class Kind {
    /// A part at the scene's expected speed moves, in one step, further than half the summed
    /// thickness of the thinnest fixture geom and the thinnest part: its centre then crosses
    /// the fixture's mid-surface within one step, the collider's least-penetration normal
    /// points out of the far side and the part is pushed through (or it skips the fixture).
    /// Checked for the reference engine and for ODE with speculative contacts off: ODE's
    /// speculative contacts give a fast part its contacts before it arrives.
    Tunnelling,
    /// A box standing on another box (overlapping it in plan) whose bottom lies less than the
    /// thinnest part's thickness below the other's top (or above it): a thin part slips into
    /// the seam and under the wall.
    FlushWall,
    /// Heaviest / lightest part mass beyond what the iteration count transmits through a stack
    /// (measured boundary, see check.cpp): the light part is crushed into the floor or passed.
    MassRatio,
    /// Full vibration: fewer than kMinStepsPerCycle steps per vibration period.
    CoarseVibrationStep,
    /// A vibrating fixture's peak acceleration is beyond kMaxFeederAcceleration times gravity:
    /// vibratory feeders run at a few g, so a value far beyond is most often a unit slip (an
    /// amplitude in millimetres given as metres, a torsion in degrees given as radians). value:
    /// the peak acceleration (m/s^2): A w^2 for the translation, theta w^2 r for the torsion at
    /// the fixture's farthest point r from the axis, combined as perpendicular; limit: the bound.
    ExtremeVibration,
    /// A translating vibration (no torsion; the drift measured along a direction) whose throw
    /// (of +-direction, the one pointing up) has a horizontal part against
    /// Outputs::conveying_direction: the parts drift backwards,
    /// away from the exit; most often a throw angle beyond 90 degrees ("angle_rad": 3 meant in
    /// degrees). value: the cosine between the two; limit: 0.
    AgainstConveyingDirection,
    /// A spawn region reaches into a fixture geom: parts start inside it.
    SpawnInsideFixture,
    /// A spawn region lies below Scene::removal_height: parts are removed as they appear.
    SpawnBelowRemoval,
    /// Gravity vertical, and no fixture geom under a spawn region (none overlaps it in plan
    /// below its top; no plane, no unloaded mesh): its parts fall to the removal height and
    /// are lost. value: the region's height above the lowest fixture (m, -inf with none).
    SpawnOverNothing,
    /// Parts spawned over time (PartSpec::rate > 0) faster than the region holds them side by
    /// side: more appear while one falls its own largest size than fit in the region (a region
    /// narrower than a part and the next part within that time, or a rate that spawns many
    /// within a step), so parts appear inside each other and are pushed out at up to
    /// solver.max_correcting_velocity. value: the interval between parts (s); limit: the fall
    /// time over the number that fit side by side (s). A lower bound on the trouble: parts are
    /// placed at random, and can overlap below it.
    SpawnStreamOverlap,
    /// A part shape against a fixture shape that ODE 0.16 collides poorly: capsule or cylinder
    /// parts on cylinder fixtures (libccd's general convex test, one contact point per pair, no
    /// persistent support: parts tip into the fixture and sink through it).
    WeakCollider,
    /// material.restitution near 1 (>= kHighRestitution): Newton's impact law is applied per
    /// contact point, so a box landing on an edge or a corner can leave faster than it came
    /// (boxes dropped 0.5 m with restitution 1 reached 8.4 m/s against 3.1 m/s of free fall).
    HighRestitution,
    /// A setting the engine of this method does not use (e.g. restitution in the reference).
    IgnoredSetting,
    /// A test of the check that would take too long, or cannot be made, was skipped: a fixture
    /// mesh's wall thickness beyond kMaxMeshRayTests ray tests (the check says so instead of
    /// hanging), or a spawn region within the bounding box of an open fixture mesh, which bounds
    /// no solid, so whether parts start inside its walls cannot be told.
    CheckSkipped,
  };
  Kind kind = Kind::Tunnelling;
  std::string message;       ///< what is wrong, naming the values (SI units)
  std::string where;         ///< JSON path(s) of the values, e.g. "parts[0].size[2]"
  std::string safe_setting;  ///< what avoids it, e.g. "solver.time_step <= 0.0012 s"
  double value = 0;          ///< the offending number (unit in `message`)
  double limit = 0;          ///< the number it must not exceed (same unit)
};

/// Printable name of a hazard kind ("tunnelling", "flush_wall", ...).
const char* toString(Hazard::Kind kind);

/// Full-vibration runs need at least this many steps per vibration period (the vibrating
/// fixture's secant velocity over one step averages the sine over the step: at 20 steps per
/// cycle its peak is 1 - sin(pi / 20) / (pi / 20) = 0.4 % low and lags by half a step, 9 degrees).
constexpr double kMinStepsPerCycle = 20;

/// Peak feeder acceleration, in units of |gravity| (9.81 m/s^2 without gravity), beyond which
/// the check warns (ExtremeVibration): vibratory feeders run at throw numbers of about 1 to 5
/// (NOTES section 5), a few g; the stability matrix's extreme track runs at throw number 6 (about
/// 12 g along its 30 degree vibration). Not a measured boundary of the engines: a plausibility
/// bound that catches a unit slip, which is 1000 times off.
constexpr double kMaxFeederAcceleration = 50;

/// Restitution from which the check warns (dimensionless): from one observation (boxes dropped
/// 0.5 m on a belt with restitution 1 gained energy), not a measured boundary; the stability
/// matrix's restitution cases (spheres at 0 to 1, 30 boxes in a bin at 1) stayed within their
/// energy budgets.
constexpr double kHighRestitution = 0.9;

/// Share of a mesh's surface area (dimensionless) below whose wall thickness the check takes
/// the mesh's thickness (meshWallThickness).
constexpr double kThinShare = 0.05;
/// Work limit of one mesh wall-thickness test (ray/triangle and ray/box tests): about 2 s of
/// one core. A closed mesh of 1e6 triangles needs some 1e8 (check_mesh.cpp); only meshes of
/// many stacked or coincident triangles come near it.
constexpr long long kMaxMeshRayTests = 400000000;

/// The wall thickness of a closed triangle mesh scaled by `scale`.
struct MeshWallThickness {
  double thickness = 0;     ///< (m) see meshWallThickness; 0 when no ray met a far side
  bool measured = true;     ///< false: skipped after `max_tests` tests, thickness unknown
  long long ray_tests = 0;  ///< ray/triangle and ray/box tests done
};
/// Wall thickness of a closed triangle mesh (m): from the centroid of every triangle a ray goes
/// inwards (against the outward normal); the nearest other triangle it meets is the wall's far
/// side there. Returned: the thickness below which lies kThinShare of the surface area, not the
/// minimum, which a vanishing wedge (the start of a ramp that rises from a floor) takes to zero
/// and overlapping shells make the overlap (demos/meshes/vibratory_bowl.stl: its ramp overlaps
/// the wall by 1 mm over 2 % of the area; its thinnest real wall, the 4 mm ramp, is 19 %). A
/// crude estimate: a thin wall covering less than 5 % of a mesh is not seen. The rays are cast
/// against a bounding-volume tree of the triangles, O(n log n) for n triangles; the result
/// equals the all-pairs test's exactly. Stops and reports `measured` false after `max_tests`.
MeshWallThickness meshWallThickness(const TriangleMesh& mesh, double scale,
                                    long long max_tests = kMaxMeshRayTests);

/// The known hazards of `scene` when run with `method`, grouped by kind. Uses
/// scene.solver.time_step as the step of the run (the caller sets the step it will use). Mesh
/// geoms and parts are measured only if their triangles are loaded (scene_io.hpp); otherwise
/// their thickness is taken as 0 and the message says so. Does not validate the scene.
std::vector<Hazard> checkScene(const Scene& scene, Method method);

/// The hazards as text for stderr, one block per hazard:
///   "<prefix>warning [<kind>] <where>: <message>\n<prefix>  safe: <safe_setting>\n".
/// Empty for no hazards.
std::string formatHazards(const std::vector<Hazard>& hazards, const std::string& prefix = "");

/// What a caller does before a run: checkScene for `method`, the hazards printed on stderr
/// (formatHazards, prefixed "rheofeed: <scene>, <method>: ") and returned one line each,
/// "<kind> at <where>: <message> (safe: <safe_setting>)", for the run's outputs
/// (RunMetrics::scene_check).
std::vector<std::string> reportSceneCheck(const Scene& scene, Method method);

/// The largest heaviest/lightest part mass ratio that a stack holds (penetration below a
/// quarter of the light part's thickness) with ODE's quickstep at `iterations` and a light
/// part of thickness `thickness` (m) at step `time_step` (s) under gravity `g` (m/s^2), from
/// the measured table in check.cpp (conservative: the measured grid point at or below the
/// arguments, halved for quickstep's random constraint order). Returns 1 below the measured grid
/// (any ratio above 1 warns) and 0 where even equal masses were crushed (any stack warns).
/// `warm_start`: the run warm-starts its contacts (SolverSettings::warm_start); the limit is
/// then the smaller of the tables measured with and without warm starts at each point.
double odeQuickstepMassRatioLimit(int iterations, double thickness, double time_step, double g,
                                  bool warm_start = false);

/// As odeQuickstepMassRatioLimit for the reference solver (CCP, APGD or PGS, `iterations` =
/// the CCP iteration budget).
double referenceMassRatioLimit(int iterations, double thickness, double time_step, double g);

}  // namespace rheofeed::scene
