// SPDX-License-Identifier: MIT
// run_outputs.cpp: a run's series CSV and JSON summary read back (the JSON with nlohmann-json)
// and compared with the RunMetrics written; writeRunOutputs leaves complete files only.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "rheofeed/output/output.hpp"

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The CSV's drift numbers are printed with eight significant digits (%.8g): half a unit of the
// eighth. (The JSON's numbers round-trip: they are compared exactly.)
constexpr double kEightDigits = 5e-8;
// Times in the CSV have six decimals (%.6f), in seconds.
constexpr double kSixDecimals = 5e-7;

RunMetrics run() {
  RunMetrics r;
  r.scene = "trough \"A\"";
  r.method = Method::ReferenceRheonomic;
  r.time_step = 0.01;
  r.seed = std::numeric_limits<std::uint64_t>::max();  // every bit of the seed survives
  r.drift_models = {"track: local", "bowl: calibrated_drift"};
  DriftField bowl;
  bowl.fixture = "bowl";
  bowl.drift_model = "calibrated_drift";
  bowl.calibrated_drift = Twist{{0, 0, 0}, {0, 0, 0.3125}, {0.5, -0.25, 0}};
  r.drift_fields = {DriftField{"track", "local", {}, std::nullopt}, bowl};
  r.calibration_warnings = {"fixture 'bowl': the calibrated drift 0.3125 +- 0.0625 is known"};
  r.angular = false;
  DriftSample a;
  a.time = 0.5;
  a.parts = 12;
  a.mean_velocity = 0.0123456789;
  a.ci95 = 0.00087654321;
  a.mean_height = 0.0051;
  a.exited = 1;
  a.fell = 2;
  DriftSample b = a;
  b.time = 1.0;
  b.parts = 11;
  b.mean_velocity = -0.002;
  b.through_fixture = 1;
  b.out_of_bounds = 3;
  b.nonfinite = 4;
  b.too_fast = 5;
  r.series = {a, b};
  r.mean_drift = 0.0234567891;
  r.mean_drift_ci95 = 0.0012345678;
  r.vertical_displacement = -0.0004;
  r.displacement_parts = 12;
  r.throughput = 1.5;
  r.parts = 12;
  r.drift_parts = 12;
  r.cpu_seconds = 2.5;
  r.simulated_seconds = 10;
  r.warmup = 1.5;
  r.real_time_factor = 0.25;
  RunHealth& h = r.health;
  h.steps = 1000;
  h.parts_exited = 1;
  h.parts_fell = 2;
  h.parts_through_fixture = 1;
  h.coulomb_fallback_steps = 30;
  h.solver_unconverged_steps = 4;
  h.friction_dropped_contacts = 7;
  h.friction_model = "cone";
  h.broad_phase = "sweep_and_prune";
  h.gyroscopic_fallback_steps = 2;
  h.max_part_speed = 3.5;
  h.speed_bound = 100;
  h.ignored_settings = {"solver.apgd = true (ODE ignores it)"};
  h.local_law_feeders = 1;
  h.local_law.contacts = 123456789012LL;
  h.local_law.wall_contacts = 5;
  h.local_law.cells_computed = 6;
  h.local_law.model_runs = 7;
  h.local_law.model_cpu_seconds = 0.25;
  h.local_law_corners_at_start = 8;
  r.scene_check = {"tunnelling: step \\ 2\nsafe"};
  r.feeder.note = "the scene has no exit plane";
  return r;
}

