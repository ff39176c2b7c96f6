// SPDX-License-Identifier: MIT
// Limits where input enters (issue 9): scene values beyond what ODE and the solvers represent,
// scene and mesh files that are not regular files or too large, degenerate meshes. Each
// refusal must name the JSON path (or the file), the value and the allowed range; the expected
// ranges are the ones scene.hpp documents. The repository's own scenes (demos/scenes/*.json and
// builtin_scenes.hpp) must all pass the limits.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>

#include "common/builtin_scenes.hpp"
#include "rheofeed/scene/mesh.hpp"
#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;

const fs::path kData = RHEOFEED_IO_TEST_DATA;
const fs::path kDemoScenes = fs::path(RHEOFEED_DEMO_DIR) / "scenes";

// A valid scene with every section the tests break: a vibrating track, a belt, a drift
// turntable, two part families and an exit plane.
const char* kGood = R"({
  "fixtures": [
    {"name": "track", "geoms": [{"shape": "box", "size": [1, 0.1, 0.02], "position": [0, 0, -0.01]}],
     "law": {"vibration": {"amplitude": 2e-4, "frequency": 50, "angle_deg": 20}}},
    {"name": "belt", "geoms": [{"shape": "box", "size": [1, 0.1, 0.02], "position": [0, 1, -0.01]}],
     "law": {"belt": {"direction": [1, 0, 0], "speed": 0.3}}},
    {"name": "table", "geoms": [{"shape": "cylinder", "radius": 0.2, "length": 0.02,
                                 "position": [0, 2, -0.01]}],
     "law": {"drift": {"linear": [0, 0, 0], "angular": [0, 0, 1], "origin": [0, 2, 0]}}},
    {"name": "floor", "geoms": [{"shape": "plane", "normal": [0, 0, 1], "offset": -0.5}]}
  ],
  "parts": [{"shape": "box", "size": [0.02, 0.02, 0.005], "density": 7800,
             "spawn_min": [0, 0, 0.003], "spawn_max": [0.1, 0.05, 0.003], "count": 3,
             "initial_velocity": [0, 0, 0]},
            {"shape": "sphere", "size": [{"mean": 0.004, "stddev": 0.0005, "min": 0.003, "max": 0.005}],
             "spawn_min": [0.3, 0, 0.005], "spawn_max": [0.3, 0, 0.005]}],
  "material": {"mu": 0.5, "restitution": 0.1},
  "solver": {"time_step": 0.001, "iterations": 50, "coulomb_iterations": 10,
             "max_correcting_velocity": 0.5, "surface_layer": 1e-4},
  "outputs": {"exit_plane": true, "exit_point": [0.5, 0, 0], "exit_normal": [1, 0, 0],
              "sample_interval": 0.01, "warmup": 0.2},
  "removal_height": -1,
  "duration": 1
})";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

// Parses `text` as "bad.json" and expects a refusal at `path` whose message contains every
// one of `parts` (the value and the allowed range).
void refused(const std::string& text, const std::string& path,
             std::initializer_list<std::string> parts) {
  try {
    parseScene(text, "bad.json");
    ADD_FAILURE() << "accepted; expected a refusal at " << path;
  } catch (const SceneFileError& e) {
    EXPECT_EQ(e.path(), path) << e.what();
    EXPECT_EQ(e.source(), "bad.json") << e.what();
    for (const std::string& p : parts) {
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos)
          << "message: " << e.what() << "\nmissing: " << p;
    }
  }
}

// Expects loadScene(file) to be refused with a message naming the file and containing `what`.
void fileRefused(const fs::path& file, const std::string& what) {
  try {
    loadScene(file);
    ADD_FAILURE() << "accepted " << file;
  } catch (const SceneFileError& e) {
    EXPECT_EQ(e.source(), file.string()) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos)
        << "message: " << e.what() << "\nmissing: " << what;
  }
}

fs::path tempDir() {
  const fs::path dir = fs::path(testing::TempDir()) / "rheofeed_bad_scene_test";
  fs::create_directories(dir);
  return dir;
}

