// SPDX-License-Identifier: MIT
// The scene check (check.hpp): each hazard fires on a scene built to have it, with numbers
// recomputed here from mechanics (free fall, semi-implicit Euler travel, masses from densities
// and edges), and stays quiet on the built-in and demo scenes that run well. The mass-ratio
// limits are checked against ODE itself: a stack at the table's limit holds, ten times it does
// not.
#include "rheofeed/simulation/check.hpp"

#include "rheofeed/contact_collider.hpp"

#include <gtest/gtest.h>
#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <utility>

#include "common/builtin_scenes.hpp"
#include "mesh_shell.hpp"
#include "rheofeed/scene/mesh.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "rheofeed/simulation/simulation.hpp"
#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kG = 9.81;
// The check's numbers are closed forms of the same inputs: only rounding differs.
constexpr double kRelative = 1e-9;

Fixture floorBox(double thickness) {  // 1 m x 1 m, top at z = 0
  return test::boxFixture("floor", {1, 1, thickness});
}

PartSpec cubes(double edge, double density, const Vec3& lo, const Vec3& hi, int count = 1) {
  PartSpec p;
  p.shape = Shape::Kind::Box;
  for (auto& d : p.size) d.mean = edge;
  p.density = density;
  p.spawn_min = lo;
  p.spawn_max = hi;
  p.count = count;
  return p;
}

std::vector<Hazard> ofKind(const std::vector<Hazard>& all, Hazard::Kind kind) {
  std::vector<Hazard> out;
  for (const Hazard& h : all) {
    if (h.kind == kind) out.push_back(h);
  }
  return out;
}

TEST(SceneCheck, TunnellingFiresForAFallFasterThanHalfTheThicknessPerStep) {
  Scene s;
  s.fixtures.push_back(floorBox(0.010));
  const double edge = 0.005, height = 1.0, h = 0.01;
  s.parts.push_back(cubes(edge, 1000, {0, 0, 0.2}, {0.1, 0.1, height}, 5));
  s.solver.time_step = h;
  s.solver.speculative_contacts = false;  // ODE's contacts only where geoms overlap
  const std::vector<Hazard> t =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::Tunnelling);
  ASSERT_EQ(t.size(), 1u) << formatHazards(checkScene(s, Method::OdeRheonomic));
  const double v = std::sqrt(2 * kG * height);  // free fall to the floor top at z = 0
  EXPECT_NEAR(t[0].value, h * (v + kG * h), kRelative * t[0].value);
  // Thinnest obstacle: the 5 mm part itself (the floor is 10 mm): centres cross at 5 mm.
  EXPECT_NEAR(t[0].limit, 0.5 * (edge + edge), kRelative);
  EXPECT_NE(t[0].where.find("solver.time_step"), std::string::npos);
  EXPECT_NE(t[0].safe_setting.find("solver.time_step <="), std::string::npos);
  // The step that moves the falling part exactly 5 mm: h (v + g h) = 5 mm.
  const double safe_h = (-v + std::sqrt(v * v + 4 * kG * edge)) / (2 * kG);
  s.solver.time_step = 0.999 * safe_h;
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::Tunnelling).empty());
  s.solver.time_step = 1.001 * safe_h;
  EXPECT_EQ(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::Tunnelling).size(), 1u);
  // The reference engine has no speculative contacts: the same hazard whatever the setting.
  EXPECT_EQ(ofKind(checkScene(s, Method::ReferenceRheonomic), Hazard::Kind::Tunnelling).size(), 1u);
}

// With speculative contacts (the default) ODE sweeps a fast part and lands it
// (Plugin ContactCollider.Speculative*): its travel per step is no hazard for the ODE methods.
TEST(SceneCheck, SpeculativeContactsTakeTheTunnellingHazardFromOdeRuns) {
  Scene s;
  s.fixtures.push_back(floorBox(0.010));
  s.parts.push_back(cubes(0.005, 1000, {0, 0, 0.2}, {0.1, 0.1, 1.0}, 5));
  s.solver.time_step = 0.01;
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::Tunnelling).empty());
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeFullVibration), Hazard::Kind::Tunnelling).empty());
  EXPECT_EQ(ofKind(checkScene(s, Method::ReferenceRheonomic), Hazard::Kind::Tunnelling).size(), 1u);
  s.solver.speculative_contacts = true;
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::Tunnelling).empty());
}

TEST(SceneCheck, TunnellingThroughAThinWallAtBeltSpeed) {
  Scene s;
  s.fixtures.push_back(floorBox(0.1));
  s.fixtures[0].law.kind = FeederLaw::Kind::Belt;
  s.fixtures[0].law.belt_speed = 10;  // m/s
  Fixture wall;
  wall.name = "wall";
  Fixture::Geom g;
  g.shape.kind = Shape::Kind::Box;
  g.shape.size = {0.002, 1, 0.05};
  g.pose.position = {0.4, 0, 0.02};
  wall.geoms.push_back(g);
  s.fixtures.push_back(wall);
  s.parts.push_back(cubes(0.02, 1000, {0, 0, 0.011}, {0, 0, 0.011}));
  s.solver.time_step = 0.002;
  s.solver.speculative_contacts = false;
  const std::vector<Hazard> t =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::Tunnelling);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_NEAR(t[0].value, 0.002 * (10 + kG * 0.002), kRelative);
  EXPECT_NEAR(t[0].limit, 0.5 * (0.002 + 0.02), kRelative);
  EXPECT_NE(t[0].where.find("fixtures[1].geoms[0]"), std::string::npos);
  EXPECT_NE(t[0].message.find("fixtures[0].law.belt.speed"), std::string::npos);
}

