// SPDX-License-Identifier: MIT
// output.cpp: files written atomically and the feeder metrics' CSV and JSON, read back (the
// JSON with nlohmann-json, the CSV split by hand) and compared with the metrics written.
#include "rheofeed/output/output.hpp"
#include "rheofeed/output/plot.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The files print rates and times with eight significant digits (%.8g): half a unit of the
// eighth digit, relative.
constexpr double kEightDigits = 5e-8;
// Window bounds are printed with six decimals (%.6f): half a unit of the sixth, in seconds.
constexpr double kSixDecimals = 5e-7;

// A fresh, empty folder for one test.
fs::path freshFolder(const std::string& name) {
  const fs::path folder = fs::path(testing::TempDir()) / ("rheofeed_output_test_" + name);
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> fileNames(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    names.push_back(entry.path().filename().string());
  }
  return names;
}

// CSV rows split at commas outside double quotes ("" inside quotes is one quote).
std::vector<std::vector<std::string>> parseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (c == '"' && quoted && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = !quoted;
      } else if (c == ',' && !quoted) {
        cells.emplace_back();
      } else {
        cells.back() += c;
      }
    }
    rows.push_back(cells);
  }
  return rows;
}

// Three exits at 1.25, 2.5 and 3.75 s in two windows of 2 s; three families, the third with the
// first one's name; a family name with a comma and a quote for the CSV's quoting.
FeederMetrics feeder() {
  FeederMetrics f;
  f.exit_plane = true;
  f.up = {0, 0, 1};
  f.exit_times = {1.25, 2.5, 3.75};
  f.first_exit_time = 1.25;
  f.mean_rate_per_min = 48;  // (3 - 1) exits / (3.75 - 1.25) s x 60
  f.rate_window = 2;
  f.rate = {{0, 2, 1, 30, 1}, {2, 4, 2, 60, 3}};
  f.spawned_beyond_exit = 1;
  FamilyExits cubes;
  cubes.name = "cubes";
  cubes.shape = Shape::Kind::Box;
  cubes.spawned = 5;
  cubes.exited = 2;
  cubes.removed_without_exit = 1;
  cubes.lost_before_exit = 2;
  cubes.up_axis = {0, 0, 0, 0, 2, 0};
  FamilyExits balls;
  balls.name = "nut, \"M6\"";
  balls.shape = Shape::Kind::Sphere;
  balls.spawned = 3;
  balls.exited = 1;
  balls.up_axis = {1, 0, 0, 0, 0, 0};
  balls.orientation_meaningful = false;
  FamilyExits again = cubes;
  again.spawned = 4;
  again.exited = 0;
  again.removed_without_exit = 0;
  again.lost_before_exit = 0;
  again.up_axis = {};
  f.families = {cubes, balls, again};
  return f;
}

TEST(WriteFileAtomically, WritesTheTextAndLeavesNoTemporaryFile) {
  const fs::path folder = freshFolder("write");
  const fs::path path = folder / "sub" / "run.csv";  // the folder is created
  writeFileAtomically(path, "a,b\n1,2\n");
  EXPECT_EQ(readFile(path), "a,b\n1,2\n");
  writeFileAtomically(path, "x\n");  // a shorter text replaces the whole file
  EXPECT_EQ(readFile(path), "x\n");
  EXPECT_EQ(fileNames(folder / "sub"), std::vector<std::string>{"run.csv"});
}