fs::path writeFile(const std::string& name, const std::string& text) {
  const fs::path path = tempDir() / name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// ---- The repository's scenes pass -------------------------------------------------------------

TEST(SceneLimits, TheTestSceneIsAccepted) {
  EXPECT_NO_THROW(parseScene(kGood, "good.json"));
}

TEST(SceneLimits, EveryDemoSceneFileIsAccepted) {
  int files = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kDemoScenes)) {
    if (entry.path().extension() != ".json") continue;
    ++files;
    EXPECT_NO_THROW(loadScene(entry.path())) << entry.path();
  }
  EXPECT_GE(files, 4);  // belt, bowl, trough, turntable
}

TEST(SceneLimits, EveryBuiltinSceneIsAccepted) {
  const Scene scenes[] = {beltScene(),
                          beltScene(10),
                          inclineBeltScene(0.3),
                          turntableScene(),
                          turntableScene(50),
                          helicalRampScene(1),
                          helicalRampScene(-1),
                          pileOnBeltScene(),
                          pileOnBeltScene(100),
                          vibratingTrackScene(),
                          vibratingTrackScene(0.02e-3, 500, 0.349066, 4),
                          linearTroughScene(),
                          troughScene(),
                          troughScene(40, true)};
  for (const Scene& s : scenes) {
    EXPECT_NO_THROW(s.validate()) << s.name;
    EXPECT_NO_THROW(drawParts(s)) << s.name;
  }
}

// ---- Positions: ODE's hash space ----------------------------------------------------------------

TEST(SceneLimits, GeomPositionBeyondTheHashSpaceIsRefused) {
  refused(replaced(kGood, "[0, 0, -0.01]", "[3e9, 0, -0.01]"), "fixtures[0].geoms[0].position.x",
          {"3e+09", "[-1e+06, 1e+06] m"});
}

TEST(SceneLimits, SpawnBoundBeyondTheHashSpaceIsRefused) {
  refused(
      replaced(kGood, R"("spawn_max": [0.1, 0.05, 0.003])", R"("spawn_max": [0.1, 5e9, 0.003])"),
      "parts[0].spawn_max.y", {"5e+09", "[-1e+06, 1e+06] m"});
}

TEST(SceneLimits, ExitPointBeyondTheHashSpaceIsRefused) {
  refused(replaced(kGood, "[0.5, 0, 0]", "[0.5, 0, -2e7]"), "outputs.exit_point.z",
          {"-2e+07", "[-1e+06, 1e+06] m"});
}

TEST(SceneLimits, DriftAxisOriginBeyondTheHashSpaceIsRefused) {
  refused(replaced(kGood, R"("origin": [0, 2, 0])", R"("origin": [0, 1e8, 0])"),
          "fixtures[2].law.drift.origin.y", {"1e+08", "[-1e+06, 1e+06] m"});
}

TEST(SceneLimits, PlaneOffsetAndRemovalHeightBeyondTheHashSpaceAreRefused) {
  refused(replaced(kGood, R"("offset": -0.5)", R"("offset": -5e6)"), "fixtures[3].geoms[0].offset",
          {"-5e+06", "[-1e+06, 1e+06] m"});
  refused(replaced(kGood, R"("removal_height": -1)", R"("removal_height": -1e300)"),
          "removal_height", {"-1e+300", "[-1e+06, 1e+06] m"});
}

// ---- Sizes and densities: mass and inertia stay representable -----------------------------------

TEST(SceneLimits, TinyPartSizeIsRefused) {
  refused(replaced(kGood, "[0.02, 0.02, 0.005]", "[1e-300, 0.02, 0.005]"), "parts[0].size[0].mean",
          {"1e-300", "[1e-05, 1000] m"});
}

TEST(SceneLimits, HugePartSizeIsRefused) {
  refused(replaced(kGood, "[0.02, 0.02, 0.005]", "[0.02, 0.02, 1e300]"), "parts[0].size[2].mean",
          {"1e+300", "[1e-05, 1000] m"});
}

TEST(SceneLimits, FixtureSizesOutsideTheSizeRangeAreRefused) {
  refused(replaced(kGood, "[1, 0.1, 0.02]", "[1e4, 0.1, 0.02]"), "fixtures[0].geoms[0].size.x",
          {"10000", "[1e-05, 1000] m"});
  refused(replaced(kGood, R"("radius": 0.2)", R"("radius": 1e-7)"), "fixtures[2].geoms[0].radius",
          {"1e-07", "[1e-05, 1000] m"});
}