TEST(SceneCheck, FlushWallFiresForAWallStandingOnTheFloorAndNotForASunkOne) {
  Scene s;
  s.fixtures.push_back(floorBox(0.02));
  Fixture wall;
  wall.name = "wall";
  Fixture::Geom g;
  g.shape.kind = Shape::Kind::Box;
  g.shape.size = {1, 0.01, 0.05};
  g.pose.position = {0, 0.3, 0.025};  // bottom at z = 0, the floor's top
  wall.geoms.push_back(g);
  s.fixtures.push_back(wall);
  PartSpec plates = cubes(0.02, 7800, {0, 0, 0.01}, {0, 0, 0.01});
  plates.size[2].mean = 0.0005;  // 0.5 mm plates
  s.parts.push_back(plates);
  const std::vector<Hazard> f =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::FlushWall);
  ASSERT_EQ(f.size(), 1u) << formatHazards(checkScene(s, Method::OdeRheonomic));
  EXPECT_NEAR(f[0].value, 0.0, 1e-12);      // the gap: flush
  EXPECT_NEAR(f[0].limit, -0.0005, 1e-12);  // sunk by at least the thinnest part
  EXPECT_NE(f[0].where.find("fixtures[1].geoms[0]"), std::string::npos);
  EXPECT_NE(f[0].safe_setting.find("0.5 mm"), std::string::npos) << f[0].safe_setting;
  // A 0.3 mm gap under the wall is still a seam a 0.5 mm plate can wedge into.
  s.fixtures[1].geoms[0].pose.position.z = 0.025 + 0.0003;
  EXPECT_EQ(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::FlushWall).size(), 1u);
  // Sunk 1 mm (two plate thicknesses) into the floor: safe.
  s.fixtures[1].geoms[0].pose.position.z = 0.025 - 0.001;
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::FlushWall).empty());
  // Beside the floor (no overlap in plan): no seam on the floor.
  s.fixtures[1].geoms[0].pose.position = {0, 0.505, 0.025};
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::FlushWall).empty());
}

// A light cube under a heavy one of the same edge on a floor (the geometry of the table in
// check.cpp): returns the largest penetration (m) in the second second.
// `warm_start`: ODE's contact warm start (solver.warm_start; the tables of check_mass_ratio.cpp
// are measured with it off and on).
double stackPenetration(double ratio, int iterations, double h, double edge, Method method,
                        bool warm_start = false) {
  Scene s;
  s.fixtures.push_back(floorBox(0.1));
  // drawParts keeps parts spawned at t = 0 apart by their bounding spheres (sqrt(3) edge):
  // the heavy cube falls 0.8 edge onto the light one.
  // Densities within the scene limits (<= 1e6 kg/m^3): water-like light cubes up to a ratio of
  // 1000, lighter ones beyond (the heavy cube then stays at 1e6 kg/m^3).
  const double light = std::min(1000.0, 1e6 / ratio);
  s.parts.push_back(cubes(edge, light, {0, 0, edge / 2}, {0, 0, edge / 2}));
  s.parts.push_back(cubes(edge, light * ratio, {0, 0, 2.3 * edge}, {0, 0, 2.3 * edge}));
  s.solver.time_step = h;
  s.outputs.sample_interval = std::max(s.outputs.sample_interval, h);  // at most once per step
  s.solver.iterations = iterations;
  if (method == Method::OdeRheonomic) s.solver.warm_start = warm_start;
  s.duration = 2;
  // Quickstep shuffles its rows with ODE's global generator; the boundary moves with it (at
  // X = 20, k = 20 a stack at R = 3.5 was crushed in 2 of 8 repeats): one fixed seed.
  dRandSetSeed(1);
  auto sim = makeSimulation(s, method);
  double worst = 0;
  while (sim->time() < 2.0 - 0.5 * h) {
    sim->step();
    if (sim->time() < 1.0) continue;
    const PartState a = sim->part(0), b = sim->part(1);
    worst = std::max(
        {worst, -(a.position.z - edge / 2), (a.position.z + edge / 2) - (b.position.z - edge / 2)});
  }
  return worst;
}

// Warm starts unset: on at rheonomic steps of small parts (X = e / (g h^2) below
// kWarmStartMaxX = 50), off at fine steps; the scene's own setting wins; never without quickstep.
TEST(SceneCheck, WarmStartsByDefaultOnlyBelowTheMassRatioProbesSafeX) {
  Scene s;
  s.fixtures.push_back(floorBox(0.1));
  const double edge = 0.005;  // X = 5.1 at 10 ms, 51,000 at 0.1 ms
  s.parts.push_back(cubes(edge, 1000, {-0.3, -0.3, 0.02}, {0.3, 0.3, 0.05}, 10));
  const double g = norm(s.gravity);
  const double h_at_limit = std::sqrt(edge / (g * kWarmStartMaxX));  // X = 50 (3.2 ms)
  const bool patched = odeHasContactWarmStart();
  EXPECT_EQ(odeWarmStartsContacts(s, 0.01), patched);
  EXPECT_EQ(odeWarmStartsContacts(s, 1.01 * h_at_limit), patched);  // X just below 50
  EXPECT_FALSE(odeWarmStartsContacts(s, 0.99 * h_at_limit));        // X just above
  EXPECT_FALSE(odeWarmStartsContacts(s, 1e-4));
  s.solver.time_step = 0.01;
  EXPECT_EQ(odeWarmStartsContacts(s), patched);  // at the scene's own step
  s.solver.warm_start = false;
  EXPECT_FALSE(odeWarmStartsContacts(s, 0.01));
  s.solver.warm_start = true;
  EXPECT_TRUE(odeWarmStartsContacts(s, 1e-4));  // asked for: even at fine steps
  s.solver.ode_quickstep = false;
  EXPECT_FALSE(odeWarmStartsContacts(s, 0.01));  // dWorldStep has no use for it
}

