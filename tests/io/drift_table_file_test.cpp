// SPDX-License-Identifier: MIT
// Drift table files (rheofeed/scene/drift_table_file.hpp): a table written and read back gives
// the same drifts bit for bit without running the point-mass model; files that are not a table
// of this build's settings, or are malformed, are refused by path and key, adding nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "rheofeed/scene/drift_table_file.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "rheofeed/vibration_drift.hpp"

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;

PointMassSettings coarse() {
  PointMassSettings s;
  s.steps_per_cycle = 1024;
  return s;
}

fs::path writeText(const std::string& name, const std::string& text) {
  const fs::path path = fs::temp_directory_path() / ("rheofeed_drift_table_" + name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A filled table: a few points on and off the grid lines, two friction coefficients.
std::vector<PointMassParams> fill(LocalDriftTable& table) {
  std::vector<PointMassParams> points;
  for (int i = 0; i < 6; ++i) {
    PointMassParams p;
    p.normal_throw = 0.4 + 0.27 * i;
    p.tangential_throw = 1.1 + 0.31 * i;
    p.slope_along = i % 3 ? 0.013 * i : 0.0;
    p.slope_across = i % 2 ? 0.021 : 0.0;
    p.mu = i % 2 ? 0.35 : 0.5;
    table.drift(p);
    points.push_back(p);
  }
  return points;
}

// The message of the SceneFileError that loading `path` throws ("" when none).
std::string loadError(const fs::path& path, LocalDriftTable& table) {
  try {
    loadDriftTable(path, table);
  } catch (const SceneFileError& e) {
    EXPECT_EQ(e.source(), path.string());
    return e.what();
  }
  return "";
}

TEST(DriftTableFile, WrittenAndReadBackGivesTheSameDriftsWithoutModelRuns) {
  LocalDriftTable first(coarse());
  const std::vector<PointMassParams> points = fill(first);
  const fs::path path = writeText("roundtrip.json", driftTableJson(first));
  LocalDriftTable second(coarse());
  EXPECT_EQ(loadDriftTable(path, second), first.numCorners());
  for (const PointMassParams& p : points) {
    EXPECT_EQ(second.drift(p).along, first.drift(p).along);
    EXPECT_EQ(second.drift(p).across, first.drift(p).across);
  }
  EXPECT_EQ(second.stats().model_runs, 0);
  // Written again, the table is the same text.
  EXPECT_EQ(driftTableJson(second), driftTableJson(first));
  fs::remove(path);
}

TEST(DriftTableFile, RefusesFilesOfOtherSettingsOrMalformed) {
  LocalDriftTable source(coarse());
  fill(source);
  const std::string good = driftTableJson(source);
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  struct Case {
    std::string name, text, expected;
  };
  const std::vector<Case> cases = {
      {"syntax.json", "{\"format\": ", "syntax error"},
      {"scene.json", "{\"name\": \"a scene\"}", "format: must be \"rheofeed local drift table\""},
      {"revision.json", replaced("\"model_revision\":1", "\"model_revision\":0"),
       "model_revision: is 0; this build's point-mass model is revision 1"},
      {"settings.json", replaced("\"steps_per_cycle\":1024", "\"steps_per_cycle\":2048"),
       "point_mass_settings.steps_per_cycle: is 2048 in the file and 1024 in this build"},
      {"grid.json", replaced("\"slope\":0.02", "\"slope\":0.01"),
       "grid_steps.slope: is 0.01 in the file and 0.02 in this build"},
      {"row.json", replaced("\n[", "\n[1,2,3,"), "corners[0]: must be an array of 8 numbers"},
      {"valid.json", replaced(",1]\n", ",2]\n"), "][7]: must be 0 or 1, found 2"},
      {"mu.json", replaced("\n[", "\n[0,0,0,0,-1,0,0,1],\n["), "corners[0][4]: mu must be >= 0"},
      {"negative.json", replaced("\n[", "\n[-5,0,0,0,0.5,0,0,1],\n["),
       "corners[0][0]: must be >= 0, found -5"},
      {"twice.json", replaced("\n[", "\n[0,0,0,0,0.5,0,0,1],\n[0,0,0,0,0.5,1,0,1],\n["),
       "corners[1]: the same grid point and mu as corners[0]"},
      {"unknown.json", replaced("\"format\"", "\"note\":1,\"format\""), "note: unknown key"},
      {"columns.json", replaced("\"valid\"]", "\"ok\"]"), "columns: must be ["},
      {"no_grid.json", replaced("\"grid_steps\"", "\"grid\""), "grid_steps: is missing"},
  };
  for (const Case& c : cases) {
    const fs::path path = writeText(c.name, c.text);
    LocalDriftTable table(coarse());
    const std::string message = loadError(path, table);
    EXPECT_NE(message.find(path.string()), std::string::npos) << c.name << ": " << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.name << ": " << message;
    EXPECT_EQ(table.numCorners(), 0u) << c.name;
    fs::remove(path);
  }
  LocalDriftTable table(coarse());
  const fs::path missing = fs::temp_directory_path() / "rheofeed_drift_table_missing.json";
  fs::remove(missing);
  EXPECT_NE(loadError(missing, table).find("file not found"), std::string::npos);
  EXPECT_NE(loadError(fs::temp_directory_path(), table).find("directory"), std::string::npos);
}

// A scene file's "drift_table" names a table relative to the scene's folder: loading the scene
// reads its corners (exactly the file's), makes the name absolute so that the scene written
// elsewhere still finds it, and writes it back; an empty name or a malformed table is an error
// naming the scene, the key and the table's own problem; a table that is not there is noted.
TEST(DriftTableFile, SceneFileNamesItsTableRelativeToItsFolder) {
  const fs::path folder = fs::temp_directory_path() / "rheofeed_scene_drift_table";
  fs::remove_all(folder);
  fs::create_directories(folder / "tables");
  // The process's table settings: a scene's table adds to LocalDriftTable::shared().
  LocalDriftTable filled(LocalDriftTable::shared()->settings());
  PointMassParams p;
  p.normal_throw = 1.2;
  p.tangential_throw = 2.0;
  p.mu = 0.4;
  filled.drift(p);  // one cell on the level: its 4 corners
  ASSERT_GT(filled.numCorners(), 0u);
  std::ofstream(folder / "tables" / "t.json", std::ios::binary) << driftTableJson(filled);
  const std::string base = R"({"drift_table": "NAME",
    "fixtures": [{"geoms": [{"shape": "box", "size": [1, 0.1, 0.02]}],
                  "law": {"vibration": {"amplitude": 2e-4, "frequency": 50}}}],
    "parts": [{"shape": "box", "size": [0.02, 0.02, 0.005],
               "spawn_min": [0, 0, 0.02], "spawn_max": [0, 0, 0.02]}]})";
  auto write = [&](const std::string& name) {
    std::string text = base;
    text.replace(text.find("NAME"), 4, name);
    const fs::path file = folder / "scene.json";
    std::ofstream(file, std::ios::binary) << text;
    return file;
  };
  const Scene scene = loadScene(write("tables/t.json"));
  ASSERT_NE(scene.drift_table_corners, nullptr);
  ASSERT_EQ(scene.drift_table_corners->size(), filled.numCorners());
  const std::vector<DriftTableCorner> expected = filled.corners();
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ((*scene.drift_table_corners)[k].along, expected[k].along) << k;
    EXPECT_EQ((*scene.drift_table_corners)[k].across, expected[k].across) << k;
  }
  EXPECT_EQ(fs::path(scene.drift_table), fs::absolute(folder / "tables" / "t.json"));
  EXPECT_NE(toJson(scene).find("\"drift_table\": \"" + scene.drift_table + "\""),
            std::string::npos);

  std::ofstream(folder / "tables" / "bad.json", std::ios::binary) << "{\"format\": 1}";
  const std::pair<const char*, const char*> refused[] = {
      {"", "empty file name"}, {"tables/bad.json", "not a drift table file"}};
  for (const auto& [name, problem] : refused) {
    SCOPED_TRACE(name);
    try {
      loadScene(write(name));
      ADD_FAILURE() << "no error";
    } catch (const SceneFileError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("scene.json: drift_table: "), std::string::npos) << message;
      EXPECT_NE(message.find(problem), std::string::npos) << message;
    }
  }
  // A table that is not there (the scene copied without it) is noted, not refused.
  const Scene copied = loadScene(write("tables/none.json"));
  EXPECT_EQ(copied.drift_table_corners, nullptr);
  EXPECT_NE(copied.drift_table_problem.find("none.json: file not found, not read"),
            std::string::npos)
      << copied.drift_table_problem;
  fs::remove_all(folder);
}

}  // namespace
}  // namespace rheofeed::scene