TEST(WriteFileAtomically, AFailedRenameThrowsNamingThePathAndLeavesNoPartialFile) {
  const fs::path folder = freshFolder("rename");
  const fs::path path = folder / "taken";
  fs::create_directories(path / "inside");  // a non-empty folder where the file should go
  try {
    writeFileAtomically(path, "text");
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(fileNames(folder), std::vector<std::string>{"taken"});  // no "taken.partial"
  EXPECT_TRUE(fs::is_directory(path / "inside"));
}

// Writers of one path at the same time (sweep jobs sharing a drift table): the file always holds
// one writer's whole text, and no temporary file is left.
TEST(WriteFileAtomically, ConcurrentWritersLeaveOneWholeText) {
  const fs::path folder = freshFolder("concurrent");
  const fs::path path = folder / "table.json";
  std::vector<std::string> texts;
  for (char c : {'a', 'b', 'c', 'd'}) texts.push_back(std::string(200000, c) + "\n");
  std::vector<std::thread> writers;
  for (const std::string& text : texts) {
    writers.emplace_back([&path, &text] {
      for (int k = 0; k < 20; ++k) writeFileAtomically(path, text);
    });
  }
  for (std::thread& t : writers) t.join();
  const std::string final_text = readFile(path);
  EXPECT_NE(std::find(texts.begin(), texts.end(), final_text), texts.end())
      << "a mix of " << final_text.size() << " bytes";
  EXPECT_EQ(fileNames(folder), std::vector<std::string>{"table.json"});
}

TEST(WriteFileAtomically, AFolderThatCannotBeCreatedThrowsNamingIt) {
  const fs::path folder = freshFolder("nofolder");
  writeFileAtomically(folder / "file", "plain file");
  try {
    writeFileAtomically(folder / "file" / "run.json", "{}");
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((folder / "file").string()), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(readFile(folder / "file"), "plain file");
  EXPECT_EQ(fileNames(folder), std::vector<std::string>{"file"});
}

// A plot whose file name holds a quote is written, and leaves nothing else beside it (gnuplot
// read the name up to the quote, failed, and left a stray file named by its first part).
TEST(PlotPng, AQuoteInTheFileNameIsWrittenAndLeavesNothingElse) {
  const fs::path folder = freshFolder("plot_quote");
  const fs::path path = folder / "o'k.png";
  ASSERT_TRUE(plotPng("set datafile separator ','\nplot $d using 1:2 with lines",
                      {{"d", "x,y\n0,0\n1,1\n"}}, path.string()));
  EXPECT_EQ(fileNames(folder), std::vector<std::string>{"o'k.png"});
}

// Without gnuplot (not on the PATH), a plot whose data fill more than a pipe's buffer fails and
// says so: the process is not killed by SIGPIPE, and no file is left.
TEST(PlotPng, WithoutGnuplotALargePlotFailsWithoutKillingTheProcess) {
  const fs::path folder = freshFolder("plot_nognuplot");
  std::string csv = "x,y\n";
  for (int k = 0; k < 20000; ++k) csv += std::to_string(k) + "," + std::to_string(k % 7) + "\n";
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path ? old_path : "";
  ::setenv("PATH", (folder / "nothing_here").c_str(), 1);
  const bool written = plotPng("plot $d using 1:2", {{"d", csv}}, (folder / "big.png").string());
  ::setenv("PATH", saved.c_str(), 1);
  EXPECT_FALSE(written);
  EXPECT_TRUE(fileNames(folder).empty());
}

TEST(JsonQuoted, EscapesQuotesBackslashesAndControlCharacters) {
  const std::string text = "a \"b\" \\ c\nd\te\x01";
  EXPECT_EQ(json::parse(jsonQuoted(text)).get<std::string>(), text);
}

TEST(ExitsCsv, OneRowPerRateWindowReadsBackAsTheWindows) {
  const FeederMetrics f = feeder();
  const auto rows = parseCsv(exitsCsv(f));
  ASSERT_EQ(rows.size(), 1 + f.rate.size());
  EXPECT_EQ(rows[0], (std::vector<std::string>{"window_start_s", "window_end_s", "exits",
                                               "rate_per_min", "cumulative_exits"}));
  for (std::size_t k = 0; k < f.rate.size(); ++k) {
    const auto& r = rows[k + 1];
    ASSERT_EQ(r.size(), 5u);
    EXPECT_NEAR(std::stod(r[0]), f.rate[k].start, kSixDecimals);
    EXPECT_NEAR(std::stod(r[1]), f.rate[k].end, kSixDecimals);
    EXPECT_EQ(std::stoi(r[2]), f.rate[k].exits);
    EXPECT_NEAR(std::stod(r[3]), f.rate[k].rate_per_min, kEightDigits * f.rate[k].rate_per_min);
    EXPECT_EQ(std::stoi(r[4]), f.rate[k].cumulative);
  }
}

TEST(OrientationCsv, OneRowPerFamilyWithItsCountsAndHistogram) {
  const FeederMetrics f = feeder();
  const auto rows = parseCsv(orientationCsv(f));
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0],
            (std::vector<std::string>{
                "family", "shape", "spawned", "exited", "removed_without_exit", "lost_before_exit",
                "orientation_meaningful", "+x", "-x", "+y", "-y", "+z", "-z"}));
  EXPECT_EQ(rows[1], (std::vector<std::string>{"cubes", "box", "5", "2", "1", "2", "true", "0", "0",
                                               "0", "0", "2", "0"}));
  // The comma and the quotes survive the CSV quoting; the repeated name gets its index.
  EXPECT_EQ(rows[2], (std::vector<std::string>{"nut, \"M6\"", "sphere", "3", "1", "0", "0", "false",
                                               "1", "0", "0", "0", "0", "0"}));
  EXPECT_EQ(rows[3][0], "cubes[2]");
  EXPECT_EQ(rows[3][2], "4");
}