TEST(SceneCheck, MassRatioFiresWithTheMassesFromDensitiesAndEdges) {
  Scene s;
  s.fixtures.push_back(floorBox(0.1));
  const double edge = 0.01, h = 0.005;
  s.parts.push_back(cubes(edge, 1000, {-0.3, -0.3, 0.02}, {0.3, 0.3, 0.05}, 10));
  s.parts.push_back(cubes(edge, 1e6, {-0.3, -0.3, 0.06}, {0.3, 0.3, 0.09}, 10));
  s.solver.time_step = h;
  s.solver.iterations = 50;
  const std::vector<Hazard> m =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::MassRatio);
  ASSERT_EQ(m.size(), 1u) << formatHazards(checkScene(s, Method::OdeRheonomic));
  const double light = 1000 * edge * edge * edge, heavy = 1e6 * edge * edge * edge;
  EXPECT_NEAR(m[0].value, heavy / light, kRelative * heavy / light);
  // the scene's ODE run warm-starts its contacts by the rule of odeWarmStartsContacts
  const bool warm = odeWarmStartsContacts(s);
  EXPECT_EQ(m[0].limit, odeQuickstepMassRatioLimit(50, edge, h, kG, warm));
  EXPECT_NE(m[0].safe_setting.find("ode_quickstep = false"), std::string::npos);
  // Dantzig (dWorldStep) solves the LCP exactly: no iteration count to run out of.
  s.solver.ode_quickstep = false;
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::MassRatio).empty());
  // Masses within the limit: quiet.
  s.solver.ode_quickstep = true;
  s.parts[1].density = 1000 * odeQuickstepMassRatioLimit(50, edge, h, kG, warm);
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::MassRatio).empty());
}

// Equal parts below the measured range (X = e / (g h^2) under 5): the warning does not call them
// a heavy and a light part, nor advise closer masses.
TEST(SceneCheck, EqualPartsBelowTheMeasuredRangeAreNotCalledHeavyAndLight) {
  Scene s;
  s.fixtures.push_back(floorBox(0.1));
  s.parts.push_back(cubes(0.004, 1000, {-0.3, -0.3, 0.02}, {0.3, 0.3, 0.05}, 10));  // X = 4.1
  s.solver.time_step = 0.01;
  const std::vector<Hazard> m =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::MassRatio);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NE(m[0].message.find("the parts are of equal mass"), std::string::npos) << m[0].message;
  EXPECT_EQ(m[0].message.find("heavy part"), std::string::npos) << m[0].message;
  EXPECT_EQ(m[0].safe_setting.find("closer masses"), std::string::npos) << m[0].safe_setting;
  EXPECT_NE(m[0].safe_setting.find("thicker parts"), std::string::npos) << m[0].safe_setting;
}

// The table's limits are ODE's behaviour: at the limit the stack holds (penetration below a
// quarter edge, as measured), at ten times the limit it does not. Three points of the table.
TEST(SceneCheck, OdeQuickstepHoldsAStackAtTheTableLimitAndNotAtTenTimesIt) {
  const double edge = 0.01;
  for (const auto& [x, k] : {std::pair<double, int>{20, 20}, {100, 50}, {500, 100}}) {
    const double h = std::sqrt(edge / (kG * x));
    const double limit = odeQuickstepMassRatioLimit(k, edge, h, kG);
    SCOPED_TRACE("X = " + std::to_string(x) + ", k = " + std::to_string(k) +
                 ", limit = " + std::to_string(limit));
    EXPECT_LT(stackPenetration(limit, k, h, edge, Method::OdeRheonomic), edge / 4);
    EXPECT_GT(stackPenetration(10 * limit, k, h, edge, Method::OdeRheonomic), edge / 4);
  }
}

// With contact warm starts the limit is the smaller of the two tables; a stack at it holds.
TEST(SceneCheck, OdeQuickstepWithWarmStartsHoldsAStackAtItsLimit) {
  if (!odeHasContactWarmStart()) GTEST_SKIP() << "the linked ODE has no warm start (stock ODE)";
  const double edge = 0.01;
  for (const auto& [x, k] : {std::pair<double, int>{20, 20}, {100, 50}, {500, 100}}) {
    const double h = std::sqrt(edge / (kG * x));
    const double limit = odeQuickstepMassRatioLimit(k, edge, h, kG, true);
    SCOPED_TRACE("X = " + std::to_string(x) + ", k = " + std::to_string(k) +
                 ", limit = " + std::to_string(limit));
    EXPECT_LE(limit, odeQuickstepMassRatioLimit(k, edge, h, kG, false));
    EXPECT_LT(stackPenetration(limit, k, h, edge, Method::OdeRheonomic, true), edge / 4);
  }
}

TEST(SceneCheck, ReferenceHoldsAStackAtItsTableLimit) {
  const double edge = 0.01, x = 100;
  const int k = 50;
  const double h = std::sqrt(edge / (kG * x));
  const double limit = referenceMassRatioLimit(k, edge, h, kG);
  EXPECT_GT(limit, odeQuickstepMassRatioLimit(k, edge, h, kG));
  EXPECT_LT(stackPenetration(limit, k, h, edge, Method::ReferenceRheonomic), edge / 4);
}