TEST(SceneLimits, HugeDensityIsRefused) {
  refused(replaced(kGood, R"("density": 7800)", R"("density": 1e300)"), "parts[0].density",
          {"1e+300", "[0.001, 1e+06] kg/m^3"});
  refused(replaced(kGood, R"("density": 7800)", R"("density": 1e150)"), "parts[0].density",
          {"1e+150", "[0.001, 1e+06] kg/m^3"});
}

TEST(SceneLimits, TinyDensityIsRefused) {
  refused(replaced(kGood, R"("density": 7800)", R"("density": 1e-300)"), "parts[0].density",
          {"1e-300", "[0.001, 1e+06] kg/m^3"});
}

// ---- Speeds: the contact's motion1 and fdir1 stay finite ----------------------------------------

TEST(SceneLimits, BeltSpeedBeyondTheSpeedBoundIsRefused) {
  refused(replaced(kGood, R"("speed": 0.3)", R"("speed": 1e154)"), "fixtures[1].law.belt.speed",
          {"1e+154", "[-1000, 1000] m/s"});
}

TEST(SceneLimits, DriftSpeedsBeyondTheBoundsAreRefused) {
  refused(replaced(kGood, R"("linear": [0, 0, 0], "angular": [0, 0, 1])",
                   R"("linear": [1e154, 0, 0], "angular": [0, 0, 1])"),
          "fixtures[2].law.drift.linear", {"magnitude", "1e+154", "<= 1000 m/s"});
  refused(replaced(kGood, R"("angular": [0, 0, 1])", R"("angular": [0, 0, 2e4])"),
          "fixtures[2].law.drift.angular", {"magnitude", "20000", "<= 10000 rad/s"});
}

TEST(SceneLimits, InitialVelocityBeyondTheSpeedBoundIsRefused) {
  refused(replaced(kGood, R"("initial_velocity": [0, 0, 0])", R"("initial_velocity": [0, 3e3, 0])"),
          "parts[0].initial_velocity", {"magnitude", "3000", "<= 1000 m/s"});
}

TEST(SceneLimits, VibrationPeakSpeedBeyondTheSpeedBoundIsRefused) {
  // 2 pi 50 Hz 10 m = 3142 m/s.
  refused(replaced(kGood, R"("amplitude": 2e-4)", R"("amplitude": 10)"),
          "fixtures[0].law.vibration.amplitude", {"3141.59", "<= 1000 m/s"});
}

TEST(SceneLimits, VibrationFrequencyBeyondUltrasoundIsRefused) {
  refused(replaced(kGood, R"("frequency": 50)", R"("frequency": 1e7)"),
          "fixtures[0].law.vibration.frequency", {"1e+07", "[0, 100000] Hz"});
}

TEST(SceneLimits, GravityAndCorrectingVelocityBeyondTheirBoundsAreRefused) {
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1, "gravity": [0, 0, -1e5])"),
          "gravity", {"magnitude", "100000", "<= 1000 m/s^2"});
  refused(replaced(kGood, R"("max_correcting_velocity": 0.5)", R"("max_correcting_velocity": 1e9)"),
          "solver.max_correcting_velocity", {"1e+09", "[0, 1000] m/s"});
}

// ---- Steps, iterations and samples: no hang, no empty run ---------------------------------------

TEST(SceneLimits, TinyTimeStepIsRefused) {
  refused(replaced(kGood, R"("time_step": 0.001)", R"("time_step": 1e-12)"), "solver.time_step",
          {"1e-12", "[1e-06, 1] s"});
}

TEST(SceneLimits, TimeStepLongerThanTheDurationIsRefused) {
  refused(replaced(replaced(kGood, R"("time_step": 0.001)", R"("time_step": 0.5)"),
                   R"("duration": 1)", R"("duration": 0.1)"),
          "duration", {"0.1", "must be >= solver.time_step (0.5 s)", "no step"});
}

TEST(SceneLimits, DurationOfAstronomicalStepCountIsRefused) {
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1e300)"), "duration",
          {"1e+300", "would take 1e+303 steps", "at most 1e+09 steps"});
}

// Integer settings are named in full (2000000000, not 2e+09), with their range.
TEST(SceneLimits, IterationCountsBeyondTheirCapsAreRefused) {
  refused(replaced(kGood, R"("iterations": 50)", R"("iterations": 2e9)"), "solver.iterations",
          {"got 2000000000", "[1, 1000000]"});
  refused(replaced(kGood, R"("coulomb_iterations": 10)", R"("coulomb_iterations": 1e7)"),
          "solver.coulomb_iterations", {"got 10000000", "[0, 1000000]"});
}