std::vector<std::vector<std::string>> csvRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream l(line);
    std::string cell;
    while (std::getline(l, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

TEST(SeriesCsv, OneRowPerSampleReadsBackAsTheSeries) {
  const RunMetrics r = run();
  const auto rows = csvRows(seriesCsv(r));
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{
                         "time_s", "parts", "mean_velocity_mps", "ci95_mps", "mean_height_m",
                         "exited", "lost_fell", "lost_through_fixture", "lost_out_of_bounds",
                         "lost_nonfinite", "lost_too_fast", "lost_left_feeder"}));
  for (std::size_t k = 0; k < r.series.size(); ++k) {
    const DriftSample& d = r.series[k];
    const auto& row = rows[k + 1];
    ASSERT_EQ(row.size(), 12u);
    EXPECT_NEAR(std::stod(row[0]), d.time, kSixDecimals);
    EXPECT_EQ(std::stoi(row[1]), d.parts);
    EXPECT_NEAR(std::stod(row[2]), d.mean_velocity, kEightDigits * std::abs(d.mean_velocity));
    EXPECT_NEAR(std::stod(row[3]), d.ci95, kEightDigits * d.ci95);
    EXPECT_NEAR(std::stod(row[4]), d.mean_height, kEightDigits * d.mean_height);
    const int counts[] = {d.exited,        d.fell,      d.through_fixture,
                          d.out_of_bounds, d.nonfinite, d.too_fast};
    for (int c = 0; c < 6; ++c) EXPECT_EQ(std::stoi(row[5 + c]), counts[c]) << "column " << 5 + c;
  }
}

TEST(SeriesCsv, AnAngularDriftNamesItsUnitRadiansPerSecond) {
  RunMetrics r = run();
  r.angular = true;
  const auto rows = csvRows(seriesCsv(r));
  ASSERT_GE(rows.size(), 1u);
  ASSERT_GE(rows[0].size(), 4u);
  EXPECT_EQ(rows[0][2], "mean_drift_radps");
  EXPECT_EQ(rows[0][3], "ci95_radps");
}

// One part has no spread, so no confidence interval: null in the JSON and an empty CSV field,
// not a 0 that claims certainty.
TEST(SummaryJson, OnePartHasNoConfidenceInterval) {
  RunMetrics r = run();
  r.parts = 1;
  r.drift_parts = 1;
  for (DriftSample& d : r.series) d.parts = 1;
  EXPECT_TRUE(json::parse(summaryJson(r))["mean_drift_ci95"].is_null());
  const std::string csv = seriesCsv(r);
  const std::string row =
      csv.substr(csv.find('\n') + 1, csv.find('\n', csv.find('\n') + 1) - csv.find('\n') - 1);
  EXPECT_NE(row.find(",1,0.012345679,,"), std::string::npos) << row;  // parts, drift, no ci95
}

// Twelve parts spawned, none measured (all lost, or spawned beyond the exit): no mean drift, no
// interval and no vertical displacement - null, not a 0 +- 0 that reads as a feeder standing
// still.
TEST(SummaryJson, NoPartMeasuredHasNoMeanDrift) {
  RunMetrics r = run();
  r.drift_parts = 0;
  r.displacement_parts = 0;
  const json j = json::parse(summaryJson(r));
  EXPECT_TRUE(j["mean_drift"].is_null());
  EXPECT_TRUE(j["mean_drift_ci95"].is_null());
  EXPECT_TRUE(j["vertical_displacement_m"].is_null());
  EXPECT_EQ(j["parts"], 12);
}

// A sample with no part in it (none spawned yet, or all gone) has no mean drift and no mean
// height: empty fields, not 0 m/s at 0 m, which a plot would draw as parts standing on z = 0.
TEST(SeriesCsv, ASampleWithNoPartHasNoDriftAndNoHeight) {
  RunMetrics r = run();
  r.series[0].parts = 0;
  const auto rows = csvRows(seriesCsv(r));
  ASSERT_EQ(rows.size(), 3u);
  ASSERT_EQ(rows[1].size(), 12u);
  EXPECT_EQ(rows[1][1], "0");
  EXPECT_EQ(rows[1][2], "");   // mean drift
  EXPECT_EQ(rows[1][3], "");   // ci95
  EXPECT_EQ(rows[1][4], "");   // mean height
  EXPECT_EQ(rows[1][5], "1");  // the counts are still counts
  EXPECT_NE(rows[2][2], "");   // the next sample has its parts
}