// The measurement behind the tables of check.cpp (not a test: prints the boundary).
//   rheofeed_scene_tests --gtest_also_run_disabled_tests --gtest_filter='*MassRatioProbe*'
// RHEOFEED_PROBE selects the runs: "ode" (cold starts), "ode_warm" (solver.warm_start on),
// "reference"; unset: all three.
TEST(SceneCheck, DISABLED_MassRatioProbe) {
  const double ratios[] = {1,   1.5, 2,   3,   5,   7,    10,   15,   20,   30,   50,   70,   100,
                           150, 200, 300, 500, 700, 1000, 1500, 2000, 3000, 5000, 7000, 10000};
  const char* only = std::getenv("RHEOFEED_PROBE");
  // RHEOFEED_PROBE_POINT="edge,X,k" (e.g. "0.002,20,200"): that grid point only.
  const char* point = std::getenv("RHEOFEED_PROBE_POINT");
  double point_edge = 0, point_x = 0;
  int point_k = 0;
  if (point) std::sscanf(point, "%lf,%lf,%d", &point_edge, &point_x, &point_k);
  const struct {
    const char* name;
    Method method;
    bool warm;
  } runs[] = {{"ode", Method::OdeRheonomic, false},
              {"ode_warm", Method::OdeRheonomic, true},
              {"reference", Method::ReferenceRheonomic, false}};
  for (const auto& run : runs) {
    if (only && std::string(only) != run.name) continue;
    for (double edge : {0.002, 0.01, 0.05}) {
      if (point && edge != point_edge) continue;
      for (double x : {5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 2000.0, 8000.0}) {
        if (point && x != point_x) continue;
        const double h = std::sqrt(edge / (kG * x));
        for (int k : {10, 20, 50, 100, 200}) {
          if (point && k != point_k) continue;
          double hold = 0, crush = 0;
          for (double r : ratios) {
            if (stackPenetration(r, k, h, edge, run.method, run.warm) > edge / 4) {
              crush = r;
              break;
            }
            hold = r;
          }
          std::printf("%s edge=%g X=%g h=%.3g k=%d hold=%g crush=%g\n", run.name, edge, x, h, k,
                      hold, crush);
          std::fflush(stdout);
        }
      }
    }
  }
}

TEST(SceneCheck, CoarseFullVibrationStepFires) {
  Scene s = vibratingTrackScene(0.2e-3, 50);
  s.solver.time_step = 1.0 / (10 * 50);  // 10 steps per cycle
  const std::vector<Hazard> c =
      ofKind(checkScene(s, Method::OdeFullVibration), Hazard::Kind::CoarseVibrationStep);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c[0].value, 10, 1e-9);
  EXPECT_NE(c[0].safe_setting.find("0.001"), std::string::npos) << c[0].safe_setting;
  // A rheonomic run does not vibrate.
  EXPECT_TRUE(
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::CoarseVibrationStep).empty());
}

// A unit slip in the vibration (millimetres given as metres, degrees as radians) drives the
// feeder at hundreds of g; a real feeder's few g pass.
TEST(SceneCheck, AnAmplitudeInMillimetresGivenAsMetresIsAnExtremeVibration) {
  const double w = 2 * kPi * 50;
  Scene real = vibratingTrackScene(0.2e-3, 50);  // 0.2 mm at 50 Hz: 19.7 m/s^2, 2 g
  EXPECT_TRUE(
      ofKind(checkScene(real, Method::OdeRheonomic), Hazard::Kind::ExtremeVibration).empty());
  Scene slip = vibratingTrackScene(0.2, 50);  // "0.2" meant in mm
  const std::vector<Hazard> h =
      ofKind(checkScene(slip, Method::OdeRheonomic), Hazard::Kind::ExtremeVibration);
  ASSERT_EQ(h.size(), 1u);
  EXPECT_NEAR(h[0].value, 0.2 * w * w, 1e-9 * h[0].value);  // A w^2 = 19739 m/s^2
  EXPECT_NEAR(h[0].limit, kMaxFeederAcceleration * 9.81, 1e-9);
  EXPECT_EQ(h[0].where, "fixtures[0].law.vibration.amplitude");
  EXPECT_NE(h[0].message.find("(2012 g: amplitude 0.2 m, 50 Hz)"), std::string::npos)
      << h[0].message;
  EXPECT_NE(h[0].message.find("in mm given as m"), std::string::npos) << h[0].message;
  // or the frequency that would keep 0.2 m at 50 g: sqrt(50 g / 0.2) / (2 pi) = 7.88 Hz
  EXPECT_NE(h[0].safe_setting.find("frequency <= 7.88 Hz at this amplitude"), std::string::npos)
      << h[0].safe_setting;
  // The largest amplitude at 50 g and 50 Hz: 50 * 9.81 / w^2 = 4.97 mm.
  EXPECT_NE(h[0].safe_setting.find("amplitude <= 0.00497 m at 50 Hz"), std::string::npos)
      << h[0].safe_setting;
  EXPECT_EQ(toString(h[0].kind), std::string("extreme_vibration"));
}