TEST(SceneLimits, SampleIntervalLongerThanTheDurationIsRefused) {
  refused(replaced(kGood, R"("sample_interval": 0.01)", R"("sample_interval": 5)"),
          "outputs.sample_interval", {"5", "must be <= duration (1 s)", "no sample"});
}

TEST(SceneLimits, WarmupLongerThanTheDurationIsRefused) {
  refused(replaced(kGood, R"("warmup": 0.2)", R"("warmup": 1)"), "outputs.warmup",
          {"must be <= duration - solver.time_step (0.999 s)", "no drift"});
}

// Issue 20: absurd values that were accepted without a word.

TEST(SceneLimits, SampleIntervalShorterThanTheStepIsRefusedNamingBoth) {
  refused(replaced(kGood, R"("sample_interval": 0.01)", R"("sample_interval": 1e-12)"),
          "outputs.sample_interval", {"1e-12", ">= solver.time_step (0.001 s)"});
}

TEST(SceneLimits, AngleBeyondAMillionDegreesIsRefusedWithItsRange) {
  refused(replaced(kGood, R"("angle_deg": 20)", R"("angle_deg": 1e300)"),
          "fixtures[0].law.vibration.angle_deg", {"1e+300", "[-1000000, 1000000] degrees"});
  refused(replaced(kGood, R"("angle_deg": 20)", R"("angle_rad": -1e7)"),
          "fixtures[0].law.vibration.angle_rad", {"-10000000", "17453.29252", "rad"});
  // The edge of the range is accepted (a phase; a throw angle must be within one turn).
  EXPECT_NO_THROW(parseScene(
      replaced(kGood, R"("angle_deg": 20)", R"("angle_deg": 20, "phase_deg": 1e6)"), "ok"));
}

// A torsion beyond half a turn is named in the unit it was given in.
TEST(SceneLimits, TorsionBeyondHalfATurnIsRefusedInItsOwnUnit) {
  refused(replaced(kGood, R"("angle_deg": 20)", R"("angle_deg": 20, "torsion_amplitude_deg": 400)"),
          "fixtures[0].law.vibration.torsion_amplitude_deg",
          {"at most half a turn, 180 degrees or pi rad, got 400 degrees"});
  refused(replaced(kGood, R"("angle_deg": 20)", R"("angle_deg": 20, "torsion_amplitude_rad": 4)"),
          "fixtures[0].law.vibration.torsion_amplitude_rad", {"got 4 rad"});
}

TEST(SceneLimits, GeomRotationAngleBeyondTheRangeIsRefused) {
  refused(
      replaced(kGood, R"("position": [0, 1, -0.01]})",
               R"("position": [0, 1, -0.01], "rotation": {"axis": [0, 0, 1], "angle_deg": -2e6}})"),
      "fixtures[1].geoms[0].rotation.angle_deg", {"-2000000", "degrees"});
}

TEST(SceneLimits, RemovalHeightAboveEverySpawnPointIsRefused) {
  // The highest spawn point: parts[1] at z = 0.005 m.
  refused(replaced(kGood, R"("removal_height": -1)", R"("removal_height": 0.01)"), "removal_height",
          {"0.01", "above every spawn point", "z = 0.005 m"});
  // Above one family's region only: accepted (the scene check warns, spawn_below_removal).
  EXPECT_NO_THROW(
      parseScene(replaced(kGood, R"("removal_height": -1)", R"("removal_height": 0.004)"), "ok"));
}

TEST(SceneLimits, HugeVectorMagnitudeIsPrintedAsANumber) {
  // |(1e300, 1e300, 0)| = 1.414e300 is finite; its square is not.
  try {
    parseScene(replaced(kGood, R"("initial_velocity": [0, 0, 0])",
                        R"("initial_velocity": [1e300, 1e300, 0])"),
               "bad.json");
    ADD_FAILURE() << "accepted";
  } catch (const SceneFileError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("1.41421e+300"), std::string::npos) << what;
    EXPECT_EQ(what.find("inf"), std::string::npos) << what;
  }
}

