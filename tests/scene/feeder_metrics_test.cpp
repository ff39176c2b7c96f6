// SPDX-License-Identifier: MIT
// Feeder metrics (issue 10): output rate over time, cumulative count, time to the first part
// out, exit orientation per part family. The expectations come from kinematics (free fall from
// a known height with a known initial speed, spawn times i / rate), from the geometry of
// rotations (which body axis a 90 degree turn brings up) and from drawParts, not from the code
// under test.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>

#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kGravity = 9.81;  // m/s^2
const Method kRheonomic[] = {Method::OdeRheonomic, Method::ReferenceRheonomic};

// ---- Which body axis points up ------------------------------------------------------------

// Rotation about a world axis by `degrees` (right hand), row-major body to world.
void rotation(char axis, double degrees, double r[9]) {
  const double a = degrees * 3.14159265358979323846 / 180, c = std::cos(a), s = std::sin(a);
  const double x[9] = {1, 0, 0, 0, c, -s, 0, s, c};
  const double y[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
  const double z[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
  const double* m = axis == 'x' ? x : axis == 'y' ? y : z;
  for (int k = 0; k < 9; ++k) r[k] = m[k];
}

TEST(FeederMetrics, UpAxisOfBoxesTurnedByRightAngles) {
  const Vec3 up{0, 0, 1};
  double r[9];
  rotation('z', 0, r);
  EXPECT_EQ(upAxis(r, up), UpAxis::PlusZ);  // not turned: its own z is up
  rotation('x', 90, r);                     // +90 about x takes body y to world z
  EXPECT_EQ(upAxis(r, up), UpAxis::PlusY);
  rotation('x', -90, r);  // -90 about x takes body -y to world z
  EXPECT_EQ(upAxis(r, up), UpAxis::MinusY);
  rotation('y', 90, r);  // +90 about y takes body x to world -z, body -x to +z
  EXPECT_EQ(upAxis(r, up), UpAxis::MinusX);
  rotation('y', -90, r);
  EXPECT_EQ(upAxis(r, up), UpAxis::PlusX);
  rotation('x', 180, r);  // upside down
  EXPECT_EQ(upAxis(r, up), UpAxis::MinusZ);
  rotation('x', 30, r);  // tilted by less than 45 degrees: z is still the nearest axis to up
  EXPECT_EQ(upAxis(r, up), UpAxis::PlusZ);
  rotation('x', 60, r);  // more than 45 degrees: body y is nearer
  EXPECT_EQ(upAxis(r, up), UpAxis::PlusY);
  rotation('z', 0, r);
  EXPECT_EQ(upAxis(r, Vec3{1, 0, 0}), UpAxis::PlusX);  // gravity along -x: x is up
  EXPECT_EQ(upAxis(r, Vec3{0, -1, 0}), UpAxis::MinusY);
}

TEST(FeederMetrics, UpIsAgainstGravity) {
  const Vec3 up = upDirection({0, 0, -9.81});
  EXPECT_DOUBLE_EQ(up.z, 1);
  const Vec3 sideways = upDirection({3, 0, 4});
  EXPECT_DOUBLE_EQ(sideways.x, -0.6);
  EXPECT_DOUBLE_EQ(sideways.z, -0.8);
  EXPECT_DOUBLE_EQ(upDirection({0, 0, 0}).z, 1);  // no gravity: +z, as documented
}

// ---- Rate windows -------------------------------------------------------------------------

TEST(FeederMetrics, RateWindowsCountExitsAndAccumulate) {
  // Exits at 0.05, 0.15, 0.16, 0.35 s in windows of 0.1 s over 0.35 s: windows [0, 0.1),
  // [0.1, 0.2), [0.2, 0.3), [0.3, 0.35] with 1, 2, 0, 1 exits.
  const std::vector<RateWindow> w = exitRate({0.05, 0.15, 0.16, 0.35}, 0.35, 0.1);
  ASSERT_EQ(w.size(), 4u);
  const int exits[] = {1, 2, 0, 1}, cumulative[] = {1, 3, 3, 4};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(w[k].exits, exits[k]) << k;
    EXPECT_EQ(w[k].cumulative, cumulative[k]) << k;
  }
  EXPECT_NEAR(w[1].rate_per_min, 2 / 0.1 * 60, 1e-9);
  EXPECT_NEAR(w[3].end, 0.35, 1e-15);  // the last window is the short one
  EXPECT_NEAR(w[3].rate_per_min, 1 / 0.05 * 60, 1e-9);
  // 50 windows over a run, none shorter than a sample.
  EXPECT_DOUBLE_EQ(exitRateWindow(2.0, 0.01), 0.04);
  EXPECT_DOUBLE_EQ(exitRateWindow(0.2, 0.01), 0.01);
}

TEST(FeederMetrics, BadRateWindowIsRefusedNamingTheValue) {
  try {
    exitRate({}, 1.0, -0.5);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("window = -0.5 s"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("> 0"), std::string::npos) << e.what();
  }
  EXPECT_THROW(exitRate({}, std::numeric_limits<double>::quiet_NaN(), 0.1), std::invalid_argument);
}

TEST(FeederMetrics, PartFamiliesFollowTheSpawnOrderOfDrawParts) {
  Scene s;
  s.parts.resize(3);
  s.parts[0].count = 4;
  s.parts[0].rate = 10;
  s.parts[1].count = 3;  // all at t = 0
  s.parts[2].count = 5;
  s.parts[2].rate = 25;
  for (std::size_t k = 0; k < 3; ++k) {
    s.parts[k].spawn_min = {0, 0, double(k)};
    s.parts[k].spawn_max = {1, 1, double(k) + 1};
  }
  const std::vector<PartInstance> drawn = drawParts(s);
  const std::vector<int> family = partFamilies(s);
  ASSERT_EQ(family.size(), drawn.size());
  for (std::size_t i = 0; i < drawn.size(); ++i) EXPECT_EQ(family[i], drawn[i].spec) << i;
}

// ---- A known exit flow: cubes thrown down through a horizontal exit plane -----------------

// Cuboids (10 x 20 x 30 mm) spawned at height kDrop above the exit plane z = 0 (normal -z,
// pointing out), anywhere in a kSpread square across the fall, thrown down at kThrow, kRate per
// second. No fixture: each falls freely, and the crossing time is t = (sqrt(v0^2 + 2 g H) - v0)
// / g after its spawn. At kRate the previous part is already v0 / kRate + g / (2 kRate^2) =
// 42 mm lower when the next spawns, more than the 30 mm longest edge: they never touch.
constexpr double kDrop = 0.5, kThrow = 2.0, kRate = 50, kStep = 1e-3, kEdge = 0.01;
constexpr int kCount = 60;
constexpr double kDuration = 2.0;
// Side of the spawn square across the fall (m): larger than a part, so that the scene check
// (spawn_stream_overlap, which does not credit the initial speed) sees no overlap.
constexpr double kSpread = 0.2;
// Semi-implicit Euler (both engines, no contact) drops v0 t + g t (t + h) / 2 by the step times
// t = n h: it leads the analytic fall and crosses the plane earlier, by g T h / (2 (v0 + g T))
// < h / 2. One step bounds the difference from the analytic crossing.
constexpr double kCrossingTolerance = kStep;
// The crossing time is interpolated linearly between the two steps around it; the discrete
// positions lie on the parabola above, whose curvature g makes the linear interpolation miss its
// zero by at most (g / 2)(h / 2)^2 / v0 (the speed is at least v0).
constexpr double kInterpolationTolerance = 0.5 * kGravity * 0.25 * kStep * kStep / kThrow;
// A spawn or a crossing within a step of a window boundary can be counted on either side.
constexpr int kCountSlack = 1;

double analyticCrossing() {
  return (std::sqrt(kThrow * kThrow + 2 * kGravity * kDrop) - kThrow) / kGravity;
}

// Where the semi-implicit Euler parabola H = v0 t + g t (t + h) / 2 reaches the plane.
double discreteCrossing() {
  const double b = kThrow + 0.5 * kGravity * kStep;
  return (std::sqrt(b * b + 2 * kGravity * kDrop) - b) / kGravity;
}

PartSpec fallingCubes(const std::string& name, int count, double rate) {
  PartSpec p;
  p.name = name;
  p.shape = Shape::Kind::Box;
  p.size[0].mean = kEdge;
  p.size[1].mean = 2 * kEdge;  // distinct edges: the body axes are not interchangeable
  p.size[2].mean = 3 * kEdge;
  p.density = 1000;
  p.count = count;
  p.rate = rate;
  p.random_orientation = false;  // body frame = world frame at spawn
  return p;
}

// Parts fall along `down` (unit) from kDrop above the exit plane through the origin.
Scene dropScene(const Vec3& down) {
  Scene s;
  s.name = "drop";
  s.gravity = kGravity * down;
  PartSpec p = fallingCubes("cubes", kCount, kRate);
  // The spawn square spans the two axes across `down` (a world axis).
  const Vec3 across{1 - std::abs(down.x), 1 - std::abs(down.y), 1 - std::abs(down.z)};
  p.spawn_min = -kDrop * down - 0.5 * kSpread * across;
  p.spawn_max = -kDrop * down + 0.5 * kSpread * across;
  p.initial_velocity = kThrow * down;
  s.parts.push_back(p);
  s.solver.time_step = kStep;
  s.duration = kDuration;
  s.outputs.exit_plane = true;
  s.outputs.exit_point = {0, 0, 0};
  s.outputs.exit_normal = down;
  return s;
}

TEST(FeederMetrics, FirstExitRateAndCountOfAFreeFallFlowMatchKinematics) {
  const double crossing = analyticCrossing();  // 0.175 s
  const double discrete = discreteCrossing();  // 0.23 ms earlier
  for (Method m : kRheonomic) {
    SCOPED_TRACE(toString(m));
    const Scene s = dropScene({0, 0, -1});
    const RunMetrics r = measureRun(s, m);
    const FeederMetrics& f = r.feeder;
    ASSERT_TRUE(f.exit_plane);
    EXPECT_TRUE(f.note.empty()) << f.note;
    EXPECT_EQ(r.health.partsLost(), 0);
    EXPECT_NEAR(f.first_exit_time, crossing, kCrossingTolerance);
    ASSERT_EQ(f.exit_times.size(), static_cast<std::size_t>(kCount));
    EXPECT_NEAR(f.first_exit_time, discrete, kInterpolationTolerance);
    // Every part crosses `crossing` after its spawn at i / rate.
    for (int i = 0; i < kCount; ++i) {
      EXPECT_NEAR(f.exit_times[static_cast<std::size_t>(i)], i / kRate + discrete,
                  kInterpolationTolerance)
          << i;
    }
    // Windows of max(sample interval, duration / 50) = 0.04 s.
    EXPECT_DOUBLE_EQ(f.rate_window, kDuration / kRateWindowsPerRun);
    ASSERT_EQ(f.rate.size(), static_cast<std::size_t>(kRateWindowsPerRun));
    const double last_crossing = (kCount - 1) / kRate + crossing;
    for (const RateWindow& w : f.rate) {
      int expected = 0;  // analytic arrivals before the window's end
      for (int i = 0; i < kCount; ++i) expected += i / kRate + crossing < w.end ? 1 : 0;
      EXPECT_NEAR(w.cumulative, expected, kCountSlack) << "window ending " << w.end;
      if (w.start > crossing + kStep && w.end < last_crossing - kStep) {
        // Inside the steady flow: the spawn rate, within one part per window.
        EXPECT_NEAR(w.rate_per_min, 60 * kRate, 60.0 * kCountSlack / (w.end - w.start))
            << "window ending " << w.end;
      }
      if (w.end < crossing - kStep) {
        EXPECT_EQ(w.exits, 0) << "window ending " << w.end;
      }
    }
    EXPECT_EQ(f.rate.back().cumulative, kCount);
    // From the first to the last exit the flow is the spawn rate: kCount - 1 intervals of
    // 1 / kRate, each exact to twice the interpolation tolerance.
    const double span = (kCount - 1) / kRate;
    EXPECT_NEAR(f.mean_rate_per_min, 60 * kRate,
                60 * kRate * 2 * kInterpolationTolerance / (span - 2 * kInterpolationTolerance));
    ASSERT_EQ(f.families.size(), 1u);
    EXPECT_EQ(f.families[0].spawned, kCount);
    EXPECT_EQ(f.families[0].exited, kCount);
    EXPECT_EQ(f.families[0].removed_without_exit, 0);
  }
}

TEST(FeederMetrics, UnturnedBoxesFallingThroughTheExitCountAsTheAxisAgainstGravity) {
  // Not turned, a body axis is a world axis: with gravity along -z the body z points up, with
  // gravity along -x the body x, with gravity along +y the body -y.
  const std::pair<Vec3, UpAxis> cases[] = {
      {{0, 0, -1}, UpAxis::PlusZ}, {{-1, 0, 0}, UpAxis::PlusX}, {{0, 1, 0}, UpAxis::MinusY}};
  for (const auto& [down, expected] : cases) {
    SCOPED_TRACE(toString(expected));
    Scene s = dropScene(down);
    s.duration = 0.5;
    s.parts[0].count = 5;
    const RunMetrics r = measureRun(s, Method::OdeRheonomic);
    ASSERT_EQ(r.feeder.families.size(), 1u);
    const FamilyExits& f = r.feeder.families[0];
    EXPECT_EQ(f.exited, 5);
    for (int a = 0; a < kUpAxisCount; ++a) {
      EXPECT_EQ(f.up_axis[static_cast<std::size_t>(a)], a == static_cast<int>(expected) ? 5 : 0)
          << toString(static_cast<UpAxis>(a));
    }
    EXPECT_TRUE(f.orientation_meaningful);
  }
}

TEST(FeederMetrics, FamiliesAreCountedSeparatelyAndSpheresSaidMeaningless) {
  Scene s = dropScene({0, 0, -1});
  s.duration = 0.6;
  s.parts[0].count = 6;
  PartSpec balls = fallingCubes("balls", 4, 20);
  balls.shape = Shape::Kind::Sphere;
  balls.size[0].mean = 0.005;
  balls.spawn_min = {0.3, -0.1, kDrop};
  balls.spawn_max = {0.5, 0.1, kDrop};
  balls.initial_velocity = {0, 0, -kThrow};
  s.parts.push_back(balls);
  PartSpec tumbling = fallingCubes("tumbling", 12, 40);
  tumbling.random_orientation = true;
  tumbling.spawn_min = {-0.5, -0.1, kDrop};
  tumbling.spawn_max = {-0.3, 0.1, kDrop};
  tumbling.initial_velocity = {0, 0, -kThrow};
  s.parts.push_back(tumbling);
  const RunMetrics r = measureRun(s, Method::ReferenceRheonomic);
  ASSERT_EQ(r.feeder.families.size(), 3u);
  const FamilyExits &cubes = r.feeder.families[0], &spheres = r.feeder.families[1],
                    &random = r.feeder.families[2];
  EXPECT_EQ(cubes.exited, 6);
  EXPECT_EQ(cubes.up_axis[static_cast<std::size_t>(UpAxis::PlusZ)], 6);
  EXPECT_EQ(spheres.spawned, 4);
  EXPECT_EQ(spheres.exited, 4);
  EXPECT_FALSE(spheres.orientation_meaningful);
  EXPECT_EQ(spheres.up_axis[static_cast<std::size_t>(UpAxis::PlusZ)], 4);  // still counted
  EXPECT_EQ(random.spawned, 12);
  EXPECT_EQ(random.exited, 12);
  int sum = 0, bins_used = 0;
  for (int n : random.up_axis) {
    sum += n;
    bins_used += n > 0 ? 1 : 0;
  }
  EXPECT_EQ(sum, 12);
  EXPECT_GE(bins_used, 2);  // random orientations do not all point one way
  EXPECT_EQ(r.feeder.exit_times.size(), 22u);
}

// Two families may share a name; the outputs must still tell them apart: the second goes by
// "cubes[1]" in the feeder metrics (and so in the part events and drift fields, familyKeys).
TEST(FeederMetrics, FamiliesThatShareANameAreToldApartByTheirIndex) {
  Scene s = dropScene({0, 0, -1});
  s.duration = 0.6;
  s.parts[0].count = 3;
  PartSpec twin = s.parts[0];
  twin.count = 2;
  s.parts.push_back(twin);
  EXPECT_EQ(familyKeys(s.parts),
            (std::vector<std::string>{s.parts[0].name, s.parts[0].name + "[1]"}));
  const RunMetrics r = measureRun(s, Method::ReferenceRheonomic);
  ASSERT_EQ(r.feeder.families.size(), 2u);
  EXPECT_EQ(r.feeder.families[0].name, s.parts[0].name);
  EXPECT_EQ(r.feeder.families[1].name, s.parts[0].name + "[1]");
  EXPECT_EQ(r.feeder.families[0].spawned, 3);
  EXPECT_EQ(r.feeder.families[1].spawned, 2);
  // Unique already: unchanged; a name taken by an earlier suffixed one is suffixed too.
  EXPECT_EQ(uniqueNames({"a", "a[1]", "b"}), (std::vector<std::string>{"a", "a[1]", "b"}));
  EXPECT_EQ(uniqueNames({"a", "a", "a[1]"}), (std::vector<std::string>{"a", "a[1]", "a[1][2]"}));
  EXPECT_EQ(uniqueNames({"a[2]", "a", "a"}), (std::vector<std::string>{"a[2]", "a", "a[2][2]"}));
}

// A library caller's run of a loaded scene names its file like `rheofeed run` does.
TEST(FeederMetrics, ARunNamesTheFileItsSceneWasLoadedFrom) {
  Scene s = dropScene({0, 0, -1});
  s.duration = 0.1;
  EXPECT_EQ(measureRun(s, Method::OdeRheonomic).scene_file, "");  // built in code
  s.source_file = "/data/scenes/drop.json";
  EXPECT_EQ(measureRun(s, Method::OdeRheonomic).scene_file, "/data/scenes/drop.json");
}

TEST(FeederMetrics, NoPartReachingTheExitIsSaid) {
  Scene s = dropScene({0, 0, -1});
  s.duration = 0.1;  // shorter than the 0.175 s fall
  s.parts[0].count = 3;
  const RunMetrics r = measureRun(s, Method::OdeRheonomic);
  EXPECT_TRUE(std::isnan(r.feeder.first_exit_time));
  EXPECT_TRUE(r.feeder.exit_times.empty());
  EXPECT_EQ(r.feeder.note, "no part reached the exit in 0.1 s");
  const nlohmann::json j = nlohmann::json::parse(summaryJson(r));
  EXPECT_TRUE(j["feeder"]["first_exit_time_s"].is_null());
  EXPECT_EQ(j["feeder"]["note"], "no part reached the exit in 0.1 s");
  EXPECT_EQ(j["feeder"]["parts_exited"], 0);
  EXPECT_TRUE(j["feeder"]["mean_exit_rate_per_min"].is_null());
}

TEST(FeederMetrics, SceneWithoutExitPlaneSaysSoAndWritesNoExitFiles) {
  Scene s = dropScene({0, 0, -1});
  s.outputs.exit_plane = false;
  s.duration = 0.3;
  s.parts[0].count = 2;
  const RunMetrics r = measureRun(s, Method::OdeRheonomic);
  EXPECT_FALSE(r.feeder.exit_plane);
  EXPECT_NE(r.feeder.note.find("no exit plane"), std::string::npos) << r.feeder.note;
  EXPECT_TRUE(r.feeder.exit_times.empty());
  EXPECT_EQ(r.feeder.families.at(0).spawned, 2);  // the families are still counted
  EXPECT_TRUE(writeFeederOutputs(r.feeder, "unused", "x", "t").empty());
}

TEST(FeederMetrics, JsonAndCsvCarryTheFeederMetrics) {
  Scene s = dropScene({0, 0, -1});
  s.duration = 0.5;
  s.parts[0].count = 10;
  const RunMetrics r = measureRun(s, Method::OdeRheonomic);
  const nlohmann::json j = nlohmann::json::parse(summaryJson(r));
  const nlohmann::json& f = j.at("feeder");
  EXPECT_EQ(f.at("exit_plane"), true);
  EXPECT_NEAR(f.at("first_exit_time_s").get<double>(), analyticCrossing(), kCrossingTolerance);
  EXPECT_EQ(f.at("parts_exited"), 10);
  EXPECT_EQ(f.at("exit_orientation").at("cubes").at("+z"), 10);
  EXPECT_EQ(f.at("exit_orientation").at("cubes").at("-x"), 0);
  EXPECT_EQ(f.at("families").at("cubes").at("spawned"), 10);
  const nlohmann::json& rate = f.at("exit_rate_per_min");
  ASSERT_EQ(rate.size(), r.feeder.rate.size());
  EXPECT_EQ(rate.back().at("cumulative_exits"), 10);

  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rheofeed_feeder_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::vector<std::string> written = writeRunOutputs(r, dir.string(), "run");
  const std::filesystem::path exits = dir / "run_exits.csv";
  ASSERT_TRUE(std::filesystem::exists(exits));
  std::ifstream in(exits);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header, "window_start_s,window_end_s,exits,rate_per_min,cumulative_exits");
  int rows = 0, last_cumulative = -1;
  while (std::getline(in, line)) {
    ++rows;
    last_cumulative = std::stoi(line.substr(line.rfind(',') + 1));
  }
  EXPECT_EQ(rows, static_cast<int>(r.feeder.rate.size()));
  EXPECT_EQ(last_cumulative, 10);
  EXPECT_TRUE(std::filesystem::exists(dir / "run_orientation.csv"));
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().string().find(".partial"), std::string::npos) << entry.path();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rheofeed::scene