// "angle_rad": 3 meant in degrees throws the parts at 172 degrees: backwards, away from the exit.
TEST(SceneCheck, AThrowBeyondNinetyDegreesIsAgainstTheConveyingDirection) {
  EXPECT_TRUE(ofKind(checkScene(vibratingTrackScene(0.2e-3, 50, 0.349066), Method::OdeRheonomic),
                     Hazard::Kind::AgainstConveyingDirection)
                  .empty());
  const Scene slip = vibratingTrackScene(0.2e-3, 50, 3.0);
  const std::vector<Hazard> h =
      ofKind(checkScene(slip, Method::OdeRheonomic), Hazard::Kind::AgainstConveyingDirection);
  ASSERT_EQ(h.size(), 1u);
  EXPECT_NEAR(h[0].value, -1, 1e-12);  // the horizontal part is along -x, the drift along +x
  EXPECT_NE(h[0].message.find("172 degrees above outputs.conveying_direction"), std::string::npos)
      << h[0].message;
  EXPECT_EQ(toString(h[0].kind), std::string("against_conveying_direction"));
  // direction and -direction are one motion: -20 degrees throws at 160, backwards; 200 at 20.
  const std::vector<Hazard> below =
      ofKind(checkScene(vibratingTrackScene(0.2e-3, 50, -20 * kPi / 180), Method::OdeRheonomic),
             Hazard::Kind::AgainstConveyingDirection);
  ASSERT_EQ(below.size(), 1u);
  EXPECT_NE(below[0].message.find("160 degrees above"), std::string::npos) << below[0].message;
  EXPECT_TRUE(
      ofKind(checkScene(vibratingTrackScene(0.2e-3, 50, 200 * kPi / 180), Method::OdeRheonomic),
             Hazard::Kind::AgainstConveyingDirection)
          .empty());
  Scene backwards = slip;  // a feeder meant to run the other way says so
  backwards.outputs.conveying_direction = {-1, 0, 0};
  EXPECT_TRUE(
      ofKind(checkScene(backwards, Method::OdeRheonomic), Hazard::Kind::AgainstConveyingDirection)
          .empty());
}

TEST(SceneCheck, ATorsionInDegreesGivenAsRadiansIsAnExtremeVibration) {
  Scene s = vibratingTrackScene(0, 50);  // torsion only, about the z axis through the origin
  Vibration& v = s.fixtures[0].law.vibration;
  v.torsion_amplitude = 0.5;  // "0.5" meant in degrees
  v.axis_direction = {0, 0, 1};
  v.axis_origin = {0, 0, 0};
  const std::vector<Hazard> h =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::ExtremeVibration);
  ASSERT_EQ(h.size(), 1u) << formatHazards(checkScene(s, Method::OdeRheonomic));
  EXPECT_EQ(h[0].where, "fixtures[0].law.vibration.torsion_amplitude");
  // theta w^2 r at the track's farthest corner from the axis.
  double reach = 0;
  for (const Fixture::Geom& g : s.fixtures[0].geoms) {
    for (int sx : {-1, 1}) {
      for (int sy : {-1, 1}) {
        const double x = g.pose.position.x + sx * 0.5 * g.shape.size.x;
        const double y = g.pose.position.y + sy * 0.5 * g.shape.size.y;
        reach = std::max(reach, std::hypot(x, y));
      }
    }
  }
  const double w = 2 * kPi * 50;
  EXPECT_NEAR(h[0].value, 0.5 * w * w * reach, 1e-9 * h[0].value);
  v.torsion_amplitude = 0.05 * kPi / 180;  // a real torsion: 8.8 g at the corner 1 m out
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::ExtremeVibration).empty());
}

// A spawn region beside the feeder: its parts fall past everything and are lost.
TEST(SceneCheck, ASpawnRegionOverNothingFires) {
  Scene s;
  s.fixtures.push_back(floorBox(0.02));  // 1 m x 1 m around the origin
  s.parts.push_back(cubes(0.01, 1000, {0.8, 0.8, 0.05}, {0.9, 0.9, 0.1}, 3));
  const std::vector<Hazard> h =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnOverNothing);
  ASSERT_EQ(h.size(), 1u);
  EXPECT_EQ(h[0].where, "parts[0].spawn_min/spawn_max");
  EXPECT_NE(h[0].message.find("x 0.8 to 0.9 m, y 0.8 to 0.9 m"), std::string::npos) << h[0].message;
  s.parts[0].spawn_min = {0.4, 0.4, 0.05};  // over the floor's corner: some land, no hazard
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnOverNothing).empty());
  s.parts[0].spawn_min = {0.8, 0.8, 0.05};
  s.fixtures.push_back(test::groundPlane("ground", -1));  // a plane under everything
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnOverNothing).empty());
}

TEST(SceneCheck, SpawnInsideAFixtureAndBelowTheRemovalHeightFire) {
  Scene s;
  s.fixtures.push_back(floorBox(0.02));
  s.parts.push_back(cubes(0.01, 1000, {0, 0, -0.005}, {0.1, 0.1, 0.05}, 3));
  std::vector<Hazard> all = checkScene(s, Method::OdeRheonomic);
  ASSERT_EQ(ofKind(all, Hazard::Kind::SpawnInsideFixture).size(), 1u) << formatHazards(all);
  s.parts[0].spawn_min.z = 0.006;  // centres above the top: no part can start inside
  EXPECT_TRUE(
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnInsideFixture).empty());
  // A tilted floor box: the region just above the untilted top is inside the tilted one.
  s.fixtures[0].geoms[0].pose = Pose::axisAngle({0, 1, 0}, -0.2, {0, 0, -0.01});
  EXPECT_EQ(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnInsideFixture).size(),
            1u);
  s.fixtures[0].geoms[0].pose = Pose{};
  s.fixtures[0].geoms[0].pose.position = {0, 0, -0.01};
  s.removal_height = 0.01;
  all = checkScene(s, Method::OdeRheonomic);
  const std::vector<Hazard> r = ofKind(all, Hazard::Kind::SpawnBelowRemoval);
  ASSERT_EQ(r.size(), 1u) << formatHazards(all);
  EXPECT_EQ(r[0].value, 0.006);
}