// The verdict on the run's numbers is in the JSON, before them: 3 of the 12 parts lost (fell 2,
// through a fixture 1) is a quarter, more than the default bound of a tenth; a bound of a
// quarter accepts it.
TEST(SummaryJson, SaysWhetherTheRunHasAnAnswer) {
  RunMetrics r = run();
  const std::string text = summaryJson(r);
  const json lossy = json::parse(text)["answer"];
  EXPECT_EQ(lossy["trusted"], false);
  EXPECT_EQ(lossy["why"], json({"lost 3 of 12 parts (25 %), more than max_lost_fraction 0.1"}));
  EXPECT_EQ(lossy["parts_lost"], 3);
  EXPECT_EQ(lossy["lost_fraction"].get<double>(), 0.25);
  EXPECT_EQ(lossy["max_lost_fraction"].get<double>(), 0.1);
  EXPECT_LT(text.find("\"answer\""), text.find("\"mean_drift\""));  // read before the numbers

  r.max_lost_fraction = 0.25;
  const json within = json::parse(summaryJson(r))["answer"];
  EXPECT_EQ(within["trusted"], true);
  EXPECT_EQ(within["why"], json::array());
  EXPECT_EQ(within["max_lost_fraction"].get<double>(), 0.25);

  r.parts = 0;  // no share of nothing
  EXPECT_TRUE(json::parse(summaryJson(r))["answer"]["lost_fraction"].is_null());
}

TEST(SummaryJson, HasAThroughputOnlyThroughAnExitPlane) {
  RunMetrics r = run();
  r.feeder.exit_plane = true;
  EXPECT_DOUBLE_EQ(json::parse(summaryJson(r))["throughput_parts_per_s"].get<double>(), 1.5);
  r.feeder.exit_plane = false;
  EXPECT_TRUE(json::parse(summaryJson(r))["throughput_parts_per_s"].is_null());
}