TEST(SceneFileLimits, SyntaxErrorQuotesAtMostALineOfContext) {
  // An unterminated string of 444 000 characters: the lexer read all of it.
  const std::string text = "{\"name\": \"" + std::string(444000, 'a') + "\n";
  try {
    parseScene(text, "bad.json");
    ADD_FAILURE() << "accepted";
  } catch (const SceneFileError& e) {
    const std::string what = e.what();
    EXPECT_LT(what.size(), 300u) << what.substr(0, 300);
    EXPECT_NE(what.find("syntax error"), std::string::npos) << what;
    EXPECT_NE(what.find("last read: '..."), std::string::npos) << what;
    EXPECT_EQ(e.line(), 1);
  }
}

// ---- Distributions, spawn regions, counts, material ---------------------------------------------

TEST(SceneLimits, MeanOutsideItsTruncationIsRefused) {
  refused(replaced(kGood, R"("mean": 0.004)", R"("mean": 0.01)"), "parts[1].size[0].mean",
          {"0.01", "must lie in [min, max] = [0.003, 0.005]"});
}

TEST(SceneLimits, MinAboveMaxIsRefused) {
  refused(replaced(kGood, R"("min": 0.003, "max": 0.005)", R"("min": 0.006, "max": 0.005)"),
          "parts[1].size[0].max", {"0.005", "must be >= min (0.006)"});
}

TEST(SceneLimits, NegativeStddevIsRefused) {
  refused(replaced(kGood, R"("stddev": 0.0005)", R"("stddev": -0.0005)"), "parts[1].size[0].stddev",
          {"must be >= 0", "-0.0005"});
}

TEST(SceneLimits, InvertedSpawnRegionNamesTheAxis) {
  refused(
      replaced(kGood, R"("spawn_max": [0.1, 0.05, 0.003])", R"("spawn_max": [0.1, -0.05, 0.003])"),
      "parts[0].spawn_max.y", {"-0.05", "must be >= spawn_min.y (0)"});
}

TEST(SceneLimits, PartCountBeyondTheGeomCapIsRefused) {
  refused(replaced(kGood, R"("count": 3)", R"("count": 100000)"), "parts[0].count",
          {"100000", "[1, 4096]"});
  // In full, not 1e+06; and a count beyond an int is said to be too large, not "not an integer".
  refused(replaced(kGood, R"("count": 3)", R"("count": 1000000)"), "parts[0].count",
          {"got 1000000", "[1, 4096]"});
  refused(replaced(kGood, R"("count": 3)", R"("count": 3000000000)"), "parts[0].count",
          {"between -2e9 and 2e9", "3000000000"});
}

TEST(SceneLimits, PartsAndFixtureGeomsTogetherBeyondTheGeomCapAreRefused) {
  // 4 fixture geoms + 4091 boxes + 1 sphere = 4096 is the largest allowed total (spawned over
  // time, so that they need no room at t = 0).
  const std::string flow = R"("count": 3, "rate": 1000)";
  EXPECT_NO_THROW(parseScene(replaced(kGood, R"("count": 3)", replaced(flow, "3", "4091")), "ok"));
  refused(replaced(kGood, R"("count": 3)", replaced(flow, "3", "4092")), "parts[1].count",
          {"brings the scene to 4097 geoms", "at most 4096"});
}

TEST(SceneLimits, FixtureGeomsBeyondTheGeomCapAreRefused) {
  std::string geoms;
  for (int i = 0; i < 4100; ++i) {
    geoms += std::string(i ? ", " : "") + R"({"shape": "sphere", "radius": 0.01, "position": [)" +
             std::to_string(0.03 * i) + ", 5, 0]}";
  }
  refused(replaced(kGood, R"({"shape": "plane", "normal": [0, 0, 1], "offset": -0.5})", geoms),
          "fixtures[3].geoms", {"4103 fixture geoms", "at most 4096 geoms"});
}

TEST(SceneLimits, FrictionAndRestitutionOutsideTheirRangesAreRefused) {
  refused(replaced(kGood, R"("mu": 0.5)", R"("mu": 100)"), "material.mu", {"100", "[0, 10]"});
  refused(replaced(kGood, R"("restitution": 0.1)", R"("restitution": 1.5)"), "material.restitution",
          {"must be in [0, 1]", "1.5"});
}