// A closed fixture mesh is the solid it bounds: a spawn region inside the bowl's central cone
// or its wall is named, the bowl's cavity is not. The cone's surface from the bowl's generator
// (generate_meshes.cpp): z = 11.8 mm at r = 124 mm, rising 25 degrees inwards; at r = 90..102 mm
// it is 22..28 mm high. (The check skipped every mesh until a new user's nuts, spawned inside the
// cone, were all lost as "tunnelled" with no warning.)
TEST(SceneCheck, SpawnInsideAClosedMeshFixtureFires) {
  const std::filesystem::path dir = std::filesystem::path(RHEOFEED_DEMO_DIR) / "scenes";
  Scene s = loadScene(dir / "bowl_feeder_mesh_fill.json");
  ASSERT_EQ(s.fixtures[0].geoms[0].shape.kind, Shape::Kind::Mesh);
  EXPECT_TRUE(
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnInsideFixture).empty());
  s.parts[0].spawn_min.z = 0.020;  // below the cone's surface over all of r = 90..102 mm
  s.parts[0].spawn_max.z = 0.021;
  std::vector<Hazard> inside =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnInsideFixture);
  ASSERT_EQ(inside.size(), 1u);
  EXPECT_NE(inside[0].where.find("fixtures[0].geoms[0]"), std::string::npos) << inside[0].where;
  // A region 3 mm across inside the 5 mm wall (r = 150..155 mm), on -x at z = 80 mm (on +x
  // the wall is cut down to 64 mm for the outlet).
  s.parts[0].spawn_min = {-0.154, -0.001, 0.080};
  s.parts[0].spawn_max = {-0.151, 0.001, 0.082};
  EXPECT_EQ(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnInsideFixture).size(),
            1u);
  // The same region moved 3 mm inwards, into the cavity: quiet.
  s.parts[0].spawn_min.x = -0.149;
  s.parts[0].spawn_max.x = -0.146;
  EXPECT_TRUE(
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnInsideFixture).empty());
  // The bowl turned 90 degrees about z and moved to (1, 2, 0) m, the region in the cone with it.
  Fixture::Geom& bowl = s.fixtures[0].geoms[0];
  bowl.pose = Pose::axisAngle({0, 0, 1}, kPi / 2, {1, 2, 0});
  s.parts[0].spawn_min = bowl.pose.transform({0.0, -0.100, 0.020});
  s.parts[0].spawn_max = bowl.pose.transform({0.02, -0.090, 0.021});
  std::swap(s.parts[0].spawn_min.x, s.parts[0].spawn_max.x);  // x' = -y: the bounds swap
  EXPECT_EQ(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnInsideFixture).size(),
            1u);
  // A mesh that gives its shells twice still bounds them.
  auto twice = std::make_shared<TriangleMesh>(*bowl.shape.mesh_data);
  twice->triangles.insert(twice->triangles.end(), bowl.shape.mesh_data->triangles.begin(),
                          bowl.shape.mesh_data->triangles.end());
  bowl.shape.mesh_data = twice;
  EXPECT_EQ(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnInsideFixture).size(),
            1u);
  // An open mesh (the original less its last triangle) bounds nothing: it cannot be judged, and
  // the check says so (it was silent) instead of naming it inside.
  auto open = std::make_shared<TriangleMesh>(*bowl.shape.mesh_data);
  open->triangles.resize(open->triangles.size() / 2 - 3);
  bowl.shape.mesh_data = open;
  const std::vector<Hazard> all = checkScene(s, Method::OdeRheonomic);
  EXPECT_TRUE(ofKind(all, Hazard::Kind::SpawnInsideFixture).empty());
  const std::vector<Hazard> skipped = ofKind(all, Hazard::Kind::CheckSkipped);
  ASSERT_EQ(skipped.size(), 1u) << formatHazards(all);
  EXPECT_NE(skipped[0].message.find("open mesh"), std::string::npos) << skipped[0].message;
  EXPECT_NE(skipped[0].where.find("fixtures[0].geoms[0]"), std::string::npos);
  // A region clear of the open mesh's bounding box is not reported.
  s.parts[0].spawn_min = {5, 5, 5};
  s.parts[0].spawn_max = {5.1, 5.1, 5.1};
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::CheckSkipped).empty());
}