TEST(SummaryJson, ParsesToTheRunMetricsWritten) {
  const RunMetrics r = run();
  const std::string text = summaryJson(r);
  EXPECT_EQ(text.find('\n'), std::string::npos) << "one line";
  const json j = json::parse(text);
  EXPECT_EQ(j["scene"], r.scene);
  EXPECT_EQ(j["method"], "reference_rheonomic");
  EXPECT_EQ(j["time_step_s"].get<double>(), 0.01);
  EXPECT_EQ(j["parts"], 12);
  EXPECT_EQ(j["drift_unit"], "m/s");
  EXPECT_EQ(j["mean_drift"].get<double>(), r.mean_drift);
  EXPECT_EQ(j["mean_drift_ci95"].get<double>(), r.mean_drift_ci95);
  EXPECT_EQ(j["vertical_displacement_m"].get<double>(), r.vertical_displacement);
  // The scene of run() has no exit plane: no throughput (null, not the 1.5 set in the metrics).
  EXPECT_TRUE(j["throughput_parts_per_s"].is_null());
  EXPECT_EQ(j["drift_parts"], 12);
  EXPECT_DOUBLE_EQ(j["simulated_seconds"].get<double>(), 10);
  // the run's setting written back (simulated seconds, the start of the mean drift's window)
  EXPECT_DOUBLE_EQ(j["warmup_s"].get<double>(), r.warmup);
  EXPECT_EQ(j["seed"].get<std::uint64_t>(), r.seed);
  EXPECT_EQ(j["drift_models"], json(r.drift_models));
  ASSERT_EQ(j["drift_fields"].size(), 2u);
  EXPECT_EQ(j["drift_fields"][0]["fixture"], "track");
  EXPECT_TRUE(j["drift_fields"][0]["efficiency"].is_null());
  EXPECT_TRUE(j["drift_fields"][0]["calibrated_drift"].is_null());
  EXPECT_EQ(j["drift_fields"][1]["drift_model"], "calibrated_drift");
  EXPECT_EQ(j["drift_fields"][1]["calibrated_drift"]["angular_radps"], json({0, 0, 0.3125}));
  EXPECT_EQ(j["drift_fields"][1]["calibrated_drift"]["origin_m"], json({0.5, -0.25, 0}));
  EXPECT_EQ(j["calibration_warnings"], json(r.calibration_warnings));

  const json& h = j["health"];
  EXPECT_EQ(h["steps"], 1000);
  EXPECT_EQ(h["parts_removed_after_exit"], 1);
  EXPECT_EQ(h["parts_lost"], 3);  // fell 2 + through a fixture 1
  EXPECT_EQ(h["parts_fell"], 2);
  EXPECT_EQ(h["parts_through_fixture"], 1);
  EXPECT_EQ(h["coulomb_fallback_steps"], 30);
  EXPECT_EQ(h["coulomb_fallback_share"].get<double>(), 30.0 / 1000);
  EXPECT_EQ(h["solver_unconverged_steps"], 4);
  EXPECT_EQ(h["friction_dropped_contacts"], 7);
  EXPECT_EQ(j["friction"], "cone");
  EXPECT_EQ(j["broad_phase"], "sweep_and_prune");
  EXPECT_EQ(h["gyroscopic_fallback_steps"], 2);
  EXPECT_DOUBLE_EQ(h["max_part_speed_mps"].get<double>(), 3.5);
  EXPECT_DOUBLE_EQ(h["speed_bound_mps"].get<double>(), 100);
  EXPECT_EQ(h["ignored_settings"], json(r.health.ignored_settings));
  EXPECT_EQ(j["scene_check"], json(r.scene_check));  // quotes, backslash and newline escaped

  EXPECT_EQ(j["feeder"]["note"], r.feeder.note);
  EXPECT_EQ(j["feeder"]["exit_plane"], false);
  const json& l = j["local_law"];
  EXPECT_EQ(l["feeders"], 1);
  EXPECT_EQ(l["contacts"].get<long long>(), 123456789012LL);
  EXPECT_EQ(l["wall_contacts"], 5);
  EXPECT_EQ(l["cells_computed"], 6);
  EXPECT_EQ(l["model_runs"], 7);
  EXPECT_EQ(l["model_cpu_s"], 0.25);
  EXPECT_EQ(l["corners_at_start"], 8);
  EXPECT_EQ(l.size(), 7u);  // feeders, contacts, wall_contacts, cells, model runs and CPU, corners
}

// What a user needs to reproduce a run: the version that wrote it (the CMake project's, passed
// to this test by its build).
TEST(SummaryJson, NamesTheVersionThatWroteIt) {
  EXPECT_EQ(json::parse(summaryJson(run()))["rheofeed_version"], RHEOFEED_PROJECT_VERSION);
}

// The scene file a run read, or "built-in" for a scene built in code.
TEST(SummaryJson, NamesTheSceneFileOrBuiltIn) {
  RunMetrics r = run();
  EXPECT_EQ(json::parse(summaryJson(r))["scene_source"], "built-in");  // no file: built in code
  r.scene_file = "/data/scenes/trough \"A\".json";
  EXPECT_EQ(json::parse(summaryJson(r))["scene_source"], r.scene_file);
}