TEST(SceneLimits, SurfaceLayerBeyondTheSizeBoundIsRefused) {
  refused(replaced(kGood, R"("surface_layer": 1e-4)", R"("surface_layer": 1e4)"),
          "solver.surface_layer", {"10000", "[0, 1000] m"});
}

TEST(SceneLimits, RheonomicTimeStepOutsideTheStepRangeIsRefused) {
  refused(replaced(kGood, R"("surface_layer": 1e-4)",
                   R"("surface_layer": 1e-4, "rheonomic_time_step": 1e-9)"),
          "solver.rheonomic_time_step", {"1e-09", "[1e-06, 1]"});
}

// ---- Scene files: kinds, sizes, contents
// ---------------------------------------------------------

TEST(SceneFileLimits, FifoIsRefusedWithoutBlocking) {
  const fs::path fifo = tempDir() / "scene.fifo";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  fileRefused(fifo, "is a FIFO (named pipe), not a regular file");  // would block if opened
  fs::remove(fifo);
}

TEST(SceneFileLimits, DirectoryIsRefusedAsADirectory) {
  fileRefused(tempDir(), "is a directory, not a regular file");
}

TEST(SceneFileLimits, DevZeroIsRefusedAsADevice) {
  if (!fs::exists("/dev/zero")) GTEST_SKIP() << "no /dev/zero on this system";
  fileRefused("/dev/zero", "is a character device, not a regular file");
}

TEST(SceneFileLimits, SocketIsRefused) {
  const fs::path path = tempDir() / "scene.sock";
  fs::remove(path);
  const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  ASSERT_LT(path.string().size(), sizeof(address.sun_path)) << "temp path too long for a socket";
  std::strncpy(address.sun_path, path.c_str(), sizeof(address.sun_path) - 1);
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0)
      << std::strerror(errno);
  fileRefused(path, "is a socket, not a regular file");
  close(fd);
  fs::remove(path);
}

TEST(SceneFileLimits, MissingFileIsRefused) {
  fileRefused(tempDir() / "no_such_scene.json", "file not found");
}

TEST(SceneFileLimits, EmptyFileIsRefused) {
  fileRefused(writeFile("empty.json", ""), "the file is empty");
}

TEST(SceneFileLimits, FileBeyondTheSizeCapIsRefusedBeforeReading) {
  const fs::path big = tempDir() / "big.json";
  std::ofstream(big) << "{}";
  fs::resize_file(big, (16u << 20) + 1);  // sparse: nothing is written
  fileRefused(big, "at most 16777216 bytes (16 MiB)");
  fs::remove(big);
}

TEST(SceneFileLimits, TruncatedFileIsASyntaxErrorNamingTheFile) {
  const std::string text = kGood;
  fileRefused(writeFile("truncated.json", text.substr(0, text.size() / 2)), "syntax error");
}

TEST(SceneFileLimits, WrongTypeInAFileNamesFileAndPath) {
  const fs::path file =
      writeFile("wrong_type.json", replaced(kGood, R"("duration": 1)", R"("duration": "long")"));
  fileRefused(file, "duration: expected a number, got \"long\"");
}

TEST(SceneFileLimits, LimitRefusalFromAFileNamesFilePathValueAndRange) {
  const fs::path file =
      writeFile("dense.json", replaced(kGood, R"("density": 7800)", R"("density": 1e300)"));
  fileRefused(file, file.string() +
                        ": parts[0].density: must be a finite number in [0.001, "
                        "1e+06] kg/m^3 (got 1e+300)");
}

// ---- Meshes ------------------------------------------------------------------------------------

// A closed box mesh (OBJ) of edges a x b x c centred on the origin.
std::string boxObj(double a, double b, double c) {
  std::ostringstream text;
  text.precision(17);
  for (int i = 0; i < 8; ++i) {
    text << "v " << (i & 1 ? 0.5 : -0.5) * a << " " << (i & 2 ? 0.5 : -0.5) * b << " "
         << (i & 4 ? 0.5 : -0.5) * c << "\n";
  }
  // Faces counter-clockwise seen from outside (1-based indices).
  text << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  return text.str();
}

template <class E, class F>
void expectThrowWith(F call, std::initializer_list<std::string> parts) {
  try {
    call();
    ADD_FAILURE() << "no exception";
  } catch (const E& e) {
    for (const std::string& part : parts) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "message: " << e.what() << "\nmissing: " << part;
    }
  }
}