// Parts spawned faster than they fall clear of each other overlap unless the region holds them
// side by side. An M6 nut is 11.5 mm across its corners (10 mm across flats / cos 30 degrees) and
// falls that far in sqrt(2 s / g) = 48 ms: the shipped 5 per second from a 20 mm region is
// quiet; 50 per second from a 10 mm region, and a rate that spawns every nut within one step,
// are named. (The check took a mesh part's thickness, 5 mm, as its size: 50 per second from 10
// mm passed.)
TEST(SceneCheck, SpawnStreamOverlapCountsTheRegionAgainstAMeshPartsWidth) {
  const std::filesystem::path dir = std::filesystem::path(RHEOFEED_DEMO_DIR) / "scenes";
  Scene s = loadScene(dir / "bowl_feeder_mesh_fill.json");
  ASSERT_EQ(s.parts[0].shape, Shape::Kind::Mesh);
  EXPECT_TRUE(
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnStreamOverlap).empty());
  const double across_corners = 0.010 / std::cos(kPi / 6);
  s.parts[0].rate = 50;
  s.parts[0].spawn_max.x = s.parts[0].spawn_min.x + 0.010;
  std::vector<Hazard> h =
      ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnStreamOverlap);
  ASSERT_EQ(h.size(), 1u);
  // The largest nut the size spread draws, scale 1.1 (its max): it falls its size in 51 ms, and
  // the 10 mm region holds one.
  EXPECT_NEAR(h[0].limit, std::sqrt(2 * 1.1 * across_corners / kG), 1e-9);
  EXPECT_DOUBLE_EQ(h[0].value, 1.0 / 50);
  s = loadScene(dir / "bowl_feeder_mesh_fill.json");
  s.parts[0].rate = 1e9;
  EXPECT_EQ(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::SpawnStreamOverlap).size(),
            1u);
}

TEST(SceneCheck, RestitutionNearOneIsNamed) {
  Scene s = beltScene();
  s.material.restitution = 1.0;
  const std::vector<Hazard> all = checkScene(s, Method::OdeRheonomic);
  const std::vector<Hazard> r = ofKind(all, Hazard::Kind::HighRestitution);
  ASSERT_EQ(r.size(), 1u) << formatHazards(all);
  EXPECT_EQ(r[0].value, 1.0);
  EXPECT_EQ(r[0].where, "material.restitution");
  s.material.restitution = 0.5;
  EXPECT_TRUE(ofKind(checkScene(s, Method::OdeRheonomic), Hazard::Kind::HighRestitution).empty());
}

TEST(SceneCheck, FormatNamesKindPathAndSafeSetting) {
  Hazard h;
  h.kind = Hazard::Kind::Tunnelling;
  h.where = "solver.time_step";
  h.message = "m";
  h.safe_setting = "solver.time_step <= 0.001 s";
  EXPECT_EQ(formatHazards({h}, "demo: "),
            "demo: warning [tunnelling] solver.time_step: m\n"
            "demo:   safe: solver.time_step <= 0.001 s\n");
  EXPECT_EQ(formatHazards({}), "");
}

// Scenes that run well are not flagged. Built-in scenes with their own steps; the demo scenes
// with the steps their demos use (full vibration: the file's step; rheonomic: the step the
// file's comment or the demo gives).
void expectQuiet(const Scene& s, Method m) {
  const std::vector<Hazard> all = checkScene(s, m);
  EXPECT_TRUE(all.empty()) << s.name << " " << toString(m) << " h = " << s.solver.time_step << "\n"
                           << formatHazards(all);
}

TEST(SceneCheck, BuiltInScenesAreQuiet) {
  for (const Scene& s :
       {beltScene(), inclineBeltScene(0.25), turntableScene(), helicalRampScene(1),
        pileOnBeltScene(), troughScene(40, false), troughScene(40, true), linearTroughScene()}) {
    for (Method m : {Method::OdeRheonomic, Method::ReferenceRheonomic}) expectQuiet(s, m);
    if (s.hasVibration()) {
      for (Method m : {Method::OdeFullVibration, Method::ReferenceFullVibration}) expectQuiet(s, m);
    }
  }
  expectQuiet(vibratingTrackScene(), Method::OdeFullVibration);
}

TEST(SceneCheck, DemoScenesAreQuietAtTheirSteps) {
  const std::filesystem::path dir = std::filesystem::path(RHEOFEED_DEMO_DIR) / "scenes";
  const Scene belt = loadScene(dir / "belt_conveyor.json");
  expectQuiet(belt, Method::OdeRheonomic);
  // The turntable's pins are square bars on its cylinder table: quiet (its former capsule pins
  // drew the weak-collider warning, and 5 of 5 went through the table in its 3 s run).
  expectQuiet(loadScene(dir / "turntable.json"), Method::OdeRheonomic);
  Scene trough = loadScene(dir / "linear_vibratory_trough.json");
  expectQuiet(trough, Method::OdeFullVibration);
  // "rheonomic runs can use 0.002" (the file's comment): the check warns about the mass ratio
  // (largest / smallest plate 25.4 against a measured 20 at 30 iterations). The free fall of
  // 0.47 m onto the catch floor is not a hazard: only parts that left over the end fall there
  // (the check looks under the spawn region, where the trough is).
  trough.solver.time_step = 0.002;
  const std::vector<Hazard> at2ms = checkScene(trough, Method::OdeRheonomic);
  ASSERT_EQ(at2ms.size(), 1u) << formatHazards(at2ms);
  EXPECT_EQ(at2ms[0].kind, Hazard::Kind::MassRatio);
  Scene bowl = loadScene(dir / "bowl_feeder.json");
  expectQuiet(bowl, Method::OdeFullVibration);
  // At bowl_feeder's former rheonomic step, 0.005 s, X = 18: the mass ratio is named (nut
  // blanks 1.83 times apart against a measured 1.5 at 40 iterations, the X = 10 row of
  // check_mass_ratio.cpp), and nothing else (the scene now runs at 0.01 s, with no nut lost in
  // 60 s over 4 seeds: demos/results/bowl_feeder.md, section 8).
  bowl.solver.time_step = 0.005;
  const std::vector<Hazard> at5ms = checkScene(bowl, Method::OdeRheonomic);
  ASSERT_EQ(at5ms.size(), 1u) << formatHazards(at5ms);
  EXPECT_EQ(at5ms[0].kind, Hazard::Kind::MassRatio);
  // The bowl's file says that nuts tunnel through its 4 mm ramp at the runner's default 0.01 s
  // without speculative contacts (the default sweeps them).
  bowl.solver.time_step = 0.01;
  EXPECT_TRUE(ofKind(checkScene(bowl, Method::OdeRheonomic), Hazard::Kind::Tunnelling).empty());
  bowl.solver.speculative_contacts = false;
  EXPECT_EQ(ofKind(checkScene(bowl, Method::OdeRheonomic), Hazard::Kind::Tunnelling).size(), 1u);
}