TEST(SummaryJson, SolverHasTheAppliedSettingsAndNullWhereOneDoesNotApply) {
  RunMetrics r = run();
  AppliedSolver& a = r.solver;
  a.engine = "ode";
  a.mode = "quickstep";
  a.iterations = 30;
  a.warm_start = true;
  a.speculative_contacts = false;
  a.erp = 0.2;
  a.cfm = 1e-5;
  a.max_correcting_velocity = 0.5;
  a.surface_layer = 1e-4;
  a.mu = 0.6;
  a.restitution = 0.1;
  const json j = json::parse(summaryJson(r))["solver"];
  EXPECT_EQ(j["engine"], "ode");
  EXPECT_EQ(j["mode"], "quickstep");
  EXPECT_EQ(j["iterations"], 30);
  EXPECT_EQ(j["warm_start"], true);
  EXPECT_EQ(j["speculative_contacts"], false);
  EXPECT_EQ(j["erp"], 0.2);  // numbers round-trip exactly
  EXPECT_EQ(j["cfm"], 1e-5);
  EXPECT_EQ(j["max_correcting_velocity_mps"], 0.5);
  EXPECT_EQ(j["surface_layer_m"], 1e-4);
  EXPECT_EQ(j["surface"], json({{"mu", 0.6}, {"restitution", 0.1}, {"bounce_velocity_mps", 0}}));
  for (const char* key : {"tolerance", "relaxed_solver", "coulomb_iterations", "ipm_rounds"}) {
    ASSERT_TRUE(j.contains(key)) << key;  // present (a sweep's metric pointer finds it), null
    EXPECT_TRUE(j[key].is_null()) << key;
  }
}

// A blown-up part's numbers: null, never "nan" or "inf", which are not JSON.
TEST(SummaryJson, NonFiniteNumbersAreNull) {
  RunMetrics r = run();
  PartEvent e;
  e.part = 3;
  e.kind = "nonfinite";
  e.position = {1, std::numeric_limits<double>::quiet_NaN(), 2};
  e.velocity = {0, 0, std::numeric_limits<double>::infinity()};
  r.health.part_events = {e};
  r.health.max_part_speed = std::numeric_limits<double>::infinity();
  const json j = json::parse(summaryJson(r));
  const json& event = j["health"]["part_events"][0];
  EXPECT_EQ(event["part"], 3);
  EXPECT_EQ(event["position_m"], json({1, nullptr, 2}));
  EXPECT_TRUE(event["velocity_mps"][2].is_null());
  EXPECT_TRUE(j["health"]["max_part_speed_mps"].is_null());
}

TEST(SummaryJson, PartEventsNameTheirFamily) {
  RunMetrics r = run();
  PartEvent e;
  e.part = 3;
  e.family = "M6 nuts";
  e.kind = "fell";
  r.health.part_events = {e};
  PartEvent inside = e;
  inside.part = 4;
  inside.family = "washers";
  inside.kind = "inside_fixture";
  r.health.inside_fixture_now = {inside};
  const json events = json::parse(summaryJson(r))["health"]["part_events"];
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0]["family"], "M6 nuts");
  EXPECT_EQ(events[1]["family"], "washers");
}

TEST(SummaryJson, AngularRunsSayRadiansPerSecond) {
  RunMetrics r = run();
  r.angular = true;
  EXPECT_EQ(json::parse(summaryJson(r))["drift_unit"], "rad/s");
}

TEST(WriteRunOutputs, WritesTheCsvAndTheJsonCompletelyAndNoTemporaryFile) {
  const fs::path folder = fs::path(testing::TempDir()) / "rheofeed_run_outputs_test";
  fs::remove_all(folder);
  const RunMetrics r = run();
  const std::vector<std::string> written = writeRunOutputs(r, folder.string(), "ode");
  ASSERT_GE(written.size(), 2u);
  EXPECT_EQ(written[0], (folder / "ode.csv").string());
  EXPECT_EQ(written[1], (folder / "ode.json").string());
  std::ifstream csv(folder / "ode.csv"), js(folder / "ode.json");
  std::ostringstream csv_text;
  csv_text << csv.rdbuf();
  EXPECT_EQ(csv_text.str(), seriesCsv(r));
  EXPECT_EQ(json::parse(js)["mean_drift"], json::parse(summaryJson(r))["mean_drift"]);
  for (const auto& entry : fs::directory_iterator(folder)) {
    EXPECT_EQ(entry.path().string().find(".partial"), std::string::npos) << entry.path();
  }
}

}  // namespace
}  // namespace rheofeed::scene