TEST(MeshLimits, TheTestBoxWrittenHereIsASolid) {  // guards the next tests' mesh writer
  const MassProperties p =
      massProperties(loadTriangleMesh(writeFile("box.obj", boxObj(1, 2, 3))), 1);
  EXPECT_NEAR(p.volume, 6.0, 1e-9);
}

TEST(MeshLimits, FifoMeshIsRefusedWithoutBlocking) {
  const fs::path fifo = tempDir() / "mesh.fifo";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  expectThrowWith<std::runtime_error>([&] { loadTriangleMesh(fifo); },
                                      {fifo.string(), "is a FIFO (named pipe)"});
  fs::remove(fifo);
}

TEST(MeshLimits, DirectoryMeshIsRefused) {
  expectThrowWith<std::runtime_error>([] { loadTriangleMesh(tempDir()); },
                                      {"is a directory, not a regular file"});
}

TEST(MeshLimits, MeshFileBeyondTheSizeCapIsRefusedBeforeReading) {
  const fs::path big = tempDir() / "big.stl";
  std::ofstream(big) << "solid x";
  fs::resize_file(big, (256u << 20) + 1);  // sparse
  expectThrowWith<std::runtime_error>([&] { loadTriangleMesh(big); },
                                      {big.string(), "at most 268435456 bytes (256 MiB)"});
  fs::remove(big);
}

TEST(MeshLimits, FlatPartMeshIsRefusedAsDegenerate) {
  // 1 m x 1 m x 1 nm: closed and outward, but its volume is 4e-10 of its bounding sphere's.
  const TriangleMesh flat = loadTriangleMesh(writeFile("flat.obj", boxObj(1, 1, 1e-9)));
  expectThrowWith<std::invalid_argument>([&] { massProperties(flat, 1000); },
                                         {"flat.obj", "degenerate solid", "at least 1e-06"});
}

TEST(MeshLimits, DegeneratePartMeshInASceneNamesThePart) {
  const fs::path flat = writeFile("flat_part.obj", boxObj(0.1, 0.1, 1e-10));
  const std::string text = R"({"parts": [{"shape": "mesh", "mesh": ")" + flat.string() +
                           R"(", "spawn_min": [0, 0, 1], "spawn_max": [0, 0, 1]}]})";
  refused(text, "parts[0].mesh", {"degenerate solid"});
}

TEST(MeshLimits, PartMeshScaledBelowTheSizeRangeIsRefused) {
  const fs::path box = writeFile("part_box.obj", boxObj(0.02, 0.02, 0.02));
  const std::string text =
      R"({"parts": [{"shape": "mesh", "mesh": ")" + box.string() +
      R"(", "size": [1e-6], "spawn_min": [0, 0, 1], "spawn_max": [0, 0, 1]}]})";
  refused(text, "parts[0].size[0].mean", {"1e-06", "[1e-05, 1000] m"});
}

TEST(MeshLimits, FixtureMeshScaledBeyondTheSizeRangeIsRefused) {
  const fs::path box = writeFile("fixture_box.obj", boxObj(1, 1, 1));
  const std::string text = R"({"fixtures": [{"geoms": [{"shape": "mesh", "mesh": ")" +
                           box.string() +
                           R"(", "scale": 1e4}]}], "parts": [{"shape": "sphere", "size": [0.01],
          "spawn_min": [0, 0, 1e4], "spawn_max": [0, 0, 1e4]}]})";
  refused(text, "fixtures[0].geoms[0].mesh", {"diagonal 17320.50808 m", "[1e-05, 1000] m"});
}

TEST(MeshLimits, FixtureMeshPlacedBeyondTheHashSpaceIsRefused) {
  const fs::path box = writeFile("far_box.obj", boxObj(1, 1, 1));
  const std::string text =
      R"({"fixtures": [{"geoms": [{"shape": "mesh", "mesh": ")" + box.string() +
      R"(", "position": [999999.5, 0, 0]}]}], "parts": [{"shape": "sphere", "size": [0.01],
          "spawn_min": [0, 0, 1], "spawn_max": [0, 0, 1]}]})";
  refused(text, "fixtures[0].geoms[0].mesh",
          {"reach 1000000.366 m", "along x", "[-1e+06, 1e+06] m"});
}

}  // namespace
}  // namespace rheofeed::scene