// ---- Mesh wall thickness ---------------------------------------------------------------------

// The all-pairs wall-thickness test the check used before issue 20 (O(n^2)), kept as the
// reference the tree search must equal exactly.
double allPairsWallThickness(const TriangleMesh& mesh, double scale) {
  const std::vector<double>& v = mesh.vertices;
  const std::vector<int>& t = mesh.triangles;
  auto vert = [&](int i) { return scale * Vec3{v[3 * i], v[3 * i + 1], v[3 * i + 2]}; };
  const std::size_t n = t.size() / 3;
  std::vector<std::pair<double, double>> walls;  // thickness, area
  double total_area = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 a = vert(t[3 * i]), b = vert(t[3 * i + 1]), c = vert(t[3 * i + 2]);
    const Vec3 normal = cross(b - a, c - a);
    const double area2 = norm(normal);
    if (!(area2 > 0)) continue;
    const Vec3 dir = (-1.0 / area2) * normal;  // inwards
    const Vec3 origin = (1.0 / 3.0) * (a + b + c);
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const Vec3 p = vert(t[3 * j]), q = vert(t[3 * j + 1]), r = vert(t[3 * j + 2]);
      const Vec3 e1 = q - p, e2 = r - p, pv = cross(dir, e2);
      const double det = dot(e1, pv);
      if (std::abs(det) < 1e-30) continue;
      const Vec3 tv = origin - p;
      const double u = dot(tv, pv) / det;
      if (u < 0 || u > 1) continue;
      const Vec3 qv = cross(tv, e1);
      const double w = dot(dir, qv) / det;
      if (w < 0 || u + w > 1) continue;
      const double dist = dot(e2, qv) / det;
      if (dist > 1e-9 * std::sqrt(area2)) nearest = std::min(nearest, dist);
    }
    total_area += 0.5 * area2;
    if (std::isfinite(nearest)) walls.emplace_back(nearest, 0.5 * area2);
  }
  std::sort(walls.begin(), walls.end());
  double area = 0;
  for (const auto& [thickness, a] : walls) {
    area += a;
    if (area >= kThinShare * total_area) return thickness;
  }
  return walls.empty() ? 0 : walls.back().first;
}

// 400 random triangles in a 10 cm cube: no wall at all, rays crossing every which way.
TriangleMesh triangleSoup() {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> x(0, 0.1);
  TriangleMesh m;
  for (int k = 0; k < 1200; ++k) {
    m.vertices.insert(m.vertices.end(), {x(gen), x(gen), x(gen)});
    m.triangles.push_back(k);
  }
  return m;
}

TEST(SceneCheck, MeshWallThicknessEqualsTheAllPairsTestExactly) {
  const TriangleMesh bowl =
      loadTriangleMesh(std::filesystem::path(RHEOFEED_DEMO_DIR) / "meshes" / "vibratory_bowl.stl");
  const TriangleMesh shell = testing::sphericalShell(0.1, 0.09, 24, 12);
  const TriangleMesh soup = triangleSoup();
  for (const TriangleMesh* m : {&bowl, &shell, &soup}) {
    for (double scale : {1.0, 0.001}) {
      SCOPED_TRACE(m->source + " x " + std::to_string(scale));
      const MeshWallThickness fast = meshWallThickness(*m, scale);
      EXPECT_TRUE(fast.measured);
      EXPECT_EQ(fast.thickness, allPairsWallThickness(*m, scale));  // bit for bit
    }
  }
  // The demo bowl's thinnest real wall is its 4 mm ramp (see check.hpp).
  EXPECT_NEAR(meshWallThickness(bowl, 0.001).thickness, 0.004, 0.0005);  // the STL is in mm
}

TEST(SceneCheck, MeshWallThicknessOfASphericalShellIsItsWall) {
  // 10 mm wall; the facets of 48 x 48 sphere sides sit up to r (1 - cos(pi / 48)) inside their
  // spheres: 0.21 mm for the outer one.
  const double outer = 0.1, inner = 0.09;
  const double facet = outer * (1 - std::cos(std::acos(-1.0) / 48));
  const MeshWallThickness wall =
      meshWallThickness(testing::sphericalShell(outer, inner, 48, 48), 1.0);
  ASSERT_TRUE(wall.measured);
  EXPECT_NEAR(wall.thickness, outer - inner, 2 * facet);
}

TEST(SceneCheck, MeshWallThicknessBeyondItsWorkLimitIsSkippedAndSaid) {
  const MeshWallThickness wall =
      meshWallThickness(testing::sphericalShell(0.1, 0.09, 24, 12), 1.0, 1000);
  EXPECT_FALSE(wall.measured);
  EXPECT_GT(wall.ray_tests, 1000);
}

}  // namespace
}  // namespace rheofeed::scene