TEST(FeederJson, ParsesToTheMetricsWritten) {
  const FeederMetrics f = feeder();
  const json j = json::parse(feederJson(f));
  EXPECT_EQ(j["exit_plane"], true);
  EXPECT_EQ(j["up"], json::array({0.0, 0.0, 1.0}));
  EXPECT_DOUBLE_EQ(j["first_exit_time_s"].get<double>(), 1.25);
  EXPECT_TRUE(j["note"].is_null());
  EXPECT_NEAR(j["mean_exit_rate_per_min"].get<double>(), 48, kEightDigits * 48);
  EXPECT_DOUBLE_EQ(j["rate_window_s"].get<double>(), 2);
  EXPECT_EQ(j["parts_exited"], 3);
  EXPECT_EQ(j["spawned_beyond_exit"], 1);
  ASSERT_EQ(j["exit_rate_per_min"].size(), 2u);
  const json& w = j["exit_rate_per_min"][1];
  EXPECT_DOUBLE_EQ(w["t_s"].get<double>(), 3);  // the window's centre
  EXPECT_DOUBLE_EQ(w["t_start_s"].get<double>(), 2);
  EXPECT_DOUBLE_EQ(w["t_end_s"].get<double>(), 4);
  EXPECT_EQ(w["exits"], 2);
  EXPECT_DOUBLE_EQ(w["rate_per_min"].get<double>(), 60);
  EXPECT_EQ(w["cumulative_exits"], 3);
  EXPECT_EQ(j["exit_times_s"], json::array({1.25, 2.5, 3.75}));
  ASSERT_EQ(j["families"].size(), 3u);
  EXPECT_EQ(j["families"]["cubes"]["shape"], "box");
  EXPECT_EQ(j["families"]["cubes"]["spawned"], 5);
  EXPECT_EQ(j["families"]["cubes"]["exited"], 2);
  EXPECT_EQ(j["families"]["cubes"]["removed_without_exit"], 1);
  EXPECT_EQ(j["families"]["cubes"]["lost_before_exit"], 2);
  EXPECT_EQ(j["families"]["nut, \"M6\""]["orientation_meaningful"], false);
  EXPECT_EQ(j["families"]["cubes[2]"]["spawned"], 4);
  EXPECT_EQ(j["exit_orientation"]["cubes"]["+z"], 2);
  EXPECT_EQ(j["exit_orientation"]["nut, \"M6\""]["+x"], 1);
  EXPECT_EQ(j["exit_orientation"]["cubes[2]"].size(), 6u);
}

TEST(FeederJson, NumbersThatAreMissingAreNullAndTheNoteSaysWhy) {
  FeederMetrics f;
  f.exit_plane = true;
  f.note = "no part reached the exit in 3 s";
  f.rate_window = 0.5;
  const json j = json::parse(feederJson(f));
  EXPECT_TRUE(j["first_exit_time_s"].is_null());  // NaN: no exit
  EXPECT_TRUE(j["mean_exit_rate_per_min"].is_null());
  EXPECT_EQ(j["note"], f.note);
  EXPECT_EQ(j["parts_exited"], 0);
  EXPECT_TRUE(j["exit_times_s"].empty());
}

TEST(WriteFeederOutputs, WritesBothCsvFilesWithAnExitPlaneAndNothingWithout) {
  const fs::path folder = freshFolder("feeder");
  const FeederMetrics f = feeder();
  const std::vector<std::string> written = writeFeederOutputs(f, folder, "run", "test");
  ASSERT_GE(written.size(), 2u);
  EXPECT_EQ(readFile(folder / "run_exits.csv"), exitsCsv(f));
  EXPECT_EQ(readFile(folder / "run_orientation.csv"), orientationCsv(f));
  for (const std::string& name : fileNames(folder)) {
    EXPECT_EQ(name.find(".partial"), std::string::npos) << name;
  }
  FeederMetrics none = f;
  none.exit_plane = false;
  const fs::path empty = freshFolder("feeder_none");
  EXPECT_TRUE(writeFeederOutputs(none, empty, "run", "test").empty());
  EXPECT_TRUE(fileNames(empty).empty());
}

}  // namespace
}  // namespace rheofeed::scene
